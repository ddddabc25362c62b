"""bench/embree_floor.py and bench/ray_replay: a render's rays recorded and traced again by Embree alone."""
from __future__ import annotations

import importlib.util
import json
import subprocess
from pathlib import Path

import pytest

from neepp_tools import runner

REPO = Path(__file__).resolve().parents[2]
SCENE = REPO / "scenes" / "door-ajar" / "scene.xml"
spec = importlib.util.spec_from_file_location("embree_floor", REPO / "bench" / "embree_floor.py")
embree_floor = importlib.util.module_from_spec(spec)
spec.loader.exec_module(embree_floor)

HEADER_BYTES, RECORD_BYTES, HIT_OFFSET = 8, 36, 32  # bench/ray_replay/ray_record.h


@pytest.fixture(scope="module")
def tools(neepp_bin):
    recorder, replay = embree_floor.tools_beside(neepp_bin)
    if not recorder.exists() or not replay.exists():
        pytest.skip(f"ray replay tools not built beside {neepp_bin}")
    return recorder, replay


def record(neepp_bin, recorder, tmp_path) -> tuple[dict, list[Path]]:
    rays = tmp_path / "rays"
    rays.mkdir()
    r = runner.run_neepp(SCENE, tmp_path / "img.exr", spp=2, resx=40, resy=30, threads=2, binary=neepp_bin,
                         env={"LD_PRELOAD": str(recorder), "NEEPP_RAY_RECORD_DIR": str(rays)})
    return r.stats, sorted(rays.glob("rays.*.bin"))


def replay(replay_bin, files) -> dict:
    out = subprocess.run([str(replay_bin), str(SCENE), "-D", "resx=40", "-D", "resy=30", "--reps", "1",
                          *map(str, files)], capture_output=True, text=True, check=True)
    return json.loads(out.stdout)


def test_replay_traces_the_recorded_rays_with_the_same_outcomes(neepp_bin, tools, tmp_path):
    stats, files = record(neepp_bin, tools[0], tmp_path)
    assert files, "the recorder wrote no file"
    r = replay(tools[1], files)
    assert (r["intersect_rays"], r["occluded_rays"]) == (stats["rays"], stats["shadow_rays"])
    assert r["intersect_rays"] >= 40 * 30 * 2  # a camera ray per sample at least
    for mode in ("packets", "single"):
        assert r[mode]["mismatches"] == 0
        assert len(r[mode]["seconds"]) == 1 and r[mode]["seconds"][0] > 0


def test_replay_reports_an_outcome_that_differs_from_the_render(neepp_bin, tools, tmp_path):
    _, files = record(neepp_bin, tools[0], tmp_path)
    data = bytearray(files[0].read_bytes())
    data[HEADER_BYTES + HIT_OFFSET] ^= 1  # the first ray's recorded outcome, flipped
    files[0].write_bytes(bytes(data))
    r = replay(tools[1], files)
    assert r["packets"]["mismatches"] == 1 and r["single"]["mismatches"] == 1


def test_replay_rejects_a_file_that_is_not_a_recording(tools, tmp_path):
    bad = tmp_path / "rays.0.bin"
    bad.write_bytes(b"\x07" * 100)
    out = subprocess.run([str(tools[1]), str(SCENE), str(bad)], capture_output=True, text=True)
    assert out.returncode != 0 and "not a ray record file" in out.stderr


def test_floor_report(neepp_bin, tools, tmp_path):
    assert embree_floor.main(["--scenes", str(SCENE), "--res", "40x30", "--spp", "1", "--record-spp", "1",
                              "--reps", "1", "--out", str(tmp_path)]) == 0
    (res,) = json.loads((tmp_path / "results.json").read_text())["results"]
    assert res["rays_per_sample"] == pytest.approx(res["intersect_per_sample"] + res["shadow_per_sample"])
    assert res["intersect_per_sample"] >= 1
    assert res["floor_samples_per_s"] == pytest.approx(res["packets"]["rays_per_s"] / res["rays_per_sample"])
    assert res["ray_share"] > 0
    assert "floor M samples/s" in (tmp_path / "report.md").read_text()
