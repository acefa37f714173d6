"""What the cameras cost and what they show: the arms' camera-detail meshes, and looks that render only
the cameras they need."""

from __future__ import annotations

import filecmp
from importlib.resources import files
from pathlib import Path

import numpy as np
import pybullet as p
import pytest

from cbrs.sim.arms import PANDA_URDF, ArmDetail, ArmSide, panda_urdf
from cbrs.sim.perceived import PerceivedWorld
from cbrs.sim.world import HomeWorld, open_world

PYBULLET_PANDA = Path(str(files("pybullet_data"))) / "franka_panda"
REDUCED = Path(panda_urdf(ArmDetail.REDUCED)).parent
DECIMATED = {f"link{i}.obj" for i in range(1, 7)}


def test_the_reduced_arm_is_pybullet_datas_arm_but_for_the_decimated_visual_meshes() -> None:
    """Physics reads the URDF and the collision meshes: byte for byte the same files."""
    assert panda_urdf(ArmDetail.FULL) == PANDA_URDF
    same = ["panda.urdf", "LICENSE.txt"]
    same += [f"meshes/collision/{f.name}" for f in (PYBULLET_PANDA / "meshes" / "collision").iterdir()]
    same += [
        f"meshes/visual/{f.name}" for f in (PYBULLET_PANDA / "meshes" / "visual").iterdir() if f.name not in DECIMATED
    ]
    for name in same:
        assert filecmp.cmp(PYBULLET_PANDA / name, REDUCED / name, shallow=False), name
    for name in sorted(DECIMATED):
        full, reduced = PYBULLET_PANDA / "meshes/visual" / name, REDUCED / "meshes/visual" / name
        faces = [sum(line.startswith("f ") for line in path.read_text().splitlines()) for path in (full, reduced)]
        assert faces[1] < faces[0] / 5, name


def _joints(world: HomeWorld) -> list[tuple[float, ...]]:
    arms = [world.arm(side).body for side in ArmSide]
    return [
        tuple(
            s[0]
            for s in p.getJointStates(
                b, range(p.getNumJoints(b, physicsClientId=world.client)), physicsClientId=world.client
            )
        )
        for b in arms
    ]


def test_the_arms_move_exactly_alike_whatever_their_visual_meshes() -> None:
    results = []
    for detail in ArmDetail:
        with open_world(seed=1, arm_detail=detail) as world:
            assert world.arm_detail is detail
            arm = world.arm(ArmSide.RIGHT)
            assert arm.home().reached
            world.step(0.5)
            results.append((_joints(world), world.snapshot()))
    assert results[0] == results[1]


def test_a_camera_that_does_not_see_the_arms_renders_the_same_image_with_either_mesh() -> None:
    frames = []
    for detail in ArmDetail:
        with open_world(seed=0, arm_detail=detail) as world:
            frames.append(world.camera("Kinect01").capture())
    assert np.array_equal(frames[0].rgb, frames[1].rgb)
    assert np.array_equal(frames[0].depth, frames[1].depth)


def test_an_unknown_detail_is_refused_by_name() -> None:
    with pytest.raises(ValueError, match="'coarse'"):
        panda_urdf("coarse")


def test_a_look_for_an_object_renders_only_the_preferred_camera_that_finds_it() -> None:
    with open_world(seed=0) as world:
        belief = PerceivedWorld(world)
        belief.look(["Cup"], people=False)
        assert belief.objects["Cup"].source == "Kinect01"
        assert belief.frames == 1
        assert [world.camera(name).renders for name in sorted(world.cameras)] == [0, 0, 1]


def test_when_the_preferred_camera_does_not_find_the_object_the_others_are_asked() -> None:
    with open_world(seed=0) as world:
        world.fail_camera("Kinect01")
        belief = PerceivedWorld(world)
        belief.look(["Pen"], people=False)
        assert "Pen" not in belief.objects  # from 4.5 m up the pen is a few pixels: too few to tell
        assert {name: world.camera(name).renders for name in world.cameras} == {
            "CeilingCamera01": 1,
            "CeilingCamera02": 1,
            "Kinect01": 0,
        }


def test_a_look_for_people_renders_every_camera_looking_down() -> None:
    with open_world(seed=0) as world:
        belief = PerceivedWorld(world)
        belief.look([], people=True)
        assert "Person" in belief.people
        assert {name: world.camera(name).renders for name in world.cameras} == {
            "CeilingCamera01": 1,
            "CeilingCamera02": 1,
            "Kinect01": 0,
        }


def test_the_floor_is_drawn_last_by_a_body_of_its_own_and_keeps_its_collision_shape_and_colour() -> None:
    with open_world(seed=0) as world:
        c = world.client
        floor = world.body("Floor")
        assert p.getCollisionShapeData(floor, -1, physicsClientId=c)
        (*_, rgba), *_ = [shape[:8] for shape in p.getVisualShapeData(floor, physicsClientId=c)]
        assert rgba[3] == 0.0 and rgba[:3] != (0.0, 0.0, 0.0)  # invisible, its colour still readable
        drawing = p.getBodyUniqueId(p.getNumBodies(physicsClientId=c) - 1, physicsClientId=c)
        assert drawing not in world.bodies.values()
        assert not p.getCollisionShapeData(drawing, -1, physicsClientId=c)
        assert p.getVisualShapeData(drawing, physicsClientId=c)[0][7] == (*rgba[:3], 1.0)
        # below the ceiling camera (4.5 m up, over the living room's bare floor) the floor is drawn
        frame = world.camera("CeilingCamera01").capture()
        assert frame.depth[120, 160] == pytest.approx(4.5, abs=0.01)
        red, green, blue = (int(v) for v in frame.rgb[120, 160])
        assert (
            max(red, green, blue) < 250 and max(red, green, blue) - min(red, green, blue) < 10
        )  # grey, not the white background
