#!/usr/bin/env bash
# The femcod-mpi command against the serial femcod on a deck of input/, and its refusals:
# the same approaches (to 1e-10 nm) and contact counts from summary.json; usage errors
# exit 2, a bad deck 3, an existing result set 5, each with no result file left behind.
# Run by test.sh (sourced environment.sh, from mpi/).
set -euo pipefail
femcod_mpi=$PWD/$(fpm run --profile release --flag "$FEMCOD_MPI_FLAGS" --runner echo 2>/dev/null | tail -1)
femcod=$(cd .. && pwd)/$(cd .. && env -u FPM_FC -u PKG_CONFIG_PATH fpm run --profile release --runner echo 2>/dev/null | tail -1)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
mpirun_2() { OMP_NUM_THREADS=1 mpirun $FEMCOD_MPIRUN_FLAGS -np 2 "$@"; }
failed=0
expect() { # expect CODE DESCRIPTION COMMAND...: the exit code, and no PREFIX.* left
  local want=$1 what=$2; shift 2
  local got=0
  "$@" >"$work/out.txt" 2>&1 || got=$?
  if [ "$got" -ne "$want" ]; then
    echo "  FAILED   $what: exit $got, expected $want"; sed 's/^/           /' "$work/out.txt" | head -5; failed=1
  elif [ "$want" -ne 0 ] && ls "$work"/bad.* >/dev/null 2>&1; then
    echo "  FAILED   $what: left $(ls "$work"/bad.*)"; failed=1
  else
    echo "  passed   $what"
  fi
}
echo "# femcod-mpi command"
deck=../input/sphere_d1.deck
"$femcod" run "$deck" --solver cg --loads 50,200,1000 --tol 1e-12 -o "$work/serial" --quiet
expect 0 "2 ranks on $deck" mpirun_2 "$femcod_mpi" "$deck" --loads 50,200,1000 --tol 1e-12 -o "$work/mpi" --quiet
if python3 - "$work/serial.summary.json" "$work/mpi.summary.json" <<'PY'
import json, sys
serial = json.load(open(sys.argv[1]))
mpi = json.load(open(sys.argv[2]))
def loads(doc):
    for key in ("loads", "states"):
        if key in doc:
            return doc[key]
    raise SystemExit("no loads in the summary")
a, b = loads(serial), loads(mpi)
assert len(a) == len(b) == 3, (len(a), len(b))
for x, y in zip(a, b):
    da = abs(x["approach_nm"] - y["approach_nm"])
    assert da <= 1e-10, ("approach", x["approach_nm"], y["approach_nm"])
    assert x["contacts"] == y["contacts"], ("contacts", x["contacts"], y["contacts"])
PY
then echo "  passed   the serial solver's approaches and contacts"; else echo "  FAILED   the serial solver's approaches and contacts"; failed=1; fi
# One schema (io/femcod_state_record): every field of a serial state is in femcod-mpi's
# (beside the serial patch detail), the counts equal; the scene and the run as in the
# serial summary, so that doc/cluster/collect.py reads both.
if python3 - "$work/serial.summary.json" "$work/mpi.summary.json" <<'PY'
import json, sys
serial, mpi = (json.load(open(p)) for p in sys.argv[1:])
for key in ("scene", "solver", "boundary", "stopped", "wall_time_s", "memory_bytes"):
    assert key in mpi, key
assert mpi["scene"]["NP"] == serial["scene"]["NP"] and mpi["scene"]["label"] == serial["scene"]["label"]
for a, b in zip(serial["loads"], mpi["loads"]):
    missing = set(a) - {"largest_patch_pixels", "patch_perimeter_exponent"} - set(b)
    assert not missing, missing
    for key in ("contacts", "patches_4", "patches_8", "n_above_hardness", "hdf5_group"):
        assert a[key] == b[key], (key, a[key], b[key])
PY
then echo "  passed   the serial summary's fields in femcod-mpi's"
else echo "  FAILED   the serial summary's fields in femcod-mpi's"; failed=1; fi
mkdir "$work/both" && cp "$work/serial.summary.json" "$work/mpi.summary.json" "$work/both/"
# femcod report reads femcod-mpi's set (no /history: the states make the curves): each of
# the three states' pressure and gap maps, the two curves, the patch count against load.
if "$femcod" report "$work/mpi" -q && [ "$(grep -o '<svg' "$work/mpi.report.html" | wc -l)" -eq 9 ]; then
  echo "  passed   femcod report of femcod-mpi's result set"
else echo "  FAILED   femcod report of femcod-mpi's result set"; failed=1; fi
if [ "$(python3 ../doc/cluster/collect.py "$work/both" | wc -l)" -eq 7 ]; then
  echo "  passed   doc/cluster/collect.py reads femcod run's and femcod-mpi's summaries"
else
  echo "  FAILED   doc/cluster/collect.py on femcod run's and femcod-mpi's summaries"; failed=1
fi
# loads.csv: the serial writer's header, the same contact counts and contact patches
# (the last two columns: 4- and 8-connected, joined across the ranks' slabs); one figure
# per load.
if [ "$(head -1 "$work/mpi.loads.csv")" = "$(head -1 "$work/serial.loads.csv")" ] && \
   [ "$(cut -d, -f3 "$work/mpi.loads.csv")" = "$(cut -d, -f3 "$work/serial.loads.csv")" ] && \
   [ "$(awk -F, '{print $(NF-1), $NF}' "$work/mpi.loads.csv")" = \
     "$(awk -F, '{print $(NF-1), $NF}' "$work/serial.loads.csv")" ] && \
   [ -s "$work/mpi.pressure_1.svg" ] && [ -s "$work/mpi.pressure_3.svg" ]; then
  echo "  passed   loads.csv as the serial one's (contacts, patches), a pressure figure per load"
else
  echo "  FAILED   loads.csv or the figures"; failed=1
fi
# The gap figure of each load: its image (decoded by test/tools/png_levels.py) is the
# serial run's (whose levels test_results checks against its HDF5 gap map), the gaps
# agreeing to 1e-12 of the height range: no level differs by more than one, and at most
# one pixel in a thousand by one (a gap on a level's edge).
gaps_ok=1
for k in 1 2 3; do
  python3 ../test/tools/png_levels.py "$work/mpi.gap_$k.svg" > "$work/mpi_gap.txt" 2>&1 || gaps_ok=0
  python3 ../test/tools/png_levels.py "$work/serial.gap_$k.svg" > "$work/serial_gap.txt" 2>&1 || gaps_ok=0
  python3 - "$work/mpi_gap.txt" "$work/serial_gap.txt" <<'PY' || gaps_ok=0
import sys
a, b = ([[int(v) for v in line.split()] for line in open(p).read().splitlines()[1:]] for p in sys.argv[1:])
assert len(a) == len(b) and all(len(x) == len(y) for x, y in zip(a, b))
d = [abs(u - v) for x, y in zip(a, b) for u, v in zip(x, y)]
assert max(d) <= 1 and sum(1 for v in d if v) <= len(d) // 1000, (max(d), sum(1 for v in d if v))
PY
done
if [ "$gaps_ok" = 1 ]; then echo "  passed   a gap figure per load, the serial run's image"
else echo "  FAILED   the gap figures against the serial run's"; head -3 "$work/mpi_gap.txt"; failed=1; fi
# An HDF5 deck: every rank reads its own columns; the same answer, byte for byte, as the
# text deck read by the ranks, each its range of the bytes (the same gaps, formed on the
# ranks).
"$femcod" mkdeck convert "$deck" "$work/deck.h5" >/dev/null
expect 0 "2 ranks on the HDF5 deck" mpirun_2 "$femcod_mpi" "$work/deck.h5" --loads 50,200,1000 --tol 1e-12 \
  -o "$work/mpih5" --quiet
if cmp -s "$work/mpih5.loads.csv" "$work/mpi.loads.csv" && \
   grep -q '"input": "HDF5 deck, each rank its own columns"' "$work/mpih5.summary.json" && \
   grep -q '"input": "text deck, each rank its own range of the bytes' "$work/mpi.summary.json"; then
  echo "  passed   the HDF5 deck read by slabs: loads.csv as the text deck's, the input path in the summary"
else
  echo "  FAILED   the HDF5 deck read by slabs"; failed=1
fi
expect 2 "--kernel-radius on the periodic cell refused" mpirun_2 "$femcod_mpi" "$deck" --loads 10 \
  --boundary periodic --kernel-radius 4 -o "$work/bad"
expect 2 "two decks refused" mpirun_2 "$femcod_mpi" "$deck" ../input/sphere_d2.deck --loads 10
# A solve that fails after the result file was begun (each state's maps go there as it is
# solved): exit 4, and its temporary (PREFIX.h5.part) is gone.
expect 4 "an unconverged solve leaves no temporary result file" mpirun_2 "$femcod_mpi" "$deck" --loads 50,1000 \
  --max-iterations 2 -o "$work/bad"
expect 2 "--generate of a kind the ranks do not make refused" mpirun_2 "$femcod_mpi" --generate sphere --np 32 \
  --pixel 1 --radius 10 --loads 10 -o "$work/bad"
expect 2 "--generate next to a deck refused" mpirun_2 "$femcod_mpi" "$deck" --generate self-affine --np 32 \
  --pixel 1 --loads 10 -o "$work/bad"
expect 2 "the event solver refused" mpirun_2 "$femcod_mpi" "$deck" --solver incremental --loads 10 -o "$work/bad"
printf 'a deck\n3 1 x\n' >"$work/broken.deck"
expect 3 "a broken deck" mpirun_2 "$femcod_mpi" "$work/broken.deck" --loads 10 -o "$work/bad"
printf '1 2 3\n4 5 6\n7 8 9\n' >"$work/tiny.txt"
expect 2 "a grid narrower than two columns per rank" mpirun_2 "$femcod_mpi" --lower "$work/tiny.txt" --pixel 1 \
  --loads 1 -o "$work/bad"
# doc/cluster/mpi.sbatch as Slurm would run it (no Slurm here: its variables made up).
if SLURM_CPUS_PER_TASK=1 INPUT="$deck" FEMCOD_MPI="$femcod_mpi" FEMCOD_ARGS="--loads 50,200,1000 --tol 1e-12 --quiet" \
  PREFIX="$work/sbatch/run" MPIRUN="mpirun $FEMCOD_MPIRUN_FLAGS -np 2" bash ../doc/cluster/mpi.sbatch >"$work/out.txt" 2>&1 \
  && cmp -s <(python3 -c 'import json,sys; print([l["approach_nm"] for l in json.load(open(sys.argv[1]))["loads"]])' \
  "$work/mpi.summary.json") <(python3 -c 'import json,sys; print([l["approach_nm"] for l in json.load(open(sys.argv[1]))["loads"]])' \
  "$work/sbatch/run.summary.json"); then
  echo "  passed   doc/cluster/mpi.sbatch: the same approaches as the command"
else
  echo "  FAILED   doc/cluster/mpi.sbatch"; sed 's/^/           /' "$work/out.txt" | head -5; failed=1
fi
# The Contact Mechanics Challenge script at a size this machine runs in seconds.
if NP=64 PREFIX="$work/cmc/run" MPIRUN="mpirun $FEMCOD_MPIRUN_FLAGS -np 2" FEMCOD_MPI="$femcod_mpi" \
   FEMCOD_ARGS="--loads 1e5 --quiet" bash ../doc/cluster/cmc.sbatch >"$work/out.txt" 2>&1 && \
   grep -q '"input": "made on the ranks: self-affine, NP 64' "$work/cmc/run.summary.json"; then
  echo "  passed   doc/cluster/cmc.sbatch: the surface made on the ranks, periodic, at NP 64"
else
  echo "  FAILED   doc/cluster/cmc.sbatch"; sed 's/^/           /' "$work/out.txt" | head -5; failed=1
fi
expect 5 "existing results without --force" mpirun_2 "$femcod_mpi" "$deck" --loads 50 -o "$work/mpi"
# femcod's output rule on ranks too: an input is never an output, even with --force.
printf '1 2 3 4\n2 3 4 1\n3 4 1 2\n4 1 2 3\n' >"$work/in.loads.csv"; cp "$work/in.loads.csv" "$work/in.copy"
expect 2 "an input named as an output, with --force" mpirun_2 "$femcod_mpi" --lower "$work/in.loads.csv" --pixel 1 \
  --loads 1 -o "$work/in" --force
cmp -s "$work/in.loads.csv" "$work/in.copy" || { echo "  FAILED   the input was changed"; failed=1; }
# Each rank's memory estimate (checked, summed over the ranks of a node, before the grids
# are made) against the peak the system measured on that rank: within 0.7 to 1.5 of it on
# a 1024^2 surface (measured 0.85 to 0.9 on this machine).
"$femcod" mkdeck self-affine --np 1024 --pixel 5 --rms 3 --shape-on lower -o "$work/s1024.deck" >/dev/null
expect 0 "2 ranks on a 1024^2 surface" mpirun_2 "$femcod_mpi" "$work/s1024.deck" --loads 1e5 -o "$work/mem" --quiet
if python3 - "$work/mem.summary.json" <<'PY'
import json, sys
d = json.load(open(sys.argv[1]))
for est, peak in zip(d["estimated_peak_memory_MB_per_rank"], d["peak_memory_MB_per_rank"]):
    assert 0.7 * peak <= est <= 1.5 * peak, (est, peak)
PY
then echo "  passed   each rank's memory estimate against its measured peak"
else echo "  FAILED   each rank's memory estimate against its measured peak"; failed=1; fi
# The text deck read by the ranks: rank 0 holds no more than the others, so its peak is
# within 20 % of the other rank's on the 1024^2 deck (it held the whole text and both
# surfaces once: 21 MB of text, 16 MB of heights, 8 MB of gaps more).
if python3 - "$work/mem.summary.json" <<'PY'
import json, sys
peaks = json.load(open(sys.argv[1]))["peak_memory_MB_per_rank"]
assert max(peaks) <= 1.2 * min(peaks), peaks
PY
then echo "  passed   rank 0's peak within 20 % of the other rank's (text deck read by the ranks)"
else echo "  FAILED   rank 0's peak against the other rank's"; failed=1; fi
# A bad height in the text deck's last line: found by the last rank's range, refused on
# every rank with read_deck's message (file, line, row, column), no output.
sed '$ s/[^ ]*$/nan/' "$deck" >"$work/late.deck"
got=0; mpirun_2 "$femcod_mpi" "$work/late.deck" --loads 10 -o "$work/bad" >"$work/late.out" 2>&1 || got=$?
if [ "$got" -eq 3 ] && grep -q "late.deck:[0-9]*: expected an upper-surface height in nm (row 30, column 30)" \
   "$work/late.out" && ! ls "$work"/bad.* >/dev/null 2>&1; then
  echo "  passed   a bad height in the last line of a text deck: exit 3, file and line, no output"
else echo "  FAILED   a late bad height (exit $got)"; sed 's/^/           /' "$work/late.out" | head -3; failed=1; fi
# Each rank reads its own range of a text deck's bytes: a fault anywhere gets femcod
# run's message (read_deck's: file, line, row and column; the first in the file), and a
# deck whose heights are wrapped anyhow (seven a line, commas) the same answer, on 2, 3
# and 4 ranks (ranges that cut the surfaces and the lines at other places).
python3 - "$deck" "$work" <<'PY'
import sys
text = open(sys.argv[1]).read()
head, heights = text.split("\n", 5)[:5], text.split("\n", 5)[5]
tokens = heights.split()
w = sys.argv[2] + "/"
def save(name, body): open(w + name, "w").write("\n".join(head) + "\n" + body)
save("early.deck", heights.replace("0", "x1", 1))
save("few.deck", heights[:heights.rstrip("\n").rfind("\n") + 1])
save("many.deck", heights + " 7 8\n")
cut = heights.index(" ", len(heights) * 2 // 3)
save("control.deck", heights[:cut] + "\x01" + heights[cut:])
save("both.deck", heights[:cut].replace("0", "x1", 1) + "\x01" + heights[cut:])
save("reflow.deck", "\n".join(", ".join(tokens[k:k + 7]) for k in range(0, len(tokens), 7)) + "\n")
PY
faults_ok=1
for name in early few many control both; do
  serial=$("$femcod" run "$work/$name.deck" --solver cg --loads 10 -o "$work/bad" -q 2>&1 >/dev/null | head -1 || true)
  for ranks in 2 3 4; do
    got=0
    OMP_NUM_THREADS=1 mpirun $FEMCOD_MPIRUN_FLAGS -np $ranks "$femcod_mpi" "$work/$name.deck" --loads 10 \
      -o "$work/bad" -q >"$work/fault.out" 2>&1 || got=$?
    if [ "$got" -ne 3 ] || [ "$(head -1 "$work/fault.out" | sed 's/^femcod-mpi: //')" != "${serial#femcod: }" ] || \
       ls "$work"/bad.* >/dev/null 2>&1; then
      echo "  FAILED   $name.deck on $ranks ranks (exit $got): $(head -1 "$work/fault.out") against: $serial"
      faults_ok=0
    fi
  done
done
for ranks in 2 3 4; do
  OMP_NUM_THREADS=1 mpirun $FEMCOD_MPIRUN_FLAGS -np $ranks "$femcod_mpi" "$work/reflow.deck" --loads 50,200,1000 \
    --tol 1e-12 -o "$work/reflow$ranks" --quiet
  OMP_NUM_THREADS=1 mpirun $FEMCOD_MPIRUN_FLAGS -np $ranks "$femcod_mpi" "$work/deck.h5" --loads 50,200,1000 \
    --tol 1e-12 -o "$work/h5_$ranks" --quiet
  cmp -s "$work/reflow$ranks.loads.csv" "$work/h5_$ranks.loads.csv" || { echo "  FAILED   reflowed deck on $ranks ranks"; faults_ok=0; }
done
if [ "$faults_ok" = 1 ]; then
  echo "  passed   a text deck's faults as femcod run's messages, a reflowed deck as the HDF5 deck (2, 3, 4 ranks)"
else failed=1; fi
# The combination matrix on 2 ranks (issue 34): boundary x plastic cap x interface law x
# question (loads, increasing, decreasing approaches) x (plain, --restart, the shear model
# --shear-strength 0 --shear-slope 0.1: friction as serial too, a tangential step
# --tangential 40 --friction 0.3: its force, shift and sticking pixels as serial's too) on
# the 2 nm sphere. Each
# combination answers (exit 0, as serial `femcod run --solver cg` does: loads, approaches
# and plastic volumes to 1e-6, the same contact and plastic counts) or is refused (exit 2)
# with no output and no lock; none ends in a runtime error. With --kernel-radius once more,
# under load and under displacement control (the gap variables).
# same_answer SERIAL.loads.csv MPI.loads.csv: two states each, loads, approaches and
# plastic volumes to 1e-6 (relative, absolute below 1), the same contact and plastic counts.
same_answer() {
  python3 - "$1" "$2" <<'PY'
import csv, sys
a = list(csv.DictReader(open(sys.argv[1])))
b = list(csv.DictReader(open(sys.argv[2])))
assert len(a) == len(b) == 2, (len(a), len(b))
keys = ["load_nN", "approach_nm", "plastic_volume_nm3"]
# The friction columns of the shear model, when the serial run has them.
assert ("friction_nN" in a[0]) == ("friction_nN" in b[0]), "friction columns in one file only"
if "friction_nN" in a[0]:
    keys.append("friction_nN")
counts = ["contacts", "n_plastic"]
# The tangential step's columns (a shift of NaN beyond mu P: NaN on both).
assert ("tangential_force_nN" in a[0]) == ("tangential_force_nN" in b[0]), "tangential columns in one file only"
if "tangential_force_nN" in a[0]:
    keys += ["tangential_force_nN", "tangential_shift_nm"]
    counts.append("stick_contacts")
for x, y in zip(a, b):
    for key in keys:
        u, v = float(x[key]), float(y[key])
        assert (u != u and v != v) or abs(u - v) <= 1e-6 * max(1.0, abs(u)), (key, u, v)
    for key in counts:
        assert x[key] == y[key], (key, x[key], y[key])
PY
}
# Height files as HDF5 datasets (--lower FILE.h5:/DATASET, --upper too): every rank reads
# its own columns and applies femcod run's rules over the ranks (units, finite values,
# the least-squares plane: its tilt warned of, removed with --remove-plane). A 64^2
# self-affine surface tilted by 0.8 nm a column and 0.3 a row (awk, from the deck's text):
# the serial answer and warning, with and without --remove-plane, one dataset and two.
"$femcod" mkdeck self-affine --np 64 --pixel 2 --hurst 0.8 --rms 1 --seed 11 -o "$work/s64.deck" >/dev/null
awk 'NR>5{for(i=1;i<=NF;i++){n++; if(n>64*64){m=n-64*64-1; r=int(m/64); c=m%64; printf "%s%s", $i+0.8*c+0.3*r, (c==63?"\n":" ")}}}' \
  "$work/s64.deck" >"$work/tilt.txt"
"$femcod" mkdeck matrix --file "$work/tilt.txt" --pixel 2 -o "$work/tilt.h5" >/dev/null
"$femcod" mkdeck convert "$work/s64.deck" "$work/s64.h5" >/dev/null
for extra in "" "--remove-plane" "--upper $work/s64.h5:/upper"; do
  m="$work/ds$(echo "$extra" | tr -dc a-z | head -c 12)"
  args="--lower $work/tilt.h5:/upper --pixel 2 $extra --loads 2e3,8e3 --tol 1e-10 --quiet"
  got=0; mpirun_2 "$femcod_mpi" $args -o "$m" >"$m.out" 2>&1 || got=$?
  "$femcod" run --solver cg $args -o "$m.serial" >"$m.serial.out" 2>&1 || got=1
  if [ "$got" -eq 0 ] && same_answer "$m.serial.loads.csv" "$m.loads.csv" && \
     grep -q '"input": "HDF5 height datasets, each rank its own columns"' "$m.summary.json" && \
     [ "$(grep -c 'plane rises' "$m.out")" -eq "$(grep -c 'plane rises' "$m.serial.out")" ]; then
    echo "  passed   HDF5 height datasets read by slabs ${extra:-(tilted)}: the serial answer and warnings"
  else echo "  FAILED   HDF5 height datasets ${extra:-(tilted)} (exit $got)"; failed=1; fi
done
grep -q "plane rises" "$work/ds.out" || { echo "  FAILED   no tilt warning from the ranks"; failed=1; }
expect 3 "a NaN in a height dataset, found over the ranks" mpirun_2 "$femcod_mpi" \
  --lower ../test/corpus/32_heights_nan.h5:/heights --pixel 1 --loads 1 -o "$work/bad"
matrix_deck=../input/sphere_d2.deck
combos=0; answered=0; refused=0; matrix_failed=0
for boundary in free periodic; do for plastic in "" "--plastic --hardness 11"; do
for law in none dugdale exponential; do for question in "--loads 300,800" "--approach 0.5,1" "--approach 1,0.5"; do
for variant in "" "--restart" "--shear-strength 0 --shear-slope 0.1" "--tangential 40 --friction 0.3"; do
  combos=$((combos + 1))
  args="--boundary $boundary $plastic $question --tol 1e-10 --max-iterations 20000 $variant --quiet"
  [ "$law" = none ] || args="$args --adhesion $law --work 0.05 --range 1"
  m="$work/m$combos"
  got=0; mpirun_2 "$femcod_mpi" "$matrix_deck" $args -o "$m" >"$m.out" 2>&1 || got=$?
  if grep -q -e Backtrace -e "runtime error" -e "Error termination" "$m.out" || [ -e "$m.lock" ] || \
     { [ "$got" -ne 0 ] && [ "$got" -ne 2 ]; }; then
    echo "  FAILED   femcod-mpi $args: exit $got"; sed 's/^/           /' "$m.out" | head -3; matrix_failed=1; continue
  fi
  if [ "$got" -eq 2 ]; then
    refused=$((refused + 1))
    if ls "$m".* 2>/dev/null | grep -qv '\.out$'; then echo "  FAILED   femcod-mpi $args: refused, left files"; matrix_failed=1; fi
    continue
  fi
  answered=$((answered + 1))
  "$femcod" run "$matrix_deck" --solver cg $args -o "$m.serial" >/dev/null 2>&1 || \
    { echo "  FAILED   femcod-mpi $args answered, serial femcod did not"; matrix_failed=1; continue; }
  if ! same_answer "$m.serial.loads.csv" "$m.loads.csv"; then echo "  FAILED   femcod-mpi $args: not the serial answer"; matrix_failed=1; fi
done; done; done; done; done
for args in "--loads 300,800 --kernel-radius 6" "--loads 300,800 --kernel-radius 6 --plastic --hardness 11"; do
  combos=$((combos + 1)); m="$work/m$combos"
  got=0; mpirun_2 "$femcod_mpi" "$matrix_deck" $args --tol 1e-10 --quiet -o "$m" >"$m.out" 2>&1 || got=$?
  "$femcod" run "$matrix_deck" --solver cg $args --tol 1e-10 --quiet -o "$m.serial" >/dev/null 2>&1 || got=1
  if [ "$got" -eq 0 ] && cmp -s <(cut -d, -f3,8 "$m.loads.csv") <(cut -d, -f3,8 "$m.serial.loads.csv") && \
     python3 -c 'import csv,sys; a,b=[list(csv.DictReader(open(f))) for f in sys.argv[1:]]; assert len(a)==len(b)==2; assert all(abs(float(x["approach_nm"])-float(y["approach_nm"]))<=1e-6 for x,y in zip(a,b))' \
     "$m.serial.loads.csv" "$m.loads.csv"; then answered=$((answered + 1))
  else echo "  FAILED   femcod-mpi $args: not the serial answer (exit $got)"; matrix_failed=1; fi
done
# The cut kernel in the gap variables (displacement control with the cap or a law).
for args in "--approach 0.5,1 --kernel-radius 6 --plastic --hardness 11" \
            "--approach 1,0.5 --kernel-radius 6 --adhesion exponential --work 0.05 --range 1"; do
  combos=$((combos + 1)); m="$work/m$combos"
  got=0; mpirun_2 "$femcod_mpi" "$matrix_deck" $args --tol 1e-10 --quiet -o "$m" >"$m.out" 2>&1 || got=$?
  "$femcod" run "$matrix_deck" --solver cg $args --tol 1e-10 --quiet -o "$m.serial" >/dev/null 2>&1 || got=1
  if [ "$got" -eq 0 ] && same_answer "$m.serial.loads.csv" "$m.loads.csv"; then answered=$((answered + 1))
  else echo "  FAILED   femcod-mpi $args: not the serial answer (exit $got)"; matrix_failed=1; fi
done
# --generate (the surface made on the ranks) with boundary x cap x question: the answer of
# serial femcod run on the deck femcod mkdeck writes with the same options (approaches,
# loads and plastic volumes to 1e-6, the same counts), or a refusal with no output.
surface="--np 64 --pixel 2 --hurst 0.8 --rms 1 --seed 3 --shape-on lower"
"$femcod" mkdeck self-affine $surface -o "$work/generated.deck" >/dev/null
for boundary in free periodic; do for plastic in "" "--plastic --hardness 8"; do
for question in "--loads 200,900" "--approach 1,0.5"; do
  combos=$((combos + 1)); m="$work/m$combos"
  args="--boundary $boundary $plastic $question --tol 1e-10 --max-iterations 20000 --quiet"
  got=0; mpirun_2 "$femcod_mpi" --generate self-affine $surface $args -o "$m" >"$m.out" 2>&1 || got=$?
  if [ "$got" -eq 2 ] && ! ls "$m".* 2>/dev/null | grep -qv '\.out$'; then refused=$((refused + 1)); continue; fi
  "$femcod" run "$work/generated.deck" --solver cg $args -o "$m.serial" >/dev/null 2>&1 || got=1
  if [ "$got" -eq 0 ] && grep -q '"input": "made on the ranks: self-affine' "$m.summary.json" && \
     same_answer "$m.serial.loads.csv" "$m.loads.csv"; then answered=$((answered + 1))
  else echo "  FAILED   femcod-mpi --generate self-affine $args: not the serial answer (exit $got)"; matrix_failed=1; fi
done; done; done
if [ "$matrix_failed" -eq 0 ]; then
  echo "  passed   the combination matrix on 2 ranks: $combos combinations, $refused refused, $answered answered as serial"
else
  failed=1
fi
exit $failed
