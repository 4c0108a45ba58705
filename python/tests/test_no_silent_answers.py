"""Issue 47: the library never gives an answer silently wrong. Each test failed on the
main before the fix (the defect it names is in its docstring)."""
import math
import os
import warnings

import numpy as np
import pytest

import femcod

from conftest import REPO

SPHERE = os.path.join(REPO, "input", "sphere_d1.deck")


@pytest.mark.parametrize("given", [{"young": 100}, {"poisson": 0.3}, {"young": [1, 2, 3]}, {"maxcont": 5},
                                   {"pixel": 1.0}, {"upper": np.zeros((30, 30))}])
def test_a_deck_refuses_what_it_already_gives(given):
    """Before: young=, poisson= (one or three values) with a Deck were ignored, the deck's
    values used without a word."""
    deck = femcod.read_deck(SPHERE)
    with pytest.raises(TypeError, match=next(iter(given)) + "="):
        femcod.solve(deck, loads=[1e3], **given)


def test_an_unreached_load_is_a_warning_and_not_an_answer():
    """Before: solver='incremental', maxcont=5, loads=[1e3, 10] gave the unreached 1e3 as an
    ordinary state, approach 0 and area 0, only values['reached'] == 0 telling. The
    command line leaves its row out and warns; the library warns, marks the state and
    keeps it out of column()."""
    deck = femcod.read_deck(SPHERE)
    deck.maxcont = 5
    with pytest.warns(UserWarning, match=r"load 1e3 nN not reached \(maximum number of contacts reached\)"):
        r = femcod.solve(deck, loads=[1e3, 10], solver="incremental")
    first, second = r.states
    assert not first.reached and second.reached
    assert first.load == 1e3  # what was asked stays
    assert math.isnan(first.approach) and math.isnan(first.area) and first.maps == {}
    assert math.isnan(r.areas[0]) and math.isnan(r.loads[0])
    # The reached state is the command line's: 10 nN on the sphere touches.
    assert r.loads[1] == pytest.approx(10, rel=1e-12) and r.areas[1] > 0


def test_a_tangential_step_without_contact_is_a_warning():
    """Before: --tangential 500 --friction 0.3 at a state without contact (cg, --plastic
    --approach 2.5,1) gave tangential force 0 and stick fraction 0 without a word, and the
    summary printed 'NaN %'. The state's load is the pressure map's sum: exactly 0 off
    contact (it was the residual's 3e-12 nN)."""
    deck = femcod.read_deck(SPHERE)
    with pytest.warns(UserWarning, match="has no contact: the tangential step was not applied"):
        r = femcod.solve(deck, approach=[2.5, 1], plastic=11, tangential=500, friction=0.3)
    loaded, off = r.states
    assert off.contacts == 0 and off.load == 0.0
    assert loaded.load == pytest.approx(loaded.pressure.sum() * deck.pixel ** 2, rel=1e-14)
    assert loaded.tangential_force_nN == pytest.approx(500, rel=1e-12)


def test_no_warning_when_every_state_is_answered():
    deck = femcod.read_deck(SPHERE)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        r = femcod.solve(deck, loads=[100, 1000])
    assert all(s.reached for s in r.states)


def test_a_summary_file_loads_its_result_set(tmp_path):
    """Before: femcod.load('x.summary.json') read it as a deck ('x.summary.json:2:
    expected 3 values'). Now the set beside it is read; without it, a clear error."""
    from conftest import run_femcod
    run_femcod("run", SPHERE, "--loads", "100", "-o", tmp_path / "s", "--quiet")
    r = femcod.load(tmp_path / "s.summary.json")
    assert r.states[0].load == 100 and r.summary is not None
    (tmp_path / "s.h5").unlink()
    with pytest.raises(FileNotFoundError, match="is not beside it"):
        femcod.load(tmp_path / "s.summary.json")


def test_the_c_library_refuses_null_outputs():
    """Before: femcod_state_value(s, 1, "area_nm2", NULL) dereferenced NULL (a segfault).
    Every output pointer is checked: exit code 2 and a message naming it."""
    import ctypes
    from femcod._core import _Session
    s = _Session()
    assert s.lib.femcod_read_deck(s.handle, SPHERE.encode()) == 0
    assert s.lib.femcod_set_option(s.handle, b"--loads", b"100") == 0
    keep_going = femcod._library.PROGRESS(lambda *args: 0)
    assert s.lib.femcod_solve(s.handle, keep_going, None) == 0
    assert s.lib.femcod_state_value(s.handle, 1, b"area_nm2", None) == 2
    assert "NULL given where its output goes (value)" in s.message()
    assert s.lib.femcod_state_count(s.handle, None) == 2
    assert s.lib.femcod_problem_size(s.handle, None) == 2
    value = ctypes.c_double()
    assert s.lib.femcod_state_value(s.handle, 1, b"load_nN", ctypes.byref(value)) == 0 and value.value == 100


def test_a_failed_set_keeps_the_problem_before_it():
    """Before: a femcod_set_heights that failed (here np = 0) discarded the problem set
    before it. A failed set of any kind changes nothing."""
    import ctypes
    from femcod._core import _Session
    s = _Session()
    assert s.lib.femcod_read_deck(s.handle, SPHERE.encode()) == 0
    heights = np.zeros(4)
    pointer = heights.ctypes.data_as(ctypes.POINTER(ctypes.c_double))
    assert s.lib.femcod_set_heights(s.handle, 0, 1.0, pointer, None, 200.0, 0.25, 0) == 3
    assert s.lib.femcod_read_deck(s.handle, b"/nonexistent.deck") == 3
    size = ctypes.c_int()
    assert s.lib.femcod_problem_size(s.handle, ctypes.byref(size)) == 0 and size.value == 30


def test_the_library_on_two_threads_equals_the_command_on_one(tmp_path):
    """Before: Python on 2 threads against the command on 1 gave 15 pressure pixels that
    differed (OpenMP's reductions followed the thread split). Now every bit is equal."""
    import os
    import subprocess
    from conftest import femcod_program
    deck = str(tmp_path / "r.deck")
    subprocess.run([femcod_program(), "mkdeck", "self-affine", "--np", "64", "--pixel", "5", "--rms", "3",
                    "--seed", "4", "--shape-on", "lower", "-o", deck], check=True, capture_output=True)
    env = dict(os.environ, OMP_NUM_THREADS="1")
    subprocess.run([femcod_program(), "run", deck, "--solver", "cg", "--loads", "1e4,1e5", "-o", str(tmp_path / "c"),
                    "--quiet"], check=True, capture_output=True, env=env)
    cli = femcod.load(tmp_path / "c.h5")
    lib = femcod.solve(femcod.read_deck(deck), solver="cg", loads=[1e4, 1e5], threads=2)
    for a, b in zip(cli.states, lib.states):
        assert a.approach == b.approach and a.load == b.load
        assert np.array_equal(a.pressure, b.pressure)
