"""The live page (web:=true) on the simulator node: starts the page's server
(pybullet_gazebo.web) and gives its buttons the simulator's own Gazebo services, so a
button does what the same `rosservice call` does, and a call from a terminal shows on the
page.

  Pause   ~pause_physics        Play   ~unpause_physics
  Reset   ~reset_world          Step   ~unpause_physics, then paused after web.live.STEP_TIME

Parameters (params.py): web, web_host, web_port, web_control.
"""
import rospy
from std_srvs.srv import Empty

from pybullet_gazebo.web.live import WebView
from pybullet_gazebo.web.site import MissingThreeJs, check_three

LOOPBACK = ("127.0.0.1", "localhost", "::1")


class GazeboButtons:
    """The page's operations as calls of the node's own services (from the server's worker
    threads; never from the loop's, which holds the world's lock)."""

    def __init__(self, view):
        self.view = view
        self._proxies = {}

    def _call(self, service):
        proxy = self._proxies.get(service)
        if proxy is None:
            proxy = self._proxies[service] = rospy.ServiceProxy(
                rospy.resolve_name("~" + service), Empty)
        proxy()

    def __call__(self, op):
        if op == "pause":
            self._call("pause_physics")
        elif op == "play":
            self._call("unpause_physics")
        elif op == "reset":
            self._call("reset_world")
        elif op == "step":
            self.view.step()
            self._call("unpause_physics")


def open_web_view(node, params):
    """A WebView serving the page on params.web_host:web_port, or None (with a warning
    saying why) when it cannot be served; the simulation goes on either way."""
    try:
        check_three()
        from pybullet_gazebo.web.server import WebServer     # aiohttp: only with web:=true
    except (MissingThreeJs, ImportError) as err:
        rospy.logwarn("web:=true but %s; running without the page (apt-get install "
                      "libjs-three python3-aiohttp: scripts/setup.sh does)", err)
        return None
    server = WebServer(params.web_host, params.web_port, info=rospy.loginfo,
                       warn=rospy.logwarn)
    view = WebView(node.world, server, node.lock, lambda: node.paused)
    view.pause = lambda: node.set_paused(True)
    if params.web_control:
        server.control = GazeboButtons(view)
    try:
        server.start()
    except OSError as err:
        view.close()
        rospy.logwarn("web:=true but the page cannot be served on %s:%d (%s): running "
                      "without it; pass web_port:=N with a free port", params.web_host,
                      params.web_port, err.strerror or err)
        return None
    host = params.web_host if ":" not in params.web_host else "[%s]" % params.web_host
    rospy.loginfo("web view: http://%s:%d/ (%s)", host, params.web_port,
                  "Pause, Play, Step and Reset world buttons" if params.web_control
                  else "view only: web_control:=false")
    if params.web_host not in LOOPBACK:
        rospy.logwarn("web view bound to %s: anyone who can reach port %d can watch%s; "
                      "web_host:=127.0.0.1 keeps it to this machine", params.web_host,
                      params.web_port, " and pause and reset the world"
                      if params.web_control else "")
    return view
