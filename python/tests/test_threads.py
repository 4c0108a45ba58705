"""How the femcod program's idle OpenMP threads wait (app/femcod_start_environment.f90):
passively when the tasks already running at start leave fewer cpus than threads, libgomp's
default otherwise, and a user's own OMP_WAIT_POLICY or GOMP_SPINCOUNT always kept. The
summary's "openmp" says which and why (doc/results.md). What the choice is worth is
measured in doc/performance.md ("Threads on a busy machine"), not here.

A busy machine is made for each test by one process spinning throughout (it is always
running, so at least one other task is seen) with as many threads asked for as the
machine has cpus (so one other task is one too many). A process bound to some of the cpus
(a batch system's binding) keeps the default: the first test is skipped there. A quiet machine cannot be made from
a test (anything else the host runs counts), so the default's case is not tested here.
"""
import contextlib
import json
import os
import subprocess
import sys
import time

import pytest

from conftest import REPO, femcod_program


def machine_cpus():
    """The cpuN lines of /proc/stat: the count femcod compares with."""
    with open("/proc/stat", encoding="ascii") as f:
        return sum(1 for line in f if line.startswith("cpu") and line[3].isdigit())


@contextlib.contextmanager
def one_busy_process():
    spinner = subprocess.Popen([sys.executable, "-c", "while True: pass"])
    try:
        time.sleep(0.3)
        yield
    finally:
        spinner.kill()
        spinner.wait()


def openmp_record(tmp_path, **settings):
    """The summary's "openmp" of a small run with these environment settings (and none of
    the wait variables the caller did not give)."""
    env = {k: v for k, v in os.environ.items()
           if k not in ("OMP_WAIT_POLICY", "GOMP_SPINCOUNT", "FEMCOD_BUSY_AT_START", "OMP_NUM_THREADS")}
    env.update(settings)
    prefix = tmp_path / "sphere"
    p = subprocess.run([femcod_program(), "run", os.path.join(REPO, "input", "sphere_d2.deck"), "--loads", "100",
                        "-o", str(prefix), "-q", "--figures", "none"], env=env, capture_output=True, text=True)
    assert p.returncode == 0, p.stderr
    with open(f"{prefix}.summary.json", encoding="utf-8") as f:
        return json.load(f)["openmp"]


def test_a_busy_machine_makes_the_threads_wait_passively(tmp_path):
    if len(os.sched_getaffinity(0)) < machine_cpus():
        pytest.skip("bound to some of the cpus: femcod keeps the default there (the other tasks may be elsewhere)")
    threads = max(2, machine_cpus())
    with one_busy_process():
        record = openmp_record(tmp_path, OMP_NUM_THREADS=str(threads))
    assert record["threads"] == threads
    assert record["wait_policy"].startswith("passive (chosen by femcod: "), record
    assert f", {machine_cpus()} cpus)" in record["wait_policy"], record


def test_one_thread_keeps_the_default(tmp_path):
    with one_busy_process():
        record = openmp_record(tmp_path, OMP_NUM_THREADS="1")
    assert record == {"threads": 1, "wait_policy": "default"}


def test_the_users_wait_policy_is_kept(tmp_path):
    with one_busy_process():
        record = openmp_record(tmp_path, OMP_NUM_THREADS=str(max(2, machine_cpus())), OMP_WAIT_POLICY="active")
    assert record["wait_policy"] == "active"


def test_a_spin_count_of_the_users_keeps_the_default(tmp_path):
    with one_busy_process():
        record = openmp_record(tmp_path, OMP_NUM_THREADS=str(max(2, machine_cpus())), GOMP_SPINCOUNT="1000")
    assert record["wait_policy"] == "default"


def test_the_legacy_condition_estimate_does_not_follow_openblas_threads(tmp_path):
    """The legacy solver's condition estimate (/run/trfact_condition; doc/results.md) is
    the same to the last bit whatever OpenBLAS's thread count. Through LAPACK's dlacn2
    it was not: on input/sphere_d05.deck at 1167.54 nN it read 166600739.38782102 with
    OPENBLAS_NUM_THREADS=1 and 166600739.387821 with 2 (the estimator now sums in
    femcod's own loops, legacy/femcod_trfact)."""
    import h5py
    values = []
    for threads in ("1", "2"):
        env = dict(os.environ, OPENBLAS_NUM_THREADS=threads)
        prefix = tmp_path / f"blas{threads}"
        p = subprocess.run([femcod_program(), "run", os.path.join(REPO, "input", "sphere_d05.deck"), "--solver",
                            "legacy", "--loads", "1167.5434222245665", "-o", str(prefix), "-q", "--figures", "none"],
                           env=env, capture_output=True, text=True)
        assert p.returncode == 0, p.stderr
        with h5py.File(f"{prefix}.h5", "r") as f:
            values.append(float(f["run/trfact_condition"][()]))
    assert values[0] == values[1] and values[0] > 1, values
