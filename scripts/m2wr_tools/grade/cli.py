"""Grades a class of submissions on a spec's tasks:

  scripts/grade.sh CLASS_DIR [--spec SPEC] [--output DIR] [--scheduler ADDR] [--workers N]
                   [--fresh] [--no-progress]
  scripts/grade.sh --replay STUDENT TASK RUN [--output DIR] [--gui]

CLASS_DIR holds one folder per student (m2wr_tools.grade.classroom); SPEC lists the tasks
(m2wr_tools.grade.spec; default: spec_default.yaml, episodes 5-10). Every student x task x
start x seed is one run of the batch runner, in lockstep, on Dask (an embedded LocalCluster,
or --scheduler), isolated and under the task's rules (m2wr_tools.grade.runner). Runs already
graded in DIR are kept (resume; --fresh starts over). Writes DIR/index.html (the class
table and a page per student), DIR/grades.csv (one row per student) and DIR/results.json.

--replay runs one graded run again (same scenario, same seed, lockstep) on this machine,
prints its metrics beside the graded ones and draws it (DIR/replay/<run>.png); with --gui
the simulator's window shows it at real time.

Exit status: 0 when the class was graded (failed runs and students included); 1 when it
could not run; 2 for bad input; 130 when interrupted.
"""
import os
import sys

from ..paths import ROOT
from . import classroom, scoring
from .spec import DEFAULT_SPEC, SpecError, load
from ..tool_exit import BadInput, exit_status
from .. import usage


def parse_args(argv):
    parser = usage.parser("scripts/grade.sh", __doc__, examples=[
        "scripts/grade.sh ~/class                 # one folder per student; episodes 5-10",
        "scripts/grade.sh ~/class --spec my_spec.yaml --output ~/grades --workers 2",
        "scripts/grade.sh --replay alice ep10_bug2 0 --output ~/grades --gui   # one run again"])
    parser.add_argument("class_dir", nargs="?", metavar="CLASS_DIR",
                        help="a folder with one folder per student")
    parser.add_argument("--spec", default=DEFAULT_SPEC,
                        help="the YAML spec of the tasks (default: spec_default.yaml, episodes 5-10)")
    parser.add_argument("--output", default=os.path.join(ROOT, "output", "grade"),
                        help="the report's folder (default: output/grade)")
    parser.add_argument("--scheduler", help="address of a Dask scheduler, e.g. "
                        "tcp://127.0.0.1:8786 (default: a LocalCluster)")
    parser.add_argument("--workers", type=int, help="LocalCluster workers (default: one per core)")
    parser.add_argument("--fresh", action="store_true", help="grade again from scratch")
    parser.add_argument("--no-progress", action="store_true", help="no progress bar")
    parser.add_argument("--cold-start", action="store_true",
                        help="start Python controllers and roslaunch as new interpreters "
                             "through prlimit, not forked from a warm one (same limits and "
                             "user either way)")
    parser.add_argument("--replay", nargs=3, metavar=("STUDENT", "TASK", "RUN"),
                        help="run one graded run again, on this machine, and draw it")
    parser.add_argument("--gui", action="store_true", help="with --replay: show the simulator's window, at real time")
    args = parser.parse_args(argv)
    if args.replay is None and args.class_dir is None:
        parser.error("pass CLASS_DIR (a folder with one folder per student), or --replay "
                     "STUDENT TASK RUN")
    if args.workers is not None and args.workers < 1:
        parser.error("--workers must be >= 1")
    if args.scheduler and not args.scheduler.startswith(("tcp://", "tls://", "inproc://")):
        parser.error("--scheduler must be an address like tcp://127.0.0.1:8786")
    if args.replay is not None:
        try:
            args.replay[2] = int(args.replay[2])
        except ValueError:
            parser.error("--replay STUDENT TASK RUN: RUN must be a run number (0, 1, ...)")
    return args


def say(text):
    print("[grade] %s" % text, flush=True)


def main(argv=None):
    args = parse_args(sys.argv[1:] if argv is None else argv)
    args.output = os.path.abspath(args.output)
    return exit_status("grade", lambda: grade(args), interrupted=(
        "every process of the batch stopped; run the same command again to resume"))


def grade(args):
    if args.replay is not None:
        from .replay import replay
        return replay(args.output, *args.replay, gui=args.gui, say=say)
    try:
        spec = load(args.spec)
        submissions = classroom.discover(os.path.abspath(args.class_dir))
    except (SpecError, ValueError) as err:
        raise BadInput(err) from None
    from .grading import GradeError, grade_class
    try:
        graded = grade_class(spec, submissions, args, say)
    except GradeError as err:
        raise BadInput(err) from None
    from . import report
    report.write(args.output, spec, graded)
    say("class table %s" % os.path.join(args.output, "index.html"))
    say("gradebook %s; all results %s" % (os.path.join(args.output, "grades.csv"),
                                          os.path.join(args.output, "results.json")))
    print(scoring.table(spec, graded), flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
