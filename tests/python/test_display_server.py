"""`neepp render --display-server HOST:PORT`: the render shown in tev as it converges.

A small fake tev, written here from tev's protocol (src/Ipc.cpp in github.com/Tom94/tev), listens on
127.0.0.1 and decodes what neepp sends: length-prefixed packets (a little-endian uint32 counting the whole
packet), a type byte, then the fields. The render must show the image as it converges and end on the
image it writes, and a viewer that is absent or goes away must cost a warning, never the render or its
image.
"""
from __future__ import annotations

import socket
import struct
import subprocess
import threading
import time
from pathlib import Path

import numpy as np
import pytest

from neepp_tools.exr import read_exr

REPO = Path(__file__).resolve().parents[2]
DEMO = REPO / "scenes" / "door-ajar" / "scene.xml"
# NEE++ learns between passes, so its passes are small at first: 8 spp are four passes (1, 1, 2, 4). The
# image is 2 x 2 tiles of neepp's 128 pixels a side, so each image shown is several packets.
W, H = 136, 130
TILES = {(x, y, min(128, W - x), min(128, H - y)) for x in (0, 128) for y in (0, 128)}
ARGS = ["--spp", 8, "-D", f"resx={W}", "-D", f"resy={H}", "--seed", 3, "--threads", 2, "--png", "none",
        "-I", "shadow_rays=neepp", "--quiet"]
CREATE_IMAGE, UPDATE_IMAGE_V3 = 4, 6


def decode(packet: bytes) -> dict:
    """One packet (its length included) as a dict, as tev's IpcPacket::interpretAs* reads it."""
    at = 0

    def take(fmt):
        nonlocal at
        values = struct.unpack_from("<" + fmt, packet, at)
        at += struct.calcsize("<" + fmt)
        return values if len(values) > 1 else values[0]

    def string():
        nonlocal at
        end = packet.index(b"\0", at)
        s = packet[at:end].decode()
        at = end + 1
        return s

    length, kind, grab = take("I"), take("B"), take("?")
    assert length == len(packet)
    p = {"type": kind, "grab_focus": grab, "name": string()}
    if kind == CREATE_IMAGE:
        p["width"], p["height"], n = take("iii")
        p["channels"] = [string() for _ in range(n)]
    elif kind == UPDATE_IMAGE_V3:
        n = take("i")
        p["channels"] = [string() for _ in range(n)]
        p["x"], p["y"], p["width"], p["height"] = take("iiii")
        offsets, strides = [take("q") for _ in range(n)], [take("q") for _ in range(n)]
        pixels = p["width"] * p["height"]
        size = max(o + (pixels - 1) * s + 1 for o, s in zip(offsets, strides))
        assert len(packet) - at == 4 * size, "the data must be exactly what the offsets and strides reach"
        data = np.frombuffer(packet, dtype="<f4", count=size, offset=at)
        p["data"] = np.stack([data[o:o + (pixels - 1) * s + 1:s] for o, s in zip(offsets, strides)], axis=-1)
        p["data"] = p["data"].reshape(p["height"], p["width"], n)
    else:
        raise AssertionError(f"unexpected packet type {kind}")
    return p


class FakeTev:
    """Accepts connections on a free port of 127.0.0.1 and keeps every packet received, decoded, in order.
    With hang_up_after=N it closes the connection and stops listening (tev quit) after N packets."""

    def __init__(self, hang_up_after: int | None = None):
        self.listener = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
        self.listener.bind(("127.0.0.1", 0))
        self.listener.listen(4)
        self.listener.settimeout(0.1)
        self.port = self.listener.getsockname()[1]
        self.packets: list[dict] = []
        self.connections = 0
        self.hang_up_after = hang_up_after
        self.stopping = False
        self.thread = threading.Thread(target=self._serve, daemon=True)
        self.thread.start()

    def _serve(self):
        while not self.stopping:
            try:
                conn, _ = self.listener.accept()
            except socket.timeout:
                continue
            except OSError:
                return
            self.connections += 1
            if self._read(conn):
                self.listener.close()
                return

    def _read(self, conn) -> bool:
        """Reads the connection to its end; True when it hung up on purpose."""
        buf = b""
        conn.settimeout(0.1)
        with conn:
            while not self.stopping:
                try:
                    chunk = conn.recv(1 << 16)
                except socket.timeout:
                    continue
                if not chunk:
                    return False
                buf += chunk
                while len(buf) >= 4 and len(buf) >= struct.unpack_from("<I", buf)[0]:
                    n = struct.unpack_from("<I", buf)[0]
                    self.packets.append(decode(buf[:n]))
                    buf = buf[n:]
                    if self.hang_up_after is not None and len(self.packets) >= self.hang_up_after:
                        return True
        return False

    def images(self) -> list[np.ndarray]:
        """The whole images the updates made, in order: a round of tiles from (0, 0) each."""
        images = []
        for p in self.packets:
            if p["type"] != UPDATE_IMAGE_V3:
                continue
            if (p["x"], p["y"]) == (0, 0):
                images.append(np.full((H, W, 3), np.nan, np.float32))
            images[-1][p["y"]:p["y"] + p["height"], p["x"]:p["x"] + p["width"]] = p["data"]
        return images

    def stop(self):
        self.stopping = True
        self.thread.join(timeout=5)
        try:
            self.listener.close()
        except OSError:
            pass


def render(neepp_bin, out: Path, *extra, timeout=60):
    start = time.monotonic()
    r = subprocess.run([str(neepp_bin), "render", str(DEMO), "-o", str(out), *map(str, ARGS), *map(str, extra)],
                       capture_output=True, text=True, timeout=timeout)
    return r, time.monotonic() - start


@pytest.fixture(scope="module")
def reference(neepp_bin, tmp_path_factory) -> Path:
    """The image without a display server."""
    out = tmp_path_factory.mktemp("display") / "plain.exr"
    r, _ = render(neepp_bin, out)
    assert r.returncode == 0, r.stderr
    return out


def free_port() -> int:
    """A port nothing listens on (bound for a moment, then released)."""
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def test_the_render_is_shown_as_it_converges_and_ends_on_the_image_written(neepp_bin, tmp_path, reference):
    tev = FakeTev()
    out = tmp_path / "shown.exr"
    try:
        r, _ = render(neepp_bin, out, "--display-server", f"127.0.0.1:{tev.port}")
    finally:
        tev.stop()
    assert r.returncode == 0, r.stderr
    assert "warning" not in r.stderr, r.stderr
    first = tev.packets[0]
    assert first["type"] == CREATE_IMAGE and first["grab_focus"]
    assert (first["name"], first["width"], first["height"], first["channels"]) == (str(out), W, H, ["R", "G", "B"])
    updates = tev.packets[1:]
    assert all(p["type"] == UPDATE_IMAGE_V3 and p["name"] == str(out) and not p["grab_focus"] for p in updates)
    assert all(p["channels"] == ["R", "G", "B"] for p in updates)
    # Whole images, each in the same tiles.
    assert {(p["x"], p["y"], p["width"], p["height"]) for p in updates} == TILES
    assert len(updates) % len(TILES) == 0
    images = tev.images()
    # Updates during the render (its first pass at least), then the final image: the earlier ones hold
    # fewer samples, so they differ from it.
    assert len(images) >= 2, len(images)
    assert not np.array_equal(images[0], images[-1])
    np.testing.assert_array_equal(images[-1], read_exr(out))
    # The display only reads: the file is the one a render without it writes, to the bit.
    assert out.read_bytes() == reference.read_bytes()


def test_localhost_names_resolve(neepp_bin, tmp_path, reference):
    # "localhost" may resolve to ::1 first, where the fake tev is not: the next address is tried.
    tev = FakeTev()
    out = tmp_path / "by_name.exr"
    try:
        r, _ = render(neepp_bin, out, "--display-server", f"localhost:{tev.port}")
    finally:
        tev.stop()
    assert r.returncode == 0 and "warning" not in r.stderr, r.stderr
    np.testing.assert_array_equal(tev.images()[-1], read_exr(out))


def test_no_viewer_is_a_warning_and_the_same_image(neepp_bin, tmp_path, reference):
    out = tmp_path / "absent.exr"
    r, seconds = render(neepp_bin, out, "--display-server", f"127.0.0.1:{free_port()}")
    assert r.returncode == 0, r.stderr
    warnings = [line for line in r.stderr.splitlines() if "warning" in line]
    assert len(warnings) == 1 and "cannot connect to the display server 127.0.0.1:" in warnings[0], r.stderr
    assert out.read_bytes() == reference.read_bytes()
    assert seconds < 20


def test_a_viewer_that_hangs_up_mid_render_costs_neither_the_render_nor_its_image(neepp_bin, tmp_path, reference):
    tev = FakeTev(hang_up_after=2)  # the image created and its first tile, then gone (tev quit)
    out = tmp_path / "hung_up.exr"
    try:
        r, seconds = render(neepp_bin, out, "--display-server", f"127.0.0.1:{tev.port}", timeout=30)
    finally:
        tev.stop()
    assert r.returncode == 0, r.stderr
    assert len(tev.packets) == 2 and tev.connections == 1
    warnings = [line for line in r.stderr.splitlines() if "warning" in line]
    assert len(warnings) == 1 and "lost the display server" in warnings[0], r.stderr
    assert out.read_bytes() == reference.read_bytes()
    assert seconds < 20


@pytest.mark.parametrize("address, expect", [
    ("localhost", "no port"),
    ("localhost:", "no port"),
    (":14158", "no host"),
    ("localhost:0", "not in 1..65535"),
    ("localhost:70000", "not in 1..65535"),
    ("localhost:tev", "not a number"),
    ("::1:14158", "brackets"),
])
def test_a_bad_address_is_refused_before_rendering(neepp_bin, tmp_path, address, expect):
    out = tmp_path / "never.exr"
    r, _ = render(neepp_bin, out, "--display-server", address, timeout=30)
    assert r.returncode != 0 and r.returncode < 128, r.stderr
    assert "--display-server" in r.stderr and expect in r.stderr, r.stderr
    assert not out.exists()


def test_help_names_the_option(neepp_bin):
    r = subprocess.run([str(neepp_bin), "render", "--help"], capture_output=True, text=True, timeout=30)
    assert "--display-server" in r.stdout and "tev" in r.stdout, r.stdout
