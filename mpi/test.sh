#!/usr/bin/env bash
# femcod-mpi's tests: the distributed suite on 1, 2 and 4 ranks (4 oversubscribe a
# 2-core machine), then the femcod-mpi command on a deck against the serial femcod.
# Needs the MPI build: bash setup.sh --mpi. Run from anywhere.
set -euo pipefail
cd "$(dirname "$0")"
source ./environment.sh
# fpm 0.12 may relink a test against a stale library archive, and keeps the test
# programs' objects when a module of the library they use moved: build them afresh.
find build -name "libfemcod*.a" -delete 2>/dev/null || true
find build -path "*/test/*" -type f -perm -u+x -delete 2>/dev/null || true
find build -path "*/femcod-mpi/test_*.o" -delete 2>/dev/null || true
for ranks in 1 2 4; do
  echo "== distributed suite on $ranks ranks"
  OMP_NUM_THREADS=1 fpm test --profile release --flag "$FEMCOD_MPI_FLAGS" \
    --runner "mpirun $FEMCOD_MPIRUN_FLAGS -np $ranks" | tail -8
done
# On one node the ranks transpose through shared memory; FFTW-MPI's transposes (what
# ranks on several nodes use) are kept by FEMCOD_MPI_TRANSPOSES=fftw-mpi.
echo "== distributed suite on 2 ranks, FFTW-MPI's transposes"
FEMCOD_MPI_TRANSPOSES=fftw-mpi OMP_NUM_THREADS=1 fpm test --profile release --flag "$FEMCOD_MPI_FLAGS" \
  --runner "mpirun $FEMCOD_MPIRUN_FLAGS -x FEMCOD_MPI_TRANSPOSES -np 2" | tail -8
bash ./test_command.sh
