"""Run one peer contact solver on a surface written by `femcod bench cg` and print one line.

Called by `femcod bench cg --peers PYTHON` (free boundary: aspher, contactmechanics) and
`femcod bench periodic --peers PYTHON` (periodic: tamaas, contactmechanics-periodic) with
the Python of a separate virtual environment where the peers are installed (never a femcod
dependency, see doc/performance.md):

    PYTHON app/femcod_peers.py PEER GAPS NP PIXEL ESTAR PRESSURE TOL
    PYTHON app/femcod_peers.py tamaas-adhesion GAPS NP PIXEL ESTAR MEAN_GAP TOL LAW W RANGE
    PYTHON app/femcod_peers.py tamaas-tangential GAPS NP PIXEL YOUNG PRESSURE TOL NU MU FRACTION

GAPS is NP*NP float64 values (Fortran order, nm): the initial gap between the elastic
surface and the rigid flat, 0 at the first touch; PIXEL in nm, ESTAR = E/(1-nu^2) in GPa, PRESSURE the nominal mean pressure in GPa,
TOL the solver tolerance. Output, one line:

    peer seconds iterations residual contact_fraction peak_rss_mb status

`seconds` is the solve alone (set-up of the surface excluded), peak RSS the process
high-water mark. A peer that is not installed prints `peer - - - - - missing`. The
periodic peers add an eighth field, the mean gap (nm) of the solution: the mean over the
cell of the separation of the deformed surfaces (0 in contact).

`tamaas-adhesion` (called by `femcod bench adhesion --peers PYTHON`) solves the periodic
cell at a prescribed mean gap MEAN_GAP (nm) with tamaas' adhesion functional, LAW `dugdale`
(MaugisAdhesionFunctional) or `exponential` (ExponentialAdhesionFunctional), work W
(J/m^2 = nN/nm) and range RANGE (nm; W = 0: no functional), by its gap-variable solver
(Rey, Anciaux and Molinari 2017), from the undeformed surfaces; its eighth field is the
total load (nN, the mean traction times the cell's area).

`tamaas-tangential` (called by `femcod bench tangential --peers PYTHON`) solves the periodic
cell at the mean pressure PRESSURE (GPa) and the mean tangential traction FRACTION * MU *
PRESSURE along femcod's x (the columns: tamaas' second axis) with Coulomb friction MU, by
tamaas' PolonskyKeerTan on a surface_2d model of Young's modulus YOUNG and Poisson's ratio
NU; its eighth field is the fraction of the cell that sticks, and it writes the tractions
(femcod's x, femcod's y up the page, the pressure; GPa, NP*NP float64 each in Fortran order)
to GAPS.tractions.
"""
import contextlib
import os
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


@contextlib.contextmanager
def quiet_stdout():
    """Silence what a C++ library writes to the process's standard output and error
    (tamaas prints its iterations), so that the answer is the only line."""
    sys.stdout.flush()
    sys.stderr.flush()
    saved = [os.dup(1), os.dup(2)]
    null = os.open(os.devnull, os.O_WRONLY)
    os.dup2(null, 1)
    os.dup2(null, 2)
    try:
        yield
    finally:
        sys.stdout.flush()
        sys.stderr.flush()
        os.dup2(saved[0], 1)
        os.dup2(saved[1], 2)
        os.close(null)
        for fd in saved:
            os.close(fd)


def run_tamaas(gap, n, pixel, estar, pressure, tol):
    import tamaas as tm
    height = np.ascontiguousarray(gap.max() - gap)
    length = n * pixel
    model = tm.ModelFactory.createModel(tm.model_type.basic_2d, [length, length], [n, n])
    model.E = estar
    model.nu = 0.0
    solver = tm.PolonskyKeerRey(model, height, tol)
    with quiet_stdout():
        t0 = time.perf_counter()
        error = solver.solve(pressure)
        t1 = time.perf_counter()
    traction = np.asarray(model.traction)
    separation = np.asarray(model.displacement) - height
    return (t1 - t0, "-", float(error), np.count_nonzero(traction > 0) / n ** 2, "converged",
            float(separation.mean()))


def run_contactmechanics_periodic(gap, n, pixel, estar, pressure, tol):
    from ContactMechanics import PeriodicFFTElasticHalfSpace
    from ContactMechanics.Systems import NonSmoothContactSystem
    from SurfaceTopography import Topography
    height = gap.max() - gap
    length = n * pixel
    topography = Topography(height, physical_sizes=(length, length), periodic=True)
    substrate = PeriodicFFTElasticHalfSpace((n, n), estar, physical_sizes=(length, length))
    system = NonSmoothContactSystem(substrate, topography)
    t0 = time.perf_counter()
    sol = system.minimize_proxy(external_force=pressure * length ** 2, pentol=tol * np.ptp(height))
    t1 = time.perf_counter()
    separation = system.compute_gap(sol.x, sol.offset)
    return (t1 - t0, sol.nit, float("nan"), np.count_nonzero(sol.jac > 0) / n ** 2, str(sol.success),
            float(separation.mean()))


def run_tamaas_adhesion(gap, n, pixel, estar, mean_gap, tol, law, work, rho):
    import tamaas as tm
    height = np.ascontiguousarray(gap.max() - gap)
    length = n * pixel
    model = tm.ModelFactory.createModel(tm.model_type.basic_2d, [length, length], [n, n])
    model.E = estar
    model.nu = 0.0
    solver = tm.PolonskyKeerRey(model, height, tol, tm.PolonskyKeerRey.gap, tm.PolonskyKeerRey.gap)
    solver.max_iter = 20000
    if work > 0:
        functional = (tm.MaugisAdhesionFunctional if law == "dugdale" else tm.ExponentialAdhesionFunctional)(height)
        functional.setParameters({"rho": rho, "surface_energy": work})
        solver.addFunctionalTerm(functional)
    with quiet_stdout():
        t0 = time.perf_counter()
        error = solver.solve(mean_gap)
        t1 = time.perf_counter()
    separation = np.asarray(model.displacement) - height
    load = float(np.asarray(model.traction).mean()) * length ** 2
    contact = np.count_nonzero(separation <= 1e-12 * max(rho, 1.0)) / n ** 2
    return t1 - t0, "-", float(error), contact, "converged" if error < tol else "not_converged", load


def run_tamaas_tangential(gap, n, pixel, young, pressure, tol, nu, mu, fraction, path):
    import tamaas as tm
    height = np.ascontiguousarray(gap.max() - gap)
    length = n * pixel
    model = tm.ModelFactory.createModel(tm.model_type.surface_2d, [length, length], [n, n])
    model.E = young
    model.nu = nu
    solver = tm.PolonskyKeerTan(model, height, tol, mu)
    solver.max_iter = 20000
    with quiet_stdout():
        t0 = time.perf_counter()
        error = solver.solve([0.0, fraction * mu * pressure, pressure])
        t1 = time.perf_counter()
    traction = np.asarray(model.traction)
    # tamaas' second axis is femcod's x (the columns); its first runs down femcod's rows.
    tx, ty, p = traction[..., 1], -traction[..., 0], traction[..., 2]
    np.concatenate([tx.ravel(order="F"), ty.ravel(order="F"), p.ravel(order="F")]).astype("<f8").tofile(
        path + ".tractions")
    contact = p > 0
    stick = contact & (np.hypot(tx, ty) < mu * p * (1 - 1e-6))
    return (t1 - t0, "-", float(error), np.count_nonzero(contact) / n ** 2,
            "converged" if error < tol else "not_converged", float(np.count_nonzero(stick)) / n ** 2)


PEERS = {"aspher": run_aspher, "contactmechanics": run_contactmechanics, "tamaas": run_tamaas,
         "contactmechanics-periodic": run_contactmechanics_periodic}


def main():
    peer, path, n, pixel, estar, pressure, tol = sys.argv[1:8]
    n = int(n)
    gap = np.fromfile(path, dtype="<f8").reshape((n, n), order="F")
    try:
        if peer == "tamaas-tangential":
            nu, mu, fraction = sys.argv[8:11]
            answer = run_tamaas_tangential(gap, n, float(pixel), float(estar), float(pressure), float(tol),
                                           float(nu), float(mu), float(fraction), path)
        elif peer == "tamaas-adhesion":
            law, work, rho = sys.argv[8:11]
            answer = run_tamaas_adhesion(gap, n, float(pixel), float(estar), float(pressure), float(tol), law,
                                         float(work), float(rho))
        else:
            answer = PEERS[peer](gap, n, float(pixel), float(estar), float(pressure), float(tol))
    except ImportError:
        print(peer, "-", "-", "-", "-", "-", "missing")
        return
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0
    seconds, iterations, residual, fraction, status = answer[:5]
    extra = [f"{answer[5]:.10e}"] if len(answer) > 5 else []
    print(peer, f"{seconds:.3f}", iterations, f"{residual:.2e}", f"{fraction:.5f}", f"{peak:.0f}",
          str(status).replace(" ", "_"), *extra)


if __name__ == "__main__":
    main()
