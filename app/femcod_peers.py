"""Run one peer contact solver on a surface written by `femcod bench cg` and print one line.

Called by `femcod bench cg --peers PYTHON` with the Python of a separate virtual
environment where the peers are installed (never a femcod dependency, see
doc/performance.md):

    PYTHON app/femcod_peers.py PEER GAPS NP PIXEL ESTAR PRESSURE TOL

GAPS is NP*NP float64 values (Fortran order, nm): the initial gap between the elastic
surface and the rigid flat, 0 at the first touch; PIXEL in nm, ESTAR = E/(1-nu^2) in GPa, PRESSURE the nominal mean pressure in GPa,
TOL the solver tolerance. Output, one line:

    peer seconds iterations residual contact_fraction peak_rss_mb status

`seconds` is the solve alone (set-up of the surface excluded), peak RSS the process
high-water mark. A peer that is not installed prints `peer - - - - - missing`.
"""
import resource
import sys
import time

import numpy as np


def run_aspher(gap, n, pixel, estar, pressure, tol):
    import aspher
    t0 = time.perf_counter()
    res = aspher.solve_nested(grid_size=n, gap=gap.ravel(), p_nominal=pressure,
                              domain_size=n * pixel, E_star=estar, backend="fft", tol=tol)
    t1 = time.perf_counter()
    return t1 - t0, res.iterations, res.error, res.contact_area, res.status


def run_contactmechanics(gap, n, pixel, estar, pressure, tol):
    from ContactMechanics import FreeFFTElasticHalfSpace
    from ContactMechanics.Systems import NonSmoothContactSystem
    from SurfaceTopography import Topography
    height = gap.max() - gap
    topography = Topography(height, physical_sizes=(n * pixel, n * pixel), periodic=False)
    substrate = FreeFFTElasticHalfSpace((n, n), estar, physical_sizes=(n * pixel, n * pixel))
    system = NonSmoothContactSystem(substrate, topography)
    t0 = time.perf_counter()
    sol = system.minimize_proxy(external_force=pressure * (n * pixel) ** 2, pentol=tol * np.ptp(height))
    t1 = time.perf_counter()
    forces = sol.jac
    return t1 - t0, sol.nit, float("nan"), np.count_nonzero(forces > 0) / n ** 2, str(sol.success)


PEERS = {"aspher": run_aspher, "contactmechanics": run_contactmechanics}


def main():
    peer, path, n, pixel, estar, pressure, tol = sys.argv[1:8]
    n = int(n)
    gap = np.fromfile(path, dtype="<f8").reshape((n, n), order="F")
    try:
        seconds, iterations, residual, fraction, status = PEERS[peer](
            gap, n, float(pixel), float(estar), float(pressure), float(tol))
    except ImportError:
        print(peer, "-", "-", "-", "-", "-", "missing")
        return
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0
    print(peer, f"{seconds:.3f}", iterations, f"{residual:.2e}", f"{fraction:.5f}", f"{peak:.0f}",
          str(status).replace(" ", "_"))


if __name__ == "__main__":
    main()
