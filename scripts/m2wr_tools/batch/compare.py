"""Side by side: the batches of several controllers over the same scenarios, as a Markdown
table (the README's comparison of the learned policy with obstacle_avoidance.py).

    python -m m2wr_tools.batch.compare "learned=output/cmp/learned_world02" \
                                 "obstacle_avoidance.py=output/cmp/oa_world02"

Each LABEL=FOLDER is a batch folder of scripts/evaluate.sh (its results.json). The batches
must hold the same scenarios (world, start pose, seed, duration): a comparison of different
starts would say nothing, so that is an error naming the folders.
Columns: runs without contact, median and mean distance [m], median and worst minimum
clearance [m], median time stuck [s], runs that failed for another reason (controller
crash, timeout).
"""
import statistics
import sys

from . import results
from .. import usage

HEADER = ("| controller | runs without contact | median distance [m] | mean distance [m] | "
          "median min. clearance [m] | worst min. clearance [m] | median time stuck [s] | "
          "other failures |")


def scenario_key(record):
    s = record.get("scenario", {})
    return (record.get("world"), round(record["x"], 6), round(record["y"], 6),
            round(record["yaw"], 6), record.get("seed"), s.get("duration"))


def row(label, records):
    """One Markdown row of the figures of `records` (a batch's runs)."""
    measured = [r for r in records if r.get("distance_m") is not None]
    other = len(records) - len(measured)
    clean = sum(1 for r in measured if not r.get("contact_events"))
    distances = [r["distance_m"] for r in measured]
    clearances = [r["min_clearance_m"] for r in measured if r.get("min_clearance_m") is not None]
    stuck = [r["time_stuck_s"] for r in measured if r.get("time_stuck_s") is not None]

    def fmt(values, pick, digits):
        return ("%." + str(digits) + "f") % pick(values) if values else "-"
    return "| %s | %d/%d (%.0f %%) | %s | %s | %s | %s | %s | %d |" % (
        label, clean, len(records), 100.0 * clean / max(len(records), 1),
        fmt(distances, statistics.median, 1), fmt(distances, statistics.mean, 1),
        fmt(clearances, statistics.median, 2), fmt(clearances, min, 2),
        fmt(stuck, statistics.median, 1), other)


def table(batches):
    """Markdown lines for [(label, folder)]; ValueError when the batches' scenarios differ
    or a folder holds no results."""
    loaded = []
    for label, folder in batches:
        records = list(results.load(folder).values())
        if not records:
            raise ValueError("%s: no results.json with runs in %s; run scripts/evaluate.sh "
                             "--output %s first" % (label, folder, folder))
        loaded.append((label, folder, records))
    keys = [sorted(scenario_key(r) for r in records) for _, _, records in loaded]
    for (label, folder, _), k in zip(loaded[1:], keys[1:]):
        if k != keys[0]:
            raise ValueError("%s (%s) holds other scenarios than %s (%s): compare batches "
                             "run with the same --world, start poses, --seeds and --duration"
                             % (label, folder, loaded[0][0], loaded[0][1]))
    return [HEADER, "|---|---|---|---|---|---|---|---|"] + \
        [row(label, records) for label, _, records in loaded]


def main(argv=None):
    parser = usage.parser("python -m m2wr_tools.batch.compare", __doc__, examples=[
        'python -m m2wr_tools.batch.compare "learned=output/cmp/learned_world02" \\',
        '    "obstacle_avoidance.py=output/cmp/oa_world02"'],
        exit_statuses="Exit status: 0 with the table printed; 2 for bad arguments or "
        "batches that cannot be compared.")
    parser.add_argument("batches", nargs="+", metavar="LABEL=FOLDER",
                        help="a label for the table's row and a scripts/evaluate.sh output "
                        "folder (its results.json)")
    args = parser.parse_args(argv)
    pairs = []
    for item in args.batches:
        label, sep, folder = item.partition("=")
        if not sep or not label or not folder:
            parser.error("%r: give LABEL=FOLDER, e.g. learned=output/cmp/learned_world02" % item)
        pairs.append((label, folder))
    try:
        print("\n".join(table(pairs)))
    except ValueError as err:
        print("compare: %s" % err, file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main())
