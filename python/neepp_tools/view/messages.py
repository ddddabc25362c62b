"""What the page and the server say to each other over the websocket.

The page sends JSON text, one command per message, each checked here before anything acts on it (a
malformed one is answered with an error and changes nothing):

    {"type": "orbit", "dx": RAD, "dy": RAD}          turn the eye about the target
    {"type": "pan", "dx": F, "dy": F}                slide the view (fractions of its height)
    {"type": "dolly", "amount": F}                   toward the target (> 0) or away
    {"type": "move", "forward": F, "right": F, "up": F}   walk (hundredths of the scene's size)
    {"type": "zoom", "delta": F}                     field of view times exp(delta)
    {"type": "reset"}                                the scene's own camera
    {"type": "options", "integrator": NAME, "options": {KEY: VALUE}}   switch the integrator's options
    {"type": "save", "exposure": STOPS}              write the image (EXR, PNG at that exposure, JSON)
    {"type": "pick", "x": X, "y": Y}                 the map view from pixel (X, Y) of the full image
    {"type": "reference", "source": "saved" | "none"}   measure the relMSE against the last image saved, or not

The server sends JSON text ({"type": "state" | "error" | "saved", ...}) and binary messages: a
little-endian uint32 n, n bytes of JSON (the header), spaces up to a multiple of 4, then the header's
width x height x channels little-endian float32, row by row from the top. A frame's header holds its
statistics and its pixels are linear RGB (channels absent: 3); a map view's header has "kind": "map" (the
clicked point, its cell, its light distribution) and one channel, Ṽ per pixel (NaN where unknown; width
and height 0 without a map); the reference's has "kind": "reference" and RGB (width and height 0: none).
"""
from __future__ import annotations

import json
import math
import struct

MAX_MESSAGE_BYTES = 16 * 1024

# Each camera command: its numbers and the largest magnitude each may have (a drag across the whole
# view is a turn of about pi; more is a broken or hostile page).
CAMERA_COMMANDS = {
    "orbit": {"dx": 2 * math.pi, "dy": 2 * math.pi},
    "pan": {"dx": 10.0, "dy": 10.0},
    "dolly": {"amount": 5.0},
    "move": {"forward": 100.0, "right": 100.0, "up": 100.0},
    "zoom": {"delta": 3.0},
    "reset": {},
}
MAX_OPTIONS = 32
MAX_PIXEL = 1 << 16
MAX_TEXT = 200


class BadMessage(ValueError):
    """A message the server refuses; its text is sent back to the page."""


def _number(msg: dict, key: str, limit: float) -> float:
    v = msg.get(key)
    if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
        raise BadMessage(f"'{msg['type']}' needs a finite number '{key}'")
    if abs(v) > limit:
        raise BadMessage(f"'{msg['type']}': '{key}' = {v} is out of range (at most {limit:g} in magnitude)")
    return float(v)


def _pixel(msg: dict, key: str) -> int:
    v = msg.get(key)
    if isinstance(v, bool) or not isinstance(v, int) or not 0 <= v <= MAX_PIXEL:
        raise BadMessage(f"'{msg['type']}' needs a pixel index '{key}' (an integer, 0 to {MAX_PIXEL})")
    return v


def _text(v, what: str) -> str:
    if not isinstance(v, str) or not v or len(v) > MAX_TEXT or any(c in v for c in "\0\n\r"):
        raise BadMessage(f"{what} must be a short non-empty string")
    return v


def parse(text) -> dict:
    """The command a text message holds, its numbers and names checked; raises BadMessage otherwise."""
    if not isinstance(text, str):
        raise BadMessage("messages are JSON text")
    if len(text) > MAX_MESSAGE_BYTES:
        raise BadMessage("message too long")
    try:
        msg = json.loads(text)
    except (ValueError, RecursionError):  # RecursionError: nested deeper than the parser goes
        raise BadMessage("not JSON") from None
    if not isinstance(msg, dict) or not isinstance(msg.get("type"), str):
        raise BadMessage("a message is a JSON object with a 'type'")
    kind = msg["type"]
    if kind in CAMERA_COMMANDS:
        return {"type": kind, **{k: _number(msg, k, lim) for k, lim in CAMERA_COMMANDS[kind].items()}}
    if kind == "options":
        options = msg.get("options", {})
        if not isinstance(options, dict) or len(options) > MAX_OPTIONS:
            raise BadMessage("'options' needs an object of at most 32 key: value strings")
        return {"type": "options", "integrator": _text(msg.get("integrator"), "'integrator'"),
                "options": {_text(k, "an option's name"): _text(v, f"option '{k}'") for k, v in options.items()}}
    if kind == "pick":
        return {"type": "pick", "x": _pixel(msg, "x"), "y": _pixel(msg, "y")}
    if kind == "reference":
        source = msg.get("source")
        if source not in ("saved", "none"):
            raise BadMessage("'reference' needs a 'source': 'saved' or 'none'")
        return {"type": "reference", "source": source}
    if kind == "save":
        return {"type": "save", "exposure": _number(msg, "exposure", 64.0) if "exposure" in msg else 0.0}
    raise BadMessage(f"unknown message type '{kind[:40]}'")


def encode_frame(header: dict, pixels: bytes) -> bytes:
    """A binary frame message: the statistics header, then the float32 RGB pixels."""
    head = json.dumps(header, separators=(",", ":")).encode()
    head += b" " * (-(len(head) + 4) % 4)  # JSON ignores trailing spaces; the pixels start 4-aligned
    return struct.pack("<I", len(head)) + head + pixels


def encode_map(result: dict, heat) -> bytes:
    """A map view's binary message: its header (kind "map") and the heat map, one float32 channel."""
    if heat is None:
        return encode_frame({**result, "kind": "map", "width": 0, "height": 0, "channels": 1}, b"")
    h, w = heat.shape
    return encode_frame({**result, "kind": "map", "width": w, "height": h, "channels": 1},
                        heat.astype("<f4", copy=False).tobytes())


def encode_reference(name: str, image) -> bytes:
    """The reference's binary message (kind "reference"): its RGB pixels, or none."""
    if image is None:
        return encode_frame({"kind": "reference", "name": None, "width": 0, "height": 0, "channels": 3}, b"")
    h, w = image.shape[:2]
    return encode_frame({"kind": "reference", "name": name, "width": w, "height": h, "channels": 3},
                        image.astype("<f4", copy=False).tobytes())


def decode_frame(data: bytes):
    """(header, pixel bytes) of a frame message: the page's reading of it, for tests."""
    (n,) = struct.unpack_from("<I", data)
    header = json.loads(data[4:4 + n].decode())
    return header, data[4 + n:]
