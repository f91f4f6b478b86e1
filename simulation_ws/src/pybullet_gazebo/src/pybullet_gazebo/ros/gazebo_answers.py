"""How a Gazebo service handler refuses a request it cannot honour, in one place.

A handler raises LookupError (no such model, link, joint or frame) or ValueError (a NaN pose,
a negative mass, ...) with a message naming the input; `refuses` answers the call with
`success: false` and "<Service>: <message><then>", as gazebo_ros_api_plugin words its own
refusals, and the simulator runs on. Handlers take the world's lock themselves (`with
self.sim.lock:` around what they read or change), so that work outside the world (parsing,
checking numbers) does not hold up the simulation loop.
"""
import functools

INPUT_ERRORS = (LookupError, ValueError)


def refuses(service, response_class, then="", errors=INPUT_ERRORS):
    """Decorates a handler `(self, request) -> response`: when it raises one of `errors`, the
    answer is a `response_class` with success false and status_message "<service>: <error>
    <then>" (`then`: what the caller should know, e.g. "; nothing changed")."""
    def decorate(handler):
        @functools.wraps(handler)
        def answer(self, request):
            try:
                return handler(self, request)
            except errors as err:
                response = response_class()
                response.success = False
                response.status_message = "%s: %s%s" % (service, err, then)
                return response
        return answer
    return decorate
