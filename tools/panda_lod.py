"""Make the Panda arm's camera-detail visual meshes (``sim/meshes/panda_lod/``) from pybullet_data's.

Run: python tools/panda_lod.py [--keep 0.1] [--whole hand,finger] [--out sim/meshes/panda_lod]
     python tools/panda_lod.py --compare docs/arm-detail.png   (the two arms side by side, full | reduced)

The TINY renderer draws every triangle of every visual mesh at every render, whatever the image size:
pybullet_data's Panda has about 102,000 visual triangles an arm, which cost about 35 ms of a 50-70 ms
camera frame. This writes a copy of the arm whose visual meshes keep ``--keep`` of the triangles of
each part (each material of each mesh decimated on its own, so colours stay where they were), with
the URDF, the collision meshes, the materials and the texture copied unchanged, so that physics and
inverse kinematics see the very same arm. It is run offline, once per pybullet_data release; the
output is committed (``sim/meshes/panda_lod/README.md``), so cbrs needs no decimation library.

Decimation is fast-simplification's quadric edge collapse (``pip install fast-simplification``, MIT);
each new vertex takes the texture coordinate of the nearest original vertex of its part, and normals
are smoothed across edges sharper than 40 degrees only (the originals are mostly flat-shaded
machined parts).
"""

from __future__ import annotations

import argparse
import hashlib
import shutil
from dataclasses import dataclass, field
from importlib.resources import files
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

SOURCE = Path(str(files("pybullet_data"))) / "franka_panda"
OUT = Path(__file__).resolve().parent.parent / "sim" / "meshes" / "panda_lod"
SMOOTH_ANGLE = 40.0
"""Degrees: adjacent faces further apart than this keep a hard edge between them."""
MIN_FACES = 60
"""Parts with fewer triangles than this are kept whole (a finger pad, a screw head)."""


@dataclass
class Part:
    """The faces of one material of one OBJ object: corners as (vertex, uv) index pairs."""

    name: str
    material: str
    corners: list[tuple[int, int]] = field(default_factory=list)


@dataclass
class Obj:
    mtllib: str
    vertices: NDArray[np.float64]
    uvs: NDArray[np.float64]
    parts: list[Part]


def read_obj(path: Path) -> Obj:
    vertices: list[list[float]] = []
    uvs: list[list[float]] = []
    parts: list[Part] = []
    mtllib, name = "", path.stem
    for line in path.read_text(encoding="utf-8").splitlines():
        words = line.split()
        if not words:
            continue
        if words[0] == "mtllib":
            mtllib = words[1]
        elif words[0] == "o":
            name = words[1]
        elif words[0] == "usemtl":
            parts.append(Part(name, words[1]))
        elif words[0] == "v":
            vertices.append([float(w) for w in words[1:4]])
        elif words[0] == "vt":
            uvs.append([float(w) for w in words[1:3]])
        elif words[0] == "f":
            if not parts:
                parts.append(Part(name, ""))
            refs = [w.split("/") for w in words[1:]]
            corners = [(int(r[0]) - 1, int(r[1]) - 1 if len(r) > 1 and r[1] else -1) for r in refs]
            for i in range(1, len(corners) - 1):  # a fan of triangles
                parts[-1].corners += [corners[0], corners[i], corners[i + 1]]
    return Obj(mtllib, np.array(vertices), np.array(uvs) if uvs else np.zeros((0, 2)), parts)


def face_normals(points: NDArray[np.float64], faces: NDArray[np.int64]) -> NDArray[np.float64]:
    """Each face's normal scaled by twice its area."""
    a, b, c = points[faces[:, 0]], points[faces[:, 1]], points[faces[:, 2]]
    normals: NDArray[np.float64] = np.cross(b - a, c - a)
    return normals


def corner_normals(points: NDArray[np.float64], faces: NDArray[np.int64]) -> NDArray[np.float64]:
    """A unit normal per face corner: the area-weighted mean of the vertex's faces within SMOOTH_ANGLE."""
    weighted = face_normals(points, faces)
    unit = weighted / np.maximum(np.linalg.norm(weighted, axis=1, keepdims=True), 1e-12)
    around: dict[int, list[int]] = {}
    for f, face in enumerate(faces):
        for v in face:
            around.setdefault(int(v), []).append(f)
    limit = np.cos(np.radians(SMOOTH_ANGLE))
    result = np.zeros((len(faces), 3, 3))
    for f, face in enumerate(faces):
        for k, v in enumerate(face):
            near = np.array(around[int(v)])
            close = near[unit[near] @ unit[f] >= limit]
            total = weighted[close].sum(axis=0)
            result[f, k] = total / max(float(np.linalg.norm(total)), 1e-12)
    return result.reshape(-1, 3)


def decimate(obj: Obj, part: Part, keep: float) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.int64]]:
    """The part's points, their texture coordinates and its triangles, with about ``keep`` of the triangles."""
    import fast_simplification  # offline only: cbrs itself does not need it

    corners = np.array(part.corners)
    used, local = np.unique(corners[:, 0], return_inverse=True)
    points = obj.vertices[used]
    faces = local.reshape(-1, 3).astype(np.int64)
    uv_of = np.zeros((len(used), 2))
    if len(obj.uvs):
        uv_of[local] = obj.uvs[corners[:, 1]]
    if len(faces) >= MIN_FACES:
        new_points, new_faces = fast_simplification.simplify(points, faces, target_reduction=1.0 - keep)
        # nearest original vertex of the part, for the texture coordinate
        nearest = np.array(
            [int(np.argmin(((points - q) ** 2).sum(axis=1))) for q in np.asarray(new_points, dtype=np.float64)]
        )
        return np.asarray(new_points, dtype=np.float64), uv_of[nearest], np.asarray(new_faces, dtype=np.int64)
    return points, uv_of, faces


def write_obj(obj: Obj, keep: float, target: Path, source: Path) -> int:
    """Write the decimated OBJ (each part its own object, material, points, texture coordinates and a
    normal per corner); returns its number of triangles."""
    lines = [
        f"# {source.name} of pybullet_data's franka_panda (Apache-2.0), decimated to about {keep:g} of its",
        "# triangles per part by tools/panda_lod.py (fast-simplification), for camera images.",
        f"mtllib {obj.mtllib}",
    ]
    points_before = normals_before = triangles = 0
    for part in obj.parts:
        points, uvs, faces = decimate(obj, part, keep)
        normals, normal_of = np.unique(np.round(corner_normals(points, faces), 4), axis=0, return_inverse=True)
        normal_of = normal_of.reshape(-1, 3)
        lines.append(f"o {part.name}")
        lines += [f"v {x:.6f} {y:.6f} {z:.6f}" for x, y, z in points]
        lines += [f"vt {u:.6f} {v:.6f}" for u, v in uvs]
        lines += [f"vn {x:.4f} {y:.4f} {z:.4f}" for x, y, z in normals + 0.0]  # + 0.0: no "-0.0000"
        if part.material:
            lines.append(f"usemtl {part.material}")
        lines.append("s off")
        for f, face in enumerate(faces):
            refs = [
                f"{points_before + v + 1}/{points_before + v + 1}/{normals_before + normal_of[f, k] + 1}"
                for k, v in enumerate(face)
            ]
            lines.append("f " + " ".join(refs))
        points_before += len(points)
        normals_before += len(normals)
        triangles += len(faces)
    target.write_text("\n".join(lines) + "\n", encoding="utf-8")
    return triangles


def compare(target: Path) -> None:
    """Save a 640 x 480 close-up of the dual-arm robot drawn with each ``ArmDetail``, side by side."""
    import pybullet as p
    from PIL import Image

    from cbrs.sim.arms import ArmDetail
    from cbrs.sim.cameras import render
    from cbrs.sim.world import open_world

    images = []
    for detail in (ArmDetail.FULL, ArmDetail.REDUCED):
        with open_world(seed=0, arm_detail=detail) as world:
            view = p.computeViewMatrix((7.75, 1.6, 1.5), (7.75, 2.6, 0.9), (0.0, 0.0, 1.0))
            projection = p.computeProjectionMatrixFOV(45.0, 640 / 480, 0.1, 10.0)
            rgba, _ = render(world.client, 640, 480, view, projection)
            images.append(np.reshape(np.asarray(rgba, dtype=np.uint8), (480, 640, 4))[:, :, :3])
    Image.fromarray(np.concatenate(images, axis=1)).save(target)
    print(f"written to {target}: {ArmDetail.FULL.value} | {ArmDetail.REDUCED.value}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--keep", type=float, default=0.1, help="fraction of each part's triangles kept")
    parser.add_argument(
        "--whole",
        default="hand,finger",
        help="meshes kept whole (comma-separated stems): the parts that reach into view",
    )
    parser.add_argument("--out", type=Path, default=OUT)
    parser.add_argument("--compare", type=Path, metavar="PNG", help="only draw the arms both ways into PNG")
    args = parser.parse_args()
    if args.compare is not None:
        compare(args.compare)
        return
    out: Path = args.out
    (out / "meshes" / "visual").mkdir(parents=True, exist_ok=True)
    (out / "meshes" / "collision").mkdir(parents=True, exist_ok=True)
    shutil.copyfile(SOURCE / "panda.urdf", out / "panda.urdf")
    shutil.copyfile(SOURCE / "LICENSE.txt", out / "LICENSE.txt")
    for path in sorted((SOURCE / "meshes" / "collision").iterdir()):
        shutil.copyfile(path, out / "meshes" / "collision" / path.name)
    total_before = total_after = 0
    for path in sorted((SOURCE / "meshes" / "visual").iterdir()):
        target = out / "meshes" / "visual" / path.name
        if path.suffix != ".obj":
            shutil.copyfile(path, target)
            continue
        obj = read_obj(path)
        before = sum(len(part.corners) // 3 for part in obj.parts)
        if path.stem in args.whole.split(","):
            shutil.copyfile(path, target)  # the very same mesh: the same pixels wherever it is seen
            after = before
        else:
            after = write_obj(obj, args.keep, target, path)
        total_before += before
        total_after += after
        digest = hashlib.sha256(path.read_bytes()).hexdigest()[:12]
        print(f"{path.name:12s} {before:>7} -> {after:>6} triangles (source sha256 {digest})")
    print(f"visual meshes: {total_before} -> {total_after} triangles an arm; written to {out}")


if __name__ == "__main__":
    main()
