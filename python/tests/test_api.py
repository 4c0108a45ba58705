"""femcod.solve on numpy arrays: Hertz from Python, bad arrays refused with Python
exceptions, the progress function, decks written and read back, to_xarray."""
import math
import os
import warnings

import numpy as np
import pytest

import femcod
from conftest import REPO, run_femcod


def paraboloid(n, pixel, radius):
    c = (np.arange(n) - (n - 1) / 2) * pixel
    y, x = np.meshgrid(c, c, indexing="ij")
    return -(x ** 2 + y ** 2) / (2 * radius)


@pytest.mark.parametrize("solver", ["cg", "incremental"])
def test_hertz_from_python(solver):
    """A paraboloid on a half-space against Hertz (Johnson eqs. 4.22-4.23, computed here):
    load at two loads, the approach within 1 % and the area within 5 % of pi a^2."""
    n, pixel, R, E, nu = 64, 0.5, 100.0, 200.0, 0.25
    estar = E / (1 - nu ** 2)
    loads = [200.0, 600.0]
    r = femcod.solve(paraboloid(n, pixel, R), pixel=pixel, loads=loads, solver=solver, young=E, poisson=nu,
                     maxcont=n * n)
    for s, P in zip(r.states, loads):
        a = (3 * P * R / (4 * estar)) ** (1 / 3)
        assert s.approach == pytest.approx(a * a / R, rel=0.01)
        assert s.area == pytest.approx(math.pi * a * a, rel=0.05)
        # The pressures carry the load: sum p d^2 = P (to the solver's tolerance).
        assert s.pressure.sum() * pixel ** 2 == pytest.approx(P, rel=1e-6)
        assert s.pressure.shape == (n, n) and s.gap.shape == (n, n)
    # Axis convention: a surface shifted along the columns (j) moves the contact along j.
    h = np.roll(paraboloid(n, pixel, R), 5, axis=1)
    moved = femcod.solve(h, pixel=pixel, loads=[200.0], solver=solver, maxcont=n * n)
    def centre(p):
        i, j = np.indices(p.shape)
        return (i * p).sum() / p.sum(), (j * p).sum() / p.sum()
    (i, j), (i0, j0) = centre(moved.states[0].pressure), centre(r.states[0].pressure)
    assert i == pytest.approx(i0, abs=1e-6) and j == pytest.approx(j0 + 5, abs=1e-6)


BAD = [
    ("complex", np.zeros((8, 8), complex), TypeError, "complex"),
    ("strings", np.array([["a"] * 4] * 4), TypeError, "real numbers"),
    ("objects", np.array([[None] * 4] * 4, dtype=object), TypeError, "real numbers"),
    ("not square", np.zeros((8, 6)), ValueError, "square"),
    ("one-dimensional", np.zeros(16), ValueError, "2-D"),
    ("empty", np.zeros((0, 0)), ValueError, "square"),
    ("NaN", np.where(np.eye(8) > 0, np.nan, 0.0), ValueError, "finite"),
    ("infinite", np.full((8, 8), np.inf), ValueError, "finite"),
]


@pytest.mark.parametrize("name,heights,error,words", BAD, ids=[b[0] for b in BAD])
def test_bad_arrays_are_refused(name, heights, error, words):
    with pytest.raises(error, match=words):
        femcod.solve(heights, pixel=1.0, loads=[1.0])


@pytest.mark.parametrize("pixel", [-1.0, 0.0, float("nan"), float("inf"), "wide"])
def test_bad_pixel_is_refused(pixel):
    with pytest.raises((ValueError, TypeError), match="pixel"):
        femcod.solve(np.zeros((8, 8)), pixel=pixel, loads=[1.0])


def test_refused_combinations_come_back_as_exceptions():
    h = paraboloid(16, 1.0, 50.0)
    with pytest.raises(femcod.FemcodError, match="--approach") as e:
        femcod.solve(h, pixel=1.0, loads=[10.0], adhesion="dugdale", work=0.1, range=1.0)
    assert e.value.code == 2
    with pytest.raises(femcod.FemcodError, match="legacy") as e:
        femcod.solve(h, pixel=1.0, loads=[10.0], solver="legacy", boundary="periodic")
    with pytest.raises(TypeError, match="unexpected keyword"):
        femcod.solve(h, pixel=1.0, loads=[10.0], outdir="x")
    with pytest.raises(femcod.FemcodError, match="(?i)pixel"):
        femcod.solve(h, pixel=1e9, loads=[10.0])


def test_the_library_refuses_the_commands_own_options_and_stray_values():
    """Through the C interface: run's file options are refused with the reason, and a
    value after a flag is named (femcod_set_option)."""
    from femcod._core import _Session, _set_problem
    for args, words in ((("--output", "x"), "option of the femcod command"),
                        (("--plastic", "11"), "follows no option"),
                        (("--nosuch", ""), "nosuch")):
        s = _Session()
        _set_problem(s, paraboloid(16, 1.0, 50.0), 1.0, None, 200.0, 0.25, None)
        s.check(s.lib.femcod_set_option(s.handle, b"--loads", b"10"))
        s.check(s.lib.femcod_set_option(s.handle, args[0].encode(), args[1].encode()))
        with pytest.raises(femcod.FemcodError, match=words) as e:
            s.check(s.lib.femcod_solve(s.handle, femcod._library.PROGRESS(0), None))
        assert e.value.code == 2


def test_any_real_dtype_and_layout_gives_the_same_answer():
    h = paraboloid(32, 1.0, 50.0)
    ref = femcod.solve(h, pixel=1.0, loads=[300.0])
    for variant in (np.asfortranarray(h), h.astype(np.float32).astype(np.float64), h[::-1, :][::-1, :],
                    (h * 1000).round().astype(np.int64) / 1000):
        r = femcod.solve(variant, pixel=1.0, loads=[300.0])
        assert r.states[0].contacts == pytest.approx(ref.states[0].contacts, abs=2)
    # Fortran order is converted, not misread: the very same doubles give the very same answer.
    r = femcod.solve(np.asfortranarray(h), pixel=1.0, loads=[300.0])
    assert np.array_equal(r.states[0].pressure, ref.states[0].pressure)


def test_progress_function_sees_states_and_can_stop():
    h = paraboloid(32, 1.0, 50.0)
    seen = []
    femcod.solve(h, pixel=1.0, loads=[100.0, 200.0, 300.0], progress=lambda *a: seen.append(a))
    assert [s[0] for s in seen if s[0] > 0] == [1, 2, 3]
    with pytest.raises(femcod.Stopped) as e:
        femcod.solve(h, pixel=1.0, loads=[100.0, 200.0, 300.0], progress=lambda step, *a: step >= 1)
    assert e.value.code == 6
    with pytest.raises(ZeroDivisionError):
        femcod.solve(h, pixel=1.0, loads=[100.0], progress=lambda *a: 1 / 0)


def test_decks_round_trip(tmp_path):
    deck = femcod.read_deck(os.path.join(REPO, "input", "sphere_d2.deck"))
    for name in ("copy.deck", "copy.h5"):
        femcod.write_deck(tmp_path / name, deck)
        back = femcod.read_deck(tmp_path / name)
        assert np.array_equal(back.lower, deck.lower) and np.array_equal(back.upper, deck.upper)
        assert (back.pixel, back.young, back.poisson, back.maxcont, back.label) == \
            (deck.pixel, deck.young, deck.poisson, deck.maxcont, deck.label)
        with pytest.raises(femcod.FemcodError) as e:  # an existing file is kept without force
            femcod.write_deck(tmp_path / name, deck)
        assert e.value.code == 5
        femcod.write_deck(tmp_path / name, deck, force=True)
    mine = tmp_path / "notes.txt"
    mine.write_text("my notes\n")
    with pytest.raises(femcod.FemcodError):  # not femcod's file: never replaced, even with force
        femcod.write_deck(mine, deck, force=True)
    assert mine.read_text() == "my notes\n"
    with pytest.raises(femcod.FemcodError, match="missing.deck") as e:
        femcod.read_deck(tmp_path / "missing.deck")
    assert e.value.code in (3, 5)


def test_height_files_read_as_femcod_run_reads_them(tmp_path):
    """A Gwyddion export with its units: heights in nm (from um), pixel from the width."""
    n = 16
    h = paraboloid(n, 1.0, 50.0)
    text = "# Channel: Height\n# Width: 0.016 um\n# Height: 0.016 um\n# Value units: um\n" + \
        "\n".join("\t".join(repr(float(v) / 1000) for v in row) for row in h) + "\n"
    (tmp_path / "scan.txt").write_text(text)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        deck = femcod.read_heights(tmp_path / "scan.txt")
    assert deck.pixel == pytest.approx(1.0)
    assert np.allclose(deck.lower, h - h.min(), atol=1e-9)
    assert not deck.upper.any()


def test_to_xarray_where_installed():
    xr = pytest.importorskip("xarray")
    r = femcod.solve(paraboloid(16, 1.0, 50.0), pixel=1.0, loads=[50.0, 100.0])
    ds = r.to_xarray()
    assert isinstance(ds, xr.Dataset) and ds["pressure"].shape == (2, 16, 16)


def test_coordinates_are_the_meshs(tmp_path):
    """to_xarray's x_nm, y_nm are the centres of the XDMF mesh's cells (PREFIX.h5
    /mesh: each cell's four nodes, read here with h5py), cell i * NP + j being pixel
    (i, j); and the figures' y axis runs from 0 at the bottom to NP d at the top, so row
    0, drawn at the top, is at y = NP d there as on the mesh."""
    pytest.importorskip("xarray")
    h5py = pytest.importorskip("h5py")
    prefix = str(tmp_path / "c")
    run_femcod("run", os.path.join(REPO, "input", "sphere_d1.deck"), "-o", prefix, "--loads", "100", "--quiet")
    r = femcod.load(prefix + ".h5")
    ds = r.to_xarray()
    with h5py.File(prefix + ".h5", "r") as f:
        nodes = f["/mesh/nodes_xy"][()]
        quads = f["/mesh/quadrilaterals"][()]
    n = r.deck.np
    centres = nodes[quads].mean(axis=1).reshape(n, n, 2)
    assert np.allclose(centres[:, :, 0], ds["x_nm"].values[None, :], atol=1e-12)
    assert np.allclose(centres[:, :, 1], ds["y_nm"].values[:, None], atol=1e-12)
    svg = open(prefix + ".pressure_1.svg").read()
    side = n * r.deck.pixel
    assert 'y="414.00" font-family="sans-serif" font-size="11" text-anchor="end">0<' in svg
    assert 'y="54.00" font-family="sans-serif" font-size="11" text-anchor="end">%g<' % side in svg


class StandInTopography:
    """The part of SurfaceTopography's Topography that from_topography reads (heights(),
    nb_grid_pts, physical_sizes, unit), for machines without that package."""

    def __init__(self, heights, physical_sizes, unit):
        self._h = heights
        self.nb_grid_pts = heights.shape
        self.physical_sizes = physical_sizes
        self.unit = unit

    def heights(self):
        return self._h


def test_topography_adapter():
    h = np.random.default_rng(0).standard_normal((32, 32))
    try:  # the real package where it is installed, the stand-in elsewhere
        from SurfaceTopography import Topography
        t = Topography(h, physical_sizes=(0.064, 0.064), unit="um", periodic=True)
    except ImportError:
        t = StandInTopography(h, (0.064, 0.064), "um")
    kw = femcod.from_topography(t)
    assert kw["pixel"] == pytest.approx(2.0) and np.allclose(kw["lower"], h * 1000)
    assert femcod.solve(**kw, loads=[1000.0], boundary="periodic").states[0].contacts >= 1
    with pytest.raises(ValueError, match="square"):
        femcod.from_topography(StandInTopography(np.zeros((8, 4)), (8.0, 4.0), "nm"))
    # Given as the heights themselves, its units would be lost: refused, with the way.
    with pytest.raises(TypeError, match="from_topography"):
        femcod.solve(t, pixel=2.0, loads=[1000.0])
