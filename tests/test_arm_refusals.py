"""A refused arm move says why (sim/arms.py): a straight line or a pose the arm cannot reach ("no inverse
kinematics at (x, y, z), d cm into the line"), or a posture that would come within the collision margin
of a fixed thing or the other arm, which is named. Before, a back-off that left the arm's reach was
refused as "the arm would run into a fixed thing or the other arm", though nothing was in the way.
Checked on the kinematics copies of two arms and a box or two: nothing is stepped, no world is built."""

from __future__ import annotations

import math
import re
from collections.abc import Iterator

import pytest

from cbrs.sim import skills
from cbrs.sim.arms import COLLISION_MARGIN, HOME_CONFIGURATIONS, ArmSide, Kinematics, PlannedArm
from cbrs.sim.geometry import Quat, Region, Vec3

LEFT, RIGHT = ArmSide.LEFT, ArmSide.RIGHT
MOUNTS = {LEFT: ((0.0, 0.2, 0.8), (0.0, 0.0, 0.0, 1.0)), RIGHT: ((0.0, -0.2, 0.8), (0.0, 0.0, 0.0, 1.0))}
DOWN: Quat = (1.0, 0.0, 0.0, 0.0)  # the hand pointing down
TARGET: Vec3 = (0.45, 0.25, 0.95)  # in front of the left arm
OTHERS = {RIGHT: HOME_CONFIGURATIONS[RIGHT]}
WALL = Region("Wall", 0.38, 0.52, 0.40, 0.42, 0.85, 1.05)  # beside the target, across a move along y
BLOCK = Region("Block", 0.3, 0.6, 0.1, 0.4, 0.8, 0.94)  # just under the hand at the target
MARGIN = f"within {COLLISION_MARGIN * 100:.0f} cm of"
POINT = r"\(([-\d.]+), ([-\d.]+), ([-\d.]+)\)"


@pytest.fixture(scope="module")
def free() -> Iterator[Kinematics]:
    k = Kinematics(MOUNTS)
    yield k
    k.close()


@pytest.fixture(scope="module")
def walled() -> Iterator[Kinematics]:
    k = Kinematics(MOUNTS, obstacles=[WALL, BLOCK])
    yield k
    k.close()


def _at_target(kinematics: Kinematics) -> tuple[float, ...]:
    solution = kinematics.solve(LEFT, TARGET, DOWN, [HOME_CONFIGURATIONS[LEFT]])
    assert solution.position_error < 1e-3
    return solution.q


def _point(text: str, after: str) -> Vec3:
    found = re.search(re.escape(after) + " " + POINT, text)
    assert found is not None, text
    return (float(found[1]), float(found[2]), float(found[3]))


def test_a_line_out_of_reach_says_where_it_has_no_inverse_kinematics_and_how_far_in(free: Kinematics) -> None:
    q = _at_target(free)
    far = (1.2, TARGET[1], TARGET[2])  # 75 cm straight out: past the arm's reach
    why = free.line_blocked(LEFT, q, OTHERS, far, DOWN)
    assert why.startswith("no inverse kinematics at (") and "cm into the 75.0 cm line to (1.200, 0.250, 0.950)" in why
    stuck = _point(why, "no inverse kinematics at")
    found = re.search(r", ([\d.]+) cm into", why)
    assert found is not None
    into = float(found[1])
    assert into == pytest.approx(math.dist(TARGET, stuck) * 100, abs=0.2)
    assert 0 < into < 75
    assert "would come within" not in why and "run into" not in why  # nothing was hit
    assert free.line_blocked(LEFT, q, OTHERS, (TARGET[0], TARGET[1], 1.1), DOWN) == ""  # straight up: clear


def test_a_turn_past_the_wrists_limit_says_how_far_it_turned(free: Kinematics) -> None:
    q = _at_target(free)
    half = -2.5 / 2  # DOWN turned 2.5 rad about the vertical, the way the last joint runs out of range
    turned = (math.cos(half), math.sin(half), 0.0, 0.0)
    why = free.line(LEFT, q, TARGET, turned)
    assert isinstance(why, str)
    assert why.startswith("no inverse kinematics at (0.450, 0.250, 0.950), ")
    assert re.search(r", [\d.]+ rad into the hand's 2\.50 rad turn to ", why), why


def test_a_line_into_a_fixed_thing_names_it(walled: Kinematics) -> None:
    q = _at_target(walled)
    assert walled.hits(LEFT, q, OTHERS) == "the Block"  # where it starts: the fingers over the block
    why = walled.line_blocked(LEFT, q, OTHERS, (TARGET[0], 0.55, TARGET[2]), DOWN)
    assert why.startswith(f"the arm would come within {COLLISION_MARGIN * 100:.0f} cm of the Wall with the hand at (")
    assert "cm into the 30.0 cm line to (0.450, 0.550, 0.950)" in why
    assert _point(why, "with the hand at")[1] < WALL.ymin  # before it gets there
    # what it started within the margin of does not count: it lifts off the block, and the way up is clear
    assert walled.line_blocked(LEFT, q, OTHERS, (TARGET[0], TARGET[1], 1.1), DOWN) == ""


def test_the_other_arm_is_named(free: Kinematics) -> None:
    meet = (0.45, 0.0, 0.95)  # both hands at the same point
    right = free.solve(RIGHT, meet, DOWN, [HOME_CONFIGURATIONS[RIGHT]])
    left = free.solve(LEFT, meet, DOWN, [HOME_CONFIGURATIONS[LEFT]])
    assert free.hits(LEFT, left.q, {RIGHT: right.q}) == "the right arm"
    assert free.hits(LEFT, left.q, OTHERS) == ""


def test_a_joint_path_refusal_tells_an_unreachable_pose_from_a_blocked_path(
    free: Kinematics, walled: Kinematics
) -> None:
    home = HOME_CONFIGURATIONS[LEFT]
    beyond = PlannedArm(LEFT, free, home, OTHERS).reach((1.5, 0.2, 0.9), DOWN, symmetric=False)
    assert not beyond.reached
    assert beyond.reason.startswith("no inverse kinematics at (1.500, 0.200, 0.900) from any seed posture")
    blocked = PlannedArm(LEFT, walled, home, OTHERS).reach(TARGET, DOWN, symmetric=False)
    assert not blocked.reached
    assert blocked.reason.startswith(
        "no collision-free joint path to (0.450, 0.250, 0.950): the path to the nearest posture there would come "
        f"{MARGIN} the Block (the hand at ("
    )
    high = PlannedArm(LEFT, free, home, OTHERS).reach(TARGET, DOWN, symmetric=False, min_height=1.5)
    assert re.match(
        r"no collision-free joint path to \(0\.450, 0\.250, 0\.950\) above 1\.50 m: the path to the nearest posture "
        r"there would take the hand down to 1\.\d+ m",
        high.reason,
    ), high.reason
    assert PlannedArm(LEFT, free, home, OTHERS).reach(TARGET, DOWN, symmetric=False).reached  # with nothing in the way


def test_a_back_off_says_what_it_would_hit(walled: Kinematics) -> None:
    """skills._clear_way, the put-down's check of its way back, on a dry run: the hand lifts off the block
    it let go on and backs off along y into the wall."""
    planned = PlannedArm(LEFT, walled, _at_target(walled), OTHERS)
    why = skills._clear_way(planned, [(TARGET[0], 0.55, TARGET[2])], DOWN)
    assert f"{MARGIN} the Wall" in why and "run into a fixed thing or the other arm" not in why
    assert skills._clear_way(planned, [(TARGET[0], TARGET[1], 1.1)], DOWN) == ""  # straight up: clear
