#!/usr/bin/env python3
"""Compare the numbers of two study reports (report.json) to the last digit.

Usage: compare_reports.py A/report.json B/report.json

Every number and every run's status are compared, by their JSON path; what says where and
how the runs ran, not what they computed, is left out: the top-level `study` (the study
file's path), `cost` (wall times, hosts, builds) and any `wall_time`. Exit status 1 with the
differences listed, 0 when equal (prints how many numbers were compared).
"""
import json
import sys

PROVENANCE_TOP = {"study", "cost"}
PROVENANCE_KEYS = {"wall_time", "provenance"}


def leaves(v, path, out):
    if isinstance(v, dict):
        for k, x in v.items():
            if (not path and k in PROVENANCE_TOP) or k in PROVENANCE_KEYS:
                continue
            leaves(x, f"{path}/{k}", out)
    elif isinstance(v, list):
        for i, x in enumerate(v):
            leaves(x, f"{path}/{i}", out)
    elif isinstance(v, bool) or v is None:
        out[path] = v
    elif isinstance(v, (int, float)):
        out[path] = v
    elif path.endswith("/status"):
        out[path] = v


def main():
    a_path, b_path = sys.argv[1], sys.argv[2]
    a, b = {}, {}
    with open(a_path) as f:
        leaves(json.load(f), "", a)
    with open(b_path) as f:
        leaves(json.load(f), "", b)
    diffs = [f"{k}: {a.get(k, '(absent)')!r} in {a_path}, {b.get(k, '(absent)')!r} in {b_path}" for k in sorted(set(a) | set(b)) if a.get(k, "(absent)") != b.get(k, "(absent)") or (k in a) != (k in b)]
    numbers = sum(1 for v in a.values() if isinstance(v, (int, float)) and not isinstance(v, bool))
    if diffs:
        print(f"{len(diffs)} difference(s) between the reports:")
        for d in diffs[:40]:
            print("  " + d)
        sys.exit(1)
    if numbers == 0:
        print(f"no numbers to compare in {a_path}")
        sys.exit(1)
    print(f"the reports are equal: {numbers} numbers and {sum(1 for k in a if k.endswith('/status'))} run statuses, to the last digit")


if __name__ == "__main__":
    main()
