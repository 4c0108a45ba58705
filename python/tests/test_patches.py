"""The contact patches femcod run reports (loads.csv, PREFIX.h5, the summary) against an
independent count here: a breadth-first flood fill over the contact pixels of each state's
pressure map (p > 0), 4- and 8-connected, the cell's edges wrapping when it is periodic;
with each patch's area and perimeter (pixel sides facing no contact or a free edge)."""
import csv
import json
from collections import deque

import numpy as np
import pytest

import femcod
from conftest import run_femcod


def flood_patches(contact, periodic, diagonal):
    n = contact.shape[0]
    seen = np.zeros_like(contact, dtype=bool)
    steps = [(1, 0), (-1, 0), (0, 1), (0, -1)] + ([(1, 1), (1, -1), (-1, 1), (-1, -1)] if diagonal else [])
    patches = []
    for start in zip(*np.nonzero(contact)):
        if seen[start]:
            continue
        seen[start] = True
        queue, pixels = deque([start]), []
        while queue:
            i, j = queue.popleft()
            pixels.append((i, j))
            for di, dj in steps:
                a, b = i + di, j + dj
                if periodic:
                    a, b = a % n, b % n
                elif not (0 <= a < n and 0 <= b < n):
                    continue
                if contact[a, b] and not seen[a, b]:
                    seen[a, b] = True
                    queue.append((a, b))
        sides = 0
        for i, j in pixels:
            for di, dj in steps[:4]:
                a, b = i + di, j + dj
                if periodic:
                    a, b = a % n, b % n
                elif not (0 <= a < n and 0 <= b < n):
                    sides += 1
                    continue
                sides += not contact[a, b]
        patches.append((len(pixels), sides))
    return sorted(patches)


@pytest.mark.parametrize("boundary", ["free", "periodic"])
def test_patches_of_a_rough_surface(tmp_path, boundary):
    deck = tmp_path / "rough.deck"
    run_femcod("mkdeck", "self-affine", "--np", "96", "--pixel", "5", "--hurst", "0.6", "--rms", "3", "--shape-on",
               "lower", "-o", deck)
    prefix = tmp_path / "r"
    run_femcod("run", deck, "--solver", "cg", "--boundary", boundary, "--loads", "3e3,3e4,3e5", "-o", prefix, "-q")
    r = femcod.load(f"{prefix}.h5")
    with open(f"{prefix}.loads.csv", newline="") as f:
        rows = list(csv.DictReader(f))
    with open(f"{prefix}.summary.json") as f:
        summary = json.load(f)["loads"]
    import h5py
    with h5py.File(f"{prefix}.h5") as h5:
        for k, (s, row) in enumerate(zip(r.states, rows)):
            contact = s.pressure > 0
            p4 = flood_patches(contact, boundary == "periodic", False)
            p8 = flood_patches(contact, boundary == "periodic", True)
            assert int(row["patches_4"]) == len(p4) and int(row["patches_8"]) == len(p8)
            assert summary[k]["patches_4"] == len(p4) and summary[k]["largest_patch_pixels"] == max(a for a, _ in p8)
            g = h5["loads"][f"{k + 1:03d}"]
            assert sorted(zip(g["patch_area_4"][()], g["patch_perimeter_4"][()])) == p4
            assert sorted(zip(g["patch_area_8"][()], g["patch_perimeter_8"][()])) == p8
        assert len(p4) > 10 and len(p8) < len(p4)  # the largest load: many patches, some joined by corners
