"""One image rendered by several workers on Ray (pip install "neepp[distributed]", or ray).

    image, stats = neepp.distributed.render("scene.xml", spp=256, workers=4, resx=640, resy=360)
    image, stats = neepp.distributed.render("scene.xml", time=60, address="ray://head:10001", workers=16,
                                            integrator="path", options={"shadow_rays": "neepp-adaptive"})

The image is split by sample index, not by tile: every worker renders every pixel, for a range of sample
indices [first, last), and returns its unnormalised sums (Σw·L and Σw per pixel, the splats apart in fixed
point). The driver adds them up in range order and forms the image once, so BDPT's splats, which land on
any pixel, and the filter's footprint across tile edges come out as in one render, and the result is the
same to the bit whatever the number of machines, for the same ranges.

Rendering goes in rounds. The first renders sample 0 alone: integrators that learn between passes (NEE++
seeds its visibility map and decides whether rejection pays) do it once. Every later round's ranges start
from what the earlier rounds learned: the workers' NEE++ maps are merged (the counts each added are
summed) between rounds and sent back with the next ranges, and rounds grow geometrically so that the map
learns early, as the render loop's passes do. An integrator that learns nothing renders everything left in
the second round.

The driver can die too: with checkpoint= and checkpoint_every=, it saves what the rounds so far summed and
learned at the end of a round (distributed_checkpoint.py), and resume=True goes on from there to the same
bits. Checkpoints sit at round boundaries because a round's ranges all start from the state merged before
it: a range half done holds nothing another driver could use.

A worker that dies has its range rendered again by Ray (tasks are retried; only a finished range's sums
are ever added, so nothing is lost or counted twice). A scene that a worker cannot load (a cluster whose
workers lack its files) raises the worker's SceneError in the driver.

Security: without an address, ray.init() starts a local Ray instance on this machine, listening on the
loopback interface only (127.0.0.1). With an address, the cluster's head and workers listen where that
cluster was started; Ray's own authentication (and TLS, RAY_USE_TLS) is what protects it, and anyone who
can reach its ports can run code on it: keep a cluster on a private network.
"""
from __future__ import annotations

import json
import os
import signal
import sys
import threading
import time as _time
from typing import Callable, Dict, List, Optional, Union

import numpy as np

from . import _neepp, load, option_text
from . import distributed_checkpoint as dc

__all__ = ["render", "schedule_rounds"]

_scenes: Dict[str, object] = {}  # a worker process's loaded scenes (Ray reuses processes across tasks)


def _scene(path: str, params: Dict[str, str]):
    key = json.dumps([path, sorted(params.items())])
    if key not in _scenes:
        _scenes.clear()  # one scene at a time: they can be large
        _scenes[key] = load(path, **params)
    return _scenes[key]


def _maybe_die_for_test(first: int) -> None:
    # Test hook (tests/python/test_distributed.py): the first task to claim the marker kills its own process
    # 0.3 s into its render, as a machine lost mid-range would be.
    folder = os.environ.get("NEEPP_DISTRIBUTED_KILL_ONCE")
    if not folder or first == 0:
        return
    try:
        fd = os.open(os.path.join(folder, "killed"), os.O_CREAT | os.O_EXCL | os.O_WRONLY)
    except FileExistsError:
        return
    os.write(fd, str(os.getpid()).encode())
    os.close(fd)
    threading.Timer(0.3, lambda: os.kill(os.getpid(), signal.SIGKILL)).start()


def _render_range(path: str, params: Dict[str, str], integrator: str, options: Dict[str, str], first: int, last: int,
                  seed: int, threads: int, sampler: str, state: bytes) -> dict:
    """One range of sample indices of one image (a Ray task, or called in-process)."""
    _maybe_die_for_test(first)
    scene = _scene(path, params)
    t0 = _time.monotonic()
    out = _neepp.render_range(scene, integrator, options, first, last, seed, threads, sampler, state, None)
    out["wall_s"] = _time.monotonic() - t0
    return out


def schedule_rounds(spp: int, workers: int, learns: bool, first_round: int = 1) -> List[List[tuple]]:
    """The ranges [first, last) of each round after the first (which is [0, first_round)): for an integrator
    that learns, rounds of workers ranges whose size doubles (1, 2, 4... spp each); otherwise one round
    of `workers` ranges. Depends on its arguments only, so a render's ranges are the same on any cluster
    of the same worker count."""
    rounds, start, size = [], first_round, 1
    while start < spp:
        if learns:
            per = size
            size *= 2
        else:
            per = -(-(spp - start) // workers)
        ranges = []
        for _ in range(workers):
            if start >= spp:
                break
            end = min(spp, start + per)
            ranges.append((start, end))
            start = end
        rounds.append(ranges)
    return rounds


def _round_ends_at(plan: List[List[tuple]], rounds: int, start: int) -> bool:
    """Whether the first `rounds` rounds (sample 0, then plan's) end at sample index start."""
    if rounds == 1:
        return start == 1
    return 2 <= rounds <= len(plan) + 1 and plan[rounds - 2][-1][1] == start


class _Local:
    """Runs the tasks in this process, one after another (the reference a cluster's image must equal)."""

    def submit(self, *args):
        return _render_range(*args)

    def wait(self, handles, on_done):
        for h in handles:
            on_done(h)
        return list(handles)


class _Ray:
    def __init__(self, address: Optional[str], workers: int, threads: int):
        if not address:
            # On Linux, Ray gives a local instance the machine's network address and listens there (for
            # clusters); this setting keeps it on 127.0.0.1, so nothing of it is reachable from the network.
            os.environ.setdefault("RAY_ENABLE_WINDOWS_OR_OSX_CLUSTER", "0")
        import ray
        self.ray = ray
        # ray.init puts a handler of its own on SIGTERM, which ends the process at once: a caller's own
        # (the CLI's, which saves a checkpoint first) is put back.
        on_sigterm = signal.getsignal(signal.SIGTERM)
        if not ray.is_initialized():
            if address:
                ray.init(address=address, log_to_driver=False)
            else:
                from ray._private import ray_constants  # read at start-up: when ray was imported before us
                ray_constants.ENABLE_RAY_CLUSTER = False
                ray.init(num_cpus=max(workers * threads, 1), include_dashboard=False, log_to_driver=False)
        if callable(on_sigterm) and threading.current_thread() is threading.main_thread():
            signal.signal(signal.SIGTERM, on_sigterm)
        self.task = ray.remote(num_cpus=threads, max_retries=3)(_render_range)

    def submit(self, *args):
        return self.task.remote(*args)

    def wait(self, handles, on_done):
        pending, results = list(handles), {}
        while pending:
            done, pending = self.ray.wait(pending, num_returns=1)
            for ref in done:
                try:
                    results[ref] = self.ray.get(ref)
                except self.ray.exceptions.RayTaskError as e:
                    raise _cause(e) from None
                on_done(results[ref])
        return [results[h] for h in handles]


def _cause(error):
    """The worker's own exception (SceneError, ValueError...) rather than Ray's wrapper, with the worker named."""
    cause = getattr(error, "cause", None)
    if isinstance(cause, BaseException):
        try:
            cause.add_note(f"(raised on a Ray worker, pid {getattr(error, 'pid', '?')})")
        except AttributeError:
            pass
        return cause
    return error


class _Bar:
    def __init__(self, progress):
        self.callback = progress if callable(progress) else None
        self.draw = progress is True
        self.t0 = _time.monotonic()

    def __call__(self, fraction: float) -> None:
        fraction = min(max(fraction, 0.0), 1.0)
        if self.callback:
            self.callback(fraction)
        if self.draw:
            elapsed = _time.monotonic() - self.t0
            eta = elapsed * (1 - fraction) / fraction if fraction > 0.005 else float("nan")
            filled = int(fraction * 40)
            sys.stderr.write(f"\r[{'=' * filled}{'>' if filled < 40 else ''}{' ' * max(39 - filled, 0)}] "
                             f"{100 * fraction:5.1f}% {elapsed:.1f}s elapsed, ETA {eta:.1f}s   ")
            if fraction >= 1:
                sys.stderr.write("\n")
            sys.stderr.flush()


def render(scene_path, spp: Optional[int] = None, time: Optional[float] = None, workers: int = 2,
           address: Optional[str] = None, integrator: Optional[str] = None, options: Optional[dict] = None,
           seed: Optional[int] = None, threads: int = 1, sampler: Optional[str] = None,
           progress: Union[None, bool, Callable[[float], None]] = None, local: bool = False,
           checkpoint: Optional[str] = None, checkpoint_every: Optional[float] = None, resume: bool = False,
           on_checkpoint: Optional[Callable[[np.ndarray], None]] = None, **params):
    """Renders a scene on `workers` Ray workers (each with `threads` threads); returns ``(image, stats)`` as
    neepp.render does. Scene parameters are keyword arguments (as neepp.load's), integrator options a dict.

    spp: samples per pixel (default: the scene's), or time: seconds to render for. address: a Ray cluster
    (default: a local Ray instance, started on the loopback interface if none is running). progress: a
    callable given the fraction done, or True for a bar on stderr. local=True runs the same ranges in this
    process, without Ray: the image a cluster must match to the bit.

    checkpoint: a file for the render's state (the CLI's OUT.exr.checkpoint). checkpoint_every: seconds;
    at the end of a round, once that long has passed since the last save (or the start), the sums and the
    merged integrator state are saved there (0: after every round), and again when the render is stopped
    (Ctrl-C) or its time is up; on_checkpoint then gets the image so far. resume=True continues the render
    the checkpoint holds (same scene, options, seed, workers and budget; RuntimeError naming what differs
    otherwise) to the same image, to the bit, as an uninterrupted render. The checkpoint of a render that
    reached its sample count is left for the caller to remove (distributed_checkpoint.remove) once the
    image is safely written.
    """
    if spp is not None and time is not None:
        raise ValueError("give spp or time, not both")
    if workers < 1 or threads < 1:
        raise ValueError("workers and threads must be at least 1")
    if time is not None and not time > 0:
        raise ValueError(f"time must be positive, got {time}")
    if (resume or checkpoint_every is not None) and not checkpoint:
        raise ValueError("resume and checkpoint_every need the checkpoint's file (checkpoint=...)")
    if checkpoint_every is not None and not checkpoint_every >= 0:
        raise ValueError(f"checkpoint_every must be 0 or more seconds, got {checkpoint_every}")
    path = os.path.abspath(os.fspath(scene_path))
    params = {k: option_text(v) for k, v in params.items()}
    scene = load(path, **params)  # errors in the scene surface here, before any worker starts
    name = integrator or scene.integrator
    opts = dict(scene.integrator_options)
    opts.update({k: option_text(v) for k, v in (options or {}).items()})
    if name == "pssmlt":
        raise ValueError("pssmlt cannot be rendered distributed: its Markov chains are not split by sample index")
    seed = scene.seed if seed is None else int(seed)
    sampler = sampler or scene.sampler
    total = spp if spp is not None else (None if time is not None else scene.spp)
    if total is not None and total < 1:
        raise ValueError(f"spp must be at least 1, got {total}")
    ident = dc.identity(scene, name, opts, seed, sampler, params, workers, total) if checkpoint else ""
    resumed = dc.resume(checkpoint, ident) if resume else None  # refused here, before any worker starts
    bar = _Bar(progress)
    t0 = _time.monotonic()
    runner = _Local() if local else _Ray(address, workers, threads)

    def task(first, last, state):
        return runner.submit(path, params, name, opts, first, last, seed, threads, sampler, state)

    if resumed:  # where the rounds stood after the last round saved
        sums = dc.RoundSums.from_checkpoint(resumed)
        at = json.loads(resumed["driver"])["rounds"]
        state, learns, rounds = resumed["integrator_state"], at["learns"], at["rounds"]
        next_start, size, seconds_per_spp = at["next_start"], at["size"], resumed["seconds_per_spp"]
        time_before = resumed["render_time_s"]
    else:
        sums, state, learns, rounds, next_start, size, seconds_per_spp = dc.RoundSums(), b"", False, 0, 0, 1, 0.0
        time_before = 0.0
    resumed_spp = sums.spp

    def elapsed():
        return time_before + _time.monotonic() - t0

    done_spp = [sums.spp]

    def fraction():
        if total is None:
            return elapsed() / time
        return done_spp[0] / total

    def on_done(r):
        done_spp[0] += r["last"] - r["first"]
        bar(fraction())

    saved = {"rounds": rounds, "at": _time.monotonic()}  # a resumed render's rounds are in its checkpoint

    def save():
        dc.save(checkpoint, ident, sums, state, elapsed(), seconds_per_spp,
                {"rounds": rounds, "next_start": next_start, "size": size, "learns": learns})
        saved.update(rounds=rounds, at=_time.monotonic())
        if on_checkpoint:
            on_checkpoint(_neepp.image_from_sums(scene, sums.image_sums, sums.splat_sums, sums.light_paths)[..., :3])

    def run_round(ranges):
        nonlocal state, learns, rounds, next_start, size, seconds_per_spp, committing
        round_t0 = _time.monotonic()
        out = runner.wait([task(a, b, state) for a, b in ranges], on_done)
        if rounds == 0:
            learned = out[0]["integrator_state"]
            learns = len(learned) > 0
            seconds_per_spp = out[0]["wall_s"]  # per worker: every worker renders every pixel
        else:
            learned = _neepp.merge_states(name, opts, state, [r["integrator_state"] for r in out]) if learns else state
            seconds_per_spp = (_time.monotonic() - round_t0) / max(b - a for a, b in ranges)
        # The round counts once all of it is in: a stop (Ctrl-C) in between saves the round before.
        committing = True
        sums.add(out)
        state = learned
        if rounds > 0 and learns:
            size *= 2
        rounds += 1
        next_start = ranges[-1][1]
        committing = False

    saving = checkpoint is not None and checkpoint_every is not None
    committing = False
    plan = None
    try:
        if rounds == 0:
            run_round([(0, 1)])
        plan = schedule_rounds(total, workers, learns) if total is not None else None
        if plan is not None and not _round_ends_at(plan, rounds, next_start):
            raise RuntimeError(f"checkpoint '{checkpoint}': its rounds do not fit this render's; it is damaged")
        while True:
            if plan is not None and rounds - 1 >= len(plan):
                break
            if saving and _time.monotonic() - saved["at"] >= checkpoint_every and saved["rounds"] != rounds:
                save()
            if plan is not None:
                ranges = plan[rounds - 1]
            else:  # time: rounds sized to what is left, growing as for spp while learning
                per = int((time - elapsed()) / max(seconds_per_spp, 1e-6) * 0.9)
                if learns:
                    per = min(per, size)
                if per < 1:
                    break
                ranges = [(next_start + i * per, next_start + (i + 1) * per) for i in range(workers)]
            run_round(ranges)
    except KeyboardInterrupt:
        if saving and not committing and saved["rounds"] != rounds and sums.ranges:
            save()
        raise
    stopped_by = "spp" if total is not None else "time"
    if saving and stopped_by == "time" and saved["rounds"] != rounds:  # stopped before its end: kept
        save()
    bar(1.0)
    return _merge(scene, sums, time_s=elapsed(), workers=workers, rounds=rounds, address=address, local=local,
                  stopped_by=stopped_by, resumed_spp=resumed_spp)


def _merge(scene, sums: "dc.RoundSums", time_s: float, workers: int, rounds: int, address, local: bool,
           stopped_by: str, resumed_spp: int):
    """The image and statistics of all ranges: their sums (added in range order, so the same ranges give the
    same bits however they were spread), the image formed once."""
    image = _neepp.image_from_sums(scene, sums.image_sums, sums.splat_sums, sums.light_paths)
    spp = sums.spp
    stats = dict(sums.last_stats)
    stats.update(sums.summed)
    stats.update(spp=spp, passes=sums.passes, render_time_s=time_s,
                 samples_per_s=spp * scene.width * scene.height / time_s if time_s > 0 else 0.0,
                 stopped_by=stopped_by, threads=None, resumed_spp=resumed_spp)
    stats["integrator"] = sums.first_stats["integrator"]
    stats["distributed"] = {"workers": workers, "rounds": rounds, "ranges": sums.ranges,
                            "address": address or ("in-process" if local else "local"),
                            "worker_render_time_s": sums.worker_render_time_s}
    return image[..., :3], stats


def main(argv=None) -> int:
    """`neepp render SCENE --ray [ADDRESS] --workers N ...` (the CLI hands its render arguments here)."""
    import argparse
    from . import write_exr, write_png

    ap = argparse.ArgumentParser(prog="neepp render --ray", description="Render one image on Ray workers.")
    ap.add_argument("scene")
    ap.add_argument("-o", "--output", default="render.exr")
    ap.add_argument("--spp", type=int)
    ap.add_argument("--time", type=float)
    ap.add_argument("--seed", type=int)
    ap.add_argument("--threads", type=int, default=1, help="threads per worker")
    ap.add_argument("-D", action="append", default=[], metavar="NAME=VALUE")
    ap.add_argument("--integrator")
    ap.add_argument("-I", action="append", default=[], metavar="KEY=VALUE")
    ap.add_argument("--sampler")
    ap.add_argument("--stats")
    ap.add_argument("-q", "--quiet", action="store_true")
    ap.add_argument("--ray", nargs="?", const="", default="", metavar="ADDRESS")
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--checkpoint", type=float, metavar="SECONDS",
                    help="at the end of a round, once SECONDS have passed since the last save, save the render's "
                         "state to OUTPUT.checkpoint and write the image so far; also when stopped")
    ap.add_argument("--resume", action="store_true", help="continue the render saved in OUTPUT.checkpoint")
    for unsupported in ["--snapshots", "--visibility-map", "--rfilter", "--display-server"]:
        ap.add_argument(unsupported, help=argparse.SUPPRESS)
    a = ap.parse_args(argv)
    for name in ["snapshots", "visibility_map", "rfilter", "display_server"]:
        if getattr(a, name) is not None:
            ap.error(f"--{name.replace('_', '-')} is not available with --ray")
    if a.checkpoint is not None and not a.checkpoint > 0:
        ap.error(f"--checkpoint: {a.checkpoint} is not a positive number of seconds")

    def pairs(items, flag):
        out = {}
        for item in items:
            key, eq, value = item.partition("=")
            if not eq or not key:
                ap.error(f"{flag} expects name=value, got '{item}'")
            out[key] = value
        return out

    if not a.output.endswith(".exr"):
        ap.error(f"the output image '{a.output}' must end in .exr")
    for path in [a.output, a.stats]:  # before rendering, as the CLI checks: a typing slip costs no render
        if path:
            folder = os.path.dirname(os.path.abspath(path))
            os.makedirs(folder, exist_ok=True)
            if not os.access(folder, os.W_OK):
                ap.error(f"cannot write '{path}': the folder '{folder}' is not writable")
    params = pairs(a.D, "-D")
    params.pop("spp", None)  # the sample count is --spp's (neepp.load's keywords cannot be spp or time)
    params.pop("time", None)
    png = os.path.splitext(a.output)[0] + ".png"

    def write_images(image):
        write_exr(a.output, image)
        write_png(png, image)

    # --checkpoint and --resume as the CLI's: OUTPUT.checkpoint, saved at round ends (the image so far
    # written with it), continued by the same command with --resume, removed once the image is written.
    checkpoint = a.output + ".checkpoint"
    stopped_by = []
    rendered = []

    def on_sigterm(signum, frame):  # stops as Ctrl-C does: the rounds completed are saved
        stopped_by.append(signum)
        if not rendered:
            raise KeyboardInterrupt
        # Once every round is in, there is nothing left to save for later: the image is written and the
        # checkpoint removed as for an uninterrupted render (default SIGTERM here would kill the process
        # with the finished image unwritten and the checkpoint left behind).

    previous = signal.signal(signal.SIGTERM, on_sigterm)
    try:
        return _render_and_write(a, params, pairs(a.I, "-I"), checkpoint, png, write_images, stopped_by, rendered)
    finally:
        # Once rendered, the handler stays through the exit that follows (Ray's disconnect at interpreter exit
        # takes a while): a SIGTERM then must not kill a process whose image is written (exit -15).
        if not rendered:
            signal.signal(signal.SIGTERM, previous)


def _render_and_write(a, params, options, checkpoint, png, write_images, stopped_by, rendered):
    """main's render and writes, under its SIGTERM handler."""
    try:
        image, stats = render(a.scene, spp=a.spp, time=a.time, workers=a.workers, address=a.ray or None,
                              integrator=a.integrator, options=options, seed=a.seed, threads=a.threads,
                              sampler=a.sampler, progress=None if a.quiet else sys.stderr.isatty() or
                              _LogLines(), checkpoint=checkpoint if a.checkpoint or a.resume else None,
                              checkpoint_every=a.checkpoint, resume=a.resume,
                              on_checkpoint=write_images if a.checkpoint else None, **params)
        rendered.append(True)  # in the try: a SIGTERM before it is a stop like any other
    except (ValueError, RuntimeError, OSError) as e:
        print(f"neepp: error: {e}", file=sys.stderr)
        return 1
    except KeyboardInterrupt:
        if a.checkpoint and os.path.exists(checkpoint):
            print(f"neepp: stopped; the rounds completed are in {checkpoint} (the same command with --resume "
                  "continues it)", file=sys.stderr)
        else:
            print("neepp: interrupted (a distributed render without --checkpoint keeps no partial image)",
                  file=sys.stderr)
        return 143 if stopped_by else 130
    write_images(image)
    if a.stats:
        _neepp.write_file_atomically(a.stats, lambda tmp: _write_json(tmp, stats))
    if (a.checkpoint or a.resume) and stats["stopped_by"] == "spp":
        dc.remove(checkpoint)
    if not a.quiet:
        print(f"neepp: {stats['spp']} spp on {a.workers} workers in {stats['render_time_s']:.2f} s "
              f"({stats['samples_per_s'] * 1e-6:.3f} M samples/s), wrote {a.output} and {png}", file=sys.stderr)
    return 0


def _write_json(path: str, data: dict) -> None:
    with open(path, "w") as f:
        json.dump(data, f, indent=2)
        f.write("\n")


class _LogLines:
    """Progress as a line per tenth of the render, for logs (stderr is not a terminal)."""

    def __init__(self):
        self.tenth = 0

    def __call__(self, fraction: float) -> None:
        if int(fraction * 10) > self.tenth:
            self.tenth = int(fraction * 10)
            print(f"neepp: {100 * fraction:5.1f}% done", file=sys.stderr, flush=True)


if __name__ == "__main__":
    sys.exit(main())
