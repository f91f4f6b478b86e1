"""Every command's --help, as a user types it: it names the command as typed, gives every
option a sentence, shows defaults as `(default: X)`, ends with the exit statuses, and does
nothing else (exit 0). scripts/test.sh and scripts/setup.sh refuse an unknown option with
their usage and status 2."""
import os
import re
import subprocess
import sys

import pytest

from m2wr_gym import train
from m2wr_tools import demo
from m2wr_tools.batch import compare, evaluate, gym_evaluate
from m2wr_tools.bench import bug, cli as bench_cli, grade as bench_grade, gym, loop_avoidance, \
    series_runs, switched_off_beside, web_watch
from m2wr_tools.grade import cli as grade_cli
from m2wr_tools.paths import ROOT

# (what the user types, the function that reads the command line)
PYTHON_TOOLS = [
    ("scripts/demo.sh", demo.parse_args),
    ("scripts/evaluate.sh", evaluate.parse_args),
    ("scripts/grade.sh", grade_cli.parse_args),
    ("scripts/bench.sh", bench_cli.parse_args),
    ("scripts/bench.sh --bug", bug.parse_args),
    ("scripts/bench.sh --grade", bench_grade.main),
    ("scripts/train.sh", train.parse_args),
    ("python -m m2wr_tools.batch.compare", compare.main),
    ("python -m m2wr_tools.batch.gym_evaluate", gym_evaluate.main),
    ("python -m m2wr_tools.bench.gym", gym.main),
    ("python -m m2wr_tools.bench.series_runs", series_runs.main),
    ("python -m m2wr_tools.bench.web_watch", web_watch.main),
    ("python -m m2wr_tools.bench.loop_avoidance", loop_avoidance.main),
    ("python -m m2wr_tools.bench.switched_off_beside", switched_off_beside.main),
]
# the scripts that do more than `exec python -m TOOL "$@"` (bench.sh picks its tool by the
# first argument; train.sh answers --help before it installs the training extra)
SHELL_TOOLS = ["scripts/bench.sh", "scripts/bench.sh --bug", "scripts/bench.sh --grade",
               "scripts/train.sh"]


def undocumented_options(text):
    """Options of the help's option list that have no sentence."""
    lines = text.split("\n\n")
    block = next(part for part in lines if part.startswith("options:"))
    rows = block.splitlines()[1:]
    missing = []
    for i, row in enumerate(rows):
        match = re.match(r"^  (-\S.*?)(?:\s{2,}(\S.*))?$", row)
        if not match:
            continue
        follows = rows[i + 1] if i + 1 < len(rows) else ""
        if match.group(2) is None and not re.match(r"^ {6,}\S", follows):
            missing.append(match.group(1))
    return missing


# the tools whose every option is required or a flag: nothing to show a default for
NO_DEFAULTS = {"python -m m2wr_tools.batch.compare", "python -m m2wr_tools.bench.loop_avoidance",
               "python -m m2wr_tools.bench.switched_off_beside"}


def check_help(prog, text):
    assert text.startswith("usage: %s [-h]" % prog), text[:200]
    assert ("(default: " in text) != (prog in NO_DEFAULTS), "%s --help: defaults" % prog
    assert "\nexamples:\n  %s" % prog.split(" --")[0] in text, "%s --help has no example" % prog
    assert "Exit status: 0" in text, "%s --help does not end with its exit statuses" % prog
    assert undocumented_options(text) == [], prog


@pytest.mark.parametrize("prog, read", PYTHON_TOOLS, ids=[p for p, _ in PYTHON_TOOLS])
def test_help_names_the_command_as_typed_and_shows_every_default(prog, read, capsys,
                                                                 monkeypatch):
    monkeypatch.setenv("COLUMNS", "100")
    with pytest.raises(SystemExit) as ended:
        read(["--help"])
    assert ended.value.code == 0
    check_help(prog, capsys.readouterr().out)


def run(command, *args):
    env = dict(os.environ, COLUMNS="100")
    argv = command.split()
    return subprocess.run(["bash", os.path.join(ROOT, argv[0])] + argv[1:] + list(args),
                          cwd=ROOT, env=env, capture_output=True, text=True, timeout=60)


@pytest.mark.parametrize("command", SHELL_TOOLS)
def test_the_scripts_hand_help_to_their_tool(command):
    done = run(command, "--help")
    assert done.returncode == 0, done.stderr
    assert done.stdout.startswith("usage: %s [-h]" % command), done.stdout[:200]


@pytest.mark.parametrize("command, says", [
    ("scripts/test.sh", "scripts/test.sh --unit"),
    ("scripts/setup.sh", "install what is missing"),
])
def test_test_and_setup_answer_help_and_refuse_an_unknown_option(command, says, tmp_path):
    done = run(command, "--help")
    assert done.returncode == 0 and says in done.stdout and "Exit status" in done.stdout
    assert done.stderr == ""
    refused = run(command, "--no-such-option")
    assert refused.returncode == 2
    assert refused.stderr.startswith("%s: unknown option --no-such-option" % command)
    assert says in refused.stderr
    assert refused.stdout == ""


def test_the_usage_module_keeps_a_description_whole_past_its_colon():
    from m2wr_tools import usage
    parser = usage.parser("scripts/x.sh", "Does x:\n\n  scripts/x.sh [--y]\n\nThen z: all of "
                          "it.\n  a  table row\n\nExit status: 0 always.")
    text = parser.format_help()
    assert "Does x.\n\nThen z: all of it.\n  a  table row\n" in text
    assert text.rstrip().endswith("Exit status: 0 always.")
    assert "  scripts/x.sh [--y]" not in text
