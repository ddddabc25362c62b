"""The neepp Python package as `pip install .` installs it (scripts/test.sh does): the numpy image is the
CLI's image, statistics, progress, Ctrl-C, errors, visibility maps and images."""
from __future__ import annotations

import json
import signal
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import numpy as np
import pytest

import neepp

REPO = Path(__file__).resolve().parents[2]
DEMO = REPO / "scenes" / "door-ajar" / "scene.xml"
SMALL = {"resx": 48, "resy": 32}
PACKAGE_CLI = Path(neepp.__file__).resolve().parent / "bin" / "neepp"


def test_is_the_installed_package():
    # The checkout's python/ (on sys.path for the tools) must not shadow the package and its extension.
    assert "site-packages" in neepp.__file__, neepp.__file__
    assert (Path(neepp.__file__).parent / "_neepp.pyi").exists()  # type stubs
    assert (Path(neepp.__file__).parent / "py.typed").exists()
    assert PACKAGE_CLI.exists()


@pytest.mark.parametrize("integrator,options", [("path", {}), ("path", {"shadow_rays": "neepp"}), ("bdpt", {})])
def test_image_equals_the_clis_exr(tmp_path, integrator, options):
    # Same library, same seed: the same image to the bit (bdpt's splats included), through either door.
    scene = neepp.load(DEMO, **SMALL)
    image, stats = neepp.render(scene, spp=4, integrator=integrator, seed=7, threads=2, **options)
    assert image.shape == (32, 48, 3) and image.dtype == np.float32
    out = tmp_path / "cli.exr"
    cmd = [str(PACKAGE_CLI), "render", str(DEMO), "-o", str(out), "--spp", "4", "--seed", "7", "--threads", "2",
           "--integrator", integrator, "--quiet", "-D", "resx=48", "-D", "resy=32"]
    cmd += [f"-I{k}={v}" for k, v in options.items()]
    r = subprocess.run(cmd, capture_output=True, text=True, timeout=120)
    assert r.returncode == 0, r.stderr
    cli = neepp.read_exr(out)
    assert np.array_equal(image, cli[..., :3])
    assert image.mean() > 0
    assert stats["spp"] == 4 and stats["stopped_by"] == "spp" and stats["integrator"]["name"] == integrator
    assert stats["width"] == 48 and stats["rays"] > 0


def test_scene_properties():
    scene = neepp.load(DEMO, resx=40, resy=30)
    assert (scene.width, scene.height) == (40, 30)
    assert scene.integrator == "path" and scene.integrator_options["max_depth"] == "12"
    assert len(scene.lights) == 1 and scene.lights[0]["type"] == "area" and min(scene.lights[0]["power"]) > 0
    lo, hi = scene.bounds
    assert all(a < b for a, b in zip(lo, hi))
    cam = scene.camera
    assert len(cam["to_world"]) == 4 and cam["fov"] > 0 and cam["position"] == pytest.approx(cam["to_world"][0][3:] +
                                                                                             (cam["to_world"][1][3],
                                                                                              cam["to_world"][2][3]))
    assert scene.triangle_count > 0 and "door-ajar" in repr(scene)


def test_time_limit_and_progress_callback():
    scene = neepp.load(DEMO, **SMALL)
    seen = []
    image, stats = neepp.render(scene, time=0.8, progress=seen.append)
    assert stats["stopped_by"] == "time" and stats["spp"] >= 1
    assert seen and seen[-1] == 1.0 and all(0 <= f <= 1 for f in seen)
    assert all(a <= b for a, b in zip(seen, seen[1:]))
    assert len(seen) >= 3  # called while rendering, not only at the end


def test_callback_exception_stops_the_render_and_propagates():
    scene = neepp.load(DEMO, **SMALL)

    def stop(fraction):
        raise RuntimeError("stop here")

    t0 = time.monotonic()
    with pytest.raises(RuntimeError, match="stop here"):
        neepp.render(scene, time=30, progress=stop)
    assert time.monotonic() - t0 < 10


def test_ctrl_c_returns_the_image_so_far(tmp_path):
    script = tmp_path / "ctrl_c.py"
    # The child starts with Ctrl-C as a terminal gives it: a process inherits an ignored or blocked SIGINT
    # from its parent (here a pytest worker, whose earlier tests may have left either), and Python then
    # never raises KeyboardInterrupt. What it inherited is printed for a failure's message.
    script.write_text(textwrap.dedent(f"""
        import json, signal, sys
        print("inherited SIGINT:", signal.getsignal(signal.SIGINT), "blocked:",
              signal.pthread_sigmask(signal.SIG_BLOCK, []), file=sys.stderr, flush=True)
        signal.signal(signal.SIGINT, signal.default_int_handler)
        signal.pthread_sigmask(signal.SIG_UNBLOCK, {{signal.SIGINT}})
        import neepp
        scene = neepp.load({str(DEMO)!r}, resx=48, resy=32)
        print("rendering", flush=True)
        image, stats = neepp.render(scene, time=60)
        print(json.dumps({{"stopped_by": stats["stopped_by"], "spp": stats["spp"], "mean": float(image.mean()),
                          "interrupted": stats.get("interrupted", False)}}), flush=True)
    """))
    p = subprocess.Popen([sys.executable, str(script)], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    assert p.stdout.readline().strip() == "rendering"
    time.sleep(1.5)
    t0 = time.monotonic()
    p.send_signal(signal.SIGINT)
    try:
        out, err = p.communicate(timeout=30)
    except subprocess.TimeoutExpired:
        p.kill()
        out, err = p.communicate()
        pytest.fail(f"the render did not stop within 30 s of Ctrl-C: {err[-2000:]}")
    assert p.returncode == 0, err
    assert time.monotonic() - t0 < 10
    result = json.loads(out.strip().splitlines()[-1])
    assert result["stopped_by"] == "cancel" and result["interrupted"] and result["spp"] >= 1 and result["mean"] > 0


def test_bad_input_raises_with_the_clis_messages(tmp_path):
    with pytest.raises(neepp.SceneError) as e:
        neepp.load(tmp_path / "missing.xml")
    assert e.value.file.endswith("missing.xml") and "cannot open" in e.value.problem
    bad = tmp_path / "bad.xml"
    bad.write_text('<scene version="3.0.0">\n  <shape type="sphere">\n    <float name="radius" value="abc"/>\n'
                   '  </shape>\n</scene>\n')
    with pytest.raises(neepp.SceneError) as e:
        neepp.load(bad)
    assert e.value.line == 3 and str(e.value).startswith(f"{bad}:3: ")
    assert isinstance(e.value, ValueError)
    scene = neepp.load(DEMO, **SMALL)
    with pytest.raises(ValueError, match="no option"):
        neepp.render(scene, spp=1, no_such_option=1)
    with pytest.raises(ValueError, match="unknown integrator"):
        neepp.render(scene, spp=1, integrator="nope")
    with pytest.raises(ValueError):
        neepp.render(scene, spp=4, time=1.0)
    with pytest.raises(ValueError):
        neepp.render(scene, spp=0)
    with pytest.raises(RuntimeError):
        neepp.read_exr(tmp_path / "missing.exr")


def test_check_lists_every_problem(tmp_path):
    bad = tmp_path / "bad.xml"
    bad.write_text('<scene version="3.0.0">\n  <shape type="teapot"/>\n  <shape type="sphere">\n'
                   '    <float name="radiuss" value="1"/>\n  </shape>\n</scene>\n')
    problems = neepp.check(bad)
    # the teapot, the misspelt radius, no sensor (a default camera), no light
    assert [(p["line"], p["severity"]) for p in problems] == [(2, "error"), (3, "warning"), (0, "warning"), (0, "error")]
    assert "teapot" in problems[0]["problem"] and problems[0]["text"].startswith(f"{bad}:2: error: ")
    assert neepp.check(DEMO, **SMALL) == []


def test_visibility_map_round_trip(tmp_path):
    scene = neepp.load(DEMO, **SMALL)
    vmap = neepp.VisibilityMap.build(scene, resolution=8, samples_per_pair=8)
    assert vmap.resolution == 8 and vmap.voxel_count == 512 and vmap.cell_count == 512 + 96
    counts = vmap.counts()
    assert counts.shape == (vmap.pair_count, 2) and counts.dtype == np.uint16
    known = counts[:, 1] > 0
    assert known.sum() == vmap.known_pairs > 0 and (counts[:, 0] <= counts[:, 1]).all()
    # Ṽ from the counts, for a known pair, and the view is live.
    pair = int(np.flatnonzero(known)[0])
    a = next(i for i in range(vmap.cell_count) if any(vmap.pair_index(i, j) == pair for j in range(i + 1)))
    b = next(j for j in range(a + 1) if vmap.pair_index(a, j) == pair)
    v, t = counts[pair]
    assert vmap.known(a, b) and vmap.estimate(a, b) == pytest.approx((v + 1) / (t + 2))
    vmap.add(a, b, 0, 10)
    assert counts[pair][1] == t + 10
    path = tmp_path / "door.map"
    vmap.save(path)
    again = neepp.VisibilityMap.load(path, scene, resolution=8)
    assert np.array_equal(again.counts(), vmap.counts())
    with pytest.raises(RuntimeError):  # another grid
        neepp.VisibilityMap.load(path, scene, resolution=16)
    with pytest.raises(RuntimeError):  # another scene
        neepp.VisibilityMap.load(path, neepp.load(REPO / "scenes" / "office" / "scene.xml", **SMALL), resolution=8)
    with pytest.raises(IndexError):
        vmap.estimate(vmap.cell_count, 0)
    # A render reads the file as its map (and says so).
    _, stats = neepp.render(scene, spp=2, shadow_rays="neepp", voxels=8, visibility_map=str(path), learn=False)
    used = stats["integrator_statistics"]["shadow_rays"]["map"]
    assert used["source"] == "loaded" and used["known_pairs"] == vmap.known_pairs


def test_a_map_over_the_shading_points_bounds_loads_with_its_grid(tmp_path):
    """A map from a grid_bounds=shading render (neepp view saves such maps) has a grid over where the camera's
    paths shade, which only the file knows: load reads its grid from the file, the scene's fingerprint still
    checked, and the counts are the render's."""
    scene = neepp.load(DEMO, **SMALL)
    path = tmp_path / "shading.vis"
    _, stats = neepp.render(scene, spp=2, shadow_rays="neepp", voxels=8, grid_bounds="shading",
                            visibility_map=str(path), learn=False)
    built = stats["integrator_statistics"]["shadow_rays"]["map"]
    loaded = neepp.VisibilityMap.load(path, scene)
    scene_grid = neepp.VisibilityMap.build(scene, resolution=8, samples_per_pair=1)
    assert loaded.resolution == 8 and loaded.known_pairs == built["known_pairs"] > 0
    assert loaded.bounds != scene_grid.bounds  # the shading points' box, not the scene's
    assert neepp.VisibilityMap.load(path, scene, resolution=8).known_pairs == loaded.known_pairs
    with pytest.raises(RuntimeError, match="8\\^3 grid, not 16\\^3"):
        neepp.VisibilityMap.load(path, scene, resolution=16)
    with pytest.raises(RuntimeError, match="another scene"):
        neepp.VisibilityMap.load(path, neepp.load(REPO / "scenes" / "office" / "scene.xml", **SMALL))
    # Saved again and read by a render of the same bounds as its own map.
    loaded.save(tmp_path / "again.vis")
    _, again = neepp.render(scene, spp=2, shadow_rays="neepp", voxels=8, grid_bounds="shading",
                            visibility_map=str(tmp_path / "again.vis"), learn=False)
    used = again["integrator_statistics"]["shadow_rays"]["map"]
    assert used["source"] == "loaded" and used["known_pairs"] == loaded.known_pairs
    # What neepp view writes (LiveRender.save_visibility_map) under grid_bounds=shading reads back the same way.
    live = neepp._neepp.LiveRender(neepp.load(DEMO, **SMALL), "path", {"shadow_rays": "neepp", "voxels": "8",
                                                                       "grid_bounds": "shading"}, 2, "", 0)
    live.render(2)
    assert live.save_visibility_map(tmp_path / "view.vis")
    viewed = neepp.VisibilityMap.load(tmp_path / "view.vis", scene)
    assert viewed.known_pairs == live.map_info()["known_pairs"] and viewed.bounds == loaded.bounds


def test_images_and_metrics(tmp_path):
    rng = np.random.default_rng(1)
    img = rng.random((6, 5, 3), dtype=np.float32)
    neepp.write_exr(tmp_path / "a.exr", img)
    assert np.array_equal(neepp.read_exr(tmp_path / "a.exr"), img)
    neepp.write_png(tmp_path / "a.png", img)
    png = neepp.read_image(tmp_path / "a.png")
    assert png.shape == (6, 5, 3) and np.abs(png - img ** (1 / 2.2)).max() < 0.05
    assert neepp.metrics.relmse(img, img) == 0 and neepp.metrics.relmse(img * 1.1, img) > 0
