#!/usr/bin/env python3
"""The count of a ctest run from its JUnit file (ctest --output-junit): one line
"N passed, N failed, N skipped", then each skipped test with its reason and each failed test.

  scripts/test_summary.py BUILD/junit.xml

Exit status 0 whatever the counts (make test keeps ctest's); 2 when the file cannot be read.
"""
import re
import sys
import xml.etree.ElementTree as ET


def skip_reason(case):
    """The reason a test gave for skipping: GoogleTest's message after "Skipped", a script's
    "SKIP: ..." line (exit 77), else what ctest recorded."""
    out = case.findtext("system-out") or ""
    lines = out.splitlines()
    for i, line in enumerate(lines):
        if line.rstrip().endswith(": Skipped") and i + 1 < len(lines) and lines[i + 1].strip():
            return lines[i + 1].strip()
    for line in lines:
        m = re.search(r"SKIP: (.*)", line)
        if m:
            return m.group(1).strip()
    skipped = case.find("skipped")
    message = skipped.get("message", "") if skipped is not None else ""
    return message or "no reason given"


def main():
    if len(sys.argv) != 2:
        print(__doc__.strip(), file=sys.stderr)
        return 2
    try:
        root = ET.parse(sys.argv[1]).getroot()
    except (OSError, ET.ParseError) as e:
        print(f"test summary: cannot read {sys.argv[1]}: {e}", file=sys.stderr)
        return 2
    passed, failed, skipped = [], [], []
    for case in root.iter("testcase"):
        name = case.get("name", "?")
        if case.find("failure") is not None or case.find("error") is not None or case.get("status") == "fail":
            failed.append(name)
        elif case.find("skipped") is not None or case.get("status") in ("notrun", "disabled"):
            skipped.append((name, skip_reason(case)))
        else:
            passed.append(name)
    print(f"{len(passed)} passed, {len(failed)} failed, {len(skipped)} skipped")
    for name, reason in skipped:
        print(f"  skipped {name}: {reason}")
    for name in failed:
        print(f"  failed  {name}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
