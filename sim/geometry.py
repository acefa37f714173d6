"""Small value types shared by every module: poses, axis-aligned regions and rotation helpers.

Plain tuples and frozen dataclasses, so results can cross into the knowledge base without pybullet.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

__all__ = [
    "Pose2D",
    "Pose3D",
    "Quat",
    "Region",
    "Vec3",
    "quat_from_matrix",
    "quat_from_yaw",
    "quat_to_matrix",
    "wrap_angle",
    "yaw_of",
]

Vec3 = tuple[float, float, float]
Quat = tuple[float, float, float, float]  # x, y, z, w (pybullet's order)


def wrap_angle(angle: float) -> float:
    """The same angle in [-pi, pi), so differences of headings compare as they should."""
    return (angle + math.pi) % (2.0 * math.pi) - math.pi


def quat_from_yaw(yaw: float) -> Quat:
    """A rotation about the vertical axis only."""
    return (0.0, 0.0, math.sin(yaw / 2.0), math.cos(yaw / 2.0))


def quat_to_matrix(q: Quat) -> NDArray[np.float64]:
    """3x3 rotation matrix of a unit quaternion (x, y, z, w)."""
    x, y, z, w = q
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
            [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
            [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
        ],
        dtype=np.float64,
    )


def quat_from_matrix(m: NDArray[np.float64]) -> Quat:
    """Unit quaternion (x, y, z, w) of a rotation matrix (Shepperd's method, stable for every angle)."""
    trace = float(m[0, 0] + m[1, 1] + m[2, 2])
    if trace > 0.0:
        s = math.sqrt(trace + 1.0) * 2.0
        w, x, y, z = 0.25 * s, (m[2, 1] - m[1, 2]) / s, (m[0, 2] - m[2, 0]) / s, (m[1, 0] - m[0, 1]) / s
    elif m[0, 0] > m[1, 1] and m[0, 0] > m[2, 2]:
        s = math.sqrt(1.0 + m[0, 0] - m[1, 1] - m[2, 2]) * 2.0
        w, x, y, z = (m[2, 1] - m[1, 2]) / s, 0.25 * s, (m[0, 1] + m[1, 0]) / s, (m[0, 2] + m[2, 0]) / s
    elif m[1, 1] > m[2, 2]:
        s = math.sqrt(1.0 + m[1, 1] - m[0, 0] - m[2, 2]) * 2.0
        w, x, y, z = (m[0, 2] - m[2, 0]) / s, (m[0, 1] + m[1, 0]) / s, 0.25 * s, (m[1, 2] + m[2, 1]) / s
    else:
        s = math.sqrt(1.0 + m[2, 2] - m[0, 0] - m[1, 1]) * 2.0
        w, x, y, z = (m[1, 0] - m[0, 1]) / s, (m[0, 2] + m[2, 0]) / s, (m[1, 2] + m[2, 1]) / s, 0.25 * s
    return (float(x), float(y), float(z), float(w))


def yaw_of(q: Quat) -> float:
    """Heading (rotation about z) of an orientation, for bodies that stay upright."""
    x, y, z, w = q
    return math.atan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z))


@dataclass(frozen=True)
class Pose2D:
    """A pose on the floor plane: metres and radians in the world frame (the ontology's Position2D)."""

    x: float
    y: float
    theta: float = 0.0

    @property
    def xy(self) -> tuple[float, float]:
        return (self.x, self.y)

    def distance_to(self, x: float, y: float) -> float:
        return math.hypot(self.x - x, self.y - y)

    def heading_error(self, theta: float) -> float:
        """Absolute angle between this heading and ``theta``, in [0, pi]."""
        return abs(wrap_angle(self.theta - theta))


@dataclass(frozen=True)
class Pose3D:
    """A body's position and orientation in the world frame."""

    position: Vec3
    orientation: Quat

    @property
    def yaw(self) -> float:
        return yaw_of(self.orientation)


@dataclass(frozen=True)
class Region:
    """A named axis-aligned box in the world frame; ``zmin`` is the surface things rest on."""

    name: str
    xmin: float
    xmax: float
    ymin: float
    ymax: float
    zmin: float = 0.0
    zmax: float = 0.0

    @property
    def center(self) -> Vec3:
        return ((self.xmin + self.xmax) / 2.0, (self.ymin + self.ymax) / 2.0, self.zmin)

    @property
    def size(self) -> tuple[float, float]:
        return (self.xmax - self.xmin, self.ymax - self.ymin)

    def contains_xy(self, x: float, y: float, margin: float = 0.0) -> bool:
        """Whether (x, y) is inside the footprint grown by ``margin`` (negative shrinks it)."""
        return self.xmin - margin <= x <= self.xmax + margin and self.ymin - margin <= y <= self.ymax + margin
