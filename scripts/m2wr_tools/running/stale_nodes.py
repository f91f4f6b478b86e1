"""Nodes that ended but that the ROS master still lists, and how to make it forget them.

Every rospy node of Noetic subscribes the parameter /rosout_disable_topics_generation
(rospy's rosout handler reads it with get_param_cached), and no node unsubscribes it when it
shuts down. So the master keeps each ended node's name and XML-RPC address. When a new node
registers under that name, the master sends "shutdown" to the old address; if another process
has since been given that port, that process is shut down instead. Seen in the benchmark: a
new simulator, on the port of the previous episode's controller, stopped at its start when the
next /reading_laser registered ("shutdown request: [/reading_laser] Reason: new node
registered with same name"). Tools that stop and start nodes on one master (the benchmark,
the batch runner, the grader) forget the ended nodes as they stop them.

    before = registered(master, caller)       # {node: address}, while they run
    ... stop some of them ...
    forget_ended(master, caller, before)      # the ones that ended are forgotten
"""
import socket
import xmlrpc.client
from urllib.parse import urlparse

# parameters that rospy subscribes by itself (the master keeps a node for each subscription)
ROSPY_PARAM_SUBSCRIPTIONS = ("/rosout_disable_topics_generation",)


def registered(master, caller):
    """{node name: XML-RPC address} of the nodes with a topic or service on the master
    (an xmlrpc.client.ServerProxy); {} when the master does not answer."""
    try:
        code, _, state = master.getSystemState(caller)
        if code != 1:
            return {}
        names = {node for kind in state for _, nodes in kind for node in nodes}
        nodes = {}
        for name in names:
            code, _, uri = master.lookupNode(caller, name)
            if code == 1:
                nodes[name] = uri
        return nodes
    except (OSError, xmlrpc.client.Error):
        return {}


def forget_ended(master, caller, before):
    """Of `before` ({node: address}, from registered()), the nodes that still have that
    address on the master but no longer answer there: their registrations are dropped, so the
    master forgets them. Returns their names."""
    return _forget_silent(master, caller, sorted(before), before.get)


def forget_gone(master, caller, names):
    """Of the nodes `names`, those the master still holds at an address where nothing answers
    any more are forgotten (a node that shut down by itself, such as spawn.launch's, keeps
    only rospy's parameter subscription, so no topic lists it). Returns their names."""
    return _forget_silent(master, caller, names, lambda node: None)


def _forget_silent(master, caller, names, address_then):
    """Unregisters each of `names` that the master holds at an address where nothing answers;
    `address_then(node)`: the address it had when the caller saw it run (only that one is
    forgotten: a new node of the name may have registered since), or None for any."""
    ended = []
    try:
        for node in names:
            code, _, uri = master.lookupNode(caller, node)
            then = address_then(node)
            if code == 1 and (then is None or uri == then) and not _answers(uri):
                unregister(master, node, uri)
                ended.append(node)
    except (OSError, xmlrpc.client.Error):
        pass                                  # the master itself went: nothing to forget
    return ended


def _answers(uri, timeout=0.5):
    """Whether something listens at the XML-RPC address `uri` (a refused connection: no)."""
    address = urlparse(uri)
    try:
        with socket.create_connection((address.hostname, address.port), timeout=timeout):
            return True
    except ConnectionRefusedError:
        return False
    except OSError:
        return True                           # slow or unreachable: leave it alone


def unregister(master, node, uri, state=None):
    """Drops every registration of `node` (at XML-RPC address `uri`) from the master: its
    publishers, subscribers, services and rospy's own parameter subscriptions. `state`: the
    master's getSystemState answer, if the caller has it already."""
    if state is None:
        state = master.getSystemState(node)[2]
    publishers, subscribers, services = state
    for topic, nodes in publishers:
        if node in nodes:
            master.unregisterPublisher(node, topic, uri)
    for topic, nodes in subscribers:
        if node in nodes:
            master.unregisterSubscriber(node, topic, uri)
    for service, nodes in services:
        if node in nodes:
            code, _, service_uri = master.lookupService(node, service)
            if code == 1:
                master.unregisterService(node, service, service_uri)
    for key in ROSPY_PARAM_SUBSCRIPTIONS:
        master.unsubscribeParam(node, uri, key)
