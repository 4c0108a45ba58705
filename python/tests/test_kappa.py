"""The dimensionless area-load slope kappa = (A/A0) / (p/(E* h'_rms)) each state reports
(loads.csv, summary.json, PREFIX.h5, the library), against an independent calculation
here: h'_rms of the composite surface by numpy forward differences of the deck's heights
(the upper surface flipped, Appendix B), E* from the deck's materials, A from the contact
count (how it compares with the published values: doc/studies.md)."""
import csv
import json

import numpy as np
import pytest

import femcod
from conftest import run_femcod


def rms_slope(g, pixel, periodic):
    if periodic:
        dx, dy = np.roll(g, -1, axis=0) - g, np.roll(g, -1, axis=1) - g
    else:
        dx, dy = np.diff(g, axis=0), np.diff(g, axis=1)
    return np.sqrt(np.mean(dx ** 2) + np.mean(dy ** 2)) / pixel


@pytest.mark.parametrize("boundary", ["free", "periodic"])
def test_kappa_against_the_heights(tmp_path, boundary):
    deck_path = tmp_path / "rough.deck"
    run_femcod("mkdeck", "self-affine", "--np", "128", "--pixel", "4", "--hurst", "0.8", "--rms", "2",
               "--seed", "7", "--shape-on", "lower", "-o", deck_path)
    prefix = tmp_path / "r"
    run_femcod("run", deck_path, "--solver", "cg", "--boundary", boundary, "--loads", "2e3,2e4,1e5", "-o", prefix,
               "-q")
    deck = femcod.read_deck(str(deck_path))
    g = deck.lower + deck.upper[::-1, :]
    slope = rms_slope(g, deck.pixel, boundary == "periodic")
    e1, e2 = deck.young[:2]
    n1, n2 = deck.poisson[:2]
    estar = 1 / ((1 - n1 ** 2) / e1 + (1 - n2 ** 2) / e2)
    with open(f"{prefix}.summary.json") as f:
        summary = json.load(f)
    assert summary["kappa_scale"]["rms_slope"] == pytest.approx(slope, rel=1e-12)
    with open(f"{prefix}.loads.csv", newline="") as f:
        rows = list(csv.DictReader(f))
    library = femcod.solve(deck, loads=[2e3, 2e4, 1e5], boundary=boundary)
    for row, entry, state in zip(rows, summary["loads"], library.states):
        expected = int(row["contacts"]) * deck.pixel ** 2 * estar * slope / float(row["load_nN"])
        assert float(row["kappa"]) == pytest.approx(expected, rel=1e-12)
        assert entry["kappa"] == float(row["kappa"]) and state.kappa == float(row["kappa"])


def test_kappa_is_undefined_without_load(tmp_path):
    """At zero or negative load (adhesion pulling) kappa has no meaning: NaN, null."""
    deck_path = tmp_path / "s.deck"
    run_femcod("mkdeck", "sphere", "--np", "32", "--pixel", "1", "--radius", "20", "-o", deck_path)
    prefix = tmp_path / "a"
    run_femcod("run", deck_path, "--solver", "cg", "--approach", "0,0.3", "--adhesion", "dugdale", "--work", "0.5",
               "--range", "1", "-o", prefix, "-q")
    with open(f"{prefix}.summary.json") as f:
        states = json.load(f)["loads"]
    with open(f"{prefix}.loads.csv", newline="") as f:
        rows = list(csv.DictReader(f))
    for entry, row in zip(states, rows):
        if entry["load_nN"] <= 0:
            assert entry["kappa"] is None and row["kappa"] == "nan"
        else:
            assert entry["kappa"] > 0
    assert any(e["load_nN"] <= 0 for e in states)


def test_refine_reports_the_runs_kappa(tmp_path):
    """femcod refine's area-load slope of the solve is femcod run's kappa at the same loads
    (one definition); at magnification 1 the refined slope is the solve's (no slope is
    added below the pixel), and below it the slope grows with the subpixel slope while the
    refined area falls."""
    deck_path = tmp_path / "rough.deck"
    run_femcod("mkdeck", "self-affine", "--np", "128", "--pixel", "4", "--hurst", "0.7", "--rms", "2",
               "--seed", "3", "--shape-on", "lower", "-o", deck_path)
    run_femcod("run", deck_path, "--solver", "cg", "--loads", "5e3,2e4", "-o", tmp_path / "r", "-q")
    run_femcod("refine", deck_path, "--loads", "5e3,2e4", "-o", tmp_path / "f", "-q")
    with open(tmp_path / "r.loads.csv", newline="") as f:
        kappa = {float(r["load_nN"]): float(r["kappa"]) for r in csv.DictReader(f)}
    with open(tmp_path / "f.refine.csv", newline="") as f:
        rows = list(csv.DictReader(f))
    for row in rows:
        load, zeta = float(row["load_nN"]), float(row["magnification"])
        assert float(row["area_load_slope_solve"]) == kappa[load]
        if zeta == 1:
            assert float(row["area_load_slope_refined"]) == kappa[load]
    assert len(rows) >= 4
    # PREFIX.refine.json: the same numbers as the table, by load and magnification.
    with open(tmp_path / "f.refine.json") as f:
        summary = json.load(f)
    entries = [(load, m) for load in summary["loads"] for m in load["magnifications"]]
    assert len(entries) == len(rows)
    for (load, m), row in zip(entries, rows):
        assert load["load_nN"] == float(row["load_nN"]) and m["magnification"] == float(row["magnification"])
        assert load["area_load_slope_solve"] == float(row["area_load_slope_solve"])
        for key in ("area_fraction_refined", "area_fraction_persson", "area_load_slope_refined"):
            assert m[key] == float(row[key]), key
    assert summary["command"] == "refine" and summary["scene"]["NP"] == 128


def test_refine_reads_a_height_file(tmp_path):
    """femcod refine FILE --pixel D (issue 52: the maps without a deck first) gives what
    it gives on the deck `femcod mkdeck matrix` makes of the same file: the same scene
    (the heights on an elastic body against a rigid flat), the same table."""
    import numpy as np
    deck_path = tmp_path / "rough.deck"
    run_femcod("mkdeck", "self-affine", "--np", "64", "--pixel", "4", "--hurst", "0.7", "--rms", "2",
               "--seed", "5", "--shape-on", "lower", "-o", deck_path)
    heights = tmp_path / "rough.txt"
    np.savetxt(heights, femcod.read_deck(str(deck_path)).lower, fmt="%.17g")
    made = tmp_path / "made.deck"
    run_femcod("mkdeck", "matrix", "--file", heights, "--pixel", "4", "--shape-on", "lower", "-o", made)
    run_femcod("refine", made, "--loads", "2e3,8e3", "-o", tmp_path / "d", "-q")
    run_femcod("refine", heights, "--pixel", "4", "--loads", "2e3,8e3", "-o", tmp_path / "h", "-q")
    with open(tmp_path / "d.refine.csv") as a, open(tmp_path / "h.refine.csv") as b:
        assert a.read() == b.read()
    # The height-file options belong to height files: refused next to a deck (exit 2).
    import subprocess
    got = subprocess.run(["femcod", "refine", str(made), "--loads", "10", "--remove-plane", "-o",
                          str(tmp_path / "x")], capture_output=True, text=True)
    assert got.returncode == 2 and "height file" in got.stderr and not list(tmp_path.glob("x.*"))
