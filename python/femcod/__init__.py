"""femcod from Python: the contact solvers of femcod (Bora 2012, chapter 4 and Appendix B)
on numpy arrays, through the C library libfemcod.so (doc/python.md).

    import femcod
    r = femcod.solve(heights, pixel=2.0, loads=[1e3, 1e4])      # cg by default
    r.states[0].area, r.states[0].pressure                        # nm^2; GPa map [i, j]
    r = femcod.load("out/sphere_d1.h5")                           # a femcod run result set
    deck = femcod.read_deck("input/sphere_d1.deck"); femcod.solve(deck, loads=[100], solver="incremental")

Arrays are [i, j] = row i, column j, as in femcod's decks and HDF5 files. Units: nm, GPa, nN.
"""
from ._core import (Deck, FemcodError, Result, State, Stopped, option_keywords, read_deck, read_heights, report,
                    set_threads, solve, version, write_deck)
from ._load import load, read_table
from ._topography import from_topography

__all__ = ["solve", "load", "report", "read_deck", "read_heights", "write_deck", "read_table", "from_topography", "set_threads", "version",
           "option_keywords", "Deck", "Result", "State", "FemcodError", "Stopped"]
try:
    from importlib.metadata import PackageNotFoundError, version as _distribution_version
    __version__ = _distribution_version("femcod")  # from fpm.toml at build time (python/setup.py)
except PackageNotFoundError:  # run from the source tree, not installed
    __version__ = version()
