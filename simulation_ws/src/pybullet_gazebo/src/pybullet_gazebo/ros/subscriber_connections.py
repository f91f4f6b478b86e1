"""One connection from each of this process's subscribers to each publisher.

rospy connects a subscriber to the publishers of a topic in a new thread per publisher for
every publisher list the master sends (rospy.impl.registration.RegManager.run), and each
thread first checks that the subscriber has no connection to that publisher yet
(masterslave.ROSHandler._connect_topic). Nodes that start together make the master send
several lists in quick succession, so two threads can both find no connection and both
connect. rospy then keeps the later connection and closes the earlier one, at both ends,
and whatever had already arrived on the earlier one is lost.

In the simulator that loses the first messages of controllers that start together: a
command, or a lockstep report. A report names the service calls its node answered once
only, so the simulator then waits for word of an answer that never comes, until
lockstep_timeout (the series' bug 1 switches go to point on as its three nodes start).
So the check and the connect are made one at a time for each (topic, publisher): the second
thread finds the first one's connection and leaves it.
"""
import threading

_installed = False


def connect_each_publisher_once():
    """Makes rospy's connects of this process's subscribers one at a time per (topic,
    publisher). Idempotent; a connect to another publisher or topic is not held up."""
    global _installed
    if _installed:
        return
    from rospy.impl import masterslave

    connect = masterslave.ROSHandler._connect_topic
    guard = threading.Lock()
    pending = {}                     # (topic, publisher URI) -> [lock, threads using it]

    def connect_once(self, topic, pub_uri):
        key = (topic, pub_uri)
        with guard:
            entry = pending.setdefault(key, [threading.Lock(), 0])
            entry[1] += 1
        try:
            with entry[0]:
                return connect(self, topic, pub_uri)
        finally:
            with guard:
                entry[1] -= 1
                if not entry[1]:
                    del pending[key]

    masterslave.ROSHandler._connect_topic = connect_once
    _installed = True
