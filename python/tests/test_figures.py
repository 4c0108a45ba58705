"""The figures' titles fit their 640-pixel width and keep the deck's label: each title
line measured in DejaVu Sans (matplotlib's own font, a wide sans-serif) at its size is at
most 600 px, and the lines together hold the whole label of every input/ deck (they were
one line cut at 80 characters, some 610 px at 14 px)."""
import glob
import html
import os
import re

import pytest

from conftest import REPO, run_femcod

TITLE = re.compile(r'<text x="320.00" y="[\d.]+" font-family="sans-serif" font-size="(\d+)" '
                   r'text-anchor="middle">([^<]*)</text>')


def test_titles_fit_and_keep_the_label(tmp_path):
    textpath = pytest.importorskip("matplotlib.textpath")
    from matplotlib.font_manager import FontProperties
    font = FontProperties(family="DejaVu Sans")
    for deck in sorted(glob.glob(os.path.join(REPO, "input", "*.deck"))):
        name = os.path.basename(deck)[:-5]
        prefix = tmp_path / name
        run_femcod("run", deck, "--solver", "cg", "--loads", "100", "-o", prefix, "-q")
        with open(deck) as f:
            label = f.readline().strip()
        for figure in glob.glob(f"{prefix}.*.svg"):
            with open(figure) as f:
                lines = [(int(size), html.unescape(text)) for size, text in TITLE.findall(f.read())]
            assert 1 <= len(lines) <= 2, figure
            for size, text in lines:
                width = textpath.TextPath((0, 0), text, size=size, prop=font).get_extents().width
                assert width <= 600, (figure, size, round(width), text)
            if "load_approach" in figure:
                joined = " ".join(t.strip() for _, t in lines)
                assert label in joined or len(label) > 150, (label, joined)
