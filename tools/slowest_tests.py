#!/usr/bin/env python3
"""Prints the slowest test suites of a catkin test_results directory (JUnit XML), so
that CI's time budget shows where it goes: slowest_tests.py DIR [--top N]."""
import argparse
import pathlib
import xml.etree.ElementTree as ET


def suites(root):
    for path in sorted(pathlib.Path(root).rglob("*.xml")):
        try:
            tree = ET.parse(path)
        except ET.ParseError:
            continue
        node = tree.getroot()
        seconds = node.get("time")
        if seconds is None:
            seconds = sum(float(s.get("time", 0) or 0) for s in node.iter("testsuite"))
        yield float(seconds or 0), path.stem


def main():
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("dir")
    parser.add_argument("--top", type=int, default=12)
    args = parser.parse_args()
    rows = sorted(suites(args.dir), reverse=True)
    total = sum(s for s, _ in rows)
    print(f"test suites: {len(rows)}, {total:.0f} s in all; the slowest:")
    for seconds, name in rows[: args.top]:
        print(f"  {seconds:8.1f} s  {name}")


if __name__ == "__main__":
    main()
