"""m2wr_tools.tool_exit: every tool ends with one line on stderr, "<tool>: <what>", and the
exit status a script can act on; never a traceback."""
import pytest

from m2wr_tools.running.processes import Interrupted
from m2wr_tools.tool_exit import BadInput, exit_status


class Boom(Exception):
    pass


def _raise(error):
    def body():
        raise error
    return body


@pytest.mark.parametrize("body, kwargs, status, line", [
    (lambda: None, {}, 0, ""),
    (lambda: 3, {}, 3, ""),
    (_raise(BadInput("--world world99: no such world; use world01, world02 or a path")), {},
     2, "tool: --world world99: no such world; use world01, world02 or a path\n"),
    (_raise(ValueError("bad spec line 3")), {"bad_input": (ValueError,)}, 2,
     "tool: bad spec line 3\n"),
    (_raise(Interrupted("SIGTERM")), {"interrupted": "the runs done are kept"}, 130,
     "tool: interrupted (SIGTERM); the runs done are kept\n"),
    (_raise(KeyboardInterrupt()), {}, 130, "tool: interrupted\n"),
    (_raise(FileNotFoundError(2, "No such file or directory", "/no/such")), {}, 1,
     "tool: [Errno 2] No such file or directory: '/no/such'\n"),
    (_raise(Boom("the master went away")), {"known": (Boom,)}, 1,
     "tool: the master went away\n"),
    (_raise(RuntimeError("a ROS call failed")), {"catch_all": True}, 1,
     "tool: RuntimeError: a ROS call failed\n"),
])
def test_each_ending_has_its_status_and_one_line(capsys, body, kwargs, status, line):
    assert exit_status("tool", body, **kwargs) == status
    assert capsys.readouterr().err == line


def test_an_unforeseen_error_propagates_unless_asked_to_catch_all():
    with pytest.raises(RuntimeError):
        exit_status("tool", _raise(RuntimeError("a bug of ours")))
