"""neepp from several Python threads at once (issue 43): two renders at the same time, a render while
another thread loads scenes, and a render cancelled from its progress callback each give the image they
give alone, to the bit, and nothing hangs. neepp.render and neepp.load release the GIL while they work,
so these threads really run at the same time. Every wait has a timeout: a deadlock fails the test
instead of hanging the suite. Tiny images and few samples: the whole file takes seconds."""
from __future__ import annotations

import subprocess
import sys
import threading
import time
from pathlib import Path

import numpy as np
import pytest

import neepp

REPO = Path(__file__).resolve().parents[2]
DOOR = REPO / "scenes" / "door-ajar" / "scene.xml"
OFFICE = REPO / "scenes" / "office" / "scene.xml"
COURTYARD = REPO / "scenes" / "courtyard" / "scene.xml"
SMALL = {"resx": 40, "resy": 28}
TIMEOUT_S = 60  # each test's threads, together; alone the renders take well under a second


def run_at_once(*jobs, timeout=TIMEOUT_S):
    """Runs each job (a function of no arguments) on a thread of its own, all released together by a
    barrier so that they overlap; returns their results in order, re-raises the first exception, and
    fails if a thread is still running after `timeout` seconds (a deadlock). The threads are daemons so
    that a hung one cannot keep pytest from exiting."""
    barrier = threading.Barrier(len(jobs))
    results = [None] * len(jobs)
    errors = [None] * len(jobs)

    def run(i, job):
        try:
            barrier.wait(timeout)
            results[i] = job()
        except BaseException as e:  # noqa: B036 - handed to the test's thread
            errors[i] = e

    threads = [threading.Thread(target=run, args=(i, job), daemon=True) for i, job in enumerate(jobs)]
    for t in threads:
        t.start()
    deadline = time.monotonic() + timeout
    for t in threads:
        t.join(max(deadline - time.monotonic(), 0))
    hung = [i for i, t in enumerate(threads) if t.is_alive()]
    assert not hung, f"threads {hung} still running after {timeout} s: deadlock"
    for e in errors:
        if e is not None:
            raise e
    return results


# Two renders that differ in every way the library has shared state for: scene, integrator (NEE++'s
# learnt map; BDPT's splats), thread count, sample count.
NEEPP = dict(spp=4, integrator="path", shadow_rays="neepp", seed=7, threads=2)
BDPT = dict(spp=2, integrator="bdpt", seed=3, threads=1)


@pytest.fixture(scope="module")
def door():
    return neepp.load(DOOR, **SMALL)


@pytest.fixture(scope="module")
def office():
    return neepp.load(OFFICE, **SMALL)


@pytest.fixture(scope="module")
def alone(door, office):
    """The reference images: each render on its own, nothing else running."""
    return {"neepp": neepp.render(door, **NEEPP)[0], "bdpt": neepp.render(office, **BDPT)[0]}


def test_two_renders_at_once_give_the_images_of_each_alone(door, office, alone):
    assert alone["neepp"].mean() > 0 and alone["bdpt"].mean() > 0
    for _ in range(3):  # a few rounds: another interleaving each time
        (a, sa), (b, sb) = run_at_once(lambda: neepp.render(door, **NEEPP), lambda: neepp.render(office, **BDPT))
        assert np.array_equal(a, alone["neepp"]) and np.array_equal(b, alone["bdpt"])
        assert sa["spp"] == 4 and sb["spp"] == 2 and sa["threads"] == 2 and sb["threads"] == 1


def test_one_scene_rendered_by_two_threads_at_once(door, alone):
    # The Scene is shared and read-only during a render: each render has its own integrator and film.
    a, b = run_at_once(lambda: neepp.render(door, **NEEPP)[0], lambda: neepp.render(door, **NEEPP)[0])
    assert np.array_equal(a, alone["neepp"]) and np.array_equal(b, alone["neepp"])


def test_render_while_another_thread_loads_scenes(door, alone):
    rendering = threading.Event()
    loaded = []

    def load_loop():
        # Loads (meshes, textures, the Embree BVH build, which uses the thread pool) until the render is
        # over, and at least twice.
        while len(loaded) < 2 or rendering.is_set():
            for path in (OFFICE, COURTYARD):
                loaded.append(neepp.load(path, **SMALL))

    def render():
        rendering.set()
        try:
            return neepp.render(door, **NEEPP)[0]
        finally:
            rendering.clear()

    image, _ = run_at_once(render, load_loop)
    assert np.array_equal(image, alone["neepp"])
    assert len(loaded) >= 2 and all((s.width, s.height) == (40, 28) and s.triangle_count > 0 for s in loaded)


def test_callback_cancel_and_exception_leave_the_other_render_alone(door, office, alone):
    calls = []

    def cancel(fraction):
        calls.append(fraction)
        return False  # stop the render, keep the image of the passes done

    def fail(fraction):
        raise RuntimeError("stop here")

    def expect_failure():
        with pytest.raises(RuntimeError, match="stop here"):
            neepp.render(office, time=30, progress=fail)
        return "raised"

    t0 = time.monotonic()
    (image, stats), raised, (other, _) = run_at_once(lambda: neepp.render(door, time=30, progress=cancel),
                                                     expect_failure, lambda: neepp.render(door, **NEEPP))
    assert time.monotonic() - t0 < 20  # both 30 s renders were stopped, long before their time
    assert stats["stopped_by"] == "cancel" and calls and image.shape == (28, 40, 3)
    assert raised == "raised"
    assert np.array_equal(other, alone["neepp"])


def test_callback_false_stops_a_range_with_an_error(door):
    # A range stopped early is not a partial range (its sums would count for nothing): render_range raises.
    t0 = time.monotonic()
    with pytest.raises(RuntimeError, match="stopped by the progress callback"):
        neepp._neepp.render_range(door, "path", {}, 0, 100000, 1, 1, "", b"", lambda f: False)
    assert time.monotonic() - t0 < 20


def test_slow_callback_while_the_render_ends(door, office, alone):
    # The render finishes while its callback is still running (and holds the GIL): the render must wait
    # for it, not deadlock, and the other thread's render is unaffected by that GIL holder.
    slow = []

    def callback(fraction):
        slow.append(fraction)
        time.sleep(0.2)

    (a, _), (b, _) = run_at_once(lambda: neepp.render(door, progress=callback, **NEEPP),
                                 lambda: neepp.render(office, **BDPT))
    assert np.array_equal(a, alone["neepp"]) and np.array_equal(b, alone["bdpt"])
    assert slow and slow[-1] == 1.0


EXIT_SCRIPT = """
import sys, threading, neepp
scene = neepp.load(sys.argv[1], resx=40, resy=28)
started = threading.Event()
threading.Thread(target=lambda: neepp.render(scene, time=30, progress=lambda f: started.set()), daemon=True).start()
assert started.wait(20)
print("exiting", flush=True)
"""


def test_exit_with_a_render_running_on_a_daemon_thread(tmp_path):
    # The interpreter exits while a daemon thread renders: neepp's atexit handler stops the render and waits
    # for it, instead of the thread being ended mid-render by finalization: before the handler existed, an
    # abort (std::terminate) or a crash in about half the runs, hence four of them.
    script = tmp_path / "exit.py"
    script.write_text(EXIT_SCRIPT)
    for _ in range(4):
        t0 = time.monotonic()
        r = subprocess.run([sys.executable, str(script), str(DOOR)], capture_output=True, text=True, timeout=60)
        assert r.returncode == 0 and r.stdout.strip() == "exiting", (r.returncode, r.stderr[-2000:])
        assert "terminate" not in r.stderr
        assert time.monotonic() - t0 < 20  # the 30 s render was stopped, not waited out
