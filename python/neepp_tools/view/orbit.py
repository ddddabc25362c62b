"""The viewer's camera: a position looking at a target, turned about a fixed world up, as a person moves
it with the mouse and keys. It starts from the scene's camera and gives the camera's to_world back (the
renderer's convention: camera space looks down +z, +y up, +x toward the left of the image)."""
from __future__ import annotations

import math

import numpy as np

# How far the eye may turn toward the up axis: at the pole the view's left is undefined.
MIN_POLE_ANGLE = math.radians(1.0)
MIN_FOV, MAX_FOV = 1.0, 150.0


def _normalize(v: np.ndarray) -> np.ndarray:
    n = float(np.linalg.norm(v))
    if not n > 0:
        raise ValueError("zero vector")
    return v / n


def _rotate(v: np.ndarray, axis: np.ndarray, angle: float) -> np.ndarray:
    """v turned by angle (radians) about the unit axis (Rodrigues)."""
    c, s = math.cos(angle), math.sin(angle)
    return v * c + np.cross(axis, v) * s + axis * float(np.dot(axis, v)) * (1 - c)


def _world_up(camera_up: np.ndarray) -> np.ndarray:
    """The coordinate axis nearest the camera's up: scenes are y-up or z-up, and a camera that looks down
    a little should orbit about the scene's vertical, not its own tilted up."""
    axis = int(np.argmax(np.abs(camera_up)))
    up = np.zeros(3)
    up[axis] = math.copysign(1.0, camera_up[axis])
    return up


class OrbitCamera:
    def __init__(self, to_world, fov: float, bounds):
        m = np.asarray(to_world, dtype=np.float64)
        if m.shape != (4, 4) or not np.all(np.isfinite(m)):
            raise ValueError("to_world must be a finite 4x4 matrix")
        lo, hi = (np.asarray(b, dtype=np.float64) for b in bounds)
        # Moves are in units of the scene's size: a step means the same in a room and in a city.
        self.scale = float(np.linalg.norm(hi - lo)) or 1.0
        # A mirrored camera (a to_world that flips x, as some exporters write) stays mirrored.
        self.mirrored = float(np.linalg.det(m[:3, :3])) < 0
        position = m[:3, 3].copy()
        forward = _normalize(m[:3, 2])
        self.up = _world_up(m[:3, 1])
        if abs(float(np.dot(forward, self.up))) > math.cos(MIN_POLE_ANGLE):  # looking straight down or up
            self.up = _normalize(m[:3, 1])
        # The point orbited about: on the view axis, as far as the scene's centre is along it (the scene's
        # lookat target is not kept), and never closer than a tenth of the scene.
        centre = 0.5 * (lo + hi)
        distance = max(float(np.dot(centre - position, forward)), 0.1 * self.scale)
        self.position, self.target, self.fov = position, position + forward * distance, float(fov)
        self._home = (self.position.copy(), self.target.copy(), self.fov)

    @property
    def distance(self) -> float:
        return float(np.linalg.norm(self.target - self.position))

    def _axes(self):
        forward = _normalize(self.target - self.position)
        left = _normalize(np.cross(self.up, forward))
        return forward, left, np.cross(forward, left)

    def to_world(self) -> list[list[float]]:
        """The camera's 4x4 to_world, as Mitsuba's lookat(position, target, up) makes it."""
        forward, left, up = self._axes()
        if self.mirrored:
            left = -left
        m = np.identity(4)
        m[:3, 0], m[:3, 1], m[:3, 2], m[:3, 3] = left, up, forward, self.position
        return m.tolist()

    def orbit(self, dx: float, dy: float) -> None:
        """Turns the eye about the target: dx radians about the world's up (positive: the scene turns
        right, as under a drag to the right), dy radians up or down (positive: the eye rises), its
        elevation kept short of the poles, where the view would flip over."""
        offset = self.position - self.target
        distance = float(np.linalg.norm(offset))
        height = float(np.dot(offset, self.up)) / distance
        horizontal = _normalize(_rotate(offset - self.up * float(np.dot(offset, self.up)), self.up, -dx))
        limit = math.pi / 2 - MIN_POLE_ANGLE
        elevation = min(limit, max(-limit, math.asin(max(-1.0, min(1.0, height))) + dy))
        self.position = self.target + (horizontal * math.cos(elevation) + self.up * math.sin(elevation)) * distance

    def pan(self, dx: float, dy: float) -> None:
        """Slides eye and target across the view: dx, dy in view heights at the target's distance
        (positive: the scene follows a drag right and down)."""
        _, left, up = self._axes()
        extent = 2 * self.distance * math.tan(math.radians(self.fov) / 2)
        shift = (left * dx + up * dy) * extent
        self.position, self.target = self.position + shift, self.target + shift

    def dolly(self, amount: float) -> None:
        """Moves the eye toward the target (amount > 0) or away, by a factor exp(amount) of its distance."""
        distance = max(self.distance * math.exp(-amount), 1e-4 * self.scale)
        self.position = self.target - _normalize(self.target - self.position) * distance

    def move(self, forward: float, right: float, up: float) -> None:
        """Moves eye and target together (walking): in hundredths of the scene's size along the view's
        forward, right and the world's up."""
        f, left, _ = self._axes()
        flat = f - self.up * float(np.dot(f, self.up))  # walking stays level
        flat = _normalize(flat) if np.linalg.norm(flat) > 1e-6 else f
        shift = (flat * forward - left * right + self.up * up) * 0.01 * self.scale
        self.position, self.target = self.position + shift, self.target + shift

    def zoom(self, delta: float) -> None:
        """Widens (delta > 0) or narrows the field of view by a factor exp(delta), within 1..150 degrees."""
        self.fov = min(MAX_FOV, max(MIN_FOV, self.fov * math.exp(delta)))

    def reset(self) -> None:
        """Back to the scene's own camera."""
        self.position, self.target, self.fov = self._home[0].copy(), self._home[1].copy(), self._home[2]
