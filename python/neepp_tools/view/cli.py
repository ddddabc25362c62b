"""neepp view's command line: loads the scene, binds 127.0.0.1:PORT, prints the page's address (opens it
in the browser with --open) and serves until Ctrl-C or SIGTERM, which end the render and free the port
(exit status 0)."""
from __future__ import annotations

import argparse
import asyncio
import signal
import socket
import sys
import webbrowser
from pathlib import Path

import neepp

from . import __doc__ as VIEW_DOC
from .server import ViewServer
from .session import ViewSession


def _pairs(items: list[str], what: str) -> dict:
    out = {}
    for item in items:
        key, eq, value = item.partition("=")
        if not eq or not key:
            raise ValueError(f"{what} '{item}' is not name=value")
        out[key] = value
    return out


def parse_args(argv):
    p = argparse.ArgumentParser(prog="neepp view", description=VIEW_DOC.split("\n\n")[0],
                                epilog="Mouse: drag to orbit, shift-drag or right-drag to pan, wheel to dolly. "
                                       "Keys: W/A/S/D/Q/E walk, arrows orbit, +/- field of view, R the scene's "
                                       "camera, Ctrl+S save.")
    p.add_argument("scene", type=Path, help="Scene file (Mitsuba 3 XML)")
    p.add_argument("-D", dest="define", action="append", default=[], metavar="NAME=VALUE",
                   help="Scene parameter override (as mitsuba -D)")
    p.add_argument("--integrator", default="", help="Integrator (default: the scene's)")
    p.add_argument("-I", dest="option", action="append", default=[], metavar="KEY=VALUE",
                   help="Integrator option (neepp list shows all); the page switches them live")
    p.add_argument("--port", type=int, default=0, help="Port on 127.0.0.1 (default: a free one)")
    p.add_argument("--open", action="store_true", help="Open the page in the browser")
    p.add_argument("--spp", type=int, default=1024, help="The most samples per pixel a view gets (default 1024)")
    p.add_argument("--threads", type=int, default=0, help="Worker threads (default: all cores)")
    p.add_argument("--seed", type=int, default=None, help="Random seed (default: the scene's)")
    p.add_argument("--reference", type=Path, default=None,
                   help="A reference image (EXR) of the scene's camera and film: the page shows the image's "
                        "relMSE against it and its per-pixel map")
    p.add_argument("-o", "--output-dir", type=Path, default=Path("neepp-view"),
                   help="Where the save button writes view_NNN.exr, .png, .json and .vis (NEE++'s map) (default neepp-view)")
    a = p.parse_args(argv)
    if not 0 <= a.port <= 65535:
        p.error(f"--port {a.port}: not a port (0..65535)")
    if a.spp < 1:
        p.error("--spp must be at least 1")
    if a.threads < 0:
        p.error("--threads must be at least 1")
    try:
        a.define, a.option = _pairs(a.define, "-D"), _pairs(a.option, "-I")
    except ValueError as e:
        p.error(str(e))
    if not a.scene.is_file():
        p.error(f"scene file {a.scene} does not exist")
    if a.reference is not None and not a.reference.is_file():
        p.error(f"reference image {a.reference} does not exist")
    return a


def main(argv=None) -> int:
    a = parse_args(sys.argv[1:] if argv is None else argv)
    # The port first: a port in use is said at once, not after the scene has loaded.
    sock = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
    try:
        sock.bind(("127.0.0.1", a.port))  # loopback only: the page renders and writes files for its user
    except OSError as e:
        print(f"neepp: error: cannot listen on 127.0.0.1:{a.port}: {e.strerror}", file=sys.stderr)
        return 1
    try:
        scene = neepp.load(a.scene, **a.define)
        session = ViewSession(scene, a.integrator, a.option, max_spp=a.spp, threads=a.threads, seed=a.seed,
                              output_dir=a.output_dir)
        if a.reference is not None:
            session.set_reference(neepp.read_exr(a.reference), str(a.reference))
    except (ValueError, RuntimeError, OSError) as e:
        print(f"neepp: error: {e}", file=sys.stderr)
        return 1
    sock.listen(16)
    url = f"http://127.0.0.1:{sock.getsockname()[1]}/"
    print(f"neepp view: {a.scene} at {url} (Ctrl-C stops)", flush=True)
    if a.open:
        webbrowser.open(url)
    asyncio.run(_serve(ViewServer(session), sock))
    return 0


async def _serve(server: ViewServer, sock: socket.socket) -> None:
    stop = asyncio.Event()
    loop = asyncio.get_running_loop()
    for sig in (signal.SIGINT, signal.SIGTERM):
        loop.add_signal_handler(sig, stop.set)
    await server.serve(sock, stop)
