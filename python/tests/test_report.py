"""`femcod report` as a person sees it (issue 51, section 5): a rough 128^2 plastic run with
a tangential force, its page opened offline in headless Chromium (Debian's package; the
browser checks are skipped when it is not installed: .ci/run installs it), with

- no console message at all (a page with an error in its script is shown to produce one,
  so the check can fail);
- every figure rendered: in a screenshot, each figure's box is not blank, and each map's
  box holds the colour scale's colours;
- the page's numbers equal to PREFIX.summary.json's as Python's json reads it (every
  value, by its path: the exact text in data-value, the shown one to 6 digits);
- the sorting script sorting;
- an HTML5 parser's (html5lib, strict) acceptance, and no network reference.
The reference numbers come from Python's json, the file the run wrote: not from the page's
own reader."""
import html
import json
import math
import os
import re
import shutil
import subprocess
from html.parser import HTMLParser

import numpy as np
import pytest

import femcod
from conftest import run_femcod

CHROMIUM = shutil.which("chromium") or shutil.which("chromium-browser")
WIDTH = 1400


def json_leaves(value, path=""):
    """(path, value) of every leaf, with the paths femcod's reader gives: a.b, a[0]."""
    if isinstance(value, dict):
        for k, v in value.items():
            yield from json_leaves(v, f"{path}.{k}" if path else k)
    elif isinstance(value, list):
        for i, v in enumerate(value):
            yield from json_leaves(v, f"{path}[{i}]")
    else:
        yield path, value


class Cells(HTMLParser):
    """Every element with data-path: (path, data-value, shown text)."""

    def __init__(self):
        super().__init__()
        self.cells, self._open = [], None

    def handle_starttag(self, tag, attrs):
        a = dict(attrs)
        if "data-path" in a:
            self._open = [a["data-path"], a["data-value"], ""]

    def handle_data(self, data):
        if self._open is not None:
            self._open[2] += data

    def handle_endtag(self, tag):
        if self._open is not None and tag == "td":
            self.cells.append(tuple(self._open))
            self._open = None


@pytest.fixture(scope="module")
def rough(tmp_path_factory):
    d = tmp_path_factory.mktemp("report")
    deck = d / "rough.deck"
    run_femcod("mkdeck", "self-affine", "--np", "128", "--pixel", "2", "--rms", "1", "--hurst", "0.7", "--seed", "3",
               "-o", deck)
    prefix = d / "rough"
    run_femcod("run", deck, "--solver", "cg", "--loads", "2000,8000,20000", "--plastic", "--hardness", "8",
               "--tangential", "500", "--friction", "0.3", "-o", prefix, "-q")
    run_femcod("report", prefix, "-q")
    with open(f"{prefix}.report.html", encoding="utf-8") as f:
        page = f.read()
    with open(f"{prefix}.summary.json") as f:
        summary = json.load(f)
    return prefix, page, summary


def test_page_numbers_are_the_summarys(rough):
    _, page, summary = rough
    parser = Cells()
    parser.feed(page)
    expected = dict(json_leaves(summary))
    seen = set()
    for path, value, shown in parser.cells:
        assert path in expected, path
        seen.add(path)
        want = expected[path]
        if isinstance(want, bool):
            assert value == ("true" if want else "false"), path
        elif want is None:
            assert value == "null", path
        elif isinstance(want, (int, float)):
            assert float(value) == want, (path, value, want)
            # shown to 6 significant digits: within half a unit of the 6th
            assert math.isclose(float(shown), want, rel_tol=5e-6, abs_tol=1e-300), (path, shown, want)
        else:
            assert html.unescape(value) == want and html.unescape(shown) == want, path
    assert seen == set(expected), set(expected) - seen


def test_html_is_valid_and_offline(rough):
    _, page, _ = rough
    html5lib = pytest.importorskip("html5lib")
    html5lib.HTMLParser(strict=True).parse(page)  # raises on the first parse error
    assert not re.search(r"""(src|href)\s*=\s*["']?\s*(https?:|//|ftp:)""", page, re.I)
    assert "url(" not in page and "@import" not in page and "<link" not in page
    assert "http://" not in page and "https://" not in page


def test_python_report_of_a_loaded_result(rough):
    prefix, page, _ = rough
    result = femcod.load(f"{prefix}.h5")
    out = femcod.report(result, f"{prefix}.python.html")
    with open(out, encoding="utf-8") as f:
        again = f.read()
    assert out == f"{prefix}.python.html" and again == page  # the same page from the same files
    with pytest.raises(femcod.FemcodError, match="exists"):
        femcod.report(result, out)
    with pytest.raises(ValueError, match="in memory only"):
        femcod.report(femcod.solve(np.zeros((16, 16)), pixel=1.0, loads=[1.0]))


def test_python_solve_writes_a_set_to_report(tmp_path):
    heights = femcod.read_deck(os.path.join(os.path.dirname(__file__), os.pardir, os.pardir, "input", "sphere_d2.deck"))
    r = femcod.solve(heights, loads=[300, 3000], output=tmp_path / "sphere")
    assert r.source == str(tmp_path / "sphere")
    loaded = femcod.load(tmp_path / "sphere.h5")
    assert np.array_equal(loaded.loads, r.loads) and np.array_equal(loaded.states[1].pressure, r.states[1].pressure)
    page = femcod.report(r)
    assert os.path.getsize(page) > 10000 and page.endswith("sphere.report.html")


PROBE = """<script>
(function(){
 var out={figures:[],sorted:[]};
 document.querySelectorAll('figure').forEach(function(f){var r=f.getBoundingClientRect();
  out.figures.push({x:r.left+window.scrollX,y:r.top+window.scrollY,w:r.width,h:r.height,
   map:f.querySelector('image')!==null,title:(f.querySelector('text')||{}).textContent});});
 var t=document.querySelector('#states table.sortable'),th=t.tHead.rows[0].cells,c=-1;
 for(var k=0;k<th.length;k++){if(th[k].textContent==='load_nN')c=k;}
 th[c].click();out.sorted.push(t.tBodies[0].rows[0].cells[c].dataset.value);
 th[c].click();out.sorted.push(t.tBodies[0].rows[0].cells[c].dataset.value);
 out.height=document.documentElement.scrollHeight;
 var p=document.createElement('pre');p.id='probe';p.textContent=JSON.stringify(out);document.body.appendChild(p);
})();
</script>"""


def chromium(*args):
    p = subprocess.run([CHROMIUM, "--headless", "--no-sandbox", "--disable-gpu", "--enable-logging=stderr", "--v=0",
                        "--hide-scrollbars", *args], capture_output=True, text=True, timeout=120)
    consoles = [line for line in p.stderr.splitlines() if ":CONSOLE" in line]
    return p.stdout, consoles


@pytest.mark.skipif(CHROMIUM is None, reason="headless Chromium not installed (apt-get install chromium)")
def test_in_a_browser(rough, tmp_path):
    prefix, page, summary = rough
    # The console check can fail: a page with a script error logs it.
    broken = tmp_path / "broken.html"
    broken.write_text("<!DOCTYPE html><html lang=en><title>x</title><script>no_such_function()</script></html>")
    _, consoles = chromium("--dump-dom", broken.as_uri())
    assert any("no_such_function" in c for c in consoles), consoles
    # The page itself: nothing on the console.
    _, consoles = chromium("--dump-dom", f"file://{prefix}.report.html")
    assert consoles == []
    # The probe (a copy of the page with a script that measures the figures and clicks a
    # column head twice) and a screenshot of the whole page at the same width.
    probed = tmp_path / "probed.html"
    probed.write_text(page.replace("</body>", PROBE + "</body>"), encoding="utf-8")
    dom, consoles = chromium("--dump-dom", f"--window-size={WIDTH},2000", probed.as_uri())
    assert consoles == []
    out = json.loads(html.unescape(re.search(r'<pre id="probe">(.*?)</pre>', dom, re.S).group(1)))
    loads = sorted(s["load_nN"] for s in summary["loads"])
    assert [float(v) for v in out["sorted"]] == [loads[0], loads[-1]]  # up, then down
    # 2 curves, 3 states x 4 maps (pressure, gap, plastic, stick/slip), 3 of patches
    assert len(out["figures"]) == 2 + 3 * 4 + 3
    shot = tmp_path / "shot.png"
    height = min(int(out["height"]) + 50, 16000)
    chromium(f"--screenshot={shot}", f"--window-size={WIDTH},{height}", probed.as_uri())
    image = pytest.importorskip("matplotlib.image").imread(shot)[:, :, :3]
    for f in out["figures"]:
        x0, y0 = int(f["x"]) + 2, int(f["y"]) + 2
        box = image[y0:y0 + int(f["h"]) - 4, x0:x0 + int(f["w"]) - 4]
        assert box.size > 0, f
        ink = np.mean(np.min(box, axis=2) < 0.9)
        assert ink > 0.01, (f["title"], ink)  # not blank
        if f["map"]:
            colourful = np.mean(np.ptp(box, axis=2) > 0.25)
            assert colourful > 0.002, (f["title"], colourful)  # the map's colours drawn
