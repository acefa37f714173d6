"""The robots a home of one's own keeps: what ``cbrs load --graph map --replace`` carries over from the map
it replaces when the files describe no robot (docs/tasks.md, "A home of your own").

The robots are the components' devices, and what they are (the dual-arm robot's arms, their reach and
hands, the Kinect's lens and mast, the mobile base's footprint, platform and marker) lives in graph:map
beside the home. A lab that replaced the map had to copy all of it from ``ontologies/world.ttl`` to
change only where the robots stand. Now, when the files state no robot-making part (``home:hasArm``,
``home:hasPlatform``, ``home:hasMarker``), the stored map's robots are kept with every part they have
(arms, their hands, platform, marker and its colours, the cameras mounted on them), and the files say
only where they stand: each kept thing the stored map places on the floor (:data:`PLACEMENT`) must be
placed by the files, which are refused otherwise (a :class:`HomeError` naming the thing and what it
lacks), since the old home's floor positions mean nothing in another home. Heights (``home:z``, an
extent's ``home:minZ`` and ``home:maxZ``) and a camera's pitch belong to the robot and are kept; the
room a robot ``home:isLocated`` in is the old home's, and is kept only when the files give it. A file
that states a robot-making part describes the robots itself: nothing is kept (all or nothing), as
before. A statement the files give about a kept thing wins over the stored one (one value per
property, as the map reader needs).
"""

from __future__ import annotations

from collections import defaultdict
from collections.abc import Iterable, Sequence
from dataclasses import dataclass

import pyoxigraph as ox

from cbrs.kb.home_check import HomeError
from cbrs.kb.semantic_map import HOME, local_name

__all__ = ["PLACEMENT", "ROBOT_PARTS", "KeptRobots", "kept_robots"]

ROBOT_PARTS = frozenset(ox.NamedNode(HOME + name) for name in ("hasArm", "hasPlatform", "hasMarker"))
"""The properties that make a thing of the map a robot: a file stating one describes its own robots."""
_PARTS_OF_PARTS = frozenset(ox.NamedNode(HOME + name) for name in ("hasGripper", "hasColour", "sideGraspBand"))
_MOUNTED_ON = ox.NamedNode(HOME + "mountedOn")
PLACEMENT = tuple(ox.NamedNode(HOME + name) for name in ("x", "y", "yaw", "minX", "maxX", "minY", "maxY"))
"""Where a thing stands on the floor and which way it faces: a kept thing's must come from the files."""
_ROOM = ox.NamedNode(HOME + "isLocated")


@dataclass(frozen=True)
class KeptRobots:
    """What a replacing load keeps of the stored map: the robots (their IRIs) and the statements about
    them and their parts that the files do not give."""

    robots: tuple[str, ...] = ()
    quads: tuple[ox.Quad, ...] = ()
    unplaced: HomeError | None = None
    """Why the files cannot keep them: the first kept thing the stored map places and they do not."""
    stood: tuple[ox.Quad, ...] = ()
    """Where the stored map placed the kept things the files do not place (kept only to tell a file
    that is no home at all so first)."""


def kept_robots(stored: Iterable[ox.Quad], given: Sequence[ox.Quad]) -> KeptRobots:
    """What of the ``stored`` map (its quads) a replacing load with the files' quads ``given`` keeps:
    nothing when the files state a robot-making part, else the robots and their parts, less where they
    stood, with a :class:`HomeError` (``unplaced``, not raised: a file that is no home at all is told
    that first) for a kept thing the stored map places that the files do not."""
    if any(quad.predicate in ROBOT_PARTS for quad in given):
        return KeptRobots()
    about: dict[ox.NamedNode | ox.BlankNode, list[ox.Quad]] = defaultdict(list)
    for quad in stored:
        if isinstance(quad.subject, ox.NamedNode | ox.BlankNode):
            about[quad.subject].append(quad)
    robots = sorted((s for s, quads in about.items() if any(q.predicate in ROBOT_PARTS for q in quads)), key=str)
    things = _parts(robots, about)
    said = {(quad.subject, quad.predicate) for quad in given}
    kept: list[ox.Quad] = []
    unplaced = None
    stood: list[ox.Quad] = []
    for thing in things:
        placed = [q.predicate for q in about[thing] if q.predicate in PLACEMENT]
        missing = [p for p in PLACEMENT if p in placed and (thing, p) not in said]
        if missing and unplaced is None:
            unplaced = _unplaced(thing, missing, about[thing])
        stood += [quad for quad in about[thing] if quad.predicate in missing]
        kept += [
            quad
            for quad in about[thing]
            if quad.predicate not in PLACEMENT and quad.predicate != _ROOM and (thing, quad.predicate) not in said
        ]
    return KeptRobots(tuple(_iri(robot) for robot in robots), tuple(kept), unplaced, tuple(stood))


def _parts(
    robots: list[ox.NamedNode | ox.BlankNode], about: dict[ox.NamedNode | ox.BlankNode, list[ox.Quad]]
) -> list[ox.NamedNode | ox.BlankNode]:
    """The robots, their parts and their parts' parts, however deep (an arm's hand, the bands of the arm
    behind the hand's side grasp, a marker's colours), and the devices mounted on them, each once, in
    that order."""
    found = dict.fromkeys(robots)
    for robot in robots:
        for quad in about[robot]:
            if quad.predicate in ROBOT_PARTS and isinstance(quad.object, ox.NamedNode | ox.BlankNode):
                found.setdefault(quad.object)
                below = [quad.object]
                while below:  # ends: each part is walked once
                    part = below.pop(0)
                    for q in about.get(part, []):
                        inner = q.object
                        if not isinstance(inner, ox.NamedNode | ox.BlankNode):
                            continue
                        if q.predicate in _PARTS_OF_PARTS and inner not in found:
                            found[inner] = None
                            below.append(inner)
    mounted = sorted(
        (s for s, quads in about.items() if any(q.predicate == _MOUNTED_ON and q.object in found for q in quads)),
        key=str,
    )
    found.update(dict.fromkeys(mounted))
    return list(found)


def _unplaced(thing: ox.NamedNode | ox.BlankNode, missing: list[ox.NamedNode], stated: list[ox.Quad]) -> HomeError:
    were = {quad.predicate: quad.object for quad in stated}
    names = ", ".join(f"home:{local_name(p.value)}" for p in missing)
    before = ", ".join(f"home:{local_name(p.value)} {_shown(were[p])}" for p in missing)
    return HomeError(
        _iri(thing),
        f"is kept from the map this home replaces (the files describe no robot of their own: no home:hasArm, "
        f"home:hasPlatform or home:hasMarker), but the files do not say where it stands: give its {names} "
        f"(in the map it replaces: {before}), or describe the robots in full",
    )


def _shown(term: object) -> str:
    return term.value if isinstance(term, ox.Literal | ox.NamedNode) else str(term)


def _iri(node: ox.NamedNode | ox.BlankNode) -> str:
    return node.value if isinstance(node, ox.NamedNode) else str(node)
