"""Object models (the manipulation properties the knowledge base holds) and grasp poses computed from them.

A grasp pose is where the gripper's grasp point (between the fingertips) goes, how the hand is turned,
and from which direction it comes in. Only what perception estimated, the object's model and the hand
of the arm that grasps (:class:`kb.hands.Hand`, from the store) are used: never the simulator's ground
truth.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from enum import StrEnum

import numpy as np

from cbrs.kb.hands import PANDA_HAND, Hand
from cbrs.kb.semantic_map import MapObject, NotGraspableError
from cbrs.settings import setting
from cbrs.sim.errors import GraspTooDeepError, GraspTooThinError, GraspTooWideError
from cbrs.sim.geometry import Quat, Vec3, quat_from_matrix

__all__ = [
    "GraspKind",
    "GraspPose",
    "ObjectModel",
    "check_side_depth",
    "compute_grasp_pose",
    "held_height",
    "palm_stop",
    "seen_centre_z",
    "side_held",
]


class GraspKind(StrEnum):
    """TOP: the hand comes down vertically (flat things). SIDE: it comes in horizontally (upright cups)."""

    TOP = "top"
    SIDE = "side"


@dataclass(frozen=True)
class ObjectModel:
    """What the robot knows of an object kind: its colour feature, size and how to grasp it."""

    name: str
    colour: str
    height: float
    width: float
    """Size across the fingers when grasped (diameter of a cup, thickness of a pen) as a value between
    components states it; with a ``footprint`` the grasp computes it for the way the hand is turned."""
    grasp: GraspKind
    """The approach the object is (to be) held by."""
    grasp_height: float
    """Height of the grasp point above the object's bottom."""
    approaches: tuple[GraspKind, ...] = ()
    """Every approach its class allows, best first, when it allows more than one (else empty: ``grasp``
    alone). The grasp point is the same for each: the class says where the fingers close, an approach
    only from where the hand comes."""
    footprint: tuple[float, float] | None = None
    """A box's size along its own x and y axes (m), from the map: its width across the jaws depends on
    the approach and on how it lies (:meth:`across`). None for a cylinder (its diameter whichever way)
    and for a model a value gave with its width alone (that width is used whichever way)."""
    turn: float = 0.0
    """How far (rad) a top grasp turns the closing of the fingers about the vertical from the way
    :func:`compute_grasp_pose` closes them across the object. 0 but for a round object (no ``footprint``),
    which a top grasp holds the same whichever way: a quarter turn where the fingers the usual way would
    touch a fixture the arms' planning does not avoid (``arm_choice.turned``: the flask beside a tap's lever)."""

    @property
    def preference(self) -> tuple[GraspKind, ...]:
        """The approaches to try, best first."""
        return self.approaches or (self.grasp,)

    def by(self, kind: GraspKind) -> ObjectModel:
        """The same object held by ``kind`` (one of its approaches)."""
        return self if kind is self.grasp else replace(self, grasp=kind)

    def preferring(self, kinds: tuple[GraspKind, ...]) -> ObjectModel:
        """This model with ``kinds`` (its class's approaches, best first) as the ones to fall back on after
        the one it names: a value that says how to grasp keeps its approach first."""
        order = (self.grasp, *(kind for kind in kinds if kind is not self.grasp))
        return replace(self, approaches=order if len(order) > 1 else ())

    def across(self, closing: float, axis: float | None, seen: tuple[float, float] | None = None) -> float:
        """How far apart the jaws must be to pass the object, closing along the horizontal direction
        ``closing`` (its yaw), the object's long axis lying along ``axis`` (a perceived yaw, modulo pi;
        None when perception saw no long axis): a box's extent along that direction (each side's share of
        it: |sx cos| + |sy sin| of the angle between its x axis and the jaws). A box whose axis is not
        known is at most as wide as what was ``seen`` of it along x and y (exactly, with the jaws along x
        or y: its extent along x or y), and never wider than its diagonal."""
        if self.footprint is None:
            return self.width
        sx, sy = self.footprint
        if axis is None:
            widest = math.hypot(sx, sy)
            if seen is None or min(seen) <= 0.0:
                return widest
            return min(widest, abs(math.cos(closing)) * seen[0] + abs(math.sin(closing)) * seen[1])
        turn = closing - _x_axis(self.footprint, axis)
        return abs(sx * math.cos(turn)) + abs(sy * math.sin(turn))

    def grip(self, closing: float, axis: float | None) -> float:
        """How far apart the jaws are where the fingers, narrow, touch the object, closing through its
        grasp point along ``closing``: a box's chord that way through its centre (its extent along its x or
        y axis, when the jaws close along it). A box whose axis is not known is at least its narrower
        side across (the shortest chord through a rectangle's centre): the fingers, told to close to
        that, stop where they touch it. A cylinder's diameter; a width given alone, that width."""
        if self.footprint is None:
            return self.width
        sx, sy = self.footprint
        if axis is None:
            return min(sx, sy)
        turn = closing - _x_axis(self.footprint, axis)
        along, across = abs(math.cos(turn)), abs(math.sin(turn))
        return min(sx / along if along > 1e-9 else math.inf, sy / across if across > 1e-9 else math.inf)

    @classmethod
    def of(cls, obj: MapObject) -> ObjectModel:
        """The model of a semantic-map object: a cylinder's width is its diameter whichever way the hand
        comes; a box keeps its footprint, its width across the jaws being the grasp's to compute, and
        states as its width its narrower side (the most its jaws close to, as its top grasp does)."""
        kinds = tuple(GraspKind(approach) for approach in obj.grasp_approaches)
        if not kinds:
            raise NotGraspableError(obj.iri, obj.types)
        box = obj.shape != "cylinder"
        return cls(
            obj.name,
            obj.colour,
            obj.size[2],
            min(obj.size[0], obj.size[1]),
            kinds[0],
            obj.grasp_height,
            kinds if len(kinds) > 1 else (),
            (obj.size[0], obj.size[1]) if box else None,
        )

    def top_clearance(self, hand: Hand) -> float:
        """How far ``hand``'s palm stays above the object's top in a top grasp (negative: it would press
        on it, the grasp point being deeper below the top than the palm is above the grasp point)."""
        return hand.palm_depth - (self.height - self.grasp_height)


def _x_axis(footprint: tuple[float, float], axis: float) -> float:
    """The yaw of a box's x axis, its long axis (as perception gives it) lying along ``axis``."""
    return axis if footprint[0] >= footprint[1] else axis - math.pi / 2.0


def held_height(model: ObjectModel, hand: Hand) -> float:
    """The grasp point's height above the object's bottom when ``hand`` holds it by ``model``'s approach:
    its class's, raised for a top grasp until the fingertips, ``hand.fingertip_depth`` below the grasp
    point, stay ``hand.fingertip_clearance`` above the surface it rests on (a ruler 8 mm thick at 0.5 put
    them 4 mm into the table, and the fingers closed over its top edge). :class:`GraspTooThinError` for an
    object no thicker than that clearance: nothing of it would lie between the fingertips."""
    if model.grasp is not GraspKind.TOP:
        return model.grasp_height
    if model.height <= hand.fingertip_clearance:
        raise GraspTooThinError(
            model.name, model.grasp.value, model.height, hand.fingertip_depth, hand.fingertip_clearance
        )
    return max(model.grasp_height, hand.fingertip_depth + hand.fingertip_clearance)


def side_held(depth: float, hand: Hand) -> float:
    """How much of an object ``depth`` deep along a side grasp's horizontal approach lies between
    ``hand``'s fingers: they come in tilted down by its side pitch, so they span its ``side_span`` of it
    (3.8 cm for the Panda's) from its near face, which a deeper object has at the palm (the hand stops
    there, :func:`palm_stop`), the rest of it beyond the fingertips."""
    return min(depth, hand.side_span)


def check_side_depth(model: ObjectModel, depth: float, hand: Hand) -> None:
    """:class:`GraspTooDeepError` when a side grasp by ``hand`` would hold less than its side-hold fraction
    of an object ``depth`` deep along the approach (:func:`side_held`): the grasp's own decision, which the
    checks before a run ask too (``sim.run_checks``), so that they refuse it in the same words."""
    held = side_held(depth, hand)
    if held < hand.side_hold * depth - 1e-9:
        raise GraspTooDeepError(model.name, model.grasp.value, depth, hand.finger_length, held, hand.side_hold)


def palm_stop(depth: float, hand: Hand) -> float:
    """How far short of an object's centre, along a side grasp's level approach, ``hand``'s grasp point
    stops so that the palm stops at the object's near side instead of pushing it: the near side is half
    its ``depth`` back from its centre, the palm ``palm_depth * cos(side_pitch)`` back from the grasp point
    less how far its tilted face leads (``hand.side_palm_lead``, ``home:sidePalmLead``: the Panda's 5.2 mm,
    measured on its collision mesh). 0 for an object the palm does not reach (the bundled cup, 6 cm across,
    is reached: 0.7 cm). Before, the hand went on to the centre and the palm pushed a 7 cm bottle 2.3 cm
    and tipped it 8.5 degrees before the fingers closed, and it fell."""
    palm = hand.palm_depth * math.cos(hand.side_pitch) - hand.side_palm_lead
    return max(0.0, depth / 2.0 - palm)


@dataclass(frozen=True)
class GraspPose:
    """Where to grasp, with which hand orientation, coming from which direction."""

    model: ObjectModel
    position: Vec3
    """The grasp point (between the fingertips) in the world frame."""
    orientation: Quat
    """Orientation of the gripper's grasp frame (z: approach direction, y: finger opening axis)."""
    approach: Vec3
    """Unit vector the gripper moves along to reach the grasp point."""
    bottom_offset: float
    """Grasp point height above the object's bottom: how far the object hangs below the hand (the
    model's ``grasp_height``, which :func:`held_height` may have raised for the hand)."""
    width: float
    """How far apart the jaws are when the fingers touch the object, for this approach and turn of the
    hand (:meth:`ObjectModel.grip`): what the fingers close to."""
    hand: Hand = PANDA_HAND
    """The hand that grasps so."""

    @property
    def pregrasp(self) -> Vec3:
        """The pre-grasp pose: the hand's pre-grasp distance back along the approach."""
        return self.backed_off(self.position)

    def backed_off(self, point: Vec3) -> Vec3:
        """``point`` moved the hand's pre-grasp distance back along the approach: where the hand comes
        in from, and where it backs off to after letting go."""
        x, y, z = point
        ax, ay, az = self.approach
        back = self.hand.pregrasp_distance
        return (x - ax * back, y - ay * back, z - az * back)


def top_orientation(finger_axis_yaw: float) -> Quat:
    """Hand pointing down with the fingers closing along the horizontal direction ``finger_axis_yaw``."""
    z = np.array([0.0, 0.0, -1.0])
    y = np.array([math.cos(finger_axis_yaw), math.sin(finger_axis_yaw), 0.0])
    x = np.cross(y, z)
    return quat_from_matrix(np.column_stack([x, y, z]))


def side_orientation(approach_yaw: float, pitch: float) -> Quat:
    """Hand coming in along ``approach_yaw``, tilted down by ``pitch``, fingers closing horizontally."""
    z = np.array([math.cos(approach_yaw) * math.cos(pitch), math.sin(approach_yaw) * math.cos(pitch), -math.sin(pitch)])
    y = np.array([math.sin(approach_yaw), -math.cos(approach_yaw), 0.0])
    x = np.cross(y, z)
    return quat_from_matrix(np.column_stack([x, y, z]))


SEEN_SHORT = 0.01
"""How much less of an object's height (m) perception may see than it has before the middle of what it
saw is taken for a part of it (:func:`seen_centre_z`), by default: the ``seen_short`` setting
(``CBRS_SEEN_SHORT``) sets it (:func:`seen_short`). A thing seen whole is seen within a few millimetres of
its height (the bundled cup 9.9-10.2 cm of its 10 cm, on the table and below the tap; the pen 1.56 of its
1.6 cm), the lab's apple seen in part 2.8 cm short or more."""


def seen_short() -> float:
    """SEEN_SHORT, or the ``seen_short`` setting where it is given (metres, 0 to 10 cm): a camera that sees
    whole things less exactly (fewer pixels on them) needs more before a short sighting counts as a part."""
    return float(setting("seen_short").resolve())


def seen_centre_z(centre_z: float, seen_height: float | None, height: float) -> float:
    """The height of the centre of an object ``height`` tall whose seen points span ``seen_height`` about
    ``centre_z`` (the middle of what perception saw): that middle, unless it saw less of the object's
    height than it has by more than :func:`seen_short`. Then the top of what it saw, less half the height: a
    camera above sees an object's top first (:func:`cbrs.sim.perception.recognise_object`), and a part
    it did not see is a part of the side below (hidden, or rendered off its colour). The lab's apple,
    green at the edge of what the camera calls green, was seen 4.2 cm of its 7 cm, its lower side lost;
    grasped 1.5 cm above its centre, it hung 1.5 cm lower than the grasp said, and the put-down pressed
    it into the bowl's floor, 1.2-1.3 cm short of the hand's goal (docs/simulation.md)."""
    if seen_height is None or seen_height >= height - seen_short():
        return centre_z
    return centre_z + seen_height / 2.0 - height / 2.0


def compute_grasp_pose(
    model: ObjectModel,
    centre: Vec3,
    yaw: float | None,
    arm_mount: Vec3,
    facing: float,
    seen: tuple[float, float] | None = None,
    hand: Hand = PANDA_HAND,
    seen_height: float | None = None,
) -> GraspPose:
    """The grasp for an object whose centre (and, for long objects, axis yaw; ``seen``: its extent along
    x and y) perception estimated, by an arm mounted at ``arm_mount`` facing ``facing`` (its yaw in the
    semantic map) that ends in ``hand`` (the arm's :class:`kb.hands.Hand`; the Panda's by default).

    A side grasp comes in from the robot's side of the table, tilted down by the hand's side pitch, its
    jaws closing across that direction; a top grasp closes them across the object's long axis.
    The grasp point is at :func:`held_height` above the object's bottom (the pose's model says so too).
    GraspTooWideError when the object is wider across the jaws than the hand opens them less each jaw's
    clearance (``hand.widest``), GraspTooDeepError when a side grasp would hold less than the hand's
    side-hold fraction of its depth along the approach (:func:`side_held`), GraspTooThinError when a top
    grasp would hold nothing of it above its surface: the hand could not hold it so, whatever the arm can
    reach. A side grasp's grasp point stops :func:`palm_stop` short of the centre, so the palm does not
    push the object before the fingers close. ``seen_height``: how much of the object's height perception
    saw about ``centre``, where less of it than it has moves the centre (:func:`seen_centre_z`).
    """
    cx, cy, cz = centre
    bottom = seen_centre_z(cz, seen_height, model.height) - model.height / 2.0
    raised = held_height(model, hand)
    if raised != model.grasp_height:
        model = replace(model, grasp_height=raised)
    grasp_z = bottom + model.grasp_height
    if model.grasp is GraspKind.SIDE:
        # Straight in from the robot's side of the table, whatever the object's position.
        closing = facing - math.pi / 2.0  # the grasp frame's y axis, across the approach
        pitch = hand.side_pitch
        orientation = side_orientation(facing, pitch)
        approach: Vec3 = (math.cos(facing) * math.cos(pitch), math.sin(facing) * math.cos(pitch), -math.sin(pitch))
    else:
        if yaw is not None:
            axis = yaw
        elif model.footprint is not None and seen is not None and seen[1] > seen[0]:
            axis = math.pi / 2.0  # no long axis seen: along the longer of what was, the jaws across the other
        else:
            axis = 0.0
        # Of the two finger directions across the axis, pick the one nearer the arm's natural wrist
        # yaw (fingers across the arm's reach), so the wrist does not run into its joint limit.
        reach_yaw = math.atan2(cy - arm_mount[1], cx - arm_mount[0])
        finger = axis + math.pi / 2.0 + model.turn
        if math.cos(finger - (reach_yaw + math.pi / 2.0)) < 0.0:
            finger += math.pi
        closing = finger
        orientation = top_orientation(finger)
        approach = (0.0, 0.0, -1.0)
    width = model.across(closing, yaw, seen)
    if width > hand.widest + 1e-9:
        raise GraspTooWideError(model.name, model.grasp.value, width, hand.jaw_opening, hand.jaw_clearance)
    if model.grasp is GraspKind.SIDE:
        depth = model.across(facing, yaw, seen)  # its extent along the approach, as across the jaws
        check_side_depth(model, depth, hand)
        short = palm_stop(depth, hand)
        cx, cy = cx - math.cos(facing) * short, cy - math.sin(facing) * short
    grip = model.grip(closing, yaw)
    return GraspPose(model, (cx, cy, grasp_z), orientation, approach, model.grasp_height, grip, hand)
