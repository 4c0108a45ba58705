"""Read a femcod PREFIX.summary.json with Python's own json module (independently of
femcod) and print, one per line, "name value" for the fields test_results checks:
every load's approach and contacts, wall_time_s, and each entry of timings_s.

    python3 test/tools/summary_fields.py PREFIX.summary.json
"""
import json
import sys


def main(path):
    with open(path, encoding="utf-8") as f:
        summary = json.load(f)
    for k, load in enumerate(summary["loads"], start=1):
        print(f"approach_{k} {load['approach_nm']!r}")
        print(f"contacts_{k} {load['contacts']}")
    print(f"wall_time_s {summary['wall_time_s']!r}")
    for name, seconds in summary["timings_s"].items():
        print(f"timing_{name} {seconds!r}")


if __name__ == "__main__":
    main(sys.argv[1])
