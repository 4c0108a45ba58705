"""femcod.load reads what every femcod command writes: run's PREFIX.h5 (with its
summary.json) into the Result femcod.solve returns, mkdeck's decks (text and HDF5) into a
Deck, and the CSV tables of resolution, summits, multiscale and refine into dicts of columns;
femcod-mpi's PREFIX.h5 too where femcod-mpi is installed (setup.sh --mpi)."""
import csv
import os
import shutil
import subprocess

import numpy as np
import pytest

import femcod
from conftest import REPO, run_femcod


@pytest.fixture(scope="module")
def rough(tmp_path_factory):
    d = tmp_path_factory.mktemp("rough")
    run_femcod("mkdeck", "self-affine", "--np", "64", "--pixel", "5", "--hurst", "0.8", "--rms", "2", "-o",
               d / "rough.deck")
    return d, d / "rough.deck"


def csv_columns(path):
    with open(path, newline="") as f:
        return next(csv.reader(f))


def test_run_result_set(rough):
    d, deck = rough
    run_femcod("run", deck, "-o", d / "r", "--solver", "cg", "--loads", "1000,5000", "-q")
    r = femcod.load(d / "r.h5")
    assert isinstance(r, femcod.Result) and r.solver == "cg" and len(r.states) == 2
    # The numbers of loads.csv, row by row (its text is the exact shortest form of each double).
    with open(d / "r.loads.csv", newline="") as f:
        rows = list(csv.DictReader(f))
    for s, row in zip(r.states, rows):
        for name in ("load_nN", "approach_nm", "contacts", "area_nm2", "area_fraction", "max_pressure_GPa"):
            assert s.values[name] == float(row[name]), name
        assert s.pressure.shape == (64, 64) and s.gap.shape == (64, 64)
    assert r.summary is not None and "loads" in r.summary
    assert np.array_equal(r.deck.lower, femcod.read_deck(deck).lower)


def test_event_history(rough):
    d, deck = rough
    run_femcod("run", deck, "-o", d / "e", "--loads", "2000", "-q")
    r = femcod.load(d / "e.h5")
    with open(d / "e.history.csv", newline="") as f:
        rows = list(csv.DictReader(f))
    assert len(r.history["load_nN"]) == len(rows)
    assert [float(x["load_nN"]) for x in rows] == list(r.history["load_nN"])


def test_decks(rough):
    d, deck = rough
    run_femcod("mkdeck", "self-affine", "--np", "32", "--pixel", "5", "-o", d / "deck.h5")
    for path in (deck, d / "deck.h5"):
        loaded = femcod.load(path)
        assert isinstance(loaded, femcod.Deck)
        assert np.array_equal(loaded.lower, femcod.read_deck(path).lower)


@pytest.mark.parametrize("command,args", [
    ("resolution", ["--levels", "64,32"]),
    ("summits", []),
    ("multiscale", []),
    ("refine", ["--loads", "1e4,1e5", "--down-to", "1"]),
])
def test_study_tables(rough, command, args):
    d, deck = rough
    prefix = d / command
    run_femcod(command, deck, *args, "-o", prefix, "-q")
    tables = femcod.load(prefix)
    written = sorted(f for f in os.listdir(d) if f.startswith(command + ".") and f.endswith(".csv"))
    assert sorted(tables) == sorted(f[len(command) + 1:-4] for f in written) and tables
    for name, table in tables.items():
        path = d / f"{command}.{name}.csv"
        assert list(table) == csv_columns(path)
        with open(path, newline="") as f:
            rows = list(csv.reader(f))[1:]
        for c, column in enumerate(table.values()):
            assert len(column) == len(rows)
            if column.dtype.kind == "f":
                assert [float(r[c]) for r in rows] == [float(x) for x in column] or \
                    all(np.isnan(float(r[c])) == np.isnan(x) for r, x in zip(rows, column))


def test_femcod_mpi_result_set(rough):
    program, mpirun = shutil.which("femcod-mpi"), shutil.which("mpirun")
    if program is None or mpirun is None:
        pytest.skip("femcod-mpi is not installed (bash setup.sh --mpi)")
    d, deck = rough
    env = dict(os.environ, OMP_NUM_THREADS="1")
    p = subprocess.run([mpirun, "--allow-run-as-root", "--oversubscribe", "-n", "2", program, str(deck),
                        "-o", str(d / "m"), "--loads", "1000,5000", "-q"], capture_output=True, text=True, env=env)
    assert p.returncode == 0, p.stderr
    m = femcod.load(d / "m.h5")
    serial = femcod.solve(femcod.read_deck(deck), loads=[1000, 5000])
    assert len(m.states) == 2
    for a, b in zip(m.states, serial.states):
        assert a.contacts == b.contacts
        assert a.approach == pytest.approx(b.approach, rel=1e-9)
