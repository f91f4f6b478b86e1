#!/usr/bin/env python3
"""Reads every JUnit XML file under a folder (pytest's and catkin/rostest's) and prints one
line per failed test case and a closing line `N passed, N failed, N skipped`.

Exit status 1 when anything failed or errored, or when no test ran at all. A rostest that
crashed before writing results shows up here as catkin's "MISSING-RESULT" failure file.
rostest's own verdict per suite (`* RESULT: FAIL` in the `*-run_tests.log` files) is read
too: a failing suite whose result file another suite overwrote still counts as failed.
"""
import sys
import xml.etree.ElementTree as ET
from pathlib import Path


def count(results_dir):
    passed = failed = skipped = 0
    failures = []
    for path in sorted(Path(results_dir).rglob("*.xml")):
        try:
            root = ET.parse(path).getroot()
        except ET.ParseError as err:
            failed += 1
            failures.append("%s: unreadable result file (%s)" % (path, err))
            continue
        # a suite that errored before any case ran (setUpClass, a missing package) has
        # errors= on the suite and no failing case: count it
        suites = [root] if root.tag == "testsuite" else list(root.iter("testsuite"))
        for suite in suites:
            cases = suite.findall("testcase")
            broken = sum(1 for c in cases if c.find("failure") is not None
                         or c.find("error") is not None)
            declared = int(suite.get("errors", 0) or 0) + int(suite.get("failures", 0) or 0)
            if declared > broken:
                failed += declared - broken
                failures.append("%s: %d error(s) outside any test case (%s)"
                                % (suite.get("name", ""), declared - broken, path.name))
        for case in root.iter("testcase"):
            name = "%s.%s" % (case.get("classname", ""), case.get("name", ""))
            broken = case.find("failure")
            broken = case.find("error") if broken is None else broken
            if broken is not None:
                failed += 1
                failures.append("%s (%s)%s" % (name, path.name, why(broken)))
            elif case.find("skipped") is not None:
                skipped += 1
            else:
                passed += 1
    return passed, failed, skipped, failures


def why(element, lines=8):
    """The reason a failed case gives, indented: CI keeps only the end of the output, so the
    reason must be here, not only in the XML. pytest puts it in the message attribute and
    at the end of its traceback; rosunit (rostest's Python tests) writes the assertion's
    message first and the traceback after it, without the exception line, so there the
    message is the text before the first frame. A long message keeps its first line (what
    failed) and its end (the output it quotes ends with the error)."""
    text = (element.get("message") or "").strip()
    body = (element.text or "").strip()
    if not text and body and not body.startswith(("Traceback", '  File "')):
        message, frame, _ = body.partition('\n  File "')
        if frame:                                   # rosunit's layout (it sets no message)
            text, body = message.strip(), ""
    if body and (not text or text not in body):
        text = (text + "\n" + body).strip()
    kept = [line for line in text.splitlines() if line.strip()]
    if len(kept) > lines:
        kept = kept[:1] + ["..."] + kept[-(lines - 2):]
    return "".join("\n    " + line[:300] for line in kept)


def failed_suites(results_dir):
    """(suite, ...) whose rostest run ended `RESULT: FAIL`, from the run_tests logs."""
    suites = []
    for log in sorted(Path(results_dir).glob("*-run_tests.log")):
        suite = None
        for line in log.read_text(errors="replace").splitlines():
            if "/usr/bin/rostest " in line:
                suite = line.split()[-1]
            elif "RESULT: FAIL" in line and suite is not None:
                suites.append(suite)
    return suites


def main():
    results_dir = sys.argv[1] if len(sys.argv) > 1 else "test_results"
    passed, failed, skipped, failures = count(results_dir)
    unseen = [s for s in failed_suites(results_dir)
              if not any(Path(s).stem in f for f in failures)]
    for suite in unseen:
        failed += 1
        failures.append("%s: rostest reported failure (see its run_tests log)" % suite)
    for line in failures:
        print("FAILED: " + line)
    print("%d passed, %d failed, %d skipped" % (passed, failed, skipped))
    return 1 if failed or passed == 0 else 0


if __name__ == "__main__":
    sys.exit(main())
