"""The dual-arm robot's arms: two Franka Panda arms (pybullet_data) on a fixed torso.

Inverse kinematics runs on copies of the arms in a private pybullet client (``Kinematics``), so a
solution can be seeded with any joint angles and checked by forward kinematics without touching the
simulated arms. Cartesian motions are cut into 1 cm pieces and solved in a chain before the arm
moves: if a piece has no solution the motion is refused and the arm stays where it is. The joint
position controllers then track the chain while the world steps; every motion is bounded in
simulated time and reports whether it reached its target.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass
from enum import StrEnum
from importlib.resources import files

import numpy as np
import pybullet as p
from numpy.typing import NDArray

from cbrs.kb.hands import PANDA_HAND, Hand
from cbrs.sim.geometry import Pose3D, Quat, Region, Vec3, quat_from_matrix, quat_to_matrix
from cbrs.sim.grasping import GraspPose
from cbrs.sim.quiet import quiet_output

__all__ = [
    "ARM_JOINTS",
    "CARRY_CLEARANCE",
    "EE_LINK",
    "HOME_CONFIGURATIONS",
    "MEET_MARGIN",
    "REACH_TOLERANCE",
    "Arm",
    "ArmDetail",
    "ArmSide",
    "Kinematics",
    "MotionResult",
    "PlannedArm",
    "panda_urdf",
]


class ArmSide(StrEnum):
    LEFT = "left"
    RIGHT = "right"


PYBULLET_DATA = str(files("pybullet_data"))
"""Where pybullet_data's models are (the Panda arm)."""
PANDA_URDF = "franka_panda/panda.urdf"


class ArmDetail(StrEnum):
    """Which visual meshes the arms are drawn with; physics is the same for both (same URDF, same
    collision meshes, same inertias).

    * ``reduced``: ``sim/meshes/panda_lod``, about 10,500 triangles an arm, decimated offline from
      pybullet_data's meshes by ``tools/panda_lod.py``; a camera frame takes 20-40 ms instead of 50-75.
    * ``full``: pybullet_data's own, about 102,000 triangles an arm (smoother in close-ups).
    """

    REDUCED = "reduced"
    FULL = "full"


def panda_urdf(detail: ArmDetail | str = ArmDetail.REDUCED) -> str:
    """The Panda arm's URDF for a level of visual detail: an absolute path, or pybullet_data's name."""
    if ArmDetail(detail) is ArmDetail.FULL:
        return PANDA_URDF
    return str(files("cbrs.sim") / "meshes" / "panda_lod" / "panda.urdf")


ARM_JOINTS = (0, 1, 2, 3, 4, 5, 6)
FINGER_JOINTS = (9, 10)
EE_LINK = 11
"""panda_grasptarget: the point between the fingertips."""
_MAX_FORCES = (87.0, 87.0, 87.0, 87.0, 12.0, 12.0, 12.0)
_POSITION_GAINS = (0.3,) * 7
"""Stiffer than pybullet's default (0.1), which lets the raised home posture sag by 2 degrees."""
_LOWER = np.array([-2.9671, -1.8326, -2.9671, -3.1416, -2.9671, -0.0873, -2.9671])
_UPPER = np.array([2.9671, 1.8326, 2.9671, 0.0, 2.9671, 3.8223, 2.9671])

HOME_CONFIGURATIONS: dict[ArmSide, tuple[float, ...]] = {
    # Raised and turned outwards: clear of the table, of the Kinect's view, of each other, and of
    # the ceiling cameras' view of a base parked at the hand-over pose.
    ArmSide.LEFT: (0.9, 0.0, 0.0, -0.5, 0.0, 1.0, 0.785),
    ArmSide.RIGHT: (-0.9, 0.0, 0.0, -0.5, 0.0, 1.0, 0.785),
}
_SEEDS: tuple[tuple[float, ...], ...] = (
    # Postures to start the inverse kinematics from when the arm jumps to a new target: facing the
    # table, turned either way, with the hand down, pitched or level.
    (0.0, -0.3, 0.0, -2.2, 0.0, 2.0, 0.785),
    (0.0, 0.1, 0.0, -2.0, 0.0, 0.6, 0.785),
    (0.0, 0.1, 0.0, -2.0, 0.0, 0.6, -0.785),
    (0.0, 0.1, 0.0, -2.0, 0.0, 0.6, 2.356),
    (0.0, -0.5, 0.0, -2.5, 0.0, 2.0, -0.785),
    (0.5, -0.5, 0.0, -2.5, 0.0, 2.0, 0.785),
    (-0.5, -0.5, 0.0, -2.5, 0.0, 2.0, 0.785),
    (0.0, 0.3, 0.0, -1.8, 0.0, 2.6, 0.785),
)

CARTESIAN_STEP = 0.01
"""Length of each straight-line piece (m)."""
ANGULAR_STEP = 0.05
"""Largest hand rotation per piece (rad)."""
ARM_SPEED = 0.30
"""Hand speed along a straight line (m/s): slow enough for the position controllers to track."""
ARM_TURN_SPEED = 1.0
"""Hand rotation speed (rad/s)."""
JOINT_SPEED = 1.5
"""Fastest joint speed (rad/s) of joint-space moves."""
IK_TOLERANCE = 0.002
"""A piece whose inverse kinematics misses its point by more than 2 mm has no solution."""
REACH_TOLERANCE = 0.01
"""A motion has reached its target when the grasp point is within 1 cm of it."""
SETTLE_LIMIT = 1.0
"""At most this many simulated seconds of settling after the last piece."""
WRIST_SLACK = 0.005
"""How much deeper than it must be the arm's last link is to refuse a pose before solving it
(:meth:`Kinematics.wrist_strikes`): room for the contact query's own error."""
_WRIST_LINK = 6
"""The arm's last link (panda_link7): the hand and the grasp point are fixed to it, so the pose places it."""
_SOLVED_KEPT = 4096
"""At most this many inverse-kinematics answers are kept for asking again (a run asks a few hundred)."""
_BOUNDS_SLACK = 0.01
"""A fixed thing or the other arm whose bounding box is farther than a query's distance and this from the
arm copy's is not asked about (:meth:`Kinematics._near`): no point of it can be within that distance, and
the slack leaves room for the contact query's own error, so the answers are those of asking."""
COLLISION_MARGIN = 0.01
"""Joint-space moves keep the arm's links 1 cm clear of the torso, the table, the dispenser, the
Kinect and the other arm."""
STRIKE_DEPTH = 0.002
"""A pose the hand is asked to hold (:meth:`Arm.can_hold`) is refused when a link other than the
fingers would be more than 2 mm into a fixed thing or the other arm: the hand cannot be there without
pushing it (a top-grasped cup under the dispenser's spout, a jar carried past it)."""
CARRY_CLEARANCE = 0.01
"""A carry's moves planned to choose where an object is set down (:meth:`Arm.dry_run`'s ``clear_by``)
keep the arm, fingers included, this far from the appliances standing on the furniture (a dispenser's
body and spout, and its tap's lever, which the arms' planning does not avoid since a hand pushes it):
the margin the joint-space moves keep from the fixed things (COLLISION_MARGIN)."""
MEET_MARGIN = 0.0
"""A take's moves to the pre-grasp and grasp poses, planned to choose the arm and approach
(:meth:`Arm.dry_run`'s ``meet_by``, ``skills.plan_carry``), are refused where the arm, fingers included,
would touch a fixture (what a carry keeps clear of: a tap's lever, which the arms' planning does not
avoid since a hand pushes it). A right hand reaching for a flask beside the lever met it with a finger
and stopped 4.2 cm short of the pre-grasp pose. Touching, not a margin: a take below a tap's spout comes
within CARRY_CLEARANCE of it and is made (a cup filled there is taken from there)."""


@dataclass(frozen=True)
class MotionResult:
    reached: bool
    error: float
    """Distance between the grasp point and the target at the end (m); inf when refused."""
    reason: str = ""


@dataclass(frozen=True)
class _Solution:
    q: tuple[float, ...]
    position_error: float
    orientation_error: float


def _slerp(a: Quat, b: Quat, t: float) -> Quat:
    qa = np.asarray(a, dtype=np.float64)
    qb = np.asarray(b, dtype=np.float64)
    dot = float(np.dot(qa, qb))
    if dot < 0.0:
        qb, dot = -qb, -dot
    if dot > 0.9995:
        q = qa + t * (qb - qa)
    else:
        theta = math.acos(dot)
        q = (math.sin((1 - t) * theta) * qa + math.sin(t * theta) * qb) / math.sin(theta)
    q /= np.linalg.norm(q)
    return (float(q[0]), float(q[1]), float(q[2]), float(q[3]))


def quat_angle(a: Quat, b: Quat) -> float:
    """Angle of the rotation between two orientations (rad)."""
    dot = abs(float(np.dot(np.asarray(a), np.asarray(b))))
    return 2.0 * math.acos(min(1.0, dot))


def nearer(current: Quat, orientation: Quat) -> Quat:
    """Of a grasp orientation and its half-turn twin, the one nearer the hand's ``current`` orientation."""
    twin = flipped(orientation)
    return twin if quat_angle(current, twin) < quat_angle(current, orientation) else orientation


def flipped(q: Quat) -> Quat:
    """The same grasp with the hand turned half a turn about its approach axis (the jaws are symmetric)."""
    m: NDArray[np.float64] = quat_to_matrix(q) @ np.diag([-1.0, -1.0, 1.0])
    return quat_from_matrix(m)


class Kinematics:
    """Copies of both arms in a private DIRECT client, for inverse and forward kinematics, and boxes
    standing for the fixed things around them (torso, table top, dispenser, Kinect), so that a
    joint-space move can be checked for collisions before the real arm makes it."""

    def __init__(
        self,
        mounts: dict[ArmSide, tuple[Vec3, Quat]],
        obstacles: Sequence[Region] = (),
        fixtures: Sequence[Region] = (),
    ) -> None:
        """``fixtures``: what a carry keeps clear of (:meth:`brushes`), the appliances standing on the
        furniture, some of them (a tap's lever, which a hand pushes) not among ``obstacles``."""
        with quiet_output():
            self.client = p.connect(p.DIRECT)
        try:
            p.setAdditionalSearchPath(PYBULLET_DATA, physicsClientId=self.client)
            self._bodies = {
                # it never renders: without visual shapes an arm loads in a third of the time (the same
                # links, inertia and collision meshes, so the same kinematics and collision checks)
                side: p.loadURDF(
                    panda_urdf(),
                    pos,
                    orn,
                    useFixedBase=True,
                    flags=p.URDF_IGNORE_VISUAL_SHAPES,
                    physicsClientId=self.client,
                )
                for side, (pos, orn) in mounts.items()
            }
            self._obstacles = [self._box(region) for region in obstacles]
            self._names = {body: region.name for body, region in zip(self._obstacles, obstacles, strict=True)}
            self._fixtures = [(region.name, self._box(region)) for region in fixtures]
            self._fixture_regions = list(fixtures)
            self._at: dict[int, tuple[float, ...]] = {}  # where each copy's joints were last put
            # each body's bounding box (the union of its links'), and for a copy the posture it was taken at
            self._bounds: dict[int, tuple[tuple[float, ...] | None, tuple[Vec3, Vec3]]] = {
                body: (None, _aabb(self.client, body, -1)) for body in self._obstacles
            }
            self._links: dict[int, int] = {}  # each copy's number of links, the base aside
            self._solved: dict[tuple[object, ...], _Solution] = {}  # _refine's answers, by their inputs
            self._wrist, self._wrist_at, self._wrist_reach = self._wrist_probe()
            self.hand_reach = self._hand_reach()
            """How far from the grasp point a point of the hand (the links past the arm's last: flange, hand,
            fingers) may be, by their bounding boxes: an upper bound, the same for each arm (one URDF)."""
        except BaseException:
            p.disconnect(physicsClientId=self.client)
            raise
        self._closed = False

    def _wrist_probe(self) -> tuple[int, dict[ArmSide, tuple[Vec3, Quat]], float]:
        """A body of the last link's collision shape alone, where that link sits relative to the grasp
        point on each arm, and how far from the grasp point the link reaches."""
        mesh = str(files("cbrs.sim") / "meshes" / "panda_lod" / "meshes" / "collision" / "link7.obj")
        shape = p.createCollisionShape(p.GEOM_MESH, fileName=mesh, physicsClientId=self.client)
        probe = int(p.createMultiBody(0.0, shape, -1, (0.0, 0.0, 0.0), physicsClientId=self.client))
        offsets: dict[ArmSide, tuple[Vec3, Quat]] = {}
        for side, body in self._bodies.items():
            self._set(body, [0.0] * len(ARM_JOINTS))
            link = p.getLinkState(body, _WRIST_LINK, computeForwardKinematics=True, physicsClientId=self.client)
            ee = p.getLinkState(body, EE_LINK, computeForwardKinematics=True, physicsClientId=self.client)
            pos, orn = p.multiplyTransforms(*p.invertTransform(ee[4], ee[5]), link[4], link[5])
            offsets[side] = ((pos[0], pos[1], pos[2]), (orn[0], orn[1], orn[2], orn[3]))
        reach = 0.0
        for pos, orn in offsets.values():  # the link's bounding box with the grasp point at the origin
            p.resetBasePositionAndOrientation(probe, pos, orn, physicsClientId=self.client)
            low, high = p.getAABB(probe, physicsClientId=self.client)
            corners = [(x, y, z) for x in (low[0], high[0]) for y in (low[1], high[1]) for z in (low[2], high[2])]
            reach = max(reach, *(math.dist(corner, (0.0, 0.0, 0.0)) for corner in corners))
        return probe, offsets, reach

    def _hand_reach(self) -> float:
        """:attr:`hand_reach`: the farthest corner of the hand links' bounding boxes from the grasp point, the
        arm at its zero posture and its fingers open as wide as their joints let them; 0 for a robot with no
        arm (its copies have no body to ask, and no hand comes near a fixture)."""
        body = next(iter(self._bodies.values()), None)
        if body is None:
            return 0.0
        self._set(body, [0.0] * len(ARM_JOINTS))
        for joint in FINGER_JOINTS:
            p.resetJointState(
                body, joint, p.getJointInfo(body, joint, physicsClientId=self.client)[9], physicsClientId=self.client
            )
        ee = p.getLinkState(body, EE_LINK, computeForwardKinematics=True, physicsClientId=self.client)[4]
        reach = 0.0
        for link in range(_WRIST_LINK + 1, EE_LINK):
            low, high = _aabb(self.client, body, link)
            corners = [(x, y, z) for x in (low[0], high[0]) for y in (low[1], high[1]) for z in (low[2], high[2])]
            reach = max(reach, *(math.dist(corner, ee) for corner in corners))
        for joint in FINGER_JOINTS:
            p.resetJointState(body, joint, 0.0, physicsClientId=self.client)
        return reach

    def fixture_near(self, start: Vec3, end: Vec3, reach: float) -> str:
        """The name of the first fixture (``fixtures``) whose box comes within ``reach`` of the straight line
        from ``start`` to ``end`` (followed every centimetre); empty when none does. The map's answer, no
        contact query: whether a hand on that line could touch one at all."""
        steps = max(1, math.ceil(math.dist(start, end) / 0.01))
        points = [tuple(a + (b - a) * i / steps for a, b in zip(start, end, strict=True)) for i in range(steps + 1)]
        for region in self._fixture_regions:
            for x, y, z in points:
                dx = max(region.xmin - x, 0.0, x - region.xmax)
                dy = max(region.ymin - y, 0.0, y - region.ymax)
                dz = max(region.zmin - z, 0.0, z - region.zmax)
                if math.sqrt(dx * dx + dy * dy + dz * dz) <= reach:
                    return region.name
        return ""

    def wrist_strikes(self, side: ArmSide, position: Vec3, orientation: Quat) -> bool:
        """Whether every posture that holds the hand at this pose as closely as a solution must (within
        IK_TOLERANCE and 0.02 rad) pushes the arm's last link more than STRIKE_DEPTH into a fixed thing,
        so that :meth:`Arm.can_hold` may refuse the pose without solving it. The pose places that link
        (the hand is fixed to it), and a posture within the tolerances moves none of its points farther
        than IK_TOLERANCE + 0.02 rad times its reach from the grasp point; the link must be that much
        (and WRIST_SLACK) deeper than STRIKE_DEPTH."""
        pos, orn = p.multiplyTransforms(position, orientation, *self._wrist_at[side])
        p.resetBasePositionAndOrientation(self._wrist, pos, orn, physicsClientId=self.client)
        depth = STRIKE_DEPTH + IK_TOLERANCE + 0.02 * self._wrist_reach + WRIST_SLACK
        for target in self._obstacles:
            for point in p.getClosestPoints(self._wrist, target, 0.0, physicsClientId=self.client):
                if point[8] < -depth:
                    return True
        return False

    def _box(self, region: Region) -> int:
        half = ((region.xmax - region.xmin) / 2, (region.ymax - region.ymin) / 2, (region.zmax - region.zmin) / 2)
        centre = ((region.xmin + region.xmax) / 2, (region.ymin + region.ymax) / 2, (region.zmin + region.zmax) / 2)
        shape = p.createCollisionShape(p.GEOM_BOX, halfExtents=half, physicsClientId=self.client)
        return int(p.createMultiBody(0.0, shape, -1, centre, physicsClientId=self.client))

    def collides(self, side: ArmSide, q: Sequence[float], others: dict[ArmSide, Sequence[float]]) -> bool:
        """Whether the arm at ``q`` comes within COLLISION_MARGIN of a fixed thing or of the other arm
        (set to ``others``). The base links standing on the torso do not count."""
        return bool(self.hits(side, q, others))

    def hits(self, side: ArmSide, q: Sequence[float], others: dict[ArmSide, Sequence[float]]) -> str:
        """What the arm at ``q`` comes within COLLISION_MARGIN of first (:meth:`collides`): the fixed
        thing's name, or the other arm ("the left arm"); empty when it keeps clear of them all."""
        body, targets = self._posed(side, q, others)
        for target in self._near(body, targets, COLLISION_MARGIN):
            for point in p.getClosestPoints(body, target, COLLISION_MARGIN, physicsClientId=self.client):
                if point[3] > 0:
                    return self._name_of(target)
        return ""

    def _name_of(self, target: int) -> str:
        """A fixed thing's name, or "the <side> arm" for an arm's copy."""
        arm = next((side for side, body in self._bodies.items() if body == target), None)
        return f"the {arm.value} arm" if arm is not None else f"the {self._names.get(target, 'fixed thing')}"

    def strikes(self, side: ArmSide, q: Sequence[float], others: dict[ArmSide, Sequence[float]]) -> bool:
        """Whether the arm at ``q``, its fingers aside, is more than STRIKE_DEPTH into a fixed thing or the
        other arm (set to ``others``). Unlike :meth:`collides`, no margin: the fingers may touch the surface
        an object is taken from or set down on, and the hand may come close to what it works by."""
        body, targets = self._posed(side, q, others)
        for target in self._near(body, targets, 0.0):
            for point in p.getClosestPoints(body, target, 0.0, physicsClientId=self.client):
                if point[3] > 0 and point[3] not in FINGER_JOINTS and point[8] < -STRIKE_DEPTH:
                    return True
        return False

    def _posed(
        self, side: ArmSide, q: Sequence[float], others: dict[ArmSide, Sequence[float]]
    ) -> tuple[int, list[int]]:
        """The arm's copy put at ``q`` and the other arm's at its configuration in ``others``: the copy's body
        and what it may run into (the fixed things and the other arm)."""
        body = self._bodies[side]
        self._set(body, q)
        for other, configuration in others.items():
            if other is not side:
                self._set(self._bodies[other], configuration)
        return body, [*self._obstacles, *(b for s, b in self._bodies.items() if s is not side)]

    def _near(self, body: int, targets: list[int], distance: float) -> list[int]:
        """Those of ``targets`` (in their order) whose bounding boxes come within ``distance`` and
        _BOUNDS_SLACK of the copy's: the others have no point within ``distance`` of it (a body's box holds
        its shapes, collision margins included), so a contact query of them would return none. Asking the
        other arm costs a query of 13 links by 13 (about 100 us); the copies' boxes 13 small queries, taken
        once per posture."""
        low, high = self._box_of(body)
        gap = distance + _BOUNDS_SLACK
        near = []
        for target in targets:
            t_low, t_high = self._box_of(target)
            if all(low[i] - gap <= t_high[i] and t_low[i] <= high[i] + gap for i in range(3)):
                near.append(target)
        return near

    def _box_of(self, body: int) -> tuple[Vec3, Vec3]:
        """A body's bounding box: a fixed thing's as built, an arm copy's for the posture it is at (kept
        until it is put elsewhere)."""
        at = self._at.get(body)
        kept = self._bounds.get(body)
        if kept is not None and kept[0] == at:
            return kept[1]
        links = self._links.get(body)
        if links is None:
            links = self._links[body] = p.getNumJoints(body, physicsClientId=self.client)
        boxes = [_aabb(self.client, body, link) for link in range(-1, links)]
        low = (min(b[0][0] for b in boxes), min(b[0][1] for b in boxes), min(b[0][2] for b in boxes))
        high = (max(b[1][0] for b in boxes), max(b[1][1] for b in boxes), max(b[1][2] for b in boxes))
        self._bounds[body] = (at, (low, high))
        return low, high

    def brushes(self, side: ArmSide, q: Sequence[float], margin: float) -> str:
        """The name of the first fixture (``fixtures``) the arm at ``q``, fingers included, comes within
        ``margin`` of; empty when it keeps clear of them all."""
        body = self._bodies[side]
        self._set(body, q)
        near = self._near(body, [target for _, target in self._fixtures], margin)
        for name, target in self._fixtures:
            if target in near and p.getClosestPoints(body, target, margin, physicsClientId=self.client):
                return name
        return ""

    def path_clear(
        self,
        side: ArmSide,
        start: Sequence[float],
        goal: Sequence[float],
        others: dict[ArmSide, Sequence[float]],
        min_height: float | None = None,
    ) -> bool:
        """Whether the straight joint-space path from ``start`` to ``goal`` is free of collisions (and
        keeps the grasp point at or above ``min_height``), checked every 0.05 rad."""
        for q in _joint_samples(start, goal):
            if self.collides(side, q, others):
                return False
            if min_height is not None and self.forward(side, q).position[2] < min_height:
                return False
        return True

    def _path_blocked(
        self,
        side: ArmSide,
        start: Sequence[float],
        goal: Sequence[float],
        others: dict[ArmSide, Sequence[float]],
        min_height: float | None,
    ) -> str:
        """Why :meth:`path_clear` refuses the path: what its first posture that does would run into, or how
        low it would take the hand; empty when it is clear."""
        for q in _joint_samples(start, goal):
            hit = self.hits(side, q, others)
            at = self.forward(side, q).position
            if hit:
                return f"would come within {COLLISION_MARGIN * 100:.0f} cm of {hit} (the hand at {_fmt(at)})"
            if min_height is not None and at[2] < min_height:
                return f"would take the hand down to {at[2]:.3f} m (at {_fmt(at)})"
        return ""

    def line_blocked(
        self,
        side: ArmSide,
        start: Sequence[float],
        others: dict[ArmSide, Sequence[float]],
        position: Vec3,
        orientation: Quat,
        loose: bool = False,
    ) -> str:
        """Why the straight line from the posture ``start`` to the pose (:meth:`line`) would not keep the arm
        clear: no inverse kinematics part-way, or the first of its postures within COLLISION_MARGIN of a fixed
        thing or the other arm, by what and how far into the line; empty when it would. What the arm at
        ``start`` is within the margin of already (the surface the fingers let go on) does not count: the
        line leaves it."""
        begin = self.forward(side, start)
        chain = self.line(side, start, position, orientation, begin, loose)
        if isinstance(chain, str):
            return chain
        touching = self.hits(side, start, others)
        length = math.dist(begin.position, position)
        for q in chain:
            hit = self.hits(side, q, others)
            if hit and hit != touching:
                at = self.forward(side, q).position
                return (
                    f"the arm would come within {COLLISION_MARGIN * 100:.0f} cm of {hit} with the hand at {_fmt(at)}, "
                    f"{math.dist(begin.position, at) * 100:.1f} cm into the {length * 100:.1f} cm line to "
                    f"{_fmt(position)}"
                )
        return ""

    def line_meets_arm(
        self,
        side: ArmSide,
        start: Sequence[float],
        chain: Sequence[Sequence[float]],
        others: dict[ArmSide, Sequence[float]],
        position: Vec3,
    ) -> str:
        """Why the straight line ``chain`` (:meth:`line`, from the posture ``start`` to ``position``) cannot be
        taken: the first of its postures in which the arm, fingers included, touches the other arm (set to
        ``others``), by where the hand is and how far into the line; empty when none does. A straight line is
        planned on the inverse kinematics alone, and the other arm does not give way: the left arm's carry of
        a mug to a relay spot by the torso took its link 3 1.6 cm into the home right arm's link 2 on the
        copies, and the real arm stopped 1.3 cm short there (its dry run had gone round by joint space,
        :meth:`PlannedArm.move_to`). Touching, not a margin: the line is refused only where the arms would
        meet (the joint-space moves, which are planned, keep COLLISION_MARGIN). An arm touching the other at
        ``start`` is not refused: the line may be leaving it."""
        peers = [body for other, body in self._bodies.items() if other is not side]
        if not peers or not chain:
            return ""
        if self._touching(side, start, others, peers) is not None:
            return ""
        begin = self.forward(side, start).position
        for q in chain:
            peer = self._touching(side, q, others, peers)
            if peer is not None:
                at = self.forward(side, q).position
                return (
                    f"the arm would run into {self._name_of(peer)} with the hand at {_fmt(at)}, "
                    f"{math.dist(begin, at) * 100:.1f} cm into the {math.dist(begin, position) * 100:.1f} cm line "
                    f"to {_fmt(position)}"
                )
        return ""

    def _touching(
        self, side: ArmSide, q: Sequence[float], others: dict[ArmSide, Sequence[float]], peers: list[int]
    ) -> int | None:
        """The first of ``peers`` (the other arms' copies) the arm at ``q`` touches, the others at ``others``."""
        body, _ = self._posed(side, q, others)
        return next(
            (
                peer
                for peer in self._near(body, peers, 0.0)
                if p.getClosestPoints(body, peer, 0.0, physicsClientId=self.client)
            ),
            None,
        )

    def close(self) -> None:
        if not self._closed:
            self._closed = True
            p.disconnect(physicsClientId=self.client)

    def _set(self, body: int, q: Sequence[float]) -> None:
        """Put a copy at ``q`` (all joints in one call; nothing to do if it is there already)."""
        values = tuple(q)
        if len(values) != len(ARM_JOINTS):
            raise ValueError(f"expected {len(ARM_JOINTS)} joint angles, got {len(values)}")
        if self._at.get(body) == values:
            return
        p.resetJointStatesMultiDof(
            body,
            ARM_JOINTS,
            [[value] for value in values],
            [[0.0]] * len(ARM_JOINTS),
            physicsClientId=self.client,
        )
        self._at[body] = values

    def forward(self, side: ArmSide, q: Sequence[float]) -> Pose3D:
        body = self._bodies[side]
        self._set(body, q)
        state = p.getLinkState(body, EE_LINK, computeForwardKinematics=True, physicsClientId=self.client)
        pos, orn = state[4], state[5]
        return Pose3D((pos[0], pos[1], pos[2]), (orn[0], orn[1], orn[2], orn[3]))

    def _refine(
        self, side: ArmSide, position: Vec3, orientation: Quat, seed: Sequence[float], loose: bool = False
    ) -> _Solution:
        """Inverse kinematics from ``seed``, called again until the hand is within 0.1 mm and 0.001 rad of
        the pose (at most ten calls); ``loose``: only until it is within what a solution must be
        (IK_TOLERANCE, 0.02 rad), all a check of whether there is one needs. The answer depends on nothing
        but these inputs (each call starts by putting the copy at ``seed``), so one asked again is looked up:
        the same pose is asked from the same seed postures again and again while spots are tried."""
        key = (side, loose, np.asarray([*position, *orientation, *seed], dtype=np.float64).tobytes())  # bit-exact
        known = self._solved.get(key)
        if known is not None:
            return known
        body = self._bodies[side]
        self._set(body, seed)
        goal = np.asarray(position)
        q: tuple[float, ...] = tuple(seed)
        error, turn = math.inf, math.inf
        for _ in range(10):
            raw = p.calculateInverseKinematics(
                body,
                EE_LINK,
                position,
                orientation,
                maxNumIterations=50,
                residualThreshold=1e-6,
                physicsClientId=self.client,
            )
            q = tuple(float(v) for v in np.clip(np.asarray(raw[:7]), _LOWER, _UPPER))
            pose = self.forward(side, q)
            error = float(np.linalg.norm(np.asarray(pose.position) - goal))
            turn = quat_angle(pose.orientation, orientation)
            if (error < 1e-4 and turn < 1e-3) or (loose and error <= IK_TOLERANCE and turn <= 0.02):
                break
        solution = _Solution(q, error, turn)
        if len(self._solved) >= _SOLVED_KEPT:
            self._solved.clear()
        self._solved[key] = solution
        return solution

    def line(
        self,
        side: ArmSide,
        start: Sequence[float],
        position: Vec3,
        orientation: Quat,
        begin: Pose3D | None = None,
        loose: bool = False,
    ) -> list[tuple[float, ...]] | str:
        """The joint angles of a straight-line move of the grasp point from where the arm at ``start`` has
        it (``begin``, when known) to ``position``, turning the hand to ``orientation``: one per 1 cm (or
        0.05 rad) piece, each solved from the one before; or why there is none (a piece without a solution)."""
        begin = begin or self.forward(side, start)
        start_pos = np.asarray(begin.position)
        goal = np.asarray(position, dtype=np.float64)
        distance = float(np.linalg.norm(goal - start_pos))
        angle = quat_angle(begin.orientation, orientation)
        pieces = max(1, math.ceil(max(distance / CARTESIAN_STEP, angle / ANGULAR_STEP)))
        chain: list[tuple[float, ...]] = []
        seed = tuple(start)
        for i in range(1, pieces + 1):
            t = i / pieces
            point = start_pos + (goal - start_pos) * t
            target = (float(point[0]), float(point[1]), float(point[2]))
            solution = self.solve(side, target, _slerp(begin.orientation, orientation, t), [seed], loose)
            if solution.position_error > IK_TOLERANCE or solution.orientation_error > 0.02:
                into = (
                    f"{distance * t * 100:.1f} cm into the {distance * 100:.1f} cm line"
                    if distance >= CARTESIAN_STEP / 10
                    else f"{angle * t:.2f} rad into the hand's {angle:.2f} rad turn"
                )
                return f"no inverse kinematics at {_fmt(target)}, {into} to {_fmt(position)}"
            chain.append(solution.q)
            seed = solution.q
        return chain

    def joint_path(
        self,
        side: ArmSide,
        current: Sequence[float],
        others: dict[ArmSide, Sequence[float]],
        position: Vec3,
        orientation: Quat,
        symmetric: bool = True,
        min_height: float | None = None,
        loose: bool = False,
        down_to: float | None = None,
    ) -> _Solution | None:
        """Where a joint-space move to a pose ends (:meth:`Arm.reach`): of the inverse-kinematics solutions
        (one per seed posture, and from ``current``), the nearest whose straight joint-space path from
        ``current`` is collision-free (and, with ``min_height``, keeps the grasp point at or above it;
        with ``down_to``, from which the grasp point can go straight down to that height, as a put-down
        lowers it); None when there is none."""
        candidates = [orientation, flipped(orientation)] if symmetric else [orientation]
        best: _Solution | None = None
        for candidate in candidates:
            found = []
            for seed in (*_SEEDS, current):
                solution = self.solve(side, position, candidate, [seed], loose)
                if solution.position_error <= IK_TOLERANCE and solution.orientation_error <= 0.02:
                    found.append(solution)
            # Nearest first (a stable sort keeps the seeds' order among equals): the first whose path is
            # clear is the nearest clear one, so the farther ones' paths need no checking.
            for solution in sorted(found, key=lambda s: _joint_distance(current, s.q)):
                if best is not None and not _joint_distance(current, solution.q) < _joint_distance(current, best.q):
                    break
                if self.path_clear(side, current, solution.q, others, min_height) and (
                    down_to is None or self._goes_down(side, solution.q, down_to, loose)
                ):
                    best = solution
                    break
            if best is not None and min_height is None:
                break
        return best

    def no_joint_path(
        self,
        side: ArmSide,
        current: Sequence[float],
        others: dict[ArmSide, Sequence[float]],
        position: Vec3,
        orientation: Quat,
        symmetric: bool = True,
        min_height: float | None = None,
        loose: bool = False,
        down_to: float | None = None,
    ) -> str:
        """Why :meth:`joint_path`, given the same, found no move: no inverse-kinematics solution at the pose
        from any seed posture; or what the path to the nearest solution would run into (or how low it would
        take the hand, or that the hand could not go straight down from it). Asked once a move is refused,
        its answers looked up (:meth:`_refine`)."""
        where = "" if min_height is None else f" above {min_height:.2f} m"
        if down_to is not None:
            where += f" from which the hand goes straight down to {down_to:.3f} m"
        candidates = [orientation, flipped(orientation)] if symmetric else [orientation]
        found = [
            solution
            for candidate in candidates
            for seed in (*_SEEDS, current)
            if (solution := self.solve(side, position, candidate, [seed], loose)).position_error <= IK_TOLERANCE
            and solution.orientation_error <= 0.02
        ]
        if not found:
            return (
                f"no inverse kinematics at {_fmt(position)} from any seed posture: the arm cannot reach it, the hand "
                "so turned"
            )
        nearest = min(found, key=lambda s: _joint_distance(current, s.q))
        why = self._path_blocked(side, current, nearest.q, others, min_height)
        if not why and down_to is not None and not self._goes_down(side, nearest.q, down_to, loose):
            why = f"ends where the hand cannot go straight down to {down_to:.3f} m"
        because = f": the path to the nearest posture there {why}" if why else ""
        return f"no collision-free joint path to {_fmt(position)}{where}{because}"

    def _goes_down(self, side: ArmSide, q: Sequence[float], height: float, loose: bool) -> bool:
        """Whether the grasp point goes straight down from the posture ``q`` to ``height``, the hand kept
        as it is (:meth:`line`)."""
        pose = self.forward(side, q)
        below = (pose.position[0], pose.position[1], height)
        return not isinstance(self.line(side, q, below, pose.orientation, pose, loose), str)

    def solve(
        self,
        side: ArmSide,
        position: Vec3,
        orientation: Quat,
        seeds: Sequence[Sequence[float]],
        loose: bool = False,
    ) -> _Solution:
        """The best solution over the seeds; the first seed wins when it is good (keeps motions smooth)."""
        best: _Solution | None = None
        for seed in seeds:
            solution = self._refine(side, position, orientation, seed, loose)
            if solution.position_error < 1e-4 and solution.orientation_error < 1e-3:
                return solution
            score = solution.position_error + 0.1 * solution.orientation_error
            if best is None or score < best.position_error + 0.1 * best.orientation_error:
                best = solution
        if best is None:
            raise ValueError("no seeds")
        return best


class Arm:
    """One Panda arm of the dual-arm robot, bound to its world's pybullet client, ending in ``hand`` (what
    the store says of its gripper, :class:`kb.hands.Hand`: the grasp planner's; its fingers open as far as
    the hand's jaws, at most as far as the URDF's finger joints allow)."""

    def __init__(
        self,
        client: int,
        side: ArmSide,
        body: int,
        kinematics: Kinematics,
        step: Callable[[float], None],
        hand: Hand = PANDA_HAND,
    ) -> None:
        self.client = client
        self.side = side
        self.body = body
        self.hand = hand
        limits = sum(p.getJointInfo(body, joint, physicsClientId=client)[9] for joint in FINGER_JOINTS)
        self.open_width = min(hand.jaw_opening, limits)
        """How far apart the fingers open (m): the hand's jaw opening, within the fingers' joint limits."""
        self._kinematics = kinematics
        self._step = step
        self._grasp_constraint: int | None = None
        self.held: int | None = None
        """Body id of the object the gripper holds, if any."""
        self.held_grasp: GraspPose | None = None
        """The grasp the held object was picked with (how far it hangs below the hand)."""
        self.released: tuple[int, Vec3] | None = None
        """The last object let go and where its centre was by the hand's pose then (proprioception: the
        arm knows where it put a thing down without seeing it)."""
        self._targets: tuple[float, ...] = HOME_CONFIGURATIONS[side]
        self._gripper_width = self.open_width
        self.peers: dict[ArmSide, Arm] = {}
        """Both arms of the robot (set by the world), for collision checks against the other arm."""
        for joint, q in zip(ARM_JOINTS, self._targets, strict=True):
            p.resetJointState(body, joint, q, physicsClientId=client)
        for joint in FINGER_JOINTS:
            p.resetJointState(body, joint, self.open_width / 2.0, physicsClientId=client)
        self._command()

    # --- state --------------------------------------------------------------------------------

    def joint_positions(self) -> tuple[float, ...]:
        states = p.getJointStates(self.body, ARM_JOINTS, physicsClientId=self.client)
        return tuple(float(s[0]) for s in states)

    def ee_pose(self) -> Pose3D:
        """Pose of the grasp point (between the fingertips)."""
        state = p.getLinkState(self.body, EE_LINK, computeForwardKinematics=True, physicsClientId=self.client)
        pos, orn = state[4], state[5]
        return Pose3D((pos[0], pos[1], pos[2]), (orn[0], orn[1], orn[2], orn[3]))

    def carried_centre(self) -> Vec3 | None:
        """Where the held object's centre is by the hand's pose and the grasp it was taken with (it
        hangs ``bottom_offset`` below the grasp point, and its centre half its height above its bottom)."""
        if self.held is None or self.held_grasp is None:
            return None
        x, y, z = self.ee_pose().position
        grasp = self.held_grasp
        return (x, y, z - grasp.bottom_offset + grasp.model.height / 2.0)

    def gripper_width(self) -> float:
        states = p.getJointStates(self.body, FINGER_JOINTS, physicsClientId=self.client)
        return float(states[0][0] + states[1][0])

    # --- control ------------------------------------------------------------------------------

    def _command(self) -> None:
        p.setJointMotorControlArray(
            self.body,
            ARM_JOINTS,
            p.POSITION_CONTROL,
            targetPositions=self._targets,
            forces=_MAX_FORCES,
            positionGains=_POSITION_GAINS,
            physicsClientId=self.client,
        )
        half = self._gripper_width / 2.0
        p.setJointMotorControlArray(
            self.body,
            FINGER_JOINTS,
            p.POSITION_CONTROL,
            targetPositions=(half, half),
            forces=(40.0, 40.0),
            physicsClientId=self.client,
        )

    def move_to(
        self,
        position: Vec3,
        orientation: Quat,
        speed: float = ARM_SPEED,
        tolerance: float = REACH_TOLERANCE,
        symmetric: bool = True,
    ) -> MotionResult:
        """Move the grasp point along a straight line to ``position``, turning the hand to ``orientation``.

        With ``symmetric`` the hand may end half a turn about its approach axis from ``orientation``
        (a parallel gripper grasps the same either way), whichever is the smaller turn. A line on which
        the arm would run into the other arm is refused before it moves (:meth:`Kinematics.line_meets_arm`),
        as its dry run refuses it.
        """
        start = self.ee_pose()
        if symmetric:
            orientation = nearer(start.orientation, orientation)
        goal = np.asarray(position, dtype=np.float64)
        distance = float(np.linalg.norm(goal - np.asarray(start.position)))
        angle = quat_angle(start.orientation, orientation)
        current = self.joint_positions()
        chain = self._kinematics.line(self.side, current, position, orientation, start)
        if isinstance(chain, str):
            return MotionResult(False, math.inf, chain)
        meets = self._kinematics.line_meets_arm(self.side, current, chain, self._others(), position)
        if meets:
            return MotionResult(False, math.inf, meets)
        piece_time = max(distance / speed, angle / ARM_TURN_SPEED, 1e-3) / len(chain)
        for q in chain:
            self._targets = q
            self._command()
            self._step(piece_time)
        error = self._settle(goal)
        return MotionResult(error <= tolerance, error, "" if error <= tolerance else f"stopped {error:.3f} m short")

    def reach(
        self,
        position: Vec3,
        orientation: Quat,
        symmetric: bool = True,
        min_height: float | None = None,
        down_to: float | None = None,
    ) -> MotionResult:
        """Go to a pose through joint space (from the home posture to a pre-grasp pose, or across the
        workspace when a straight line would leave the arm's reach).

        Of the inverse-kinematics solutions (one per seed posture), the nearest one whose straight
        joint-space path is collision-free is taken. With ``min_height`` the grasp point must also stay
        at or above that height all the way: a held object then passes over the table and the torso
        instead of through them. With ``down_to``, the posture must let the hand go straight down to
        that height afterwards (:meth:`Kinematics.joint_path`).
        """
        current = self.joint_positions()
        best = self._kinematics.joint_path(
            self.side, current, self._others(), position, orientation, symmetric, min_height, down_to=down_to
        )
        if best is None:
            why = self._kinematics.no_joint_path(
                self.side, current, self._others(), position, orientation, symmetric, min_height, down_to=down_to
            )
            return MotionResult(False, math.inf, why)
        motion = self.move_joints(best.q)
        error = float(np.linalg.norm(np.asarray(self.ee_pose().position) - np.asarray(position)))
        ok = motion.reached and error <= REACH_TOLERANCE
        return MotionResult(ok, error, "" if ok else f"stopped {error:.3f} m short")

    def can_hold(
        self, position: Vec3, orientation: Quat, symmetric: bool = True, folded: Sequence[ArmSide] = ()
    ) -> bool:
        """Whether the hand can be at this pose at all (inverse kinematics from any seed posture, or from
        the current one, in a posture that does not push into a fixed thing: :meth:`Kinematics.strikes`),
        without moving: a skill asks before it picks up what it could not set down. Before, a posture in
        the dispenser's spout counted, and a cup taken from the top was carried into the spout. The arms
        of ``folded`` are taken to be home, as in :meth:`dry_run`."""
        return next(self._holding(position, orientation, symmetric, folded), None) is not None

    def hold_meets(self, position: Vec3, orientation: Quat, margin: float, symmetric: bool = True) -> str:
        """The fixture (``Kinematics``'s ``fixtures``: the appliances, a tap's lever too) that every posture
        holding the hand at this pose (those :meth:`can_hold` takes) brings the arm, fingers included,
        within ``margin`` of, the first such posture's; empty when one keeps farther from them all, or none
        holds the pose (:meth:`can_hold` says that)."""
        met = ""
        for posture in self._holding(position, orientation, symmetric):
            name = self._kinematics.brushes(self.side, posture, margin)
            if not name:
                return ""
            met = met or name
        return met

    def _holding(
        self, position: Vec3, orientation: Quat, symmetric: bool, folded: Sequence[ArmSide] = ()
    ) -> Iterator[tuple[float, ...]]:
        """The postures (joint positions) that hold the hand at this pose, the half-turned hand too when
        ``symmetric``, solved from each seed posture and the current one in turn, lazily: those within the
        tolerances that push into no fixed thing (:meth:`Kinematics.strikes`)."""
        candidates = [orientation, flipped(orientation)] if symmetric else [orientation]
        others = self._others(folded)
        for candidate in candidates:
            if self._kinematics.wrist_strikes(self.side, position, candidate):
                continue  # every solution would push into it: no need to solve
            for seed in (*_SEEDS, self.joint_positions()):
                solution = self._kinematics.solve(self.side, position, candidate, [seed], loose=True)
                if (
                    solution.position_error <= IK_TOLERANCE
                    and solution.orientation_error <= 0.02
                    and not self._kinematics.strikes(self.side, solution.q, others)
                ):
                    yield solution.q

    def _others(self, folded: Sequence[ArmSide] = ()) -> dict[ArmSide, Sequence[float]]:
        """The other arms' postures: where they are, or home for those of ``folded``."""
        return {
            side: HOME_CONFIGURATIONS[side] if side in folded else arm.joint_positions()
            for side, arm in self.peers.items()
            if side is not self.side
        }

    def fixture_near(self, start: Vec3, end: Vec3, margin: float = MEET_MARGIN) -> str:
        """The first fixture the hand, its grasp point on the line from ``start`` to ``end``, could come
        within ``margin`` of by the map (:meth:`Kinematics.fixture_near` with the hand's reach); empty when
        none: the hand there cannot come that near one."""
        return self._kinematics.fixture_near(start, end, self._kinematics.hand_reach + margin)

    def dry_run(
        self, folded: Sequence[ArmSide] = (), clear_by: float | None = None, meet_by: float | None = None
    ) -> PlannedArm:
        """A stand-in for this arm, from its posture now, whose moves are planned and not made; the other
        arms where they are, or those of ``folded`` in their home posture (where they will be by then: an
        arm that sets an object down for this one folds home after). With ``clear_by`` it notes where its
        moves first come within that distance of a fixture (:attr:`PlannedArm.brushed`): the clearance a
        check asks of a carry (``skills.plan_carry``'s ``clearance``); with ``meet_by`` the same, apart, while
        it is not set to None (:attr:`PlannedArm.met`): what a take's approach must not touch."""
        return PlannedArm(self.side, self._kinematics, self.joint_positions(), self._others(folded), clear_by, meet_by)

    def _settle(self, goal: NDArray[np.float64]) -> float:
        waited = 0.0
        error = float(np.linalg.norm(np.asarray(self.ee_pose().position) - goal))
        while error > REACH_TOLERANCE / 4.0 and waited < SETTLE_LIMIT:
            self._step(0.05)
            waited += 0.05
            error = float(np.linalg.norm(np.asarray(self.ee_pose().position) - goal))
        return error

    def move_joints(self, configuration: Sequence[float]) -> MotionResult:
        """Interpolate in joint space to ``configuration`` at up to ``JOINT_SPEED``."""
        start = np.asarray(self.joint_positions())
        goal = np.asarray(configuration, dtype=np.float64)
        seconds = max(0.2, float(np.max(np.abs(goal - start))) / JOINT_SPEED)
        pieces = max(1, math.ceil(seconds / 0.05))
        for i in range(1, pieces + 1):
            q = start + (goal - start) * (i / pieces)
            self._targets = tuple(float(v) for v in q)
            self._command()
            self._step(seconds / pieces)
        waited = 0.0
        error = float(np.max(np.abs(np.asarray(self.joint_positions()) - goal)))
        while error > 0.01 and waited < SETTLE_LIMIT:
            self._step(0.05)
            waited += 0.05
            error = float(np.max(np.abs(np.asarray(self.joint_positions()) - goal)))
        return MotionResult(error <= 0.02, error, "" if error <= 0.02 else f"joints {error:.3f} rad off")

    def home(self) -> MotionResult:
        """Raise the arm back to its home posture, through the "ready" posture if the direct joint-space
        path would hit something."""
        home = HOME_CONFIGURATIONS[self.side]
        current = self.joint_positions()
        others = self._others()
        ready = _SEEDS[0]
        if not self._kinematics.path_clear(self.side, current, home, others) and (
            self._kinematics.path_clear(self.side, current, ready, others)
            and self._kinematics.path_clear(self.side, ready, home, others)
        ):
            via = self.move_joints(ready)
            if not via.reached:
                return via
        return self.move_joints(home)

    def set_gripper(self, width: float, seconds: float = 0.3) -> None:
        """Open the fingers to ``width`` (m, 0 to :attr:`open_width`) and give them time to move."""
        self._gripper_width = min(max(width, 0.0), self.open_width)
        self._command()
        self._step(seconds)

    def open_gripper(self, seconds: float = 0.3) -> None:
        """Open the fingers as far as they go (:attr:`open_width`)."""
        self.set_gripper(self.open_width, seconds)

    # --- grasping -----------------------------------------------------------------------------

    def attach(self, body: int, grasp: GraspPose | None = None) -> None:
        """Hold ``body`` rigidly where it is relative to the grasp point (the closed fingers' grip)."""
        if self.held is not None:
            self.detach()
        ee = self.ee_pose()
        obj_pos, obj_orn = p.getBasePositionAndOrientation(body, physicsClientId=self.client)
        inv_pos, inv_orn = p.invertTransform(ee.position, ee.orientation)
        rel_pos, rel_orn = p.multiplyTransforms(inv_pos, inv_orn, obj_pos, obj_orn)
        self._grasp_constraint = p.createConstraint(
            self.body,
            EE_LINK,
            body,
            -1,
            p.JOINT_FIXED,
            (0.0, 0.0, 0.0),
            rel_pos,
            (0.0, 0.0, 0.0),
            parentFrameOrientation=rel_orn,
            childFrameOrientation=(0.0, 0.0, 0.0, 1.0),
            physicsClientId=self.client,
        )
        p.changeConstraint(self._grasp_constraint, maxForce=200.0, physicsClientId=self.client)
        self.held = body
        self.held_grasp = grasp

    def detach(self) -> int | None:
        """Let go of the held object; returns its body id."""
        held = self.held
        if held is not None:
            self.released = (held, self.carried_centre() or self.ee_pose().position)
        if self._grasp_constraint is not None:
            p.removeConstraint(self._grasp_constraint, physicsClientId=self.client)
        self._grasp_constraint = None
        self.held = None
        self.held_grasp = None
        return held


class PlannedArm:
    """An arm's moves planned on the kinematics copies and not made (a dry run): each straight line and
    joint-space reach is planned as :class:`Arm` plans it (:meth:`Kinematics.line`,
    :meth:`Kinematics.joint_path`) and ends where that plan ends, the other arm kept where it was. It
    asks whether the arm's own planning would refuse a sequence of moves before any is made; it knows
    nothing of the physics (how the motors track, what the hand or the held object touches)."""

    def __init__(
        self,
        side: ArmSide,
        kinematics: Kinematics,
        q: Sequence[float],
        others: dict[ArmSide, Sequence[float]],
        clear_by: float | None = None,
        meet_by: float | None = None,
    ) -> None:
        self.side = side
        self._kinematics = kinematics
        self._q = tuple(q)
        self._others = others
        self._clear_by = clear_by
        self.brushed = ""
        """Where the moves planned on it first came within ``clear_by`` of a fixture
        (:meth:`Kinematics.brushes`), which they are not refused for, as the arm's own planning does not
        refuse them; empty when they kept clear or no clearance is asked."""
        self.meet_by = meet_by
        """The distance from a fixture at which :attr:`met` notes a move; None: moves from now on are not
        asked (a take's dry run asks its approach, not its carry)."""
        self.met = ""
        """Where the moves planned on it while ``meet_by`` was set first came within it of a fixture; empty
        when none did."""

    def joint_positions(self) -> tuple[float, ...]:
        return self._q

    def dry_run(self, *, clear_by: float | None = None) -> PlannedArm:
        """A copy from the posture planned so far, to plan moves on without changing this one (a probe);
        with ``clear_by``, noting where they first come that near a fixture, as :meth:`Arm.dry_run`."""
        return PlannedArm(self.side, self._kinematics, self._q, self._others, clear_by)

    def _note(self, postures: Sequence[Sequence[float]], target: Vec3) -> None:
        """Note the first of ``postures`` (a move to ``target``) within ``clear_by`` of a fixture, and the
        first within ``meet_by``."""
        if self._clear_by is not None and not self.brushed:
            found = self._within(postures, self._clear_by)
            if found:
                name, at = found
                self.brushed = (
                    f"on the way to {_fmt(target)} the arm would come within {self._clear_by * 100:.0f} cm of "
                    f"the {name} (the hand at {_fmt(at)})"
                )
        if self.meet_by is not None and not self.met:
            found = self._within(postures, self.meet_by)
            if found:
                name, at = found
                near = "touch" if self.meet_by <= 0.0 else f"come within {self.meet_by * 100:.0f} cm of"
                self.met = (
                    f"on the way to {_fmt(target)} the arm, fingers included, would {near} the {name}, a fixture "
                    f"its planning does not keep clear of (the hand at {_fmt(at)})"
                )

    def _within(self, postures: Sequence[Sequence[float]], margin: float) -> tuple[str, Vec3] | None:
        """The first fixture the first of ``postures`` within ``margin`` of one comes that near, and where the
        hand is then; None when every posture keeps farther."""
        for q in postures:
            name = self._kinematics.brushes(self.side, q, margin)
            if name:
                return name, self._kinematics.forward(self.side, q).position
        return None

    def ee_pose(self) -> Pose3D:
        return self._kinematics.forward(self.side, self._q)

    def move_to(
        self,
        position: Vec3,
        orientation: Quat,
        speed: float = ARM_SPEED,
        tolerance: float = REACH_TOLERANCE,
        symmetric: bool = True,
    ) -> MotionResult:
        """:meth:`Arm.move_to`, planned (``speed`` and ``tolerance`` are the real move's). The line is solved
        loosely (each piece to IK_TOLERANCE), and where that runs out of inverse kinematics, as the real
        arm solves it (each piece to 0.1 mm, :meth:`Kinematics.line`): loose pieces, each solved from the
        last, drift from the real line's postures, and one ran out 8.9 cm into the left arm's carry of a
        mug whose real line went on into the right arm; the dry run planned a joint-space move instead
        (:func:`skills._carry`'s fallback), which keeps clear of the other arm, and passed."""
        start = self.ee_pose()
        if symmetric:
            orientation = nearer(start.orientation, orientation)
        chain = self._kinematics.line(self.side, self._q, position, orientation, start, loose=True)
        if isinstance(chain, str):
            chain = self._kinematics.line(self.side, self._q, position, orientation, start)
        if isinstance(chain, str):
            return MotionResult(False, math.inf, chain)
        meets = self._kinematics.line_meets_arm(self.side, self._q, chain, self._others, position)
        if meets:
            return MotionResult(False, math.inf, meets)
        self._note(chain, position)
        self._q = chain[-1]
        return MotionResult(True, 0.0)

    def blocked(self, position: Vec3, orientation: Quat) -> str:
        """Why the straight line from here to the pose would not keep the arm clear of the fixed things and
        the other arm (:meth:`Kinematics.line_blocked`); empty when it would. Planned, not made."""
        return self._kinematics.line_blocked(self.side, self._q, self._others, position, orientation, loose=True)

    def reach(
        self,
        position: Vec3,
        orientation: Quat,
        symmetric: bool = True,
        min_height: float | None = None,
        down_to: float | None = None,
    ) -> MotionResult:
        """:meth:`Arm.reach`, planned."""
        best = self._kinematics.joint_path(
            self.side, self._q, self._others, position, orientation, symmetric, min_height, True, down_to
        )
        if best is None:
            why = self._kinematics.no_joint_path(
                self.side, self._q, self._others, position, orientation, symmetric, min_height, True, down_to
            )
            return MotionResult(False, math.inf, why)
        self._note(_joint_samples(self._q, best.q), position)
        self._q = best.q
        return MotionResult(True, 0.0)


def _joint_samples(start: Sequence[float], goal: Sequence[float]) -> list[list[float]]:
    """The postures of a straight joint-space path, every 0.05 rad, as :meth:`Kinematics.path_clear` checks it."""
    a, b = np.asarray(start), np.asarray(goal)
    samples = max(2, math.ceil(float(np.max(np.abs(b - a))) / 0.05))
    return [[float(v) for v in a + (b - a) * (i / samples)] for i in range(samples + 1)]


def _joint_distance(a: Sequence[float], b: Sequence[float]) -> float:
    return float(np.max(np.abs(np.asarray(a) - np.asarray(b))))


def _aabb(client: int, body: int, link: int) -> tuple[Vec3, Vec3]:
    low, high = p.getAABB(body, link, physicsClientId=client)
    return (low[0], low[1], low[2]), (high[0], high[1], high[2])


def _fmt(point: Vec3) -> str:
    return f"({point[0]:.3f}, {point[1]:.3f}, {point[2]:.3f})"
