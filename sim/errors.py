"""Typed errors of the simulation. Each keeps the offending input so a caller can react to it.

``sim`` does not import the knowledge base, so these derive from ``Exception``; the executor that
wraps the simulation as components maps them onto its own error types.
"""

from __future__ import annotations

from collections.abc import Sequence


class SimulationError(Exception):
    """Base of every error the simulation raises on purpose; ``str(error)`` is one line fit for a person."""


class WorldClosedError(SimulationError):
    """The world was used after ``close()``: its pybullet client no longer exists."""

    def __init__(self, client: int) -> None:
        self.client = client
        super().__init__(f"the world on pybullet client {client} is closed")


class UnknownEntityError(SimulationError):
    """A name that is not an entity (body, camera or region) of the home."""

    def __init__(self, name: str, known: Sequence[str]) -> None:
        self.name = name
        self.known = tuple(known)
        super().__init__(f"no entity named {name!r}; known: {', '.join(self.known)}")


class UnknownPlaceError(SimulationError, ValueError):
    """A place to weigh (``sim.load``) that is neither a body of the home nor a thing of its map with an
    extent."""

    def __init__(self, place: str) -> None:
        self.place = place
        super().__init__(
            f"nothing of the simulated home is named {place!r}: name a body (a table, the tray) or a place of"
            " the map with an extent (a scale's plate, a region), by its IRI or its local name"
        )


class ImageSizeError(SimulationError, ValueError):
    """An image size for a camera that is not two positive whole numbers of pixels."""

    def __init__(self, camera: str, size: object) -> None:
        self.camera = camera
        self.size = size
        super().__init__(f"image size {size!r} for camera {camera!r}: give (width, height), two positive integers")


class CameraUnavailableError(SimulationError):
    """The camera is switched off (failed); a component should fall back to another camera."""

    def __init__(self, camera: str) -> None:
        self.camera = camera
        super().__init__(f"camera {camera} is not available (failed)")


class PerceptionError(SimulationError):
    """Base of the perception failures."""


class NotVisibleError(PerceptionError):
    """What was looked for is not in the image (out of view, occluded, or too few pixels of its colour)."""

    def __init__(self, camera: str, target: str, pixels: int, needed: int) -> None:
        self.camera = camera
        self.target = target
        self.pixels = pixels
        self.needed = needed
        super().__init__(f"{target} not visible in {camera}: {pixels} matching pixels, at least {needed} needed")


class CutByBorderError(NotVisibleError):
    """What was looked for is in the image but cut by its border: its shape, hence any estimate, would be
    wrong. ``pixels`` is how many of its pixels there are, ``on_border`` how many lie on the border."""

    def __init__(self, camera: str, target: str, pixels: int, on_border: int) -> None:
        self.camera = camera
        self.target = target
        self.pixels = pixels
        self.needed = pixels
        self.on_border = on_border
        PerceptionError.__init__(
            self,
            f"{target} is cut by the border of {camera}'s image ({on_border} of its {pixels} pixels on the "
            "border): it is partly out of view",
        )


class AmbiguousSightingError(PerceptionError):
    """Several separate things of the colour looked for are in view, and nothing says which is meant."""

    def __init__(self, camera: str, colour: str, positions: Sequence[tuple[float, float, float]]) -> None:
        self.camera = camera
        self.colour = colour
        self.positions = tuple(positions)
        where = ", ".join(f"({x:.2f}, {y:.2f})" for x, y, _ in self.positions)
        super().__init__(
            f"{len(self.positions)} separate {colour} things in view of {camera}, at {where}: "
            "say where the one meant is believed to be"
        )


class UnknownColourError(PerceptionError):
    """A colour name the segmenter has no range for."""

    def __init__(self, colour: str, known: Sequence[str]) -> None:
        self.colour = colour
        self.known = tuple(known)
        super().__init__(f"unknown colour {colour!r}; known: {', '.join(self.known)}")


class GraspMisfitError(SimulationError):
    """The hand could not hold the object by this approach, wherever the arm reaches: the object does not
    fit the hand that way. An approach so refused is passed over for the next its class allows."""

    name: str
    approach: str


class GraspTooWideError(GraspMisfitError):
    """An object wider across the jaws than they open, for the approach and the way the hand is turned to
    it (a long box taken from the side across its length): the hand could not close on it so, wherever
    the arm reaches. ``width`` and ``opening`` are in metres."""

    def __init__(self, name: str, approach: str, width: float, opening: float, clearance: float = 0.0) -> None:
        self.name = name
        self.approach = approach
        self.width = width
        self.opening = opening
        self.clearance = clearance
        """How far each jaw must clear the object (the hand's ``jaw_clearance``)."""
        clear = (
            f", less {clearance * 100:.2f} cm clear of each jaw: at most {(opening - 2 * clearance) * 100:.1f} cm"
            if clearance > 0.0
            else ""
        )
        super().__init__(
            f"the {name} is {width * 100:.1f} cm wide across the jaws by its {approach} grasp, and the hand "
            f"opens {opening * 100:.1f} cm{clear}"
        )


class GraspTooThinError(GraspMisfitError):
    """An object too thin for a top grasp to hold above the surface it rests on: with the fingertips kept
    ``clearance`` above that surface, no part of its ``height`` would lie between them (the fingertips
    reach ``fingertip_depth`` below the grasp point). Lengths in metres."""

    def __init__(self, name: str, approach: str, height: float, fingertip_depth: float, clearance: float) -> None:
        self.name = name
        self.approach = approach
        self.height = height
        self.fingertip_depth = fingertip_depth
        self.clearance = clearance
        super().__init__(
            f"the {name} is {height * 100:.2f} cm thick, and its {approach} grasp keeps the fingertips "
            f"{clearance * 100:.2f} cm above the surface it rests on (they reach {fingertip_depth * 100:.2f} cm "
            "below the grasp point): nothing of it would lie between them"
        )


class GraspTooDeepError(GraspMisfitError):
    """An object deeper along a side grasp's approach than the fingers can hold: pushed against the palm,
    less than ``least`` of its ``depth`` would lie between them (``held``, the fingers' ``finger_length``
    along the hand's axis, tilted down, measured along the approach), its centre of mass beyond the
    fingertips at the default half. The jaws would close on its near part only. Lengths in metres."""

    def __init__(self, name: str, approach: str, depth: float, finger_length: float, held: float, least: float) -> None:
        self.name = name
        self.approach = approach
        self.depth = depth
        self.finger_length = finger_length
        self.held = held
        self.least = least
        super().__init__(
            f"the {name} is {depth * 100:.1f} cm deep along the hand's approach by its {approach} grasp, and the "
            f"fingers are {finger_length * 100:.1f} cm long: {held * 100:.1f} cm of it would lie between them, "
            f"less than the {least:.0%} a hold needs"
        )


class MovesRefusedError(SimulationError):
    """The arm's own motion planning would refuse the moves of a hold by every approach left to it (a dry
    run of the approach, the pick-up and, when known, the carry over the spot it will aim at), so the step
    fails before anything moves. ``refused`` holds (approach, the spot's centre (x, y) or None, why) for
    each approach dry-run; ``ruled_out`` (approach, why) those its end poses or its fit ruled out first;
    ``before`` what had not moved yet (a pass between the arms is refused with the object already in hand)."""

    def __init__(
        self,
        name: str,
        arm: str,
        purpose: str,
        refused: Sequence[tuple[str, tuple[float, float] | None, str]],
        ruled_out: Sequence[tuple[str, str]] = (),
        before: str = "anything moved",
        advice: str = "",
    ) -> None:
        self.name = name
        self.arm = arm
        self.purpose = purpose
        self.refused = tuple(refused)
        self.ruled_out = tuple(ruled_out)
        self.advice = advice or (
            f"set the {name} or its place nearer the arm, or allow it another approach (home:graspApproach)"
        )
        """What would help: given by the refusal (a carry held up by an arm band: ``arm_choice.floor_advice``),
        else to set the object nearer the arm or allow it another approach."""
        reasons = "; ".join(why for _, _, why in self.refused)
        others = "".join(f"; not by its {approach} grasp: {why}" for approach, why in self.ruled_out)
        super().__init__(
            f"{purpose}: refused before {before}, the {arm} arm's planning making the moves by no approach: "
            f"{reasons}{others}; {self.advice}"
        )


class MapError(SimulationError):
    """Base of the map and planning failures."""


class OutsideMapError(MapError):
    """A world point that is not on the grid map."""

    def __init__(self, x: float, y: float) -> None:
        self.x = x
        self.y = y
        super().__init__(f"point ({x:.3f}, {y:.3f}) is outside the map")


class NoFreeCellError(MapError):
    """A start or goal lies in an obstacle and no free cell is near enough to snap it to."""

    def __init__(self, x: float, y: float, radius: float) -> None:
        self.x = x
        self.y = y
        self.radius = radius
        super().__init__(f"no free cell within {radius:.2f} m of ({x:.3f}, {y:.3f})")


class NoPathError(MapError):
    """Start and goal are both free but not connected on the inflated grid."""

    def __init__(self, start: tuple[float, float], goal: tuple[float, float], algorithm: str) -> None:
        self.start = start
        self.goal = goal
        self.algorithm = algorithm
        super().__init__(
            f"{algorithm}: no path from ({start[0]:.2f}, {start[1]:.2f}) to ({goal[0]:.2f}, {goal[1]:.2f}) "
            "on the inflated grid"
        )


class UnknownAlgorithmError(MapError):
    """A planner name other than the supported ones."""

    def __init__(self, algorithm: str, known: Sequence[str]) -> None:
        self.algorithm = algorithm
        self.known = tuple(known)
        super().__init__(f"unknown planner {algorithm!r}; use one of {', '.join(self.known)}")
