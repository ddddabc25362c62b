"""The Mitsuba 3 side of the comparisons (neepp_tools.runner.run_mitsuba, which runs
neepp_tools.mitsuba_worker in a child process) finishes and reports what it rendered, including with a
single thread: Mitsuba's Bitmap.write used to hang forever after a one-thread render."""
from __future__ import annotations

from neepp_tools import REPO_ROOT, runner


def test_one_thread_render_finishes(tmp_path, mitsuba_variant):
    xml = REPO_ROOT / "scenes" / "door-ajar" / "scene.xml"
    r = runner.run_mitsuba(xml, tmp_path / "one_thread.exr", variant=mitsuba_variant, resx=16, resy=12, spp=2,
                           max_depth=3, threads=1, timeout=120)
    assert r.image.shape[:2] == (12, 16)
    assert r.stats["threads"] == 1
    assert r.stats["samples_per_s"] > 0
