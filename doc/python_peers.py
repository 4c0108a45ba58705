"""The same contact problem in femcod, tamaas, ContactMechanics and ASPHER, from Python
(doc/python.md, "The peers side by side").

    PYTHON doc/python_peers.py [--np 512] [--repeats 3]

PYTHON is an environment with femcod (pip install ./python) and the peers (pip install
tamaas ContactMechanics aspher; ASPHER needs libeigen3-dev to build): never a femcod
dependency. A peer that is not installed gets a row saying so.

The problem: a self-affine surface (Hurst 0.8, rms 3 nm, pixel 2 nm, `femcod mkdeck`) on
an elastic half-space (E* = 213.3 GPa) against a rigid flat, at the mean pressure for about
5 % contact (p = 0.05 E* h'rms / 2), tolerance 1e-8 in each solver's own measure; once as
a periodic cell (femcod, tamaas, ContactMechanics) and once as a free surface (femcod,
ContactMechanics, ASPHER). Each solver gets the same gap array. Times are the call a user
makes (femcod.solve whole, the peers' solve call alone), the median of --repeats.
"""
import argparse
import contextlib
import os
import shutil
import statistics
import subprocess
import tempfile
import time

import numpy as np

import femcod

TOL = 1e-8


@contextlib.contextmanager
def quiet():
    """tamaas prints its iterations on the process's standard output and error (C++
    streams, flushed through C's stdio before the descriptors are given back)."""
    import ctypes
    libc = ctypes.CDLL(None)
    saved = [os.dup(1), os.dup(2)]
    null = os.open(os.devnull, os.O_WRONLY)
    os.dup2(null, 1)
    os.dup2(null, 2)
    try:
        yield
    finally:
        libc.fflush(None)
        os.dup2(saved[0], 1)
        os.dup2(saved[1], 2)
        os.close(null)
        for fd in saved:
            os.close(fd)


def femcod_solver(periodic):
    def run(deck, height, pressure, estar):
        n, d = deck.np, deck.pixel
        r = femcod.solve(deck, loads=[pressure * (n * d) ** 2], solver="cg",
                         boundary="periodic" if periodic else "free", tol=TOL)
        s = r.states[0]
        return s.area_fraction, s.mean_gap_nm
    return run


def tamaas_periodic(deck, height, pressure, estar):
    import tamaas as tm
    n, d = deck.np, deck.pixel
    model = tm.ModelFactory.createModel(tm.model_type.basic_2d, [n * d, n * d], [n, n])
    model.E, model.nu = estar, 0.0
    solver = tm.PolonskyKeerRey(model, height, TOL)
    with quiet():
        solver.solve(pressure)
    traction = np.asarray(model.traction)
    return np.count_nonzero(traction > 0) / n ** 2, float((np.asarray(model.displacement) - height).mean())


def contactmechanics(periodic):
    def run(deck, height, pressure, estar):
        from ContactMechanics import FreeFFTElasticHalfSpace, PeriodicFFTElasticHalfSpace
        from ContactMechanics.Systems import NonSmoothContactSystem
        from SurfaceTopography import Topography
        n, d = deck.np, deck.pixel
        half_space = PeriodicFFTElasticHalfSpace if periodic else FreeFFTElasticHalfSpace
        system = NonSmoothContactSystem(half_space((n, n), estar, physical_sizes=(n * d, n * d)),
                                        Topography(height, physical_sizes=(n * d, n * d), periodic=periodic))
        sol = system.minimize_proxy(external_force=pressure * (n * d) ** 2, pentol=TOL * np.ptp(height))
        return np.count_nonzero(sol.jac > 0) / n ** 2, float(system.compute_gap(sol.x, sol.offset).mean())
    return run


def aspher_free(deck, height, pressure, estar):
    import aspher
    n, d = deck.np, deck.pixel
    gap = height.max() - height
    res = aspher.solve_nested(grid_size=n, gap=gap.ravel(), p_nominal=pressure, domain_size=n * d, E_star=estar,
                              backend="fft", tol=TOL)
    return res.contact_area, float("nan")


CODE = {
    "femcod": "femcod.solve(deck, loads=[p*L**2], solver='cg', boundary=B, tol=1e-8)",
    "tamaas": "tm.PolonskyKeerRey(model, h, 1e-8).solve(p)",
    "ContactMechanics": "NonSmoothContactSystem(HalfSpace(...), Topography(h, ...)).minimize_proxy(external_force=p*L**2, "
                        "pentol=1e-8*ptp(h))",
    "ASPHER": "aspher.solve_nested(grid_size=n, gap=g, p_nominal=p, domain_size=L, E_star=E, backend='fft', tol=1e-8)",
}


def row(name, boundary, runner, deck, height, pressure, estar, repeats):
    times, answer = [], None
    try:
        for _ in range(repeats):
            t0 = time.perf_counter()
            answer = runner(deck, height, pressure, estar)
            times.append(time.perf_counter() - t0)
    except ImportError as e:
        print(f"| {boundary} | {name} | not installed ({e.name}) | | | |")
        return
    fraction, mean_gap = answer
    gap_text = "" if np.isnan(mean_gap) else f"{mean_gap:.6f}"
    print(f"| {boundary} | {name} | `{CODE[name]}` | {fraction:.5f} | {gap_text} | {statistics.median(times):.3f} |")


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--np", type=int, default=512)
    parser.add_argument("--repeats", type=int, default=3)
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as d:
        path = os.path.join(d, "surface.h5")
        subprocess.run([shutil.which("femcod"), "mkdeck", "self-affine", "--np", str(args.np), "--pixel", "2",
                        "--hurst", "0.8", "--rms", "3", "--shape-on", "lower", "-o", path], check=True,
                       capture_output=True)
        deck = femcod.read_deck(path)
    height = np.ascontiguousarray(deck.lower)
    estar = deck.young[0] / (1 - deck.poisson[0] ** 2)
    gy, gx = np.gradient(height, deck.pixel)
    pressure = 0.05 * estar * np.sqrt(np.mean(gx ** 2 + gy ** 2)) / 2
    print(f"NP = {args.np}, pixel {deck.pixel} nm, E* = {estar:.4g} GPa, mean pressure {pressure:.5g} GPa, "
          f"tolerance {TOL}, medians of {args.repeats}")
    print("| boundary | solver | code | contact fraction | mean gap (nm) | seconds |")
    print("|---|---|---|---|---|---|")
    for name, runner in (("femcod", femcod_solver(True)), ("tamaas", tamaas_periodic),
                         ("ContactMechanics", contactmechanics(True))):
        row(name, "periodic", runner, deck, height, pressure, estar, args.repeats)
    for name, runner in (("femcod", femcod_solver(False)), ("ContactMechanics", contactmechanics(False)),
                         ("ASPHER", aspher_free)):
        row(name, "free", runner, deck, height, pressure, estar, args.repeats)


if __name__ == "__main__":
    main()
