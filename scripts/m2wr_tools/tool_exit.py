"""How every tool of scripts/ ends: the error that stopped it said on one line of stderr,
"<tool>: <what happened>", and an exit status, never a traceback.

    status = exit_status("evaluate", lambda: body(args))

  the body returns                        its status (None: 0)
  BadInput (the user's input is wrong;    2   its message names the input and what to do
    also ValueError where `bad_input` lists it)
  Interrupted (SIGTERM, SIGHUP) or Ctrl-C 130 "interrupted", then `interrupted` (what the
                                              user should know: the results kept, resuming)
  OSError, or an error listed in `known`  1   its message
  any other Exception                     1   its type and message (a ROS call failed);
                                              with `catch_all` only, else it propagates

The tool's own clean-up (a session shut down, processes stopped by PID) stays in its
`finally`, around this call."""
import sys


class Interrupted(Exception):
    """Ctrl-C (SIGINT) or SIGTERM, raised in the main thread by
    running.processes.raise_on_signals' handler; its text is the signal's name."""


class BadInput(Exception):
    """The user's input cannot be used; the message names it and says what to do."""


def exit_status(tool, body, interrupted="", known=(), bad_input=(), catch_all=False):
    def say(text):
        sys.stderr.write("%s: %s\n" % (tool, text))
    try:
        status = body()
        return 0 if status is None else status
    except (BadInput,) + tuple(bad_input) as err:
        say(err)
        return 2
    except Interrupted as err:
        say("interrupted (%s)%s" % (err, "; " + interrupted if interrupted else ""))
        return 130
    except KeyboardInterrupt:
        say("interrupted%s" % ("; " + interrupted if interrupted else ""))
        return 130
    except (OSError,) + tuple(known) as err:
        say(err)
        return 1
    except Exception as err:
        if not catch_all:
            raise
        say("%s: %s" % (type(err).__name__, err))
        return 1
