"""Mutation fuzz of femcod's file readers (issue 47, section 8).

    femcod-python python/benchmarks/fuzz_readers.py [--count 10000] [--seed 1] [--every 20]
        [--seeds FILE ...] [--keep DIR]

Seeds: a NanoScope file (test/corpus/58_nanoscope_channels.spm), a Gwyddion text export
(test/corpus/95_gwyddion_1nm.txt), HDF5 heights (test/corpus/63_heights.h5:/heights), an
HDF5 deck and a text deck (made here by `femcod mkdeck`), and any files given with
--seeds (for example an instrument's own files). Each mutated file (bit flips, bytes
overwritten, a truncation, a chunk repeated or cut, a digit of a header changed) is read
by the library (femcod.read_heights / femcod.read_deck) in a worker process, one file at
a time with a 30 s bound, and every --every-th also by `femcod run --lower FILE` (or the
deck) in a process of its own. A file must be read or refused (FemcodError code 3, exit
3): a signal, a dead worker, a hang, a backtrace or another exit code is a failure, kept
in --keep DIR. Prints one row per seed format: files, read, refused, failures, seconds;
exits 1 on any failure.
"""
import argparse
import os
import random
import shutil
import subprocess
import sys
import tempfile
import time

REPO = os.path.abspath(os.path.join(os.path.dirname(__file__), os.pardir, os.pardir))
CORPUS = os.path.join(REPO, "test", "corpus")

WORKER = r"""
import sys, warnings
import femcod
warnings.simplefilter("ignore")
for line in sys.stdin:
    kind, path = line.rstrip("\n").split("\t", 1)
    try:
        if kind == "deck":
            femcod.read_deck(path)
        else:
            femcod.read_heights(path, pixel=1.0)
        print("read", flush=True)
    except femcod.FemcodError as e:
        print(f"refused {e.code}", flush=True)
    except Exception as e:  # a Python-level error of the package is a failure too
        print(f"error {type(e).__name__}: {e}".replace("\n", " "), flush=True)
"""


class Worker:
    """A Python process reading files with the library, one per request, bounded in time."""

    def __init__(self):
        self.proc = subprocess.Popen([sys.executable, "-c", WORKER], stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                                     stderr=subprocess.DEVNULL, text=True, bufsize=1)

    def read(self, kind, path, timeout=30.0):
        self.proc.stdin.write(f"{kind}\t{path}\n")
        self.proc.stdin.flush()
        import selectors
        sel = selectors.DefaultSelector()
        sel.register(self.proc.stdout, selectors.EVENT_READ)
        if not sel.select(timeout):
            self.proc.kill()
            return "hang"
        line = self.proc.stdout.readline()
        if not line:
            code = self.proc.wait()
            return f"died {code}"
        return line.strip()

    def close(self):
        try:
            self.proc.stdin.close()
            self.proc.wait(timeout=10)
        except Exception:
            self.proc.kill()


def mutate(data, rng):
    data = bytearray(data)
    for _ in range(rng.randint(1, 3)):
        how = rng.choice(["flip", "byte", "truncate", "repeat", "cut", "digit"])
        if not data:
            break
        at = rng.randrange(len(data))
        if how == "flip":
            for _ in range(rng.randint(1, 8)):
                k = rng.randrange(len(data))
                data[k] ^= 1 << rng.randrange(8)
        elif how == "byte":
            data[at] = rng.choice([0, 0xFF, 0x7F, 0x80, ord("9"), ord("-"), ord("\\"), ord("\n"), rng.randrange(256)])
        elif how == "truncate":
            del data[at:]
        elif how == "repeat":
            n = rng.randint(1, 256)
            data[at:at] = data[at:at + n]
        elif how == "cut":
            del data[at:at + rng.randint(1, 256)]
        elif how == "digit":
            digits = [k for k in range(len(data)) if 48 <= data[k] <= 57]
            if digits:
                k = rng.choice(digits)
                data[k:k + 1] = rng.choice([b"9", b"0", b"99999999", b"-1", b"1e308", b"nan", b""])
    return bytes(data)


def make_seeds(workdir, femcod, extra):
    """(name, kind, path of the seed, suffix of a dataset path) for each seed."""
    deck_txt = os.path.join(workdir, "seed.deck")
    deck_h5 = os.path.join(workdir, "seed_deck.h5")
    subprocess.run([femcod, "mkdeck", "self-affine", "--np", "8", "--pixel", "2", "--seed", "3", "-o", deck_txt],
                   check=True, capture_output=True)
    subprocess.run([femcod, "mkdeck", "convert", deck_txt, deck_h5], check=True, capture_output=True)
    seeds = [("NanoScope", "heights", os.path.join(CORPUS, "58_nanoscope_channels.spm"), ""),
             ("Gwyddion export", "heights", os.path.join(CORPUS, "95_gwyddion_1nm.txt"), ""),
             ("HDF5 heights", "heights", os.path.join(CORPUS, "63_heights.h5"), ":/heights"),
             ("HDF5 deck", "deck", deck_h5, ""),
             ("text deck", "deck", deck_txt, "")]
    for path in extra:
        seeds.append((os.path.basename(path), "heights", os.path.abspath(path), ""))
    return seeds


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--count", type=int, default=10000, help="mutated files in all (default 10000)")
    ap.add_argument("--seed", type=int, default=1, help="random seed (default 1)")
    ap.add_argument("--every", type=int, default=20, help="also run the command on every N-th file (default 20)")
    ap.add_argument("--seeds", nargs="*", default=[], help="more seed files (heights)")
    ap.add_argument("--keep", default="fuzz-failures", help="where failing files are kept (default fuzz-failures)")
    args = ap.parse_args()
    femcod = shutil.which("femcod")
    if femcod is None:
        sys.exit("fuzz_readers: the femcod program is not on PATH (bash setup.sh)")
    rng = random.Random(args.seed)
    work = tempfile.mkdtemp(prefix="femcod-fuzz-")
    seeds = make_seeds(work, femcod, args.seeds)
    rows = {name: dict(files=0, read=0, refused=0, failures=0, commands=0, seconds=0.0) for name, *_ in seeds}
    failures = []
    worker = Worker()
    for n in range(args.count):
        name, kind, seed, dataset = seeds[n % len(seeds)]
        with open(seed, "rb") as f:
            data = mutate(f.read(), rng)
        path = os.path.join(work, f"m{n}" + os.path.splitext(seed)[1])
        with open(path, "wb") as f:
            f.write(data)
        row = rows[name]
        row["files"] += 1
        t0 = time.perf_counter()
        answer = worker.read(kind, path + dataset)
        bad = None
        if answer == "read":
            row["read"] += 1
        elif answer.startswith("refused"):
            row["refused"] += 1
            if answer != "refused 3":
                bad = answer
        else:
            bad = answer
            worker.close()
            worker = Worker()
        if bad is None and row["files"] % args.every == 1:
            row["commands"] += 1
            out = os.path.join(work, f"out{n}")
            cmd = [femcod, "run", path + dataset] if kind == "deck" else [femcod, "run", "--lower", path + dataset,
                                                                           "--pixel", "1"]
            try:
                p = subprocess.run(cmd + ["--loads", "1", "-o", out, "--quiet"], capture_output=True, text=True,
                                   errors="replace",
                                   timeout=60)
                if p.returncode not in (0, 3, 4) or "Backtrace" in p.stderr or "runtime error" in p.stderr.lower():
                    bad = f"command exit {p.returncode}: {p.stderr.strip()[:200]}"
            except subprocess.TimeoutExpired:
                bad = "command hang"
            for f in os.listdir(work):
                if f.startswith(f"out{n}."):
                    os.remove(os.path.join(work, f))
        row["seconds"] += time.perf_counter() - t0
        if bad is not None:
            row["failures"] += 1
            os.makedirs(args.keep, exist_ok=True)
            kept = os.path.join(args.keep, os.path.basename(path))
            shutil.copy(path, kept)
            failures.append(f"{kept} ({name}): {bad}")
        os.remove(path)
    worker.close()
    shutil.rmtree(work, ignore_errors=True)
    print("| seed format | files | read | refused (exit 3) | also run by the command | failures | seconds |")
    print("|---|---|---|---|---|---|---|")
    for name, r in rows.items():
        print(f"| {name} | {r['files']} | {r['read']} | {r['refused']} | {r['commands']} | {r['failures']} | "
              f"{r['seconds']:.1f} |")
    total = sum(r["files"] for r in rows.values())
    print(f"\n{total} files, {len(failures)} failures, {sum(r['seconds'] for r in rows.values()):.1f} s")
    for line in failures[:50]:
        print("  " + line)
    sys.exit(1 if failures else 0)


if __name__ == "__main__":
    main()
