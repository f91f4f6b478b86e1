#!/usr/bin/env python3
"""Reads every JUnit XML file under a folder (pytest's and catkin/rostest's) and prints one
line per failed test case and a closing line `N passed, N failed, N skipped`.

Exit status 1 when anything failed or errored, or when no test ran at all. A rostest that
crashed before writing results shows up here as catkin's "MISSING-RESULT" failure file.
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
        for case in root.iter("testcase"):
            name = "%s.%s" % (case.get("classname", ""), case.get("name", ""))
            if case.find("failure") is not None or case.find("error") is not None:
                failed += 1
                failures.append("%s (%s)" % (name, path.name))
            elif case.find("skipped") is not None:
                skipped += 1
            else:
                passed += 1
    return passed, failed, skipped, failures


def main():
    results_dir = sys.argv[1] if len(sys.argv) > 1 else "test_results"
    passed, failed, skipped, failures = count(results_dir)
    for line in failures:
        print("FAILED: " + line)
    print("%d passed, %d failed, %d skipped" % (passed, failed, skipped))
    return 1 if failed or passed == 0 else 0


if __name__ == "__main__":
    sys.exit(main())
