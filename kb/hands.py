"""A robot's hands: the gripper at the end of each arm, as the semantic map describes it.

KnowRob style, a hand is a part of its arm in the store (``home:hasGripper``), and what the grasp planner
needs of it is stated on it: how far its jaws open, how far its palm sits above the grasp point, how long
its fingers are (its geometry, required of a gripper the map names; how far the fingertips reach below
the grasp point, which they imply unless stated), and how it is used (its policy: the side grasp's tilt
and least hold, the pre-grasp distance, how far the fingertips stay above a surface and each jaw clear of
the object; each a default here unless the store states one, and then the store's), and what a carry must
keep clear of it (the corridor either side of its way, and the arm behind a side grasp, :mod:`kb.arm_bands`;
unstated, the Panda's, the arm and hand of every simulated robot). A value is stated on
the gripper, or once on a class of grippers (a model) it is an individual of: its own value wins, else the
nearest class's (:func:`read_hands`). The named query ``robot_hands`` reads them; an arm the map gives no
gripper has :data:`PANDA_HAND`, the hand of the simulated arms (docs/simulation.md, "The hand").
"""

from __future__ import annotations

import math
from collections import defaultdict
from dataclasses import dataclass
from typing import TYPE_CHECKING

from pyoxigraph import Literal

from cbrs.kb.arm_bands import BAND_PROPERTIES, PANDA_SIDE_ARM, ArmBand, StatedBands, band_problem, stated_bands
from cbrs.kb.namespaces import PREFIXES
from cbrs.kb.semantic_map import MapError, local_name
from cbrs.kb.shapes import nearest_term

if TYPE_CHECKING:
    from cbrs.kb.knowledge_base import KnowledgeBase

__all__ = [
    "CARRY_CORRIDOR",
    "FINGERTIP_CLEARANCE",
    "JAW_CLEARANCE",
    "PANDA_HAND",
    "PREGRASP_DISTANCE",
    "SIDE_HOLD",
    "SIDE_PITCH",
    "Hand",
    "HandError",
    "read_hands",
]

HOME = PREFIXES["home"]

SIDE_HOLD = 0.5
"""The least fraction of an object's depth along a side grasp's approach that must lie between the
fingers, its near face pushed against the palm (:attr:`Hand.side_span`). At a half its centre of mass lies
within the fingertips; a box deeper than twice what the fingers span along the approach is refused. The
default of ``home:sideHoldFraction``: raise it for a firmer hold, lower it to allow deeper boxes."""

SIDE_PITCH = math.radians(35.0)
"""A side grasp comes in tilted down by 35 degrees: with the arms mounted below the grasp height, a level
hand would need the wrist at its joint limit, while a tilted one keeps it mid-range. The default of
``home:sideGraspPitch`` (radians)."""

PREGRASP_DISTANCE = 0.10
"""The pre-grasp pose is this far back along the approach direction (m): far enough that opening the
fingers there touches nothing, near enough that the final approach is a short straight move. The default
of ``home:pregraspDistance``."""

FINGERTIP_CLEARANCE = 0.002
"""How far above the surface an object rests on a top grasp keeps the fingertips (m): the grasp point is
raised to at least the fingertips' depth and this above the object's bottom, so the hand does not come
down on the surface and close over a thin object's top edge. 2 mm: the object's bottom is found from the
depth camera's view of its top, a Kinect's depth error at a metre is of that order, and it leaves 3.8 mm of
the Panda's fingers' flat inner faces on an 8 mm ruler (docs/simulation.md, "Thin objects"). The default
of ``home:fingertipClearance``."""

JAW_CLEARANCE = 0.0035
"""How far each open jaw must clear an object as the hand moves in around it (m): an object wider than
the opening less twice this is refused. The Kinect's estimate of an object's centre is off by up to 2.3 mm
across the jaws (the cup, seeds 0-7), and the Panda's open fingers' inner faces sit 1.1 mm inside the
stated opening on each side (docs/simulation.md, "The hand"). The default of ``home:jawClearance``."""

SIDE_PALM_LEAD = 0.0052
"""How far ahead of its point on the hand's axis a side grasp's palm reaches along the level approach (m):
tilted down by the side pitch, the palm's face leans forward above the axis. The Panda hand's at 35
degrees, measured on its collision mesh (ontologies/world.ttl): the default of ``home:sidePalmLead``."""

PAYLOAD = 3.0
"""The most a hand lifts (kg): the Franka Panda's rated payload (Franka Emika's datasheet gives 3 kg), the
arm of every simulated hand. The simulation's grasp is a constraint that would hold far more (a 4.5 kg hand
weight was fetched, the twentieth round), so the check before a run refuses what is heavier. The store states
it (``home:payloadKg``, on the gripper or a class of grippers; world.ttl on the bundled hands): this is only the
fallback for a hand that states none, as the Panda's geometry is the other hands' defaults."""

CARRY_CORRIDOR = 0.10
"""How far to either side of what a hand carries (the object's footprint, or the open jaws' if wider) its
palm passes over other things, footprint to footprint (m): a carry keeps the palm over the top of any
thing standing within this of its way. The Panda hand's (its bounding box is 20.05 cm across along the
fingers' axis), the hand of every simulated arm: the default of ``home:carryCorridor``."""


@dataclass(frozen=True)
class Hand:
    """What the grasp planner knows of a two-finger hand (metres, radians)."""

    jaw_opening: float
    """How far apart the open jaws are: an object wider than this across them, for the way the hand is
    turned to it, cannot be grasped so."""
    palm_depth: float
    """How far the palm is above the grasp point (between the fingertips), the hand pointing down: an
    object whose top is higher above the grasp point than that cannot be taken from the top."""
    finger_length: float
    """How long the fingers are from the palm to their tips, along the hand's axis: what of an object can
    lie between them."""
    side_hold: float = SIDE_HOLD
    side_pitch: float = SIDE_PITCH
    pregrasp_distance: float = PREGRASP_DISTANCE
    iri: str = ""
    """The gripper in the store; empty for a hand the store does not describe."""
    fingertip_depth: float = math.nan
    """How far the fingertips reach below the grasp point, the hand pointing down; unstated (NaN), what
    the palm depth and finger length imply (``finger_length - palm_depth``), the most it can be."""
    fingertip_clearance: float = FINGERTIP_CLEARANCE
    jaw_clearance: float = JAW_CLEARANCE
    carry_corridor: float = CARRY_CORRIDOR
    side_arm: tuple[ArmBand, ...] = PANDA_SIDE_ARM
    """The arm behind a side grasp by this hand (``home:sideGraspBand``): a carry keeps each band's
    underside over what stands under it (sim/transit.py)."""
    side_palm_lead: float = SIDE_PALM_LEAD
    """How far ahead of its point on the axis the palm reaches by a side grasp (``home:sidePalmLead``):
    the grasp point stops short so the palm meets a deep object's near side (sim/grasping.py)."""
    payload: float = PAYLOAD
    """The most it lifts, in kilograms (``home:payloadKg``): a heavier object is refused before the run."""

    def __post_init__(self) -> None:
        if math.isnan(self.fingertip_depth):
            object.__setattr__(self, "fingertip_depth", self.finger_length - self.palm_depth)

    @property
    def widest(self) -> float:
        """The widest an object may be across the jaws: the opening less each jaw's clearance."""
        return self.jaw_opening - 2.0 * self.jaw_clearance

    @property
    def side_span(self) -> float:
        """How much of an object along a side grasp's horizontal approach the fingers span: tilted down by
        ``side_pitch``, ``finger_length * cos(side_pitch)`` of it (3.8 cm for the Panda's)."""
        return self.finger_length * math.cos(self.side_pitch)


PANDA_HAND = Hand(jaw_opening=0.08, palm_depth=0.034, finger_length=0.046, fingertip_depth=0.0082)
"""The Franka Panda's hand, the hand of every simulated arm (pybullet_data's ``franka_panda/panda.urdf``):
the hand of an arm the store gives no ``home:hasGripper``. ``ontologies/world.ttl`` states the same values
on the bundled robot's hands, with where each comes from; tests/test_grasp16_depth.py and
tests/test_grasp_thin.py measure them again from the URDF."""

_PROPERTIES = (
    "jawOpening",
    "palmDepth",
    "fingerLength",
    "sideHoldFraction",
    "sideGraspPitch",
    "pregraspDistance",
    "fingertipDepth",
    "fingertipClearance",
    "jawClearance",
    "carryCorridor",
    "sidePalmLead",
    "payloadKg",
)
"""The store's properties (local names in the home namespace) of :class:`Hand`'s values, in its order."""
_GEOMETRY = ("jawOpening", "palmDepth", "fingerLength")
"""What a gripper the map names must state: there is no other hand's geometry to assume for it."""


class HandError(MapError):
    """A gripper's description lacks or contradicts what the grasp planner needs: names the gripper, its
    arm and robot, the property and the value (None when missing), and the class it has the value from
    (``source``; empty for its own value, or for classes equally near that disagree, which ``problem``
    names), and the arm band of the gripper the property is of (``band``; empty for the gripper's own)."""

    def __init__(
        self,
        hand: str,
        arm: str,
        robot: str,
        prop: str,
        value: str | None,
        problem: str,
        source: str = "",
        band: str = "",
    ) -> None:
        self.hand, self.arm, self.robot, self.property, self.value = hand, arm, robot, prop, value
        self.source, self.band = source, band
        whose = "an arm" if hand == arm else f"the gripper of {local_name(arm)}"
        whose += f" of {local_name(robot)}" if robot else ""
        said = f"has no home:{prop}" if value is None else f"has home:{prop} {value!r}"
        said += f" for its arm band {local_name(band)}" if band else ""
        said += f" from its class {local_name(source)}" if source else ""
        super().__init__(hand, f"({whose}) {said}: {problem}")


@dataclass(frozen=True)
class _Stated:
    """A value the store states for a gripper: on it (``distance`` 0), or on ``source``, a class of it
    ``distance`` classes up from the gripper's own class (1)."""

    value: str
    source: str
    distance: int


def _limits(name: str, number: float) -> str:
    """Why ``number`` cannot be the ``name`` of a hand (empty if it can)."""
    if not math.isfinite(number):
        return "write a finite number"
    if name == "sideHoldFraction":
        return "" if 0.0 < number <= 1.0 else "a fraction of the object's depth, more than 0 and at most 1"
    if name == "sideGraspPitch":
        return "" if 0.0 <= number < math.pi / 2.0 else "radians down from level, at least 0 and below pi/2"
    if name in ("fingertipClearance", "jawClearance", "sidePalmLead"):
        return "" if number >= 0.0 else "a length in metres, at least 0"
    if name == "payloadKg":
        return "" if number > 0.0 else "a mass in kilograms, more than 0"
    return "" if number > 0.0 else "a length in metres, more than 0"


def _nearest(hand: str, arm: str, robot: str, name: str, stated: list[_Stated]) -> tuple[str, str] | None:
    """The value of ``name`` a gripper has, and the class it has it from (empty for its own): its own,
    else its nearest class's. :class:`HandError` for two values at the nearest distance."""
    if not stated:
        return None
    near = min(each.distance for each in stated)
    nearest = sorted({(each.value, each.source) for each in stated if each.distance == near})
    values = sorted({value for value, _ in nearest})
    if len(values) > 1:
        if near == 0:
            raise HandError(hand, arm, robot, name, " and ".join(values), "one value is needed")
        said = " and ".join(f"{local_name(source)} ({value})" for value, source in nearest)
        raise HandError(
            hand,
            arm,
            robot,
            name,
            " and ".join(values),
            f"its classes {said}, equally near it, disagree: state the value on the gripper, or on a class of it "
            "nearer than those",
        )
    return values[0], "" if near == 0 else nearest[0][1]


def _hand(hand: str, arm: str, robot: str, stated: dict[str, list[_Stated]], bands: list[StatedBands]) -> Hand:
    """The :class:`Hand` of what the store states of ``hand`` and its classes (property IRI -> values,
    and the bands of its arm it names)."""
    values: dict[str, float] = {}
    for name in _PROPERTIES:
        found = _nearest(hand, arm, robot, name, stated.get(HOME + name, []))
        if found is None:
            if name in _GEOMETRY:
                raise HandError(hand, arm, robot, name, None, f"a gripper states its geometry{_slip(name, stated)}")
            continue
        raw, source = found
        try:
            number = float(raw)
        except ValueError:
            raise HandError(hand, arm, robot, name, raw, "not a number", source) from None
        problem = _limits(name, number)
        if problem:
            raise HandError(hand, arm, robot, name, raw, problem, source)
        values[name] = number
    if values["palmDepth"] >= values["fingerLength"]:
        raise HandError(
            hand,
            arm,
            robot,
            "palmDepth",
            f"{values['palmDepth']:g}",
            f"the grasp point is between the fingertips, so the palm is nearer to it than the fingers are long "
            f"(home:fingerLength {values['fingerLength']:g})",
        )
    beyond = values["fingerLength"] - values["palmDepth"]  # how far the fingers reach past the grasp point
    if values.get("fingertipDepth", 0.0) > beyond + 1e-9:
        raise HandError(
            hand,
            arm,
            robot,
            "fingertipDepth",
            f"{values['fingertipDepth']:g}",
            f"the fingertips reach at most home:fingerLength less home:palmDepth below the grasp point ({beyond:g})",
        )
    if 2.0 * values.get("jawClearance", JAW_CLEARANCE) >= values["jawOpening"]:
        raise HandError(
            hand,
            arm,
            robot,
            "jawClearance",
            f"{values.get('jawClearance', JAW_CLEARANCE):g}",
            f"each jaw's clearance, twice over, must leave room within home:jawOpening {values['jawOpening']:g}",
        )
    return Hand(
        values["jawOpening"],
        values["palmDepth"],
        values["fingerLength"],
        values.get("sideHoldFraction", SIDE_HOLD),
        values.get("sideGraspPitch", SIDE_PITCH),
        values.get("pregraspDistance", PREGRASP_DISTANCE),
        hand,
        values.get("fingertipDepth", math.nan),
        values.get("fingertipClearance", FINGERTIP_CLEARANCE),
        values.get("jawClearance", JAW_CLEARANCE),
        values.get("carryCorridor", CARRY_CORRIDOR),
        _side_arm(hand, arm, robot, bands),
        values.get("sidePalmLead", SIDE_PALM_LEAD),
        values.get("payloadKg", PAYLOAD),
    )


def _side_arm(hand: str, arm: str, robot: str, stated: list[StatedBands]) -> tuple[ArmBand, ...]:
    """The bands of the arm behind ``hand``'s side grasp, back from the grasp point: those its nearest source
    names (itself, else its nearest class), each checked; :data:`PANDA_SIDE_ARM` when it names none.
    :class:`HandError` for equally near classes naming other bands, or a band no arm can have."""
    if not stated:
        return PANDA_SIDE_ARM
    near = [each for each in stated if each.distance == stated[0].distance]
    if any(each.bands != near[0].bands for each in near[1:]):
        said = " and ".join(
            f"{local_name(each.source)} ({', '.join(map(local_name, sorted(each.bands)))})" for each in near
        )
        raise HandError(
            hand,
            arm,
            robot,
            "sideGraspBand",
            " and ".join(sorted({local_name(band) for each in near for band in each.bands})),
            f"its classes {said}, equally near it, name other bands: name the bands on the gripper, or on a class "
            "of it nearer than those",
        )
    source = near[0].source if near[0].distance else ""
    bands = [_band(hand, arm, robot, band, values, source) for band, values in near[0].bands.items()]
    return tuple(sorted(bands, key=lambda band: (band.near, band.far, band.half_width, band.underside)))


def _band(hand: str, arm: str, robot: str, band: str, stated: dict[str, tuple[str, ...]], source: str) -> ArmBand:
    """The :class:`ArmBand` of what the store states of ``band``, one of ``hand``'s arm's bands."""
    numbers: dict[str, float] = {}
    for name in BAND_PROPERTIES:
        values = stated[name]
        if len(values) != 1:
            problem = (
                "one value is needed" if values else f"a band states all of home:{', home:'.join(BAND_PROPERTIES)}"
            )
            raise HandError(hand, arm, robot, name, " and ".join(values) or None, problem, source, band)
        try:
            numbers[name] = float(values[0])
        except ValueError:
            raise HandError(hand, arm, robot, name, values[0], "not a number", source, band) from None
    built = ArmBand(*numbers.values())
    name, problem = band_problem(built)
    if problem:
        raise HandError(hand, arm, robot, name, stated[name][0], problem, source, band)
    return built


def _slip(name: str, stated: dict[str, list[_Stated]]) -> str:
    """A did-you-mean for a missing ``name``: the property of the gripper or its classes it may be a
    misspelling of (home:jawOpenning), which the load took silently, being declared nowhere."""
    known = {HOME + other for other in (*_PROPERTIES, "sideGraspBand")}
    slip = nearest_term(HOME + name, [prop for prop in stated if prop not in known])
    if not slip:
        return ""
    first = min(stated[slip], key=lambda each: (each.distance, each.source, each.value))
    whose = f"its class {local_name(first.source)}'s" if first.distance else "its"
    return f" (did you mean home:{name} for {whose} home:{local_name(slip)} {first.value!r}?)"


def read_hands(kb: KnowledgeBase, robot: str | None = None) -> dict[str, Hand]:
    """Each arm's hand (by arm IRI) that the semantic map gives ``robot`` (every robot by default), by the
    named queries ``robot_hands`` and ``side_grasp_bands``: an arm with no ``home:hasGripper`` has
    :data:`PANDA_HAND`. Each value (and the set of bands of the arm behind a side grasp) is
    the gripper's own, else the one of the nearest of its classes (``rdf:type``, then ``rdfs:subClassOf``)
    that states it, so a gripper model's geometry is stated once on its class.
    :class:`HandError` for a gripper missing its geometry, stating a value no hand can have, or having two
    values of a property from equally near classes (:func:`_side_arm` for the bands)."""
    arms: dict[str, tuple[str, set[str]]] = {}
    stated: dict[str, dict[str, list[_Stated]]] = defaultdict(lambda: defaultdict(list))
    hand_rows, band_rows = kb.select_each(
        ["robot_hands", "side_grasp_bands"], {"robot": robot} if robot is not None else None
    )
    bands = stated_bands(band_rows)
    for row in hand_rows:
        arm = row["arm"].value
        owner, grippers = arms.setdefault(arm, (row["robot"].value, set()))
        if "hand" in row:
            grippers.add(row["hand"].value)
            if "property" in row:
                value = row["value"]
                shown = value.value if isinstance(value, Literal) else f"<{value.value}>"
                said = _Stated(shown, row["source"].value, int(row["distance"].value))
                stated[row["hand"].value][row["property"].value].append(said)
    hands = {}
    for arm, (owner, grippers) in sorted(arms.items()):
        if len(grippers) > 1:
            raise HandError(arm, arm, owner, "hasGripper", " and ".join(sorted(grippers)), "an arm ends in one gripper")
        if not grippers:
            hands[arm] = PANDA_HAND
            continue
        hand = grippers.pop()
        hands[arm] = _hand(hand, arm, owner, stated.get(hand, {}), bands.get(hand, []))
    return hands
