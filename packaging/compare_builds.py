"""Two builds of femcod give the same answers, to the last bit, on the decks of input/.

    python packaging/compare_builds.py run FEMCOD DIR     # FEMCOD's results into DIR
    python packaging/compare_builds.py compare DIR_A DIR_B

`run` solves every deck of input/ with the incremental, cg and legacy solvers: first the
deck's own incremental history (to its last contact), then each solver at 5, 15 and 30 %
of that history's final load (the loads of python/tests/test_cli_equal.py). `compare`
reads both directories' result sets with femcod.load and compares every history column and
every map of every state as doubles, bit for bit (NaN equal to NaN), and prints a table.
Needs the femcod Python package (numpy, h5py); exits 1 if anything differs.
"""
import glob
import os
import subprocess
import sys

import numpy as np

REPO = os.path.abspath(os.path.join(os.path.dirname(__file__), os.pardir))
SOLVERS = ("incremental", "cg", "legacy")


def run(program, out):
    import femcod
    os.makedirs(out, exist_ok=True)
    for deck in sorted(glob.glob(os.path.join(REPO, "input", "*.deck"))):
        name = os.path.splitext(os.path.basename(deck))[0]
        full = os.path.join(out, f"{name}_full")
        subprocess.run([program, "run", deck, "-o", full, "-q", "--force", "--figures", "none"], check=True)
        final = float(femcod.load(f"{full}.h5").history["load_nN"].max())
        loads = ",".join(repr(f * final) for f in (0.05, 0.15, 0.30))
        for solver in SOLVERS:
            subprocess.run([program, "run", deck, "--solver", solver, "--loads", loads, "-o",
                            os.path.join(out, f"{name}_{solver}"), "-q", "--force", "--figures", "none"], check=True)


def same(a, b):
    a, b = np.asarray(a, dtype=np.float64), np.asarray(b, dtype=np.float64)
    return a.shape == b.shape and np.array_equal(a.view(np.uint64), b.view(np.uint64))


def arrays(result):
    """Every history column and every numeric field of every state, by name."""
    found = {f"history/{k}": v for k, v in result.history.items()}
    for n, state in enumerate(result.states):
        for key, value in list(state.values.items()) + list(state.maps.items()):
            if np.asarray(value).dtype.kind in "iuf":
                found[f"state{n}/{key}"] = value
    return found


def compare(first, second):
    import femcod
    files = sorted(os.path.basename(p) for p in glob.glob(os.path.join(first, "*.h5")))
    differing = 0
    print(f"{'result set':34s} {'states':>6s} {'arrays':>6s} {'doubles':>9s}  identical")
    for name in files:
        a, b = femcod.load(os.path.join(first, name)), femcod.load(os.path.join(second, name))
        xa, xb = arrays(a), arrays(b)
        keys = sorted(xa)
        bad = [k for k in keys if k not in xb or not same(xa[k], xb[k])] + sorted(set(xb) - set(xa))
        doubles = sum(np.asarray(xa[k]).size for k in keys)
        differing += bool(bad)
        print(f"{name:34s} {len(a.states):6d} {len(keys):6d} {doubles:9d}  {'yes' if not bad else 'NO: ' + ', '.join(bad[:4])}")
    print(f"{len(files)} result sets, {differing} differing")
    return 1 if differing or not files else 0


if __name__ == "__main__":
    if len(sys.argv) == 4 and sys.argv[1] == "run":
        run(sys.argv[2], sys.argv[3])
    elif len(sys.argv) == 4 and sys.argv[1] == "compare":
        sys.exit(compare(sys.argv[2], sys.argv[3]))
    else:
        sys.exit(__doc__)
