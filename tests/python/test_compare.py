"""`neepp compare` as a user runs it: four methods at equal time on the demo scene against a reference,
two seeds each. The numbers in results.json are right (recomputed here from the renders), the page needs
no network, and in a real headless Chromium the page loads without a script error, every image
decodes, the A/B slider and the zoom move the viewer (the page's own #selftest), its table shows
results.json's numbers, and a screenshot shows the rendered image."""
from __future__ import annotations

import json
import re
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest

from neepp_tools import metrics
from neepp_tools.exr import read_exr

REPO = Path(__file__).resolve().parents[2]
DEMO = REPO / "scenes" / "door-ajar" / "scene.xml"
SIZE = ["-D", "resx=64", "-D", "resy=36", "--rfilter", "box"]
METHODS = ["path", "path:shadow_rays=neepp", "bdpt", "pssmlt:bootstrap=5000"]
# Long enough that a render's second pass (sized to the speed of its first, up to 32 spp: about 0.4 s of
# PSSMLT here) survives a machine twice as slow as that first pass saw: a time limit cuts a pass only past
# 1.25x the limit, and at 0.6 s a loaded pytest worker (two of them run) once lost PSSMLT's whole second
# pass, leaving one convergence point.
TIME = 1.5


@pytest.fixture(scope="module")
def report(neepp_bin, tmp_path_factory):
    d = tmp_path_factory.mktemp("compare")
    ref = d / "ref.exr"
    subprocess.run([str(neepp_bin), "render", str(DEMO), "-o", str(ref), "--spp", "2048", "--quiet", *SIZE],
                   check=True, timeout=300)
    out = d / "report"
    r = subprocess.run([str(neepp_bin), "compare", str(DEMO), "--methods", ",".join(METHODS), "--time", str(TIME),
                        "--seeds", "2", "--reference", str(ref), "-o", str(out), *SIZE],
                       capture_output=True, text=True, timeout=600)
    assert r.returncode == 0, r.stderr
    return out, ref


def test_results_hold_the_renders_numbers(report):
    out, ref_path = report
    res = json.loads((out / "results.json").read_text())
    ref = read_exr(ref_path)
    assert [m["label"] for m in res["methods"]] == METHODS
    assert res["mode"] == "equal time" and res["time_s"] == TIME and res["seeds"] == 2
    for m in res["methods"]:
        a = read_exr(out / "renders" / f"{m['label'].replace(':', '_').replace('=', '_')}_seed0.exr")
        b = read_exr(out / "renders" / f"{m['label'].replace(':', '_').replace('=', '_')}_seed1.exr")
        assert m["relmse"] == pytest.approx(metrics.relmse(a, ref), rel=1e-9), m["label"]
        assert m["rel_variance"] == pytest.approx(metrics.relative_variance(a, b, ref), rel=1e-9), m["label"]
        assert 0 < m["mean_flip"] < 1, m["label"]
        assert m["spp"] >= 1 and 0 < m["render_time_s"] < 1.5 * TIME + 0.5, m
        conv = m["convergence"]
        assert len(conv) >= 2, m["label"]
        times = [c["render_time_s"] for c in conv]
        assert times == sorted(times) and conv[-1]["spp"] == m["spp"], m["label"]
        assert conv[-1]["relmse"] == pytest.approx(m["relmse"], rel=1e-6), m["label"]  # the last snapshot is the image
    # NEE++'s rejection skips shadow rays that plain NEE traces.
    by = {m["label"]: m for m in res["methods"]}
    assert by["path:shadow_rays=neepp"]["shadow_rays"] < by["path"]["shadow_rays"] * by["path:shadow_rays=neepp"]["spp"] / by["path"]["spp"]
    for name in ["side_by_side.png", "convergence.png", "path_image.png", "path_error.png", "path_flip.png",
                 "reference_image.png"]:
        assert (out / "figures" / name).stat().st_size > 100, name


def test_page_is_self_contained(report):
    out, _ = report
    page = (out / "index.html").read_text()
    assert not re.search(r"""(src|href)\s*=\s*["']?(https?:)?//""", page), "the page loads something from a network"
    assert "@RESULTS@" not in page and "@IMAGES@" not in page
    assert page.count("data:image/png;base64,") >= 4 * 3 + 1  # images, error and FLIP maps, the reference


def _chromium():
    exe = shutil.which("chromium") or shutil.which("chromium-browser")
    if exe is None:
        pytest.skip("chromium is not installed (scripts/test.sh installs it)")
    return [exe, "--headless", "--no-sandbox", "--disable-gpu", "--hide-scrollbars", "--enable-logging=stderr",
            "--v=0"]


def test_page_in_headless_chromium(report, tmp_path):
    out, _ = report
    url = (out / "index.html").resolve().as_uri()
    r = subprocess.run(_chromium() + ["--virtual-time-budget=10000", "--dump-dom", url + "#selftest"],
                       capture_output=True, text=True, timeout=120)
    assert r.returncode == 0, r.stderr[-2000:]
    dom = r.stdout
    verdict = re.search(r'<pre id="selftest">([^<]*)</pre>', dom)  # what the page's self-test wrote
    assert verdict and verdict.group(1).startswith("selftest ok"), verdict and verdict.group(1)
    console = [line for line in r.stderr.splitlines() if "CONSOLE" in line or "Uncaught" in line]
    assert not console, console
    # The table's cells carry the numbers they show: they must be results.json's.
    res = json.loads((out / "results.json").read_text())
    rows = re.findall(r"<tr>(.*?)</tr>", dom, flags=re.S)[1:]
    assert len(rows) == len(res["methods"])
    for row, m in zip(rows, res["methods"]):
        cells = dict(re.findall(r'data-key="(\w+)" data-value="([^"]*)"', row))
        for key in ("relmse", "rel_variance", "mean_flip", "spp", "shadow_rays", "render_time_s"):
            assert json.loads(cells[key].replace("&quot;", '"')) == m[key], (m["label"], key)
    # A screenshot shows the images: the viewer's enlarged render holds many pixels of the colour of its
    # brightest part (the lit doorway).
    shot = tmp_path / "shot.png"
    r = subprocess.run(_chromium() + ["--virtual-time-budget=10000", "--window-size=1280,1400", f"--screenshot={shot}",
                                      url], capture_output=True, text=True, timeout=120)
    assert r.returncode == 0 and shot.exists(), r.stderr[-2000:]
    from PIL import Image
    pixels = np.asarray(Image.open(shot).convert("RGB"), dtype=np.float64).reshape(-1, 3)
    render = np.asarray(Image.open(out / "figures" / "path_image.png").convert("RGB"), dtype=np.float64).reshape(-1, 3)
    bright = render[render.sum(1) >= np.percentile(render.sum(1), 95)].mean(0)
    near = np.linalg.norm(pixels - bright, axis=1) < 40
    assert near.sum() > 20 * len(render) * 0.05, (bright, near.sum())
    assert len(np.unique(pixels.astype(np.uint8), axis=0)) > 500  # images, not a blank page


@pytest.mark.parametrize("args, expect", [
    (["--methods", "path:no_such_option=1"], "no_such_option"),
    (["--methods", "path,path"], "twice"),
    (["--methods", "path:nee"], "not key=value"),
    (["--methods", "path", "--reference", "/nonexistent/ref.exr"], "does not exist"),
])
def test_bad_input_is_a_clear_error(neepp_bin, tmp_path, args, expect):
    r = subprocess.run([str(neepp_bin), "compare", str(DEMO), "--time", "0.2", "-o", str(tmp_path / "o"), *SIZE, *args],
                       capture_output=True, text=True, timeout=120)
    assert r.returncode == 1 and expect in r.stderr, (r.returncode, r.stderr[-2000:])


def test_without_its_python_modules_it_says_what_is_missing(neepp_bin, tmp_path):
    """A checkout without .venv (a user who ran only the demo) runs compare with a bare python3: one message
    naming what is missing and the command that installs it, not a traceback."""
    import os
    import sys

    bare = tmp_path / "bare_python"
    bare.write_text(f'#!/bin/sh\nexec "{sys.executable}" -S "$@"\n')  # -S: no site-packages, no numpy
    bare.chmod(0o755)
    env = dict(os.environ, NEEPP_PYTHON=str(bare))
    r = subprocess.run([str(neepp_bin), "compare", str(DEMO), "--time", "0.2", "-o", str(tmp_path / "o"), *SIZE],
                       capture_output=True, text=True, timeout=120, env=env)
    assert r.returncode == 1, (r.returncode, r.stderr[-2000:])
    assert "Traceback" not in r.stderr, r.stderr[-2000:]
    assert "numpy" in r.stderr and "matplotlib" in r.stderr, r.stderr[-2000:]
    assert "scripts/setup_python.sh" in r.stderr and "NEEPP_PYTHON" in r.stderr, r.stderr[-2000:]
    assert not (tmp_path / "o").exists()
