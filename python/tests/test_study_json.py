"""The studies' JSON files (PREFIX.resolution.json, .summits.json, .multiscale.json and
refine's PREFIX.refine.json) hold the numbers of their CSV tables: every table, every row,
every field (the CSV file is the reference; nan and empty fields are null)."""
import csv
import glob
import json
import os

import pytest

from conftest import REPO, run_femcod


def same(field, value):
    if field == "" or field.lower() == "nan":
        return value is None
    try:
        return float(field) == value
    except ValueError:
        return field == value


@pytest.mark.parametrize("command", ["resolution", "summits", "multiscale"])
def test_study_json_holds_its_tables(tmp_path, command):
    deck = os.path.join(REPO, "input", "rough_selfaffine_32.deck")
    if command != "resolution":
        deck = tmp_path / "wm.deck"
        run_femcod("mkdeck", "wm", "--np", "128", "--pixel", "4", "-o", deck)
    prefix = tmp_path / "s"
    run_femcod(command, deck, "-o", prefix, "-q")
    with open(f"{prefix}.{command}.json") as f:
        doc = json.load(f)
    assert doc["command"] == command and doc["command_line"].startswith(f"femcod {command} ")
    tables = sorted(glob.glob(f"{prefix}.*.csv"))
    assert sorted(doc["tables"]) == sorted(os.path.basename(t)[len("s."):-len(".csv")] for t in tables)
    checked = 0
    for path in tables:
        with open(path, newline="") as f:
            rows = list(csv.DictReader(f))
        entries = doc["tables"][os.path.basename(path)[len("s."):-len(".csv")]]
        assert len(entries) == len(rows), path
        for row, entry in zip(rows, entries):
            assert list(entry) == list(row), path
            for key, field in row.items():
                assert same(field, entry[key]), (path, key, field, entry[key])
                checked += 1
    assert checked > 20
