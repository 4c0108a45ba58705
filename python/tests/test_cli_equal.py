"""The library's answer is the command line's, to the last bit.

For every deck of input/ and every solver, `femcod run DECK --solver S --loads ...`
writes PREFIX.h5 (read back by femcod.load) and femcod.solve(femcod.read_deck(DECK),
solver=S, loads=...) answers in memory: every state value the file holds, every map and
every history column must be the same doubles. The loads are 5, 15 and 30 % of the load
at which the deck's full incremental history ends (the legacy solver's cost grows as the
fourth power of the contacts). Further cases pass the other physics through (periodic,
plastic, adhesion, friction, a tangential step).
"""
import glob
import os

import numpy as np
import pytest

import femcod
from conftest import REPO, run_femcod

DECKS = sorted(glob.glob(os.path.join(REPO, "input", "*.deck")))
_final_load = {}


def final_load(deck, tmp_path):
    if deck not in _final_load:
        prefix = tmp_path / "full"
        run_femcod("run", deck, "-o", prefix, "-q", "--force")
        _final_load[deck] = float(femcod.load(f"{prefix}.h5").history["load_nN"].max())
    return _final_load[deck]


def same(a, b):
    """Bit for bit, NaN equal to NaN."""
    a, b = np.asarray(a, dtype=np.float64), np.asarray(b, dtype=np.float64)
    return a.shape == b.shape and np.array_equal(a.view(np.uint64), b.view(np.uint64))


def compare(cli, py):
    reached = [s for s in py.states if s.reached]
    assert len(reached) == len(cli.states) > 0
    checked = 0
    for c, p in zip(cli.states, reached):
        for name, value in c.values.items():
            if name in p.values:
                assert same(value, p.values[name]), f"{name}: command {value!r}, library {p.values[name]!r}"
                checked += 1
        assert set(c.maps) == set(p.maps)
        for name in c.maps:
            assert same(c.maps[name], p.maps[name]), f"map {name} differs"
    for name, column in cli.history.items():
        if name in py.history:
            assert same(column, py.history[name]), f"history {name} differs"
    assert checked >= 9 * len(reached)


@pytest.mark.parametrize("solver", ["incremental", "legacy", "cg"])
@pytest.mark.parametrize("deck", DECKS, ids=[os.path.basename(d)[:-5] for d in DECKS])
def test_input_decks_equal_the_command_line(deck, solver, tmp_path):
    top = final_load(deck, tmp_path)
    loads = [0.05 * top, 0.15 * top, 0.3 * top]
    text = ",".join(repr(x) for x in loads)
    prefix = tmp_path / solver
    run_femcod("run", deck, "-o", prefix, "--solver", solver, "--loads", text, "-q", "--force")
    cli = femcod.load(f"{prefix}.h5")
    py = femcod.solve(femcod.read_deck(deck), loads=loads, solver=solver)
    compare(cli, py)


PHYSICS = [
    ("cg periodic", ["--solver", "cg", "--boundary", "periodic", "--loads", "2000,8000"],
     dict(solver="cg", boundary="periodic", loads=[2000, 8000])),
    ("cg plastic", ["--solver", "cg", "--plastic", "--hardness", "5", "--loads", "2000,8000"],
     dict(solver="cg", plastic=5, loads=[2000, 8000])),
    ("incremental plastic", ["--plastic", "--hardness", "5", "--loads", "2000,8000"],
     dict(solver="incremental", plastic=5, loads=[2000, 8000])),
    ("cg adhesion", ["--solver", "cg", "--adhesion", "exponential", "--work", "0.05", "--range", "1", "--approach",
                     "0.5,2,0.2"],
     dict(solver="cg", adhesion="exponential", work=0.05, range=1, approach=[0.5, 2, 0.2])),
    ("cg plastic approach", ["--solver", "cg", "--plastic", "--hardness", "5", "--approach", "1,3"],
     dict(solver="cg", plastic=5, approach=[1, 3])),
    ("incremental friction", ["--shear-strength", "0.1", "--shear-slope", "0.2", "--loads", "3000"],
     dict(solver="incremental", shear_strength=0.1, shear_slope=0.2, loads=[3000])),
    ("cg tangential", ["--solver", "cg", "--loads", "3000,8000", "--tangential", "300", "--friction", "0.3"],
     dict(solver="cg", loads=[3000, 8000], tangential=300, friction=0.3)),
]


@pytest.mark.parametrize("name,args,kwargs", PHYSICS, ids=[p[0] for p in PHYSICS])
def test_physics_equal_the_command_line(name, args, kwargs, tmp_path):
    deck = os.path.join(REPO, "input", "rough_selfaffine_32.deck")
    prefix = tmp_path / "x"
    run_femcod("run", deck, "-o", prefix, *args, "-q", "--force")
    compare(femcod.load(f"{prefix}.h5"), femcod.solve(femcod.read_deck(deck), **kwargs))
