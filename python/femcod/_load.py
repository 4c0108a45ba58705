"""femcod.load: a result set the femcod command wrote, read back into Python objects.

- PREFIX.h5 of `femcod run` or `femcod-mpi` (schema: doc/results.md): a Result, the same
  object femcod.solve returns, with its summary.json beside it when there is one;
- a deck (text, or the HDF5 deck of `femcod mkdeck ... -o X.h5`): a Deck;
- the CSV files of `femcod resolution`, `summits`, `multiscale` and `bench` (a file, or
  the prefix they share): a dict of tables, each a dict of columns (numpy arrays).
"""
import csv
import glob
import json
import os

import numpy as np

from ._core import Deck, Result, State, read_deck

#: History datasets and the names femcod.solve gives the same columns.
# The state values that are flags (io/femcod_state_record's FIELD_FLAG), stored in
# PREFIX.h5 as 1 or 0; test_schema.py keeps this set equal to the library's kinds.
FLAGS = {"gross_sliding"}
_HISTORY = {"step": "step", "contacts": "contacts", "load": "load_nN", "approach": "approach_nm", "area": "area_nm2",
            "area_fraction": "area_fraction", "n_above_hardness": "n_above_hardness", "n_plastic": "n_plastic",
            "friction": "friction_nN", "friction_coefficient": "friction_coefficient"}


def _is_hdf5(path):
    with open(path, "rb") as f:
        return f.read(8) == b"\x89HDF\r\n\x1a\n"


def load(path):
    """Read what a femcod command wrote at `path` (see the module's description)."""
    path = os.fspath(path)
    for companion in (".summary.json", ".xdmf"):
        # A companion of PREFIX.h5 names the set: read the set (with its summary).
        if path.endswith(companion):
            prefix = path[:-len(companion)]
            if os.path.isfile(prefix + ".h5"):
                return load(prefix + ".h5")
            raise FileNotFoundError(f"{path}: a companion file of a femcod result set; its data, {prefix}.h5, "
                                    f"is not beside it (femcod.load reads PREFIX.h5, a deck or PREFIX.*.csv)")
    if os.path.isfile(path) and _is_hdf5(path):
        import h5py
        with h5py.File(path, "r") as f:
            if "loads" in f or "history" in f:
                return _run_result(f, path)
        return read_deck(path)
    if os.path.isfile(path) and not path.endswith(".csv"):
        return read_deck(path)
    files = [path] if path.endswith(".csv") else sorted(glob.glob(glob.escape(path) + ".*.csv"))
    if not files:
        raise FileNotFoundError(f"{path}: no femcod result set (PREFIX.h5, a deck, or PREFIX.*.csv)")
    return {os.path.basename(f)[len(os.path.basename(path)) + 1:-4] if f != path else
            os.path.basename(f)[:-4]: read_table(f) for f in files}


def read_table(path):
    """A femcod CSV file as a dict of columns: numbers as float64 arrays, text as str arrays."""
    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    if not rows:
        raise ValueError(f"{path}: empty file")
    header, body = rows[0], rows[1:]
    table = {}
    for c, name in enumerate(header):
        cells = [r[c] if c < len(r) else "" for r in body]
        try:
            table[name] = np.array([float(x) for x in cells], dtype=np.float64)
        except ValueError:
            table[name] = np.array(cells, dtype=str)
    return table


def _attributes(obj):
    out = {}
    for k, v in obj.attrs.items():
        if isinstance(v, bytes):
            v = v.decode()
        elif isinstance(v, np.ndarray) and v.size == 1:
            v = v.item()
        elif isinstance(v, np.generic):
            v = v.item()
        out[k] = v
    return out


def _run_result(f, path):
    d = _attributes(f["deck"])
    surfaces = [f[k][()] if k in f else None for k in ("surfaces/lower", "surfaces/upper")]
    # femcod-mpi's set names the grid and the pixel only (doc/cluster.md).
    deck = Deck(surfaces[0], surfaces[1], d["pixel_nm"],
                tuple(d.get(f"young_{b}_GPa", np.nan) for b in ("lower", "upper", "contact")),
                tuple(d.get(f"poisson_{b}", np.nan) for b in ("lower", "upper", "contact")), d.get("MAXCONT", 0),
                d.get("label", ""), int(d["NP"]))
    states = []
    if "loads" in f:
        for name in sorted(f["loads"].keys()):
            g = f["loads"][name]
            # Integer attributes are counts (ints), or flags (1/0: bools); the others floats.
            values = {k: (bool(v) if k in FLAGS else v) if isinstance(v, int) else float(v)
                      for k, v in _attributes(g).items() if isinstance(v, (int, float)) and k != "index"}
            if "area_fraction" not in values:
                # a file from before 0.3: as femcod run's loads.csv, contacts d^2 / (NP^2 d^2)
                values["area_fraction"] = values["contacts"] * deck.pixel ** 2 / (deck.np ** 2 * deck.pixel ** 2)
            values["reached"] = True
            maps = {k: g[k][()] for k in g.keys() if g[k].ndim == 2}
            states.append(State(values, maps))
    history = {}
    if "history" in f:
        for k in f["history"].keys():
            history[_HISTORY.get(k, k)] = np.asarray(f["history"][k][()], dtype=np.float64)
    run = _attributes(f["run"]) if "run" in f else {}
    summary = None
    stem = path[:-3] if path.endswith(".h5") else path
    if os.path.exists(stem + ".summary.json"):
        with open(stem + ".summary.json") as s:
            summary = json.load(s)
    return Result(states, history, deck, run.get("solver", ""), run, summary, stem)
