"""The benchmark's arithmetic and its side-by-side table, from plain numbers (no ROS)."""
import math


def rate(count, seconds):
    """count / seconds, or nan when there was no time."""
    return count / seconds if seconds > 0 else math.nan


def growth_percent(start, end):
    """How much `end` grew over `start` [%] (nan without a start)."""
    if not start:
        return math.nan
    return 100.0 * (end - start) / start


def stamp_rate(stamps):
    """Messages per second of the stamps' own clock: (n - 1) / (last - first) for sorted,
    distinct stamps [s] (nan for fewer than two)."""
    stamps = sorted(set(stamps))
    if len(stamps) < 2 or stamps[-1] <= stamps[0]:
        return math.nan
    return (len(stamps) - 1) / (stamps[-1] - stamps[0])


def missing_periods(stamps, period, tolerance=0.25):
    """How many messages are missing from a stream that should carry one stamp every
    `period` [s]: gaps longer than (1 + tolerance) periods count (gap / period - 1) each."""
    stamps = sorted(set(stamps))
    missing = 0
    for a, b in zip(stamps, stamps[1:]):
        gap = b - a
        if gap > (1.0 + tolerance) * period:
            missing += int(round(gap / period)) - 1
    return missing


def every_scan_handled(heard, handled, missing, edge=0):
    """True when the controller handled every scan the simulator published: `heard` scans
    reached the bench, `missing` more are gaps in their stamps (published, not heard by the
    bench), `handled` counts the controller's case lines (one per scan callback, or per tick
    of a loop program). `edge`: how far the window's two paused edges may shift the count
    (a loop program: the tick of the scan published just before a pause is handed on after
    the unpause, when lockstep had not handed it on yet, so the count may gain or lose one)."""
    published = heard + missing
    return published > 0 and abs(handled - published) <= edge


def lockstep_verdict(heard, handled, answers, missing, edge=0):
    """One line: did the controller receive every scan the simulator published?"""
    published = heard + missing
    if published == 0:
        return "no scans heard"
    word = "yes" if every_scan_handled(heard, handled, missing, edge) else "no"
    return "%s: %d scans published (%d heard by the bench), %d handled by the controller, " \
           "%d cmd_vel answers" % (word, published, heard, handled, answers)


def fmt(value, spec="%.1f"):
    if value is None or (isinstance(value, float) and math.isnan(value)):
        return "n/a"
    return spec % value


def table(header, rows, first_width=44):
    """Left column of labels, then one right-aligned column per header entry."""
    widths = [max(len(h), max((len(r[i + 1]) for r in rows), default=0)) + 2
              for i, h in enumerate(header)]
    lines = [" " * first_width + "".join(h.rjust(w) for h, w in zip(header, widths))]
    for row in rows:
        lines.append(row[0].ljust(first_width)
                     + "".join(cell.rjust(w) for cell, w in zip(row[1:], widths)))
    return "\n".join(lines)
