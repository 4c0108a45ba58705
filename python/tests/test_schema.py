"""One schema for a state's values (io/femcod_state_record): the state's entry in
PREFIX.summary.json, the attributes of its load group in PREFIX.h5, its row of
PREFIX.loads.csv and the library's state values name the same values alike, and hold the
same doubles. The reference of each number is another of femcod's writers: what this
test guards is that no writer keeps a list of its own that drifts (femcod-mpi's wrote
no adhesion attributes, and its summary had no "scene" for doc/cluster/collect.py).
"""
import csv
import json
import os

import h5py
import numpy as np
import pytest

import femcod
from conftest import REPO, run_femcod
from femcod._load import FLAGS

DECK = os.path.join(REPO, "input", "sphere_d1.deck")

# Each program's own fields beside the state's: the summary's (the load group, the
# patches' largest and perimeter exponent), the file's (the load group's index and the
# patches' exponent) and the library's (whether the state was reached).
SUMMARY_ONLY = {"reached", "hdf5_group", "largest_patch_pixels", "patch_perimeter_exponent"}
FILE_ONLY = {"index", "patch_perimeter_exponent"}

CASES = {
    "cg, tangential step, shear model": (["--solver", "cg", "--loads", "200,1000", "--tangential", "40",
                                          "--friction", "0.3", "--shear-strength", "0.5", "--shear-slope", "0.1"],
                                         dict(solver="cg", loads=[200, 1000], tangential=40, friction=0.3,
                                              shear_strength=0.5, shear_slope=0.1)),
    "cg, adhesion by approach": (["--solver", "cg", "--approach", "0.2,0.6", "--adhesion", "dugdale",
                                  "--work", "0.5", "--range", "0.5"],
                                 dict(solver="cg", approach=[0.2, 0.6], adhesion="dugdale", work=0.5, range=0.5)),
    "incremental, plastic": (["--solver", "incremental", "--loads", "300", "--plastic", "--hardness", "20"],
                             dict(solver="incremental", loads=[300], plastic=20)),
}


@pytest.mark.parametrize("case", list(CASES))
def test_every_writer_names_a_state_alike(case, tmp_path):
    args, keywords = CASES[case]
    prefix = tmp_path / "s"
    run_femcod("run", DECK, *args, "-o", prefix, "-q")
    with open(f"{prefix}.summary.json") as f:
        summary = json.load(f)["loads"]
    with open(f"{prefix}.loads.csv", newline="") as f:
        rows = list(csv.DictReader(f))
    library = femcod.solve(femcod.read_deck(DECK), **keywords)
    assert len(summary) == len(rows) == len(library.states) > 0
    with h5py.File(f"{prefix}.h5") as h5:
        for k, (entry, row, state) in enumerate(zip(summary, rows, library.states)):
            attributes = dict(h5["loads"][f"{k + 1:03d}"].attrs)
            names = set(attributes) - FILE_ONLY
            # The summary leaves out an approach bound where there is none (-1 in the file).
            expected = names - ({"approach_error_bound_nm"} if attributes.get("approach_error_bound_nm", 0) < 0 else set())
            assert set(entry) - SUMMARY_ONLY == expected, case
            assert set(state.values) - {"reached"} == names, case
            for name in expected:
                assert float(entry[name]) == float(attributes[name]), (name, entry[name], attributes[name])
            for name in names:
                assert float(state.values[name]) == float(attributes[name]), (name, state.values[name],
                                                                             attributes[name])
            for name in set(row) & names:
                assert float(row[name]) == float(attributes[name]), (name, row[name], attributes[name])
            assert len(set(row) & names) >= 11
            # Counts are ints, flags bools (the library's kinds, the file's integers).
            for name, value in state.values.items():
                integral = name == "reached" or isinstance(attributes.get(name), (int, np.integer))
                assert isinstance(value, (int, bool)) == integral, (name, value)
                assert isinstance(value, bool) == (name == "reached" or name in FLAGS), (name, value)
            assert isinstance(state.contacts, int) and isinstance(state.reached, bool)
    read = femcod.load(f"{prefix}.h5")
    for state, back in zip(library.states, read.states):
        for name in set(state.values) & set(back.values):
            assert type(state.values[name]) is type(back.values[name]), name
            assert state.values[name] == back.values[name], name


def test_the_file_reader_knows_every_flag():
    """femcod.load types a file's flags from FLAGS: the library's flags, every physics on."""
    r = femcod.solve(femcod.read_deck(DECK), loads=[500], tangential=40, friction=0.3, shear_strength=0.5,
                     shear_slope=0.1)
    flags = {name for name, v in r.states[0].values.items() if isinstance(v, bool)} - {"reached"}
    assert flags == FLAGS and "gross_sliding" in flags


def test_the_states_as_a_table():
    """Result.to_dataframe: a row per state, the values as columns, counts as integers."""
    pd = pytest.importorskip("pandas")
    r = femcod.solve(femcod.read_deck(DECK), loads=[100, 400, 1000])
    frame = r.to_dataframe()
    assert list(frame.index) == [1, 2, 3] and frame.index.name == "state"
    assert list(frame["load_nN"]) == [100, 400, 1000]
    assert pd.api.types.is_integer_dtype(frame["contacts"]) and list(frame["contacts"]) == [s.contacts for s in r.states]
    assert frame["contacts"].is_monotonic_increasing and frame["reached"].all()
