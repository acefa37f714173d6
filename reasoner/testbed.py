"""The paper's matchmaking testbed (section 6.1): 20 requirements and 100 service components.

The paper says only that it "generated a testing database including 20 requirements and 100 service
components" and "selected some testing pairs of Advertisements and Requirements in which their IOPE
entities were not given with exactly the same strings", with Position and Location (both x, y, theta)
as the example. This module rebuilds such a database for the home-care domain of ``ontologies/`` from
rules fixed before any method was run on it. ``python -m reasoner.testbed`` writes
``reasoner/data/paper_testbed.ttl`` and ``reasoner/data/paper_testbed_truth.json``; the same seed gives
byte-identical files.

Rules of the testbed
--------------------

T1. Twenty requirement intents of home-care robots (the catalogue ``INTENTS`` below), each one
    requirement in the shape of ``ontologies/requirements.ttl``: requester, DN, SN, SC and IOPE.
    Requirements state no SEA and no QoS bounds: the SEA/QoS filters act the same for every method
    and section 6.1 measures the matching of IOPE entities.
T2. Every intent has one to three relevant advertisements, 42 in all. A relevant advertisement does
    what the requester asks, can be invoked with what the requester offers (each of its inputs is one
    of the offered concepts, a superclass of one, or a variant of one by a rule below) and, where the
    requirement states an effect, has an effect that says the same thing (possibly with sub- or
    superclass terms).
T3. No relevant pair shares the exact string of its decisive entity: the requested output, or for a
    requirement without outputs the effect (or input) that varies. Each relevant pair exercises one
    naming variation on that entity, recorded in the truth file:

    - ``synonym-sibling``: another word for the same thing, declared next to the requested concept
      (neither subsumes the other, they meet at most two is-a links above each) with the same parts,
      if any. Position vs Location, RobotPosition vs RobotLocation.
    - ``subclass``: a differently named, more specific declared concept (OccupancyGridMap for GridMap).
    - ``superclass``: a differently named, more general declared concept (Temperature for
      RoomTemperature): accepted by the paper's threshold {Exact, SubClassOf, HasSubClass}.
    - ``reworded-compound``: the requested concept's words with the head word moved, joined by a
      linking word (TemperatureOfRoom for RoomTemperature, like home:ColourOfMarker for
      MarkerColour); the testbed declares it as a subclass of the concept it rewords.
    - ``undeclared``: a concept declared in no ontology (only used as a parameter type), so that no
      taxonomy information exists and only the name can help; it keeps the head word of the concept
      it stands for (ResidentLocation for PersonLocation).
    - ``parts-not-wholes``: the whole concepts are different kinds of thing (they meet more than two
      is-a links above one of them, or only at the root) but every part of the requested concept
      has an equal or is-a related part in the advertised one (a 3D bounding box for an object's 3D
      position, GoalPose for PersonLocation, a map image with resolution and origin for a grid map).

    The mix is fixed by the catalogue: 8 synonym-sibling, 8 subclass, 4 superclass, 8
    reworded-compound, 7 undeclared, 7 parts-not-wholes. The paper's own example (same parts under
    another name) and naming variation weigh most; a superclass offer is rarer because it is less
    specific than asked.
T4. The other 58 advertisements are distractors written for one intent each (and every advertisement
    of another intent is a distractor too). Their kinds: ``same-words`` (shares words with the
    request but is another thing: PersonPosition when the robot's position is wanted),
    ``same-family`` (a sibling concept of the same family: a topological map for a grid map),
    ``wrong-inputs`` (the requested output, or nearly, from inputs the requester cannot provide),
    ``other-output`` (takes what the requester offers, returns something else), ``consumes-it``
    (takes the requested concept as input) and ``wrong-effect`` (acts on the same things with another
    effect). No distractor is relevant to any intent.
T5. New concepts are declared in the testbed file under ``tb:`` as subclasses of home classes, with
    their parts restated as existential hasPart restrictions (the home.ttl convention).
T6. The seed decides only what does not change relevance: which device of a pool hosts each
    service (and so its SEA), its QoS figures, and the numbers in the advertisement IRIs
    (``tb:A017_...``), which decide ties in the matchmaker's ordering. The catalogue order, the
    IOPE of every description and the truth never depend on it.

The data was not adjusted after seeing any method's scores.
"""

from __future__ import annotations

import argparse
import json
import random
import re
import sys
from collections import Counter
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from kb import Advertisement, KnowledgeBase, PartNode, Requirement, ServiceDescription, Store
from kb.namespaces import GraphName
from kb.resources import bundled_files
from reasoner.names import local_name, words
from reasoner.taxonomy import ROOT, TaxonomyIndex

TB = "https://w3id.org/cbrs/testbed#"
HOME = "https://w3id.org/cbrs/home#"
CBRS = "https://w3id.org/cbrs/core#"
SEED = 61
DATA_DIR = Path(__file__).resolve().parent / "data"
TESTBED_FILE = DATA_DIR / "paper_testbed.ttl"
TRUTH_FILE = DATA_DIR / "paper_testbed_truth.json"

RULES: dict[str, str] = {
    "synonym-sibling": "another word for the same thing, declared beside the requested concept, same parts",
    "subclass": "a differently named, more specific declared concept",
    "superclass": "a differently named, more general declared concept",
    "reworded-compound": "the same words with the head word moved and a linking word (TemperatureOfRoom)",
    "undeclared": "a concept declared nowhere, keeping the head word; only its name can help",
    "parts-not-wholes": "wholes of different kinds, the requested parts all found among the advertised parts",
}

DISTRACTOR_KINDS: dict[str, str] = {
    "same-words": "shares words with the requested concept but is another thing",
    "same-family": "a sibling concept of the same family, not the one asked for",
    "wrong-inputs": "the requested output, or nearly, from inputs the requester cannot provide",
    "other-output": "takes what the requester offers and returns something else",
    "consumes-it": "takes the requested concept as an input instead of producing it",
    "wrong-effect": "acts on the same things with another effect",
}

_KINDS = {
    "DPC": "cbrs:DynamicPerceptionComponent",
    "SDC": "cbrs:StaticDataComponent",
    "PMC": "cbrs:PhysicalManipulationComponent",
    "MIC": "cbrs:MethodInvocationComponent",
}

# Floor plan shared with ontologies/services.ttl: place concept and bounding box (min x, max x, min y, max y).
_AREAS: dict[str, tuple[str, float, float, float, float]] = {
    "LivingRoom": ("home:LivingRoom", 0.0, 6.0, 0.0, 5.0),
    "Kitchen": ("home:Kitchen", 6.0, 10.0, 0.0, 5.0),
    "Bedroom": ("home:Bedroom", 0.0, 6.0, 5.0, 9.0),
    "Home": ("home:Home", 0.0, 10.0, 0.0, 9.0),
    "KitchenTable": ("home:Kitchen", 7.0, 8.5, 3.0, 4.5),
}

Triple = tuple[str, str, str]


# --------------------------------------------------------------------------------------------------
# Catalogue types
# --------------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class NewClass:
    """A concept the testbed declares: its parent home class and its parts (property, class)."""

    name: str
    parent: str
    comment: str
    parts: tuple[tuple[str, str], ...] = ()


@dataclass(frozen=True)
class Device:
    name: str
    cls: str
    area: str
    comment: str


@dataclass(frozen=True)
class Ad:
    """An advertisement template: everything but its host, QoS and IRI number."""

    service: str
    kind: str
    hosts: tuple[str, ...]
    category: str
    inputs: tuple[str, ...] = ()
    outputs: tuple[str, ...] = ()
    preconditions: tuple[Triple, ...] = ()
    effects: tuple[Triple, ...] = ()
    port: str = "data"


@dataclass(frozen=True)
class Relevant:
    ad: Ad
    rule: str
    role: str  # which entity carries the variation: output, input, effect subject, effect object
    requested: str
    advertised: str
    why: str


@dataclass(frozen=True)
class Distractor:
    ad: Ad
    kind: str
    why: str


@dataclass(frozen=True)
class Intent:
    key: str
    title: str
    requester: str
    category: str
    comment: str
    relevant: tuple[Relevant, ...]
    distractors: tuple[Distractor, ...]
    inputs: tuple[str, ...] = ()
    outputs: tuple[str, ...] = ()
    preconditions: tuple[Triple, ...] = ()
    effects: tuple[Triple, ...] = ()


def _ad(
    service: str,
    kind: str,
    hosts: tuple[str, ...],
    category: str,
    *,
    ins: tuple[str, ...] = (),
    outs: tuple[str, ...] = (),
    pre: tuple[Triple, ...] = (),
    eff: tuple[Triple, ...] = (),
    port: str = "data",
) -> Ad:
    return Ad(service, _KINDS[kind], hosts, category, ins, outs, pre, eff, port)


# --------------------------------------------------------------------------------------------------
# Devices (host pools)
# --------------------------------------------------------------------------------------------------

DEVICES: tuple[Device, ...] = (
    Device("CeilingCamera11", "home:CeilingCamera", "LivingRoom", "Global camera on the living-room ceiling."),
    Device("CeilingCamera12", "home:CeilingCamera", "Kitchen", "Global camera on the kitchen ceiling."),
    Device("CeilingCamera13", "home:CeilingCamera", "Bedroom", "Global camera on the bedroom ceiling."),
    Device("WebCamera11", "home:WebCamera", "LivingRoom", "Network camera on the living-room shelf."),
    Device("WebCamera12", "home:WebCamera", "Bedroom", "Network camera in the bedroom."),
    Device("Kinect11", "home:KinectSensor", "KitchenTable", "Kinect calibrated to the dual-arm robot."),
    Device("LaserScanner11", "home:LaserScanner", "Kitchen", "Planar laser on the kitchen wall."),
    Device("SensorBoard11", "home:EnvironmentalSensorBoard", "LivingRoom", "Cortex-M3 board, living room."),
    Device("SensorBoard12", "home:EnvironmentalSensorBoard", "Kitchen", "Cortex-M3 board, kitchen."),
    Device("SensorBoard13", "home:EnvironmentalSensorBoard", "Bedroom", "Cortex-M3 board, bedroom."),
    Device("DoorSensor11", "home:DoorSensor", "LivingRoom", "Reed contact on the living-room door."),
    Device("DoorSensor12", "home:DoorSensor", "Bedroom", "Reed contact on the bedroom door."),
    Device("Microphone11", "home:Microphone", "LivingRoom", "Microphone array in the living room."),
    Device("Thermostat11", "home:Sensor", "LivingRoom", "Wall thermostat in the living room."),
    Device("WearableSensor11", "home:Sensor", "Home", "Wrist-worn motion sensor of the resident."),
    Device("HomeServer11", "home:Server", "Home", "The home server: knowledge, maps and planners."),
    Device("CloudServer11", "home:Server", "Home", "A cloud service reached through the home gateway."),
    Device("CytonDualArm11", "home:DualArmRobot", "KitchenTable", "Dual-arm robot at the kitchen table."),
    Device("P3DX11", "home:CarrierRobot", "Home", "Pioneer 3-DX carrier robot with a colour marker."),
    Device("CareRobot11", "home:MobileRobot", "Home", "Mobile care robot that watches over the resident."),
    Device("DoorOpener11", "home:Device", "LivingRoom", "Motorised opener of the living-room door."),
    Device("DoorOpener12", "home:Device", "Bedroom", "Motorised opener of the bedroom door."),
    Device("Speaker11", "home:Speaker", "LivingRoom", "Loudspeaker in the living room."),
    Device("ChargingDock11", "home:Device", "LivingRoom", "Charging dock of the mobile robots."),
)

CEILING = ("CeilingCamera11", "CeilingCamera12", "CeilingCamera13")
WEBCAM = ("WebCamera11", "WebCamera12")
BOARD = ("SensorBoard11", "SensorBoard12", "SensorBoard13")
SERVER = ("HomeServer11", "CloudServer11")
DOORSENSOR = ("DoorSensor11", "DoorSensor12")
OPENER = ("DoorOpener11", "DoorOpener12")
KINECT = ("Kinect11",)
ARM = ("CytonDualArm11",)
P3DX = ("P3DX11",)

# --------------------------------------------------------------------------------------------------
# New concepts (rule T5)
# --------------------------------------------------------------------------------------------------

_XY_THETA = (
    ("home:hasXCoordinate", "home:XCoordinate"),
    ("home:hasYCoordinate", "home:YCoordinate"),
    ("home:hasOrientation", "home:Theta"),
)
_POSE3D = (("home:hasPosition", "home:Point3D"), ("home:hasRotation", "home:Quaternion"))
_STAMP = (("home:hasTimestamp", "home:Timestamp"),)
_COLOUR_FEATURE = (("home:hasColour", "home:Colour"), ("home:hasHue", "home:Hue"))
_NAMES = (("home:hasFamilyName", "home:FamilyName"), ("home:hasGivenName", "home:GivenName"))
_STREAM = (("home:hasFrame", "home:RGBImage"), ("home:hasResolution", "home:Resolution"))

NEW_CLASSES: tuple[NewClass, ...] = (
    # used by relevant advertisements
    NewClass(
        "MapImage",
        "home:Image",
        "A floor-plan image with its cell size and origin, as a map server stores a map on disk.",
        (
            ("home:hasResolution", "home:Resolution"),
            ("home:hasOrigin", "home:MapOrigin"),
            ("home:hasWidth", "home:Width"),
            ("home:hasHeight", "home:Height"),
            *_STAMP,
        ),
    ),
    NewClass(
        "BoundingBox3D",
        "home:Measurement",
        "The box around a recognised object: its centre (x, y, z), its yaw and its size.",
        (*_XY_THETA, ("home:hasZCoordinate", "home:ZCoordinate"), ("home:hasSize", "home:ObjectSize")),
    ),
    NewClass("PathToGoal", "home:Path", "A path worded from its goal.", (("home:hasWaypoint", "home:Waypoint"),)),
    NewClass("PoseOfGrasp", "home:GraspPose", "A grasp pose worded the other way round.", _POSE3D),
    NewClass("GripperTarget", "home:MotionData", "The pose a gripper is sent to: a 3D point and a rotation.", _POSE3D),
    NewClass("TemperatureOfRoom", "home:RoomTemperature", "A room temperature worded the other way round.", _STAMP),
    NewClass("RelativeHumidity", "home:Humidity", "Humidity as a percentage of saturation.", _STAMP),
    NewClass("HumidityOfRoom", "home:Humidity", "The humidity of a room, worded with the room last.", _STAMP),
    NewClass("StatusOfDoor", "home:DoorStatus", "A door status worded the other way round."),
    NewClass("DoorState", "home:Status", "Whether a door is open or shut: another word for door status."),
    NewClass(
        "ElderlyFallEvent",
        "home:FallDownEvent",
        "A fall of an elderly resident.",
        (*_STAMP, ("home:hasPosition", "home:PersonPosition")),
    ),
    NewClass(
        "FallAlert",
        "home:AlarmMessage",
        "A notification that someone fell, with when and where.",
        (*_STAMP, ("home:hasPosition", "home:PersonPosition")),
    ),
    NewClass("ColourHistogram", "home:ColourFeature", "A colour feature given as a hue histogram.", _COLOUR_FEATURE),
    NewClass("ColourModel", "home:ObjectKnowledge", "Stored knowledge of an object kind's colour.", _COLOUR_FEATURE),
    NewClass("CameraFeed", "home:SensorData", "A live feed of camera frames: another word for video stream.", _STREAM),
    NewClass("StreamOfVideo", "home:VideoStream", "A video stream worded the other way round.", _STREAM),
    NewClass("PlaceOfObject", "home:ObjectPlace", "An object place worded the other way round."),
    NewClass("StoragePlace", "home:Region", "Where a thing is kept: another word for object place."),
    NewClass("LevelOfBattery", "home:BatteryLevel", "A battery level worded the other way round."),
    NewClass("DailyActivity", "home:HumanActivity", "An activity of daily living.", _STAMP),
    NewClass("PersonBehaviour", "home:Event", "What a person is doing: another word for human activity.", _STAMP),
    NewClass("PersonRecord", "home:PersonalData", "A person's record of names: another word for profile.", _NAMES),
    NewClass(
        "HingedDoor",
        "home:Door",
        "A door that swings on hinges.",
        (("home:hasHandle", "home:Handle"), ("home:hasStatus", "home:DoorStatus")),
    ),
    NewClass("UnderSpout", "home:Region", "The region under the dispenser's spout: another word for below of tap."),
    # used by distractors
    NewClass(
        "GripperPosition",
        "home:Position3D",
        "Where a robot's gripper is (x, y, z, theta).",
        (*_XY_THETA, ("home:hasZCoordinate", "home:ZCoordinate")),
    ),
    NewClass("PersonCount", "home:Measurement", "How many people are in a room."),
    NewClass("JointTrajectory", "home:MotionData", "Timed joint angles for an arm.", _STAMP),
    NewClass("WaterTemperature", "home:Temperature", "The temperature of the dispenser's water.", _STAMP),
    NewClass("OutdoorTemperature", "home:Temperature", "The temperature outside the home.", _STAMP),
    NewClass("BatteryTemperature", "home:Temperature", "The temperature of a robot's battery.", _STAMP),
    NewClass("HighHumidityAlarmEvent", "home:AlarmEvent", "A room is too humid.", _STAMP),
    NewClass("WindowStatus", "home:Status", "Whether a window is open."),
    NewClass("RobotActivity", "home:RobotStatus", "What a robot is doing."),
)

# Concepts used as parameter or statement types that no ontology declares (rule "undeclared").
UNDECLARED = (
    "tb:MobileRobotPosition",
    "tb:ResidentLocation",
    "tb:IndoorTemperature",
    "tb:PersonFallDownEvent",
    "tb:BatteryChargeLevel",
    "tb:ObstacleEvent",
    "tb:FullyOpened",
)

# --------------------------------------------------------------------------------------------------
# The twenty intents (rules T1-T4)
# --------------------------------------------------------------------------------------------------

_MARKER_PRE: Triple = ("home:MobileRobot", "home:hasMarker", "home:ColourMarker")
_LOCALISED_PRE: Triple = ("home:MobileRobot", "home:isLocalisedIn", "home:Room")
_GRASPED_PRE: Triple = ("home:PhysicalObject", "home:isGraspedBy", "home:Gripper")

INTENTS: tuple[Intent, ...] = (
    Intent(
        "RobotSelfPosition",
        "robot self-position",
        "P3DX11",
        "Localisation",
        "The carrier robot has no sensors for self-localisation; it offers the colour of its marker "
        "and asks for its own position (the paper's Table 2).",
        inputs=("home:ColourOfMarker",),
        outputs=("home:RobotPosition",),
        preconditions=(_MARKER_PRE,),
        relevant=(
            Relevant(
                _ad(
                    "LocateMobileRobot",
                    "DPC",
                    CEILING,
                    "Localisation",
                    ins=("home:MarkerColour",),
                    outs=("home:RobotLocation",),
                    pre=(_MARKER_PRE,),
                    eff=(("home:MobileRobot", "home:isLocalisedIn", "home:Room"),),
                ),
                "synonym-sibling",
                "output",
                "home:RobotPosition",
                "home:RobotLocation",
                "a ceiling camera finds the marker colour and publishes the robot's location; Location is "
                "Position's sibling with the same x, y, theta parts (the paper's example)",
            ),
            Relevant(
                _ad(
                    "TrackRobotMarker",
                    "DPC",
                    WEBCAM,
                    "Localisation",
                    ins=("home:MarkerColour",),
                    outs=("tb:MobileRobotPosition",),
                    pre=(_MARKER_PRE,),
                ),
                "undeclared",
                "output",
                "home:RobotPosition",
                "tb:MobileRobotPosition",
                "a web camera tracks the robot's marker; its output type is declared nowhere, only the "
                "name says it is a robot's position",
            ),
        ),
        distractors=(
            Distractor(
                _ad(
                    "EstimateRobotPositionFromSonar",
                    "MIC",
                    SERVER,
                    "Localisation",
                    ins=("home:SonarReading", "home:OccupancyGridMap"),
                    outs=("home:RobotPosition",),
                    port="service",
                ),
                "wrong-inputs",
                "the exact output, but from sonar readings and a map the robot does not have",
            ),
            Distractor(
                _ad(
                    "DetectColourMarker",
                    "DPC",
                    CEILING,
                    "MarkerDetection",
                    ins=("home:RGBImage",),
                    outs=("home:ColourMarker",),
                    port="service",
                ),
                "same-words",
                "reports a colour marker found in an image, not a position",
            ),
            Distractor(
                _ad("ReportGripperPosition", "DPC", ARM, "Proprioception", outs=("tb:GripperPosition",)),
                "same-words",
                "a robot position of another kind: where the arm's gripper is",
            ),
            Distractor(
                _ad(
                    "LocaliseRobotByLaser",
                    "MIC",
                    ("LaserScanner11",),
                    "Localisation",
                    ins=("home:LaserScan", "home:OccupancyGridMap"),
                    outs=("home:RobotPose",),
                ),
                "wrong-inputs",
                "a robot pose, but from a laser scan and a map the requester cannot give",
            ),
        ),
    ),
    Intent(
        "PersonLocation",
        "person position",
        "CareRobot11",
        "PeopleTracking",
        "The care robot asks where the elderly resident is.",
        inputs=("home:ElderlyPerson",),
        outputs=("home:PersonLocation",),
        relevant=(
            Relevant(
                _ad(
                    "TrackPerson", "DPC", CEILING, "PeopleTracking", ins=("home:Person",), outs=("home:PersonPosition",)
                ),
                "synonym-sibling",
                "output",
                "home:PersonLocation",
                "home:PersonPosition",
                "a ceiling camera tracks people; PersonPosition and PersonLocation are siblings with the same parts",
            ),
            Relevant(
                _ad(
                    "LocateResidentBySound",
                    "DPC",
                    ("Microphone11",),
                    "PeopleTracking",
                    ins=("home:Person",),
                    outs=("tb:ResidentLocation",),
                ),
                "undeclared",
                "output",
                "home:PersonLocation",
                "tb:ResidentLocation",
                "a microphone array localises the speaking resident; the output type is declared nowhere",
            ),
        ),
        distractors=(
            Distractor(
                _ad(
                    "EstimatePersonPositionFromImage",
                    "MIC",
                    SERVER,
                    "PeopleTracking",
                    ins=("home:RGBImage",),
                    outs=("home:PersonPosition",),
                    port="service",
                ),
                "wrong-inputs",
                "a person's position, but from an image the requester does not offer",
            ),
            Distractor(
                _ad(
                    "InferObjectLocation",
                    "SDC",
                    SERVER,
                    "ObjectKnowledge",
                    ins=("home:PhysicalObject",),
                    outs=("home:ObjectLocation",),
                    port="service",
                ),
                "same-words",
                "a location, but of an object",
            ),
            Distractor(
                _ad("CountPeople", "DPC", CEILING, "PeopleTracking", outs=("tb:PersonCount",)),
                "same-words",
                "counts people instead of locating one",
            ),
            Distractor(
                _ad(
                    "DetectPersonEntering",
                    "DPC",
                    DOORSENSOR,
                    "EventDetection",
                    outs=("home:PersonEnteredRoomEvent",),
                    port="event",
                ),
                "same-family",
                "an event about a person entering a room, not where she is",
            ),
        ),
    ),
    Intent(
        "ObjectPosition3D",
        "object 3D position",
        "CytonDualArm11",
        "ObjectRecognition",
        "The dual-arm robot knows the cup's colour feature and asks for the cup's 3D position.",
        inputs=("home:ColourFeature",),
        outputs=("home:ObjectPosition3D",),
        relevant=(
            Relevant(
                _ad(
                    "LocateObjectByColour",
                    "MIC",
                    KINECT,
                    "ObjectRecognition",
                    ins=("home:ColourFeature",),
                    outs=("home:Position3D",),
                    port="service",
                ),
                "superclass",
                "output",
                "home:ObjectPosition3D",
                "home:Position3D",
                "the Kinect segments the colour and returns a 3D position, the more general concept",
            ),
            Relevant(
                _ad(
                    "DetectObjectBox",
                    "MIC",
                    KINECT,
                    "ObjectRecognition",
                    ins=("home:ColourFeature",),
                    outs=("tb:BoundingBox3D",),
                    port="service",
                ),
                "parts-not-wholes",
                "output",
                "home:ObjectPosition3D",
                "tb:BoundingBox3D",
                "a 3D bounding box (a measurement, not a Position) whose centre x, y, z and yaw are the parts "
                "of the object's 3D position",
            ),
        ),
        distractors=(
            Distractor(
                _ad(
                    "LocateObjectInPointCloud",
                    "MIC",
                    KINECT,
                    "ObjectRecognition",
                    ins=("home:PointCloud", "home:ObjectType"),
                    outs=("home:ObjectPosition3D",),
                    port="service",
                ),
                "wrong-inputs",
                "the exact output, but from a point cloud and an object type",
            ),
            Distractor(
                _ad(
                    "MeasureObjectSize",
                    "MIC",
                    KINECT,
                    "ObjectRecognition",
                    ins=("home:ColourFeature",),
                    outs=("home:ObjectSize",),
                    port="service",
                ),
                "other-output",
                "takes the colour feature, returns the object's size",
            ),
            Distractor(
                _ad(
                    "LocateObjectOnFloorPlan",
                    "MIC",
                    CEILING,
                    "ObjectRecognition",
                    ins=("home:ColourFeature",),
                    outs=("home:Position2D",),
                    port="service",
                ),
                "same-words",
                "a position on the floor plane, without the height a grasp needs",
            ),
        ),
    ),
    Intent(
        "GridMap",
        "grid map",
        "P3DX11",
        "Mapping",
        "The carrier robot needs a grid map of the home for planning.",
        outputs=("home:GridMap",),
        relevant=(
            Relevant(
                _ad("ProvideOccupancyGrid", "SDC", SERVER, "Mapping", outs=("home:OccupancyGridMap",)),
                "subclass",
                "output",
                "home:GridMap",
                "home:OccupancyGridMap",
                "the map server's occupancy grid, a kind of grid map",
            ),
            Relevant(
                _ad("ServeFloorPlanImage", "SDC", SERVER, "Mapping", outs=("tb:MapImage",)),
                "parts-not-wholes",
                "output",
                "home:GridMap",
                "tb:MapImage",
                "an image (not a Map) that carries the resolution and origin of a grid map",
            ),
        ),
        distractors=(
            Distractor(
                _ad("ProvideTopologicalMap", "SDC", SERVER, "Mapping", outs=("home:TopologicalMap",)),
                "same-family",
                "a graph of waypoints, not a grid",
            ),
            Distractor(
                _ad("ProvideSemanticMap", "SDC", SERVER, "Mapping", outs=("home:SemanticMap",)),
                "same-family",
                "names rooms and furniture, not cells",
            ),
            Distractor(
                _ad(
                    "BuildMapBySLAM",
                    "MIC",
                    SERVER,
                    "Mapping",
                    ins=("home:LaserScan", "home:OdometryPose"),
                    outs=("home:OccupancyGridMap",),
                    port="service",
                ),
                "wrong-inputs",
                "builds a grid map, but from laser scans and odometry the robot does not have",
            ),
        ),
    ),
    Intent(
        "Path",
        "path",
        "P3DX11",
        "PathPlanning",
        "The carrier robot offers its position, a goal and an occupancy grid and asks for a path.",
        inputs=("home:RobotPosition", "home:GoalPose", "home:OccupancyGridMap"),
        outputs=("home:Path",),
        relevant=(
            Relevant(
                _ad(
                    "PlanTrajectory",
                    "MIC",
                    SERVER,
                    "PathPlanning",
                    ins=("home:StartPose", "home:GoalPose", "home:OccupancyGridMap"),
                    outs=("home:Trajectory",),
                    port="service",
                ),
                "subclass",
                "output",
                "home:Path",
                "home:Trajectory",
                "a timed path; its start pose is the robot position by parts",
            ),
            Relevant(
                _ad(
                    "PlanRoute",
                    "MIC",
                    SERVER,
                    "PathPlanning",
                    ins=("home:RobotLocation", "home:GoalPose", "home:GridMap"),
                    outs=("tb:PathToGoal",),
                    port="service",
                ),
                "reworded-compound",
                "output",
                "home:Path",
                "tb:PathToGoal",
                "the path worded from its goal; takes the robot location (synonym of its position) and any grid map",
            ),
        ),
        distractors=(
            Distractor(
                _ad(
                    "PlanArmMotion",
                    "MIC",
                    ARM,
                    "MotionPlanning",
                    ins=("home:GraspPose",),
                    outs=("tb:JointTrajectory",),
                    port="service",
                ),
                "same-words",
                "a trajectory of arm joints, not a path through the home",
            ),
            Distractor(
                _ad(
                    "FollowPath",
                    "PMC",
                    P3DX,
                    "Navigation",
                    ins=("home:Path",),
                    outs=("home:VelocityCommand",),
                    port="service",
                ),
                "consumes-it",
                "takes a path and drives along it",
            ),
            Distractor(
                _ad(
                    "ComputeDistanceToGoal",
                    "MIC",
                    SERVER,
                    "PathPlanning",
                    ins=("home:RobotPosition", "home:GoalPose"),
                    outs=("home:Distance",),
                    port="service",
                ),
                "other-output",
                "takes the robot position and goal, returns only the distance",
            ),
        ),
    ),
    Intent(
        "GraspPose",
        "grasp pose",
        "CytonDualArm11",
        "Manipulation",
        "The dual-arm robot offers the cup and its 3D position and asks how to grasp it.",
        inputs=("home:Cup", "home:ObjectPosition3D"),
        outputs=("home:GraspPose",),
        relevant=(
            Relevant(
                _ad(
                    "ComputeGraspPose",
                    "MIC",
                    SERVER,
                    "Manipulation",
                    ins=("home:PhysicalObject", "home:ObjectPosition3D"),
                    outs=("tb:PoseOfGrasp",),
                    port="service",
                ),
                "reworded-compound",
                "output",
                "home:GraspPose",
                "tb:PoseOfGrasp",
                "a grasp planner whose output is worded 'pose of grasp'",
            ),
            Relevant(
                _ad(
                    "PlanGripperTarget",
                    "MIC",
                    ARM,
                    "Manipulation",
                    ins=("home:PhysicalObject", "home:Position3D"),
                    outs=("tb:GripperTarget",),
                    port="service",
                ),
                "parts-not-wholes",
                "output",
                "home:GraspPose",
                "tb:GripperTarget",
                "motion data (not a Pose) with the grasp pose's 3D point and quaternion",
            ),
        ),
        distractors=(
            Distractor(
                _ad(
                    "ClassifyGraspType",
                    "SDC",
                    SERVER,
                    "ObjectKnowledge",
                    ins=("home:PhysicalObject",),
                    outs=("home:GraspType",),
                    port="service",
                ),
                "same-words",
                "which kind of grasp suits the object, not where to grasp",
            ),
            Distractor(
                _ad(
                    "QueryManipulationProperty",
                    "SDC",
                    SERVER,
                    "ObjectKnowledge",
                    ins=("home:PhysicalObject",),
                    outs=("home:ManipulationProperty",),
                    port="service",
                ),
                "other-output",
                "the object's grasp type, size and weight",
            ),
            Distractor(
                _ad(
                    "ComputeGraspFromPointCloud",
                    "MIC",
                    KINECT,
                    "Manipulation",
                    ins=("home:PointCloud",),
                    outs=("home:GraspPose",),
                    port="service",
                ),
                "wrong-inputs",
                "the exact output, but from a point cloud the requester does not offer",
            ),
        ),
    ),
    Intent(
        "RoomTemperature",
        "room temperature",
        "CareRobot11",
        "EnvironmentMonitoring",
        "The care robot asks for the room temperature.",
        outputs=("home:RoomTemperature",),
        relevant=(
            Relevant(
                _ad("ReadTemperature", "DPC", BOARD, "EnvironmentMonitoring", outs=("home:Temperature",)),
                "superclass",
                "output",
                "home:RoomTemperature",
                "home:Temperature",
                "a room's sensor board advertises plain temperature",
            ),
            Relevant(
                _ad("ReportRoomClimate", "DPC", BOARD, "EnvironmentMonitoring", outs=("tb:TemperatureOfRoom",)),
                "reworded-compound",
                "output",
                "home:RoomTemperature",
                "tb:TemperatureOfRoom",
                "the room temperature worded the other way round",
            ),
            Relevant(
                _ad(
                    "ReadThermostat", "DPC", ("Thermostat11",), "EnvironmentMonitoring", outs=("tb:IndoorTemperature",)
                ),
                "undeclared",
                "output",
                "home:RoomTemperature",
                "tb:IndoorTemperature",
                "the thermostat's indoor temperature, a type declared nowhere",
            ),
        ),
        distractors=(
            Distractor(
                _ad(
                    "MonitorWaterTemperature",
                    "DPC",
                    ("SensorBoard12",),
                    "EnvironmentMonitoring",
                    outs=("tb:WaterTemperature",),
                ),
                "same-words",
                "the temperature of the dispenser's water",
            ),
            Distractor(
                _ad(
                    "RaiseTemperatureAlarm",
                    "DPC",
                    BOARD,
                    "EventDetection",
                    outs=("home:HighTemperatureAlarmEvent",),
                    port="event",
                ),
                "same-words",
                "an alarm when it is too hot, not the temperature",
            ),
            Distractor(
                _ad(
                    "ForecastOutdoorTemperature",
                    "SDC",
                    ("CloudServer11",),
                    "Weather",
                    outs=("tb:OutdoorTemperature",),
                    port="service",
                ),
                "same-words",
                "the temperature outside",
            ),
        ),
    ),
    Intent(
        "Humidity",
        "humidity",
        "CareRobot11",
        "EnvironmentMonitoring",
        "The care robot asks for the air humidity.",
        outputs=("home:Humidity",),
        relevant=(
            Relevant(
                _ad("ReadHumidity", "DPC", BOARD, "EnvironmentMonitoring", outs=("tb:RelativeHumidity",)),
                "subclass",
                "output",
                "home:Humidity",
                "tb:RelativeHumidity",
                "relative humidity, a kind of humidity",
            ),
            Relevant(
                _ad("ReportRoomHumidity", "DPC", BOARD, "EnvironmentMonitoring", outs=("tb:HumidityOfRoom",)),
                "reworded-compound",
                "output",
                "home:Humidity",
                "tb:HumidityOfRoom",
                "'humidity of room': the head word is now 'room'",
            ),
        ),
        distractors=(
            Distractor(
                _ad("MeasureCO2", "DPC", BOARD, "EnvironmentMonitoring", outs=("home:CO2Concentration",)),
                "same-family",
                "another environmental measure",
            ),
            Distractor(
                _ad("MeasureIlluminance", "DPC", BOARD, "EnvironmentMonitoring", outs=("home:Illuminance",)),
                "same-family",
                "another environmental measure",
            ),
            Distractor(
                _ad(
                    "RaiseHumidityAlarm",
                    "DPC",
                    BOARD,
                    "EventDetection",
                    outs=("tb:HighHumidityAlarmEvent",),
                    port="event",
                ),
                "same-words",
                "an alarm when it is too humid, not the humidity",
            ),
        ),
    ),
    Intent(
        "DoorStatus",
        "door status",
        "CareRobot11",
        "EnvironmentMonitoring",
        "The care robot asks whether the door is open or closed.",
        outputs=("home:DoorStatus",),
        relevant=(
            Relevant(
                _ad("ReadDoorContact", "DPC", DOORSENSOR, "EnvironmentMonitoring", outs=("tb:StatusOfDoor",)),
                "reworded-compound",
                "output",
                "home:DoorStatus",
                "tb:StatusOfDoor",
                "the door contact's status worded the other way round",
            ),
            Relevant(
                _ad("WatchDoor", "DPC", CEILING, "EnvironmentMonitoring", outs=("tb:DoorState",)),
                "synonym-sibling",
                "output",
                "home:DoorStatus",
                "tb:DoorState",
                "a camera reports the door's state, a sibling of door status",
            ),
        ),
        distractors=(
            Distractor(
                _ad("ReportRobotStatus", "DPC", P3DX, "RobotMonitoring", outs=("home:RobotStatus",)),
                "same-words",
                "a status, but of a robot",
            ),
            Distractor(
                _ad("ReportApplianceStatus", "DPC", BOARD, "EnvironmentMonitoring", outs=("home:DeviceStatus",)),
                "same-words",
                "a status, but of appliances",
            ),
            Distractor(
                _ad("ReadWindowContact", "DPC", DOORSENSOR, "EnvironmentMonitoring", outs=("tb:WindowStatus",)),
                "same-words",
                "a status, but of a window",
            ),
        ),
    ),
    Intent(
        "FallDownAlarm",
        "fall-down alarm",
        "CareRobot11",
        "EventDetection",
        "The care robot subscribes to fall-down events of the resident.",
        outputs=("home:FallDownEvent",),
        relevant=(
            Relevant(
                _ad("DetectFall", "DPC", CEILING, "EventDetection", outs=("tb:ElderlyFallEvent",), port="event"),
                "subclass",
                "output",
                "home:FallDownEvent",
                "tb:ElderlyFallEvent",
                "falls of elderly people, a kind of fall-down event",
            ),
            Relevant(
                _ad(
                    "DetectFallByWearable",
                    "DPC",
                    ("WearableSensor11",),
                    "EventDetection",
                    outs=("tb:PersonFallDownEvent",),
                    port="event",
                ),
                "undeclared",
                "output",
                "home:FallDownEvent",
                "tb:PersonFallDownEvent",
                "a wrist sensor's fall event, a type declared nowhere",
            ),
            Relevant(
                _ad("SendFallAlert", "MIC", SERVER, "EventDetection", outs=("tb:FallAlert",), port="event"),
                "parts-not-wholes",
                "output",
                "home:FallDownEvent",
                "tb:FallAlert",
                "an alarm message (not an event) with the fall's timestamp and person position",
            ),
        ),
        distractors=(
            Distractor(
                _ad("DetectSmoke", "DPC", BOARD, "EventDetection", outs=("home:SmokeAlarmEvent",), port="event"),
                "same-family",
                "another alarm",
            ),
            Distractor(
                _ad(
                    "DetectPersonLeaving",
                    "DPC",
                    DOORSENSOR,
                    "EventDetection",
                    outs=("home:PersonLeftRoomEvent",),
                    port="event",
                ),
                "same-family",
                "another person event",
            ),
            Distractor(
                _ad(
                    "DetectIntrusion",
                    "DPC",
                    DOORSENSOR,
                    "EventDetection",
                    outs=("home:IntrusionAlarmEvent",),
                    port="event",
                ),
                "same-family",
                "another alarm",
            ),
        ),
    ),
    Intent(
        "CupColourFeature",
        "cup colour feature",
        "CytonDualArm11",
        "ObjectKnowledge",
        "The dual-arm robot offers the cup and asks for its colour feature, to find it with the Kinect.",
        inputs=("home:Cup",),
        outputs=("home:ColourFeature",),
        relevant=(
            Relevant(
                _ad(
                    "AnalyseObjectColour",
                    "SDC",
                    SERVER,
                    "ObjectKnowledge",
                    ins=("home:PhysicalObject",),
                    outs=("tb:ColourHistogram",),
                    port="service",
                ),
                "subclass",
                "output",
                "home:ColourFeature",
                "tb:ColourHistogram",
                "a colour histogram, a kind of colour feature",
            ),
            Relevant(
                _ad(
                    "LookUpColourModel",
                    "SDC",
                    SERVER,
                    "ObjectKnowledge",
                    ins=("home:PhysicalObject",),
                    outs=("tb:ColourModel",),
                    port="service",
                ),
                "parts-not-wholes",
                "output",
                "home:ColourFeature",
                "tb:ColourModel",
                "object knowledge (not a feature) with the colour and hue a colour feature has",
            ),
        ),
        distractors=(
            Distractor(
                _ad(
                    "InferObjectShape",
                    "SDC",
                    SERVER,
                    "ObjectKnowledge",
                    ins=("home:PhysicalObject",),
                    outs=("home:ShapeFeature",),
                    port="service",
                ),
                "other-output",
                "the object's shape feature",
            ),
            Distractor(
                _ad(
                    "ReportMarkerColour",
                    "SDC",
                    P3DX,
                    "MarkerDetection",
                    ins=("home:MobileRobot",),
                    outs=("home:MarkerColour",),
                    port="service",
                ),
                "same-words",
                "the colour of a robot's marker",
            ),
            Distractor(
                _ad(
                    "ExtractColourFeature",
                    "MIC",
                    KINECT,
                    "ObjectRecognition",
                    ins=("home:RGBImage",),
                    outs=("home:ColourFeature",),
                    port="service",
                ),
                "wrong-inputs",
                "the exact output, but from an image the requester does not offer",
            ),
        ),
    ),
    Intent(
        "VideoStream",
        "video stream",
        "CareRobot11",
        "Surveillance",
        "The care robot asks for a live video stream to show the caregiver.",
        outputs=("home:VideoStream",),
        relevant=(
            Relevant(
                _ad("ProvideCameraFeed", "DPC", CEILING, "Surveillance", outs=("tb:CameraFeed",)),
                "synonym-sibling",
                "output",
                "home:VideoStream",
                "tb:CameraFeed",
                "a camera feed: another word for video stream, same frame and resolution parts",
            ),
            Relevant(
                _ad("StreamVideo", "DPC", WEBCAM, "Surveillance", outs=("tb:StreamOfVideo",)),
                "reworded-compound",
                "output",
                "home:VideoStream",
                "tb:StreamOfVideo",
                "the video stream worded the other way round",
            ),
        ),
        distractors=(
            Distractor(
                _ad("TakeSnapshot", "DPC", WEBCAM, "Surveillance", outs=("home:RGBImage",), port="service"),
                "same-family",
                "a single image, not a stream",
            ),
            Distractor(
                _ad("StreamAudio", "DPC", ("Microphone11",), "Surveillance", outs=("home:AudioSignal",)),
                "same-words",
                "a stream of sound",
            ),
            Distractor(
                _ad("StreamDepthImages", "DPC", KINECT, "Surveillance", outs=("home:DepthImage",)),
                "same-family",
                "depth images",
            ),
        ),
    ),
    Intent(
        "ObjectPlace",
        "object place",
        "P3DX11",
        "ObjectKnowledge",
        "The carrier robot offers the pen and asks where it is usually kept (scenario 2).",
        inputs=("home:Pen",),
        outputs=("home:ObjectPlace",),
        relevant=(
            Relevant(
                _ad(
                    "InferObjectPlace",
                    "SDC",
                    SERVER,
                    "ObjectKnowledge",
                    ins=("home:PhysicalObject",),
                    outs=("tb:PlaceOfObject",),
                    port="service",
                ),
                "reworded-compound",
                "output",
                "home:ObjectPlace",
                "tb:PlaceOfObject",
                "the object place worded the other way round",
            ),
            Relevant(
                _ad(
                    "LookUpStoragePlace",
                    "SDC",
                    SERVER,
                    "ObjectKnowledge",
                    ins=("home:Artifact",),
                    outs=("tb:StoragePlace",),
                    port="service",
                ),
                "synonym-sibling",
                "output",
                "home:ObjectPlace",
                "tb:StoragePlace",
                "where a thing is kept, a sibling region of object place",
            ),
        ),
        distractors=(
            Distractor(
                _ad(
                    "RecogniseObjectType",
                    "MIC",
                    KINECT,
                    "ObjectRecognition",
                    ins=("home:RGBImage",),
                    outs=("home:ObjectType",),
                    port="service",
                ),
                "same-words",
                "what kind of object is in an image",
            ),
            Distractor(
                _ad(
                    "QueryObjectAttribute",
                    "SDC",
                    SERVER,
                    "ObjectKnowledge",
                    ins=("home:PhysicalObject",),
                    outs=("home:ObjectAttribute",),
                    port="service",
                ),
                "other-output",
                "a stored attribute of the object",
            ),
        ),
    ),
    Intent(
        "BatteryLevel",
        "battery level",
        "CareRobot11",
        "RobotMonitoring",
        "The care robot asks for the battery level of the carrier robot.",
        outputs=("home:BatteryLevel",),
        relevant=(
            Relevant(
                _ad("ReportCharge", "DPC", P3DX, "RobotMonitoring", outs=("tb:LevelOfBattery",)),
                "reworded-compound",
                "output",
                "home:BatteryLevel",
                "tb:LevelOfBattery",
                "the battery level worded the other way round",
            ),
            Relevant(
                _ad("MonitorDockPower", "DPC", ("ChargingDock11",), "RobotMonitoring", outs=("tb:BatteryChargeLevel",)),
                "undeclared",
                "output",
                "home:BatteryLevel",
                "tb:BatteryChargeLevel",
                "the dock's battery charge level, a type declared nowhere",
            ),
        ),
        distractors=(
            Distractor(
                _ad("WarnBatteryLow", "DPC", P3DX, "RobotMonitoring", outs=("home:BatteryLowEvent",), port="event"),
                "same-words",
                "an event when the battery runs low, not its level",
            ),
            Distractor(
                _ad("FindChargingStation", "SDC", SERVER, "Mapping", outs=("home:ChargingStation",), port="service"),
                "same-family",
                "where to charge",
            ),
            Distractor(
                _ad("ReportBatteryTemperature", "DPC", P3DX, "RobotMonitoring", outs=("tb:BatteryTemperature",)),
                "same-words",
                "the battery's temperature",
            ),
        ),
    ),
    Intent(
        "HumanActivity",
        "activity",
        "CareRobot11",
        "ActivityRecognition",
        "The care robot asks what the resident is doing.",
        outputs=("home:HumanActivity",),
        relevant=(
            Relevant(
                _ad("RecogniseDailyActivity", "DPC", CEILING, "ActivityRecognition", outs=("tb:DailyActivity",)),
                "subclass",
                "output",
                "home:HumanActivity",
                "tb:DailyActivity",
                "activities of daily living, a kind of human activity",
            ),
            Relevant(
                _ad("ObserveBehaviour", "DPC", WEBCAM, "ActivityRecognition", outs=("tb:PersonBehaviour",)),
                "synonym-sibling",
                "output",
                "home:HumanActivity",
                "tb:PersonBehaviour",
                "a person's behaviour, a sibling event of human activity",
            ),
        ),
        distractors=(
            Distractor(
                _ad("ReportRobotActivity", "DPC", P3DX, "RobotMonitoring", outs=("tb:RobotActivity",)),
                "same-words",
                "what a robot is doing",
            ),
            Distractor(
                _ad(
                    "DetectPresence", "DPC", CEILING, "EventDetection", outs=("home:PersonDetectedEvent",), port="event"
                ),
                "same-family",
                "that someone is there, not what she does",
            ),
        ),
    ),
    Intent(
        "ObstacleAlert",
        "obstacle",
        "P3DX11",
        "Navigation",
        "The carrier robot subscribes to obstacle warnings.",
        outputs=("home:ObstacleDetectedEvent",),
        relevant=(
            Relevant(
                _ad("WarnObstacle", "DPC", ("LaserScanner11",), "Navigation", outs=("tb:ObstacleEvent",), port="event"),
                "undeclared",
                "output",
                "home:ObstacleDetectedEvent",
                "tb:ObstacleEvent",
                "the kitchen laser's obstacle event, a type declared nowhere",
            ),
            Relevant(
                _ad("PublishRobotEvents", "MIC", SERVER, "Navigation", outs=("home:RobotEvent",), port="event"),
                "superclass",
                "output",
                "home:ObstacleDetectedEvent",
                "home:RobotEvent",
                "the robot event channel, which carries obstacle events among others",
            ),
        ),
        distractors=(
            Distractor(
                _ad("SignalGoalReached", "DPC", P3DX, "Navigation", outs=("home:GoalReachedEvent",), port="event"),
                "same-family",
                "another robot event",
            ),
            Distractor(
                _ad(
                    "DetectObstacleInScan",
                    "MIC",
                    SERVER,
                    "Navigation",
                    ins=("home:LaserScan",),
                    outs=("home:ObstacleDetectedEvent",),
                    port="service",
                ),
                "wrong-inputs",
                "the exact output, but from a laser scan the robot does not have",
            ),
        ),
    ),
    Intent(
        "PersonProfile",
        "person identity",
        "CareRobot11",
        "PeopleRecognition",
        "The care robot offers a camera image and asks who is in it: the person's family and given name.",
        inputs=("home:RGBImage",),
        outputs=("home:PersonProfile",),
        relevant=(
            Relevant(
                _ad(
                    "RecogniseResident",
                    "MIC",
                    SERVER,
                    "PeopleRecognition",
                    ins=("home:RGBImage",),
                    outs=("tb:PersonRecord",),
                    port="service",
                ),
                "synonym-sibling",
                "output",
                "home:PersonProfile",
                "tb:PersonRecord",
                "a person record, a sibling of profile with the same name parts",
            ),
            Relevant(
                _ad(
                    "IdentifyFace",
                    "MIC",
                    SERVER,
                    "PeopleRecognition",
                    ins=("home:Image",),
                    outs=("home:Person",),
                    port="service",
                ),
                "parts-not-wholes",
                "output",
                "home:PersonProfile",
                "home:Person",
                "returns the person (an Agent, not data) with her family and given name",
            ),
        ),
        distractors=(
            Distractor(
                _ad(
                    "DetectPersonInImage",
                    "MIC",
                    SERVER,
                    "PeopleRecognition",
                    ins=("home:RGBImage",),
                    outs=("home:PersonDetectedEvent",),
                    port="service",
                ),
                "other-output",
                "that a person is in the image, not who",
            ),
            Distractor(
                _ad(
                    "LookUpFamilyName",
                    "SDC",
                    SERVER,
                    "PeopleRecognition",
                    ins=("home:PersonIdentity",),
                    outs=("home:FamilyName",),
                    port="service",
                ),
                "wrong-inputs",
                "one of the names, from an identity the requester does not have",
            ),
            Distractor(
                _ad(
                    "GreetPerson",
                    "PMC",
                    ("Speaker11",),
                    "Communication",
                    ins=("home:PersonProfile",),
                    outs=("home:TextMessage",),
                    port="service",
                ),
                "consumes-it",
                "takes a person profile and greets her",
            ),
        ),
    ),
    Intent(
        "OpenDoor",
        "open a door",
        "P3DX11",
        "Manipulation",
        "The carrier robot offers the door it wants to pass and asks for it to be opened: "
        "E (Door, hasStatus, Opened), the paper's PE example.",
        inputs=("home:Door",),
        effects=(("home:Door", "home:hasStatus", "home:Opened"),),
        relevant=(
            Relevant(
                _ad(
                    "OpenHingedDoor",
                    "PMC",
                    OPENER,
                    "Manipulation",
                    ins=("home:Door",),
                    eff=(("tb:HingedDoor", "home:hasStatus", "home:Opened"),),
                    port="service",
                ),
                "subclass",
                "effect subject",
                "home:Door",
                "tb:HingedDoor",
                "a door opener; its effect names hinged doors, a subclass of door",
            ),
            Relevant(
                _ad(
                    "DriveDoorOpen",
                    "PMC",
                    OPENER,
                    "Manipulation",
                    ins=("home:Door",),
                    eff=(("home:Door", "home:hasStatus", "tb:FullyOpened"),),
                    port="service",
                ),
                "undeclared",
                "effect object",
                "home:Opened",
                "tb:FullyOpened",
                "a door drive whose effect state is 'fully opened', a concept declared nowhere",
            ),
        ),
        distractors=(
            Distractor(
                _ad(
                    "CloseDoor",
                    "PMC",
                    OPENER,
                    "Manipulation",
                    ins=("home:Door",),
                    eff=(("home:Door", "home:hasStatus", "home:Closed"),),
                    port="service",
                ),
                "wrong-effect",
                "closes the door",
            ),
            Distractor(
                _ad(
                    "SwitchOnLamp",
                    "PMC",
                    SERVER,
                    "HomeAutomation",
                    ins=("home:Lamp",),
                    eff=(("home:Lamp", "home:hasStatus", "home:SwitchedOn"),),
                    port="service",
                ),
                "wrong-effect",
                "changes the status of a lamp",
            ),
        ),
    ),
    Intent(
        "PutCupBelowTap",
        "put the cup below the tap",
        "CytonDualArm11",
        "Manipulation",
        "Scenario 1's second sub-action: inputs cup and below-of-tap, E (Cup, isLocated, BelowOfTap).",
        inputs=("home:Cup", "home:BelowOfTap"),
        effects=(("home:Cup", "home:isLocated", "home:BelowOfTap"),),
        relevant=(
            Relevant(
                _ad(
                    "PutDownObject",
                    "PMC",
                    ARM,
                    "Manipulation",
                    ins=("home:PhysicalObject", "home:Place"),
                    pre=(_GRASPED_PRE,),
                    eff=(("home:PhysicalObject", "home:isLocated", "home:Place"),),
                    port="service",
                ),
                "superclass",
                "effect subject",
                "home:Cup",
                "home:PhysicalObject",
                "puts any object at any place: subject and object are superclasses of the requested ones",
            ),
            Relevant(
                _ad(
                    "PlaceCupUnderSpout",
                    "PMC",
                    ARM,
                    "Manipulation",
                    ins=("home:Cup", "tb:UnderSpout"),
                    eff=(("home:Cup", "home:isLocated", "tb:UnderSpout"),),
                    port="service",
                ),
                "synonym-sibling",
                "effect object",
                "home:BelowOfTap",
                "tb:UnderSpout",
                "'under the spout' is a sibling region of 'below of tap'",
            ),
        ),
        distractors=(
            Distractor(
                _ad(
                    "FillCup",
                    "PMC",
                    ARM,
                    "Manipulation",
                    ins=("home:Cup", "home:WaterDispenser"),
                    pre=(("home:Cup", "home:isLocated", "home:BelowOfTap"),),
                    eff=(("home:Cup", "home:contains", "home:Water"),),
                    port="service",
                ),
                "wrong-effect",
                "fills the cup; the requested statement is its precondition",
            ),
            Distractor(
                _ad(
                    "CarryObject",
                    "PMC",
                    ARM,
                    "Manipulation",
                    ins=("home:PhysicalObject", "home:Place"),
                    pre=(_GRASPED_PRE,),
                    eff=(("home:PhysicalObject", "home:isAbove", "home:Place"),),
                    port="service",
                ),
                "wrong-effect",
                "holds the object above the place",
            ),
            Distractor(
                _ad(
                    "PickUpCup",
                    "PMC",
                    ARM,
                    "Manipulation",
                    ins=("home:Cup",),
                    pre=(("home:Gripper", "home:isNear", "home:Cup"),),
                    eff=(("home:Cup", "home:isGraspedBy", "home:Gripper"),),
                    port="service",
                ),
                "wrong-effect",
                "grasps the cup",
            ),
        ),
    ),
    Intent(
        "NavigateToPerson",
        "navigate to the person",
        "P3DX11",
        "Navigation",
        "The carrier robot offers the person's location and asks to be brought near her "
        "(scenario 2): E (MobileRobot, isNear, Person).",
        inputs=("home:PersonLocation",),
        effects=(("home:MobileRobot", "home:isNear", "home:Person"),),
        relevant=(
            Relevant(
                _ad(
                    "NavigateToGoalPose",
                    "PMC",
                    P3DX,
                    "Navigation",
                    ins=("home:GoalPose",),
                    pre=(_LOCALISED_PRE,),
                    eff=(("home:MobileRobot", "home:isNear", "home:Person"),),
                    port="service",
                ),
                "parts-not-wholes",
                "input",
                "home:PersonLocation",
                "home:GoalPose",
                "takes a goal pose (a Pose, not a Location) with the x, y, theta of the person's location",
            ),
            Relevant(
                _ad(
                    "ApproachResident",
                    "PMC",
                    P3DX,
                    "Navigation",
                    ins=("home:PersonPosition",),
                    pre=(_LOCALISED_PRE,),
                    eff=(("home:CarrierRobot", "home:isNear", "home:ElderlyPerson"),),
                    port="service",
                ),
                "subclass",
                "effect subject",
                "home:MobileRobot",
                "home:CarrierRobot",
                "brings a carrier robot near an elderly person (subclass terms); takes the person position",
            ),
        ),
        distractors=(
            Distractor(
                _ad(
                    "NavigateToPlace",
                    "PMC",
                    P3DX,
                    "Navigation",
                    ins=("home:GoalPose",),
                    pre=(_LOCALISED_PRE,),
                    eff=(("home:MobileRobot", "home:isNear", "home:ObjectPlace"),),
                    port="service",
                ),
                "wrong-effect",
                "brings the robot near an object's place",
            ),
            Distractor(
                _ad(
                    "DeliverObject",
                    "PMC",
                    P3DX,
                    "Navigation",
                    ins=("home:PhysicalObject",),
                    eff=(("home:PhysicalObject", "home:isWith", "home:Person"),),
                    port="service",
                ),
                "wrong-effect",
                "hands an object to the person",
            ),
            Distractor(
                _ad(
                    "DockAtChargingStation",
                    "PMC",
                    P3DX,
                    "Navigation",
                    ins=("home:ChargingStation",),
                    pre=(_LOCALISED_PRE,),
                    eff=(("home:MobileRobot", "home:isLocated", "home:ChargingStation"),),
                    port="service",
                ),
                "wrong-effect",
                "drives to the charger",
            ),
        ),
    ),
)


# --------------------------------------------------------------------------------------------------
# Generation
# --------------------------------------------------------------------------------------------------


def expand(curie: str) -> str:
    """A ``home:``, ``tb:`` or ``cbrs:`` CURIE as a full IRI."""
    prefix, _, name = curie.partition(":")
    return {"home": HOME, "tb": TB, "cbrs": CBRS}[prefix] + name


def requirement_curie(number: int, intent: Intent) -> str:
    return f"tb:R{number:02d}_{intent.key}"


@dataclass(frozen=True)
class _Placed:
    """An advertisement template with what the seed decided: its number, host and QoS."""

    number: int
    template: Ad
    host: Device
    qos: tuple[tuple[str, float], ...]

    @property
    def curie(self) -> str:
        return f"tb:A{self.number:03d}_{self.template.service}"


def _entries() -> list[tuple[Intent, Relevant | Distractor]]:
    entries: list[tuple[Intent, Relevant | Distractor]] = []
    for intent in INTENTS:
        entries.extend((intent, item) for item in intent.relevant)
        entries.extend((intent, item) for item in intent.distractors)
    return entries


def _place(seed: int) -> list[_Placed]:
    rng = random.Random(seed)
    entries = _entries()
    numbers = list(range(1, len(entries) + 1))
    rng.shuffle(numbers)
    devices = {device.name: device for device in DEVICES}
    placed = []
    for number, (_, item) in zip(numbers, entries, strict=True):
        template = item.ad
        host = devices[rng.choice(template.hosts)]
        qos: list[tuple[str, float]] = [
            ("responseTime", round(rng.uniform(0.02, 0.5), 2)),
            ("availability", round(rng.uniform(0.85, 0.99), 2)),
        ]
        if template.port in ("data", "event"):
            qos.append(("updateRate", float(rng.choice((1, 2, 5, 10, 15, 30)))))
        placed.append(_Placed(number, template, host, tuple(qos)))
    return placed


def _lower_camel(name: str) -> str:
    """markerColour from home:MarkerColour (or from MarkerColour)."""
    name = name.rpartition(":")[2]
    return name[0].lower() + name[1:]


def _snake(name: str) -> str:
    return "_".join(words(name))


def _label(name: str) -> str:
    """bounding box 3D from BoundingBox3D."""
    return re.sub(r"(\d) d\b", r"\1D", " ".join(words(name)))


def _literal(text: str) -> str:
    return '"' + text.replace("\\", "\\\\").replace('"', '\\"') + '"'


def _number(value: float) -> str:
    return f"{value:.2f}"


def _owls_model(
    inputs: Sequence[str], outputs: Sequence[str], preconditions: Sequence[Triple], effects: Sequence[Triple]
) -> str:
    lines = ["    cbrs:hasOWLSModel [ a cbrs:OWLSModel"]
    for prop, params in (("cbrs:hasInput", inputs), ("cbrs:hasOutput", outputs)):
        for concept in params:
            lines.append(
                f"        {prop} [ a cbrs:Parameter ; cbrs:parameterName {_literal(_lower_camel(concept))} ; "
                f"cbrs:parameterType {concept} ]"
            )
    for prop, cls, statements in (
        ("cbrs:hasPrecondition", "cbrs:Precondition", preconditions),
        ("cbrs:hasEffect", "cbrs:Effect", effects),
    ):
        for s, p, o in statements:
            lines.append(f"        {prop} [ a {cls} ; rdf:subject {s} ; rdf:predicate {p} ; rdf:object {o} ]")
    return " ;\n".join(lines) + " ]"


def _class_turtle(cls: NewClass) -> str:
    head = (
        f"tb:{cls.name} a owl:Class ; rdfs:subClassOf {cls.parent} ;\n"
        f"    rdfs:label {_literal(_label(cls.name))}@en ; rdfs:comment {_literal(cls.comment)}@en"
    )
    if not cls.parts:
        return head + " .\n"
    restrictions = " ,\n        ".join(
        f"[ a owl:Restriction ; owl:onProperty {prop} ; owl:someValuesFrom {part} ]" for prop, part in cls.parts
    )
    return head + f" ;\n    rdfs:subClassOf {restrictions} .\n"


def _device_turtle(device: Device) -> str:
    return (
        f"tb:{device.name} a owl:NamedIndividual , {device.cls} ;\n"
        f"    rdfs:label {_literal(device.name)}@en ; rdfs:comment {_literal(device.comment)}@en .\n"
    )


def _advertisement_turtle(ad: _Placed) -> str:
    t = ad.template
    place, min_x, max_x, min_y, max_y = _AREAS[ad.host.area]
    port_class = {"data": "cbrs:DataPort", "event": "cbrs:EventPort", "service": "cbrs:ServicePort"}[t.port]
    topic = f"/{_snake(ad.host.name)}/{_snake(t.service)}"
    port = f"[ a {port_class} ; cbrs:portName {_literal(_lower_camel(t.service))}"
    if t.outputs:
        port += f" ; cbrs:dataType {t.outputs[0]}"
    port += f" ; cbrs:topic {_literal(topic)} ]"
    qos = " ; ".join(f"cbrs:{metric} {_number(value)}" for metric, value in ad.qos)
    parts = [
        f"{ad.curie} a {t.kind}",
        f"    rdfs:label {_literal(f'{_label(t.service).capitalize()} ({ad.host.name})')}@en",
        f"    cbrs:device tb:{ad.host.name}",
        f"    cbrs:deviceName {_literal(ad.host.name)}",
        f"    cbrs:serviceName {_literal(t.service)}",
        f"    cbrs:serviceCategory {_literal(t.category)}",
        _owls_model(t.inputs, t.outputs, t.preconditions, t.effects),
        f"    cbrs:hasSEAModel [ a cbrs:SEAModel ; cbrs:effectiveArea {place} ; cbrs:minX {_number(min_x)} ; "
        f"cbrs:maxX {_number(max_x)} ; cbrs:minY {_number(min_y)} ; cbrs:maxY {_number(max_y)} ]",
        f"    cbrs:hasQoSModel [ a cbrs:QoSModel ; {qos} ]",
        f"    cbrs:hasPort {port}",
    ]
    return " ;\n".join(parts) + " .\n"


def _requirement_turtle(number: int, intent: Intent) -> str:
    parts = [
        f"{requirement_curie(number, intent)} a cbrs:Requirement",
        f"    rdfs:label {_literal(intent.title.capitalize())}@en",
        f"    rdfs:comment {_literal(intent.comment)}@en",
        f"    cbrs:requestedBy tb:{intent.requester}",
        f"    cbrs:deviceName {_literal(intent.requester)}",
        f"    cbrs:serviceName {_literal(intent.key)}",
        f"    cbrs:serviceCategory {_literal(intent.category)}",
        _owls_model(intent.inputs, intent.outputs, intent.preconditions, intent.effects),
    ]
    return " ;\n".join(parts) + " .\n"


_HEADER = """\
@prefix tb:      <https://w3id.org/cbrs/testbed#> .
@prefix home:    <https://w3id.org/cbrs/home#> .
@prefix cbrs:    <https://w3id.org/cbrs/core#> .
@prefix dcterms: <http://purl.org/dc/terms/> .
@prefix owl:     <http://www.w3.org/2002/07/owl#> .
@prefix rdf:     <http://www.w3.org/1999/02/22-rdf-syntax-ns#> .
@prefix rdfs:    <http://www.w3.org/2000/01/rdf-schema#> .

# GENERATED by `python -m reasoner.testbed` (seed {seed}); do not edit by hand.
# The matchmaking testbed of the paper's section 6.1: {requirements} requirements and {services}
# advertisements in the home-care domain. The rules it follows are in reasoner/testbed.py and
# docs/evaluation.md; which advertisements are relevant to which requirement, and why, is in
# paper_testbed_truth.json, not here.

<https://w3id.org/cbrs/testbed>
    a owl:Ontology ;
    rdfs:label "cbrs matchmaking testbed"@en ;
    dcterms:description "Twenty requirements and one hundred service components, worded differently."@en ;
    owl:imports <https://w3id.org/cbrs/core> , <https://w3id.org/cbrs/home> .
"""


def _section(title: str) -> str:
    bar = "#" * 100
    return f"\n{bar}\n#  {title}\n{bar}\n\n"


def generate(seed: int = SEED) -> tuple[str, dict[str, Any]]:
    """The testbed as Turtle text and its ground truth, from ``seed`` (deterministic)."""
    placed = _place(seed)
    entries = _entries()
    out = [_HEADER.format(seed=seed, requirements=len(INTENTS), services=len(placed))]
    out.append(_section("Concepts the testbed adds (subclasses of home classes, parts restated)"))
    out.extend(_class_turtle(cls) + "\n" for cls in NEW_CLASSES)
    out.append(_section("Devices hosting the components"))
    out.extend(_device_turtle(device) + "\n" for device in DEVICES)
    out.append(_section("Requirements"))
    out.extend(_requirement_turtle(n, intent) + "\n" for n, intent in enumerate(INTENTS, start=1))
    out.append(_section("Advertisements (numbered by the seed)"))
    out.extend(_advertisement_turtle(ad) + "\n" for ad in sorted(placed, key=lambda ad: ad.number))
    turtle = "".join(out).rstrip("\n") + "\n"

    by_intent: dict[str, list[tuple[_Placed, Relevant | Distractor]]] = {}
    for ad, (intent, item) in zip(placed, entries, strict=True):
        by_intent.setdefault(intent.key, []).append((ad, item))
    requirements: dict[str, Any] = {}
    distractors: dict[str, Any] = {}
    for n, intent in enumerate(INTENTS, start=1):
        relevant = []
        for ad, item in by_intent[intent.key]:
            if isinstance(item, Relevant):
                relevant.append(
                    {
                        "advertisement": expand(ad.curie),
                        "rule": item.rule,
                        "role": item.role,
                        "requested": expand(item.requested),
                        "advertised": expand(item.advertised),
                        "why": item.why,
                    }
                )
            else:
                distractors[expand(ad.curie)] = {"intent": intent.key, "kind": item.kind, "why": item.why}
        requirements[expand(requirement_curie(n, intent))] = {"intent": intent.title, "relevant": relevant}
    rule_counts = Counter(item.rule for _, item in entries if isinstance(item, Relevant))
    kind_counts = Counter(item.kind for _, item in entries if isinstance(item, Distractor))
    truth: dict[str, Any] = {
        "seed": seed,
        "requirements_count": len(INTENTS),
        "services_count": len(placed),
        "rules": RULES,
        "rule_counts": {rule: rule_counts[rule] for rule in RULES},
        "distractor_kinds": DISTRACTOR_KINDS,
        "distractor_kind_counts": {kind: kind_counts[kind] for kind in DISTRACTOR_KINDS},
        "undeclared": [expand(c) for c in UNDECLARED],
        "requirements": requirements,
        "distractors": dict(sorted(distractors.items())),
    }
    return turtle, truth


def truth_json(truth: dict[str, Any]) -> str:
    return json.dumps(truth, indent=2, ensure_ascii=False) + "\n"


def load_truth(path: Path = TRUTH_FILE) -> dict[str, Any]:
    data: dict[str, Any] = json.loads(path.read_text(encoding="utf-8"))
    return data


def relevant_sets(truth: dict[str, Any]) -> dict[str, frozenset[str]]:
    """Requirement IRI -> the IRIs of its relevant advertisements."""
    return {
        requirement: frozenset(entry["advertisement"] for entry in item["relevant"])
        for requirement, item in truth["requirements"].items()
    }


def summary(truth: dict[str, Any]) -> str:
    lines = [f"{truth['requirements_count']} requirements, {truth['services_count']} advertisements"]
    relevant = sum(truth["rule_counts"].values())
    lines.append(f"relevant pairs by variation rule ({relevant}):")
    lines += [f"  {rule:<18} {count:>3}" for rule, count in truth["rule_counts"].items()]
    distractors = sum(truth["distractor_kind_counts"].values())
    lines.append(f"distractors by kind ({distractors}):")
    lines += [f"  {kind:<18} {count:>3}" for kind, count in truth["distractor_kind_counts"].items()]
    return "\n".join(lines)


# --------------------------------------------------------------------------------------------------
# Loading and checking the rules
# --------------------------------------------------------------------------------------------------


def open_testbed_kb(testbed: Path = TESTBED_FILE) -> KnowledgeBase:
    """A fresh in-memory store with the bundled ontology-graph files (core, home, actions) and the
    testbed, and none of the bundled advertisements or requirements."""
    kb = KnowledgeBase(Store.open(":memory:"))
    kb.load([item.path for item in bundled_files() if item.graph == GraphName.ONTOLOGY], graph="ontology")
    kb.load([testbed])
    return kb


def _leaves(tree: PartNode | None) -> list[str]:
    if tree is None or tree.is_leaf:
        return []
    return sorted(node.concept for node in tree.walk() if node.is_leaf)


def _isa_related(index: TaxonomyIndex, a: str, b: str) -> bool:
    if a == b:
        return True
    if a not in index or b not in index:
        return False
    return index.canonical(b) in index.is_a_ancestors(a) or index.canonical(a) in index.is_a_ancestors(b)


def _near_siblings(index: TaxonomyIndex, a: str, b: str) -> bool:
    """Neither subsumes the other and they meet at most two is-a links above each (not at the root)."""
    if a not in index or b not in index or _isa_related(index, a, b):
        return False
    common, n1, n2 = index.common_ancestor(a, b)
    return common != ROOT and n1 <= 2 and n2 <= 2


def _tree(kb: KnowledgeBase, concept: str) -> PartNode:
    # The description reader's cached part trees; KnowledgeBase has no public accessor for a bare concept.
    return kb._reader.part_tree(concept)


def _same_parts(kb: KnowledgeBase, a: str, b: str) -> bool:
    return _leaves(_tree(kb, a)) == _leaves(_tree(kb, b))


def _providable(kb: KnowledgeBase, index: TaxonomyIndex, wanted: str, offered: Sequence[str]) -> bool:
    """The requester can give ``wanted``: it offers it, a subclass of it, or a same-parts variant."""
    for concept in offered:
        if concept == wanted:
            return True
        if wanted in index and concept in index and index.canonical(wanted) in index.is_a_ancestors(concept):
            return True
        if _same_parts_cover(kb, index, wanted, concept):  # every part the input needs is offered
            return True
        if _near_siblings(index, concept, wanted) and _same_parts(kb, concept, wanted):
            return True
    return False


def _same_parts_cover(kb: KnowledgeBase, index: TaxonomyIndex, requested: str, advertised: str) -> bool:
    """Every leaf part of ``requested`` has an equal or is-a related leaf part in ``advertised``."""
    want, have = _leaves(_tree(kb, requested)), _leaves(_tree(kb, advertised))
    return bool(want) and all(any(_isa_related(index, w, h) for h in have) for w in want)


def _entities(description: ServiceDescription, role: str) -> list[str]:
    if role == "output":
        return [p.type for p in description.outputs]
    if role == "input":
        return [p.type for p in description.inputs]
    position = {"effect subject": 0, "effect object": 2}[role]
    return [(e.subject, e.predicate, e.object)[position] for e in description.effects]


def _check_pair(kb: KnowledgeBase, index: TaxonomyIndex, rule: str, requested: str, advertised: str) -> str:
    """Why the pair breaks its rule, or the empty string."""
    if local_name(requested) == local_name(advertised):
        return "same string"
    below = (
        advertised in index and requested in index and index.canonical(requested) in index.is_a_ancestors(advertised)
    )
    above = (
        advertised in index and requested in index and index.canonical(advertised) in index.is_a_ancestors(requested)
    )
    if rule == "subclass":
        return "" if below else "advertised is not below requested"
    if rule == "superclass":
        return "" if above else "advertised is not above requested"
    if rule == "reworded-compound":
        w_req, w_ad = words(local_name(requested)), words(local_name(advertised))
        if not below:
            return "not declared below the concept it rewords"
        if not set(w_req) <= set(w_ad) or w_req[-1] == w_ad[-1]:
            return "not the same words with the head moved"
        return ""
    if rule == "undeclared":
        if advertised in index:
            return "advertised concept is declared"
        return "" if words(local_name(requested))[-1] == words(local_name(advertised))[-1] else "head differs"
    if rule == "synonym-sibling":
        if not _near_siblings(index, requested, advertised):
            return "not near siblings"
        return "" if _same_parts(kb, requested, advertised) else "parts differ"
    if rule == "parts-not-wholes":
        if requested not in index or advertised not in index or _isa_related(index, requested, advertised):
            return "wholes are is-a related or undeclared"
        if _near_siblings(index, requested, advertised):
            return "wholes are near siblings (that is synonym-sibling)"
        return "" if _same_parts_cover(kb, index, requested, advertised) else "requested parts not covered"
    return f"unknown rule {rule}"


def rule_violations(kb: KnowledgeBase, truth: dict[str, Any]) -> list[str]:
    """Where the testbed breaks its own rules (T2-T4); empty when it keeps them all."""
    index = TaxonomyIndex.from_kb(kb)
    ads = {ad.iri: ad for ad in kb.advertisements()}
    reqs = {req.iri: req for req in kb.requirements()}
    problems = []
    undeclared = set(truth["undeclared"])
    for concept in undeclared:
        if concept in index:
            problems.append(f"{concept} should be undeclared")
    for description in (*ads.values(), *reqs.values()):
        used = [p.type for p in (*description.inputs, *description.outputs)] + [
            term for s in (*description.preconditions, *description.effects) for term in (s.subject, s.object)
        ]
        for concept in used:
            if concept not in index and concept not in undeclared:
                problems.append(f"{local_name(description.iri)}: {concept} is declared nowhere")
    for req_iri, item in truth["requirements"].items():
        req = reqs.get(req_iri)
        if req is None:
            problems.append(f"{req_iri} is not a requirement")
            continue
        for pair in item["relevant"]:
            ad = ads.get(pair["advertisement"])
            if ad is None:
                problems.append(f"{pair['advertisement']} is not an advertisement")
                continue
            name = f"{local_name(req_iri)} / {local_name(ad.iri)}"
            if pair["requested"] not in _entities(req, pair["role"]):
                problems.append(f"{name}: requested {local_name(pair['requested'])} is not its {pair['role']}")
            if pair["advertised"] not in _entities(ad, pair["role"]):
                problems.append(f"{name}: {local_name(pair['advertised'])} is not the ad's {pair['role']}")
            why = _check_pair(kb, index, pair["rule"], pair["requested"], pair["advertised"])
            if why:
                problems.append(f"{name}: {pair['rule']}: {why}")
            offered = [p.type for p in req.inputs]
            for parameter in ad.inputs:
                if not _providable(kb, index, parameter.type, offered):
                    problems.append(f"{name}: input {local_name(parameter.type)} cannot be provided")
            if req.outputs and {local_name(p.type) for p in req.outputs} & {local_name(p.type) for p in ad.outputs}:
                problems.append(f"{name}: an output has the requested string")
            for effect in req.effects if pair["role"].startswith("effect") else ():
                if effect in ad.effects:
                    problems.append(f"{name}: the effect is stated exactly as requested")
        relevant = {pair["advertisement"] for pair in item["relevant"]}
        for ad in ads.values():
            if ad.iri not in relevant and _logically_relevant(index, ad, req):
                problems.append(f"{local_name(req_iri)}: distractor {local_name(ad.iri)} is relevant by is-a")
    return problems


def _logically_relevant(index: TaxonomyIndex, ad: Advertisement, req: Requirement) -> bool:
    """Every requested output and effect has an is-a compatible offer, and every input of the
    advertisement is one the requester offers or a superclass of one."""
    offered = [p.type for p in req.inputs]
    if not req.outputs and not req.effects:
        return False
    for parameter in req.outputs:
        if not any(_isa_related(index, parameter.type, p.type) for p in ad.outputs):
            return False
    for effect in req.effects:
        if not any(
            all(
                _isa_related(index, a, b)
                for a, b in zip(
                    (effect.subject, effect.predicate, effect.object), (e.subject, e.predicate, e.object), strict=True
                )
            )
            for e in ad.effects
        ):
            return False
    for parameter in ad.inputs:
        if not any(
            parameter.type == concept
            or (
                parameter.type in index
                and concept in index
                and index.canonical(parameter.type) in index.is_a_ancestors(concept)
            )
            for concept in offered
        ):
            return False
    return True


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m reasoner.testbed", description=__doc__.split("\n")[0])
    parser.add_argument("--seed", type=int, default=SEED)
    parser.add_argument("--check", action="store_true", help="compare with the committed files, write nothing")
    args = parser.parse_args(argv)
    turtle, truth = generate(args.seed)
    text = truth_json(truth)
    if args.check:
        same = (
            TESTBED_FILE.exists()
            and TESTBED_FILE.read_text(encoding="utf-8") == turtle
            and TRUTH_FILE.exists()
            and TRUTH_FILE.read_text(encoding="utf-8") == text
        )
        print("testbed is current" if same else "testbed differs from generate(); run python -m reasoner.testbed")
        return 0 if same else 1
    DATA_DIR.mkdir(parents=True, exist_ok=True)
    TESTBED_FILE.write_text(turtle, encoding="utf-8")
    TRUTH_FILE.write_text(text, encoding="utf-8")
    print(f"wrote {TESTBED_FILE} and {TRUTH_FILE}")
    print(summary(truth))
    return 0


if __name__ == "__main__":
    sys.exit(main())
