#!/usr/bin/env python3
"""Collect the PREFIX.summary.json files of many femcod runs into one CSV table.

    python3 collect.py results/ > table.csv

One row per requested state (load or approach) of every run, with the run's deck label,
NP, pixel, solver and boundary; runs without requested states give one row for their
last step. Only the Python standard library is used. doc/cluster.md.
"""
import csv
import glob
import json
import os
import sys

COLUMNS = ["summary", "label", "NP", "pixel_nm", "solver", "boundary", "stopped", "load_nN",
           "approach_nm", "contacts", "area_fraction", "max_pressure_GPa", "n_plastic",
           "reached", "solve_s"]


def rows(path):
    with open(path, encoding="utf-8") as handle:
        summary = json.load(handle)
    scene = summary["scene"]
    common = {"summary": os.path.basename(path), "label": scene["label"], "NP": scene["NP"],
              "pixel_nm": scene["pixel_nm"], "solver": summary["solver"],
              "boundary": summary.get("boundary", "free"), "stopped": summary["stopped"],
              "solve_s": summary["wall_time_s"]}
    states = summary.get("loads", [])
    if not states:
        last = summary.get("last_step", {})
        yield dict(common, load_nN=last.get("load_nN"), approach_nm=last.get("approach_nm"),
                   contacts=last.get("contacts"), reached=True)
        return
    for state in states:
        yield dict(common, load_nN=state.get("load_nN"), approach_nm=state.get("approach_nm"),
                   contacts=state.get("contacts"), area_fraction=state.get("area_fraction"),
                   max_pressure_GPa=state.get("max_pressure_GPa"), n_plastic=state.get("n_plastic"),
                   reached=state.get("reached"))


def main(argv):
    if len(argv) != 2:
        sys.exit("usage: collect.py DIR  (the --outdir of the runs; writes CSV to standard output)")
    paths = sorted(glob.glob(os.path.join(argv[1], "*.summary.json")))
    if not paths:
        sys.exit(f"collect.py: no *.summary.json in {argv[1]}")
    writer = csv.DictWriter(sys.stdout, fieldnames=COLUMNS, lineterminator="\n")
    writer.writeheader()
    for path in paths:
        for row in rows(path):
            writer.writerow(row)


if __name__ == "__main__":
    main(sys.argv)
