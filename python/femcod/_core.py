"""femcod.solve, read_deck and write_deck over libfemcod.so (src/capi/femcod.h).

Axis convention, once for all of femcod: a height or result map ``a[i, j]`` is row i,
column j of the grid, as in femcod's decks and HDF5 files (C order). Units: heights and
pixel nm, moduli GPa, loads nN, pressures GPa.

Copies: an input array that is already C-ordered float64 is passed as it is (otherwise
numpy converts it once); the library copies the heights once into its problem. Each map
of the result is copied once, from the library into a new numpy array.
"""
import ctypes
import os
import math
import signal
import threading
import warnings
from dataclasses import dataclass, field

import numpy as np

from . import _library
from ._library import PROGRESS, STOPPED


class FemcodError(RuntimeError):
    """A failure the library reported; ``code`` is the femcod command's exit code for it
    (2 usage, 3 bad input, 4 numerical failure or memory, 5 I/O, 6 stopped)."""

    def __init__(self, code, message):
        super().__init__(f"femcod: {message} (code {code})")
        self.code = code
        self.message = message


class Stopped(FemcodError):
    """The progress function asked the solve to stop."""


@dataclass
class Deck:
    """A contact problem as a deck holds it (doc/deck-format.md): heights ``lower`` and
    ``upper`` (nm, NP x NP, [i, j] row i column j), the pixel (nm), the moduli (GPa) and
    Poisson's ratios of the lower body, the upper body and the contact elements, MAXCONT
    (0: 5 % of NP^2, as for a rough scene) and a one-line label."""
    lower: np.ndarray
    upper: np.ndarray
    pixel: float
    young: tuple = (200.0, 2.0e12, 2.0e12)
    poisson: tuple = (0.25, 0.25, 0.25)
    maxcont: int = 0
    label: str = "femcod deck"
    #: NP where the heights are not held (a femcod-mpi result set does not store them).
    size: int = 0

    @property
    def np(self):
        return self.lower.shape[0] if self.lower is not None else self.size


@dataclass
class State:
    """The contact state at one requested load or approach. ``values`` by their names in
    PREFIX.h5 (units in the names): counts are ints, flags bools, the others floats. A
    state the solve did not reach (``state.reached`` False; a warning says why) keeps
    only what was asked, its other values NaN, and no maps."""
    values: dict
    maps: dict = field(default_factory=dict)

    def __getattr__(self, name):
        short = {"load": "load_nN", "approach": "approach_nm", "area": "area_nm2",
                 "max_pressure": "max_pressure_GPa", "plastic_volume": "plastic_volume_nm3"}
        values = self.__dict__.get("values", {})
        maps = self.__dict__.get("maps", {})
        key = short.get(name, name)
        if key in values:
            return values[key]
        if name in maps:
            return maps[name]
        raise AttributeError(name)

    @property
    def pressure(self):
        return self.maps.get("pressure")

    @property
    def gap(self):
        return self.maps.get("gap")


@dataclass
class Result:
    """A solve's answer, or a femcod run result set read back (femcod.load): the states
    (one per load or approach asked), the step history (arrays by column), the problem
    and the run's description."""
    states: list
    history: dict
    deck: Deck
    solver: str
    options: dict = field(default_factory=dict)
    summary: dict = None
    #: The prefix of the result set on disk (femcod.load, or solve(output=...)); None: in
    #: memory only.
    source: str = None

    def column(self, name):
        """One value of every state as an array (``result.column("area_nm2")``); NaN for a
        state that was not reached (``state.reached`` False), so none is mixed in."""
        return np.array([s.values.get(name, math.nan) if s.values.get("reached", 1) else math.nan
                         for s in self.states])

    @property
    def loads(self):
        return self.column("load_nN")

    @property
    def approaches(self):
        return self.column("approach_nm")

    @property
    def areas(self):
        return self.column("area_nm2")

    def to_dataframe(self):
        """The states as a pandas.DataFrame (pandas must be installed): a row per state,
        a column per value (counts as integers where every state was reached; a state
        not reached has NaN)."""
        try:
            import pandas as pd
        except ImportError as e:  # optional, never required
            raise ImportError("to_dataframe needs pandas (pip install pandas)") from e
        names = []
        for s in self.states:
            names += [n for n in s.values if n not in names]
        frame = pd.DataFrame([{n: s.values.get(n, math.nan) for n in names} for s in self.states], columns=names)
        frame.index = pd.RangeIndex(1, len(self.states) + 1, name="state")
        return frame

    def to_xarray(self):
        """The result as an xarray.Dataset (xarray must be installed): the maps over
        (state, i, j), the state values over (state). x_nm and y_nm are the pixels'
        centres as the XDMF mesh and the figures place them: x = (j + 1/2) d to the
        right, y = (NP - i - 1/2) d upward, row i = 0 at the top (doc/results.md,
        "Coordinates")."""
        try:
            import xarray as xr
        except ImportError as e:  # optional, never required
            raise ImportError("to_xarray needs xarray (pip install xarray)") from e
        n = self.deck.np
        reached = [s for s in self.states if s.values.get("reached", 1)]
        coords = {"state": np.arange(1, len(reached) + 1), "i": np.arange(n), "j": np.arange(n),
                  "y_nm": ("i", (n - np.arange(n) - 0.5) * self.deck.pixel),
                  "x_nm": ("j", (np.arange(n) + 0.5) * self.deck.pixel)}
        data = {}
        for name in (reached[0].maps if reached else {}):
            data[name] = (("state", "i", "j"), np.stack([s.maps[name] for s in reached]))
        for name in (reached[0].values if reached else {}):
            data[name] = (("state",), np.array([s.values[name] for s in reached]))
        return xr.Dataset(data, coords=coords, attrs={"solver": self.solver, "pixel_nm": self.deck.pixel})


class _Session:
    """One libfemcod session (freed with the object)."""

    def __init__(self):
        self.lib = _library.lib()
        self.handle = self.lib.femcod_create()
        if not self.handle:
            raise MemoryError("femcod: no memory for a session")

    def __del__(self):
        if getattr(self, "handle", None):
            self.lib.femcod_destroy(self.handle)
            self.handle = None

    def message(self):
        buf = ctypes.create_string_buffer(65536)
        self.lib.femcod_message(self.handle, buf, len(buf))
        return buf.value.decode("utf-8", "replace")

    def check(self, code):
        if code != 0:
            cls = Stopped if code == STOPPED else FemcodError
            raise cls(code, self.message())

    def text(self, function, *args):
        buf = ctypes.create_string_buffer(1 << 16)
        self.check(function(self.handle, *args, buf, len(buf)))
        return buf.value.decode("utf-8", "replace")


def _pointer(a):
    return a.ctypes.data_as(ctypes.POINTER(ctypes.c_double))


def heights_array(a, name="heights"):
    """A real square array as C-ordered float64 (converted once when it is not), with a
    clear exception for what femcod cannot take."""
    if hasattr(a, "heights") and callable(a.heights):
        raise TypeError(f"{name}: a SurfaceTopography Topography carries its own units and pixel: "
                        "femcod.solve(**femcod.from_topography(t), loads=[...])")
    a = np.asarray(a)
    if a.dtype.kind == "c":
        raise TypeError(f"{name}: complex heights; give the real part (np.real) if that is what is meant")
    if a.dtype.kind not in "iuf":
        raise TypeError(f"{name}: heights must be real numbers, found dtype {a.dtype}")
    if a.ndim != 2:
        raise ValueError(f"{name}: a 2-D height map is needed, found {a.ndim} dimensions {a.shape}")
    if a.shape[0] != a.shape[1] or a.shape[0] == 0:
        raise ValueError(f"{name}: femcod's grids are square (NP x NP), found {a.shape[0]} x {a.shape[1]}")
    a = np.ascontiguousarray(a, dtype=np.float64)
    if not np.isfinite(a).all():
        bad = np.argwhere(~np.isfinite(a))[0]
        raise ValueError(f"{name}: heights must be finite, found {a[tuple(bad)]} at [{bad[0]}, {bad[1]}] "
                         f"(and {int((~np.isfinite(a)).sum()) - 1} more)")
    return a


def _positive(x, name):
    try:
        v = float(x)
    except (TypeError, ValueError):
        raise TypeError(f"{name} must be a number, found {x!r}") from None
    if not (math.isfinite(v) and v > 0):
        raise ValueError(f"{name} must be a positive size in nm, found {x!r}")
    return v


def _number_text(x):
    """A number as text that reads back to the same double (repr is the shortest such)."""
    return repr(float(x))


def _option_list(values, name):
    values = np.atleast_1d(np.asarray(values, dtype=np.float64))
    if values.ndim != 1 or values.size == 0:
        raise ValueError(f"{name}: give a number or a list of numbers")
    return ",".join(_number_text(v) for v in values)


#: solve's own keywords for femcod run's options (the others pass through by name).
_OWN_KEYWORDS = ("solver", "loads", "approach", "plastic", "adhesion", "no_final_check")
_value_options_cache = None


def _value_options():
    """Keyword arguments of solve that are femcod run's options (--kebab-case): the names
    the library takes (femcod_option_names, from the solver's option table), but solve's
    own keywords."""
    global _value_options_cache
    if _value_options_cache is None:
        buf = ctypes.create_string_buffer(4096)
        _library.lib().femcod_option_names(buf, len(buf))
        names = [n[2:].replace("-", "_") for n in buf.value.decode().split()]
        _value_options_cache = tuple(n for n in names if n not in _OWN_KEYWORDS)
    return _value_options_cache


def _options(solver, loads, approach, plastic, adhesion, final_check, extra):
    opts = [("--solver", solver)]
    if loads is not None:
        opts.append(("--loads", _option_list(loads, "loads")))
    if approach is not None:
        opts.append(("--approach", _option_list(approach, "approach")))
    if plastic is not None and plastic is not False:
        opts.append(("--plastic", ""))
        if plastic is not True:
            opts.append(("--hardness", _number_text(plastic)))
    if adhesion is not None:
        opts.append(("--adhesion", str(adhesion)))
    if not final_check:
        opts.append(("--no-final-check", ""))
    for key, value in extra.items():
        if key not in _value_options():
            raise TypeError(f"solve() got an unexpected keyword argument {key!r} (options: "
                            f"{', '.join(_value_options())})")
        if value is None:
            continue
        if isinstance(value, str):
            text = value
        elif isinstance(value, (int, np.integer)) and key in ("max_iterations", "max_contacts"):
            text = str(int(value))
        else:
            text = _number_text(value)
        opts.append(("--" + key.replace("_", "-"), text))
    return opts


def _set_problem(session, lower, pixel, upper, young, poisson, maxcont):
    """The problem into the session; returns the arrays it was given (kept alive)."""
    lib = session.lib
    if isinstance(lower, Deck):
        deck = lower
        given = [name for name, v in (("pixel", pixel), ("upper", upper), ("young", young), ("poisson", poisson),
                                      ("maxcont", maxcont)) if v is not None]
        if given:
            raise TypeError(f"solve(deck): the deck gives the pixel, both surfaces, the materials and MAXCONT; "
                            f"{', '.join(given)}= would be ignored (change the Deck's fields instead, "
                            f"dataclasses.replace(deck, young=...))")
        lo = heights_array(deck.lower, "deck.lower")
        up = heights_array(deck.upper, "deck.upper")
        if up.shape != lo.shape:
            raise ValueError(f"deck: lower {lo.shape} and upper {up.shape} differ")
        young3 = (ctypes.c_double * 3)(*[float(v) for v in deck.young])
        poisson3 = (ctypes.c_double * 3)(*[float(v) for v in deck.poisson])
        session.check(lib.femcod_set_problem(session.handle, lo.shape[0], _positive(deck.pixel, "pixel"),
                                             _pointer(lo), _pointer(up), young3, poisson3, int(deck.maxcont),
                                             str(deck.label).encode()))
        return lo, up
    if pixel is None:
        raise TypeError("solve(heights, pixel=...): the pixel size in nm is needed")
    young = 200.0 if young is None else young
    poisson = 0.25 if poisson is None else poisson
    lo = heights_array(lower, "lower")
    up = None
    if upper is not None:
        up = heights_array(upper, "upper")
        if up.shape != lo.shape:
            raise ValueError(f"upper {up.shape} and lower {lo.shape} must be the same grid")
    if np.ndim(young) == 1 and len(young) == 3:
        blank = up if up is not None else np.zeros_like(lo)
        return _set_problem(session, Deck(lo, blank, pixel, tuple(young), tuple(np.broadcast_to(poisson, 3)),
                                          int(maxcont or 0), "femcod python"),
                            None, None, None, None, None)
    session.check(lib.femcod_set_heights(session.handle, lo.shape[0], _positive(pixel, "pixel"), _pointer(lo),
                                         _pointer(up) if up is not None else None, float(young), float(poisson),
                                         int(maxcont or 0)))
    return lo, up


def _solve_session(session, progress):
    """femcod_solve with the GIL released (ctypes does so), Ctrl-C turned into a stop
    through the progress function, and the user's progress function called."""
    interrupted = []
    failure = []

    def on_sigint(signum, frame):
        interrupted.append(True)

    def callback(step, contacts, load, seconds, user):
        if interrupted:
            return 1
        if progress is None:
            return 0
        try:
            return 1 if progress(step, contacts, load, seconds) is True else 0
        except BaseException as e:  # an error in the user's function stops the solve and is raised
            failure.append(e)
            return 1

    c_callback = PROGRESS(callback)
    main = threading.current_thread() is threading.main_thread()
    previous = signal.signal(signal.SIGINT, on_sigint) if main else None
    try:
        code = session.lib.femcod_solve(session.handle, c_callback, None)
    finally:
        if main:
            signal.signal(signal.SIGINT, previous)
    if interrupted:
        raise KeyboardInterrupt("femcod: the solve was stopped (Ctrl-C); nothing was kept")
    if failure:
        raise failure[0]
    session.check(code)


def _result(session, solver, options):
    lib = session.lib
    count = ctypes.c_int()
    session.check(lib.femcod_state_count(session.handle, ctypes.byref(count)))
    value_names = [n for n in session.text(lib.femcod_value_names, 0).split(",") if n]
    # Each value's kind (the library's field table): counts as ints, flags as bools.
    kinds = dict(zip(value_names, session.text(lib.femcod_value_names, 3).split(",")))
    map_names = [n for n in session.text(lib.femcod_value_names, 1).split(",") if n]
    columns = [n for n in session.text(lib.femcod_value_names, 2).split(",") if n]
    deck = _get_deck(session)
    n = deck.np
    states = []
    value = ctypes.c_double()
    for k in range(1, count.value + 1):
        values = {}
        for name in value_names:
            session.check(lib.femcod_state_value(session.handle, k, name.encode(), ctypes.byref(value)))
            values[name] = _typed(value.value, kinds.get(name))
        if not values["reached"]:
            # Not an answer: only what was asked (the load or the approach) is kept.
            asked = "approach_nm" if any(o == "--approach" for o, _ in options) else "load_nN"
            values = {name: (v if name in ("reached", asked) else math.nan) for name, v in values.items()}
        maps = {}
        if values["reached"]:
            for name in map_names:
                m = np.empty((n, n), dtype=np.float64)
                session.check(lib.femcod_state_map(session.handle, k, name.encode(), _pointer(m), n * n))
                maps[name] = m
        states.append(State(values, maps))
    steps = ctypes.c_int()
    session.check(lib.femcod_history_length(session.handle, ctypes.byref(steps)))
    history = {}
    for name in columns:
        h = np.empty(steps.value, dtype=np.float64)
        session.check(lib.femcod_history(session.handle, name.encode(), _pointer(h), steps.value))
        history[name] = h
    return Result(states, history, deck, solver, dict(options))


def _typed(value, kind):
    """A state value as its kind says: count -> int, flag -> bool, number -> float."""
    if kind == "count":
        return int(value)
    if kind == "flag":
        return bool(value)
    return value


def _get_deck(session):
    lib = session.lib
    np_ = ctypes.c_int()
    session.check(lib.femcod_problem_size(session.handle, ctypes.byref(np_)))
    n = np_.value
    lower = np.empty((n, n), dtype=np.float64)
    upper = np.empty((n, n), dtype=np.float64)
    pixel = ctypes.c_double()
    maxcont = ctypes.c_int()
    young = (ctypes.c_double * 3)()
    poisson = (ctypes.c_double * 3)()
    session.check(lib.femcod_get_problem(session.handle, ctypes.byref(pixel), ctypes.byref(maxcont), young, poisson,
                                         _pointer(lower), _pointer(upper)))
    label = session.text(lib.femcod_get_label)
    return Deck(lower, upper, pixel.value, tuple(young), tuple(poisson), maxcont.value, label)


def solve(lower, pixel=None, loads=None, solver="cg", upper=None, young=None, poisson=None, boundary="free",
          plastic=None, adhesion=None, approach=None, maxcont=None, final_check=True, threads=None, progress=None,
          output=None, overwrite=False, **options):
    """Solve a contact problem; returns a Result.

    lower      the heights (nm, NP x NP, [i, j] row i column j; any real array), or a
               Deck (femcod.read_deck), which then gives the pixel, both surfaces and
               the materials.
    pixel      the pixel size (nm).
    loads      total loads (nN) at which to report the state; or approach= (nm).
    solver     "cg" (default), "incremental" (event-exact) or "legacy" (Appendix B).
    upper      the other surface's heights (default: flat).
    young, poisson  the elastic body's modulus (GPa, default 200) and ratio (default 0.25),
               the other body rigid, as `femcod run --lower` (or three values each: lower,
               upper, contact elements). With a Deck, these, pixel, upper and maxcont are
               the deck's and refused here (TypeError).
    boundary   "free" or "periodic".
    plastic    None, True (hardness 11 GPa), or the hardness in GPa.
    adhesion   None, "dugdale" or "exponential", with work= (J/m^2) and range= (nm).
    threads    OpenMP threads for this and later solves (default: OMP_NUM_THREADS or all).
    progress   f(step, contacts, load_nN, seconds), called after each step or state and
               every 0.1 s while iterating; returning True stops the solve (femcod.Stopped).
    output     a prefix: also write the result set `femcod run -o PREFIX` writes (PREFIX.h5,
               .summary.json, CSV tables, figures; femcod.report makes its page). Existing
               results there are replaced only with overwrite=True.
    Further keywords are femcod run's options that shape the answer, with _ for -
    (femcod.option_keywords(): hardness, tol, max_iterations, kernel_radius, max_contacts,
    event_search, work, range, shear_strength, shear_slope, tangential, slip, friction,
    tangential_tol, ...). Ctrl-C stops the solve and raises KeyboardInterrupt.
    """
    extra = dict(options)
    if boundary != "free":
        extra["boundary"] = boundary
    opts = _options(solver, loads, approach, plastic, adhesion, final_check, extra)
    session = _Session()
    if threads is not None:
        if int(threads) < 1:
            raise ValueError(f"threads must be at least 1, found {threads}")
        session.check(session.lib.femcod_set_threads(int(threads)))
    kept = _set_problem(session, lower, pixel, upper, young, poisson, maxcont)
    for name, value in opts:
        session.check(session.lib.femcod_set_option(session.handle, name.encode(), str(value).encode()))
    _solve_session(session, progress)
    del kept
    for line in session.text(session.lib.femcod_warnings).splitlines():
        warnings.warn(f"femcod: {line}", stacklevel=2)
    result = _result(session, solver, opts)
    if output is not None:
        prefix = os.fspath(output)
        session.check(session.lib.femcod_write_results(session.handle, prefix.encode(), int(bool(overwrite))))
        result.source = prefix
    return result


def report(source, path=None, force=False):
    """Write the HTML page `femcod report` writes and return its path.

    source  a Result with its files (femcod.load, or solve(..., output=PREFIX)), a result
            set's prefix (or its PREFIX.h5 or PREFIX.summary.json), a study's prefix, or a
            directory of results (then one page of all of them, and each run's page).
    path    the page (default PREFIX.report.html, DIR/report.html); an existing path is
            replaced only with force=True.
    """
    if isinstance(source, Result):
        if not source.source:
            raise ValueError("femcod.report: this Result is in memory only; solve(..., output=PREFIX) writes the "
                             "result set a report is made from (or femcod.load a set femcod run wrote)")
        target = source.source
    else:
        target = os.fspath(source)
        for suffix in (".h5", ".summary.json"):
            if target.endswith(suffix) and os.path.isfile(target):
                target = target[:-len(suffix)]
    session = _Session()
    page = ctypes.create_string_buffer(len(target.encode()) + len(os.fspath(path or "").encode()) + 4096)
    session.check(session.lib.femcod_report(session.handle, target.encode(), os.fspath(path or "").encode(),
                                            int(bool(force)), page, len(page)))
    return page.value.decode()


def read_deck(path):
    """A deck file (text or HDF5) as a Deck, read by femcod's own reader with its checks."""
    session = _Session()
    session.check(session.lib.femcod_read_deck(session.handle, str(path).encode()))
    return _get_deck(session)


def read_heights(path, pixel=None, remove_plane=False, young=200.0, poisson=0.25):
    """A height file as `femcod run --lower PATH` reads it, as a Deck: an ASCII matrix or
    Gwyddion export (with its units and width), FILE.h5:/DATASET, or a NanoScope file
    FILE[:CHANNEL]; the surface on an elastic body (young GPa, poisson) against a rigid
    flat, from its lowest point. pixel (nm): needed when the file does not give it.
    What femcod run warns of (a tilt, a guessed unit) is issued as a Python warning."""
    session = _Session()
    session.check(session.lib.femcod_read_heights(session.handle, str(path).encode(), float(pixel or 0),
                                                  1 if remove_plane else 0, float(young), float(poisson)))
    for line in session.text(session.lib.femcod_warnings).splitlines():
        warnings.warn(f"femcod: {line}", stacklevel=2)
    return _get_deck(session)


def write_deck(path, deck, force=False):
    """Write a Deck to `path` (a name ending in .h5: the HDF5 deck), atomically. An
    existing file is replaced only with force=True, and only if femcod wrote it."""
    session = _Session()
    _set_problem(session, deck, None, None, None, None, None)
    session.check(session.lib.femcod_write_deck(session.handle, str(path).encode(), 1 if force else 0))


def set_threads(threads):
    """OpenMP threads of the solvers for the whole process."""
    session = _Session()
    session.check(session.lib.femcod_set_threads(int(threads)))


def option_keywords():
    """The keywords solve() takes for femcod run's options (the library's option table)."""
    return _value_options()


def version():
    buf = ctypes.create_string_buffer(256)
    _library.lib().femcod_version(buf, len(buf))
    return buf.value.decode()
