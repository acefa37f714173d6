"""A home of one's own keeps the robots (``kb.kept_robots``): ``cbrs load --graph map --replace`` with files
that describe no robot keeps what the stored map says the robots are, and the files say where they stand.

Before, the studio flat (docs/examples/studio_flat/home.ttl) copied 26 lines of the robots' descriptions
from ontologies/world.ttl to change only their poses. No simulation: the map is read and checked."""

from __future__ import annotations

import re
from pathlib import Path

import pytest
from click.testing import CliRunner

from cbrs.cli import cli
from cbrs.kb import KnowledgeBase
from cbrs.kb.home_check import HomeError
from cbrs.kb.namespaces import PREFIXES, GraphName
from cbrs.kb.semantic_map import MapError, SemanticMap

HOME_FILE = Path(__file__).resolve().parents[1] / "docs" / "examples" / "studio_flat" / "home.ttl"
SVC, WORLD = PREFIXES["svc"], "https://w3id.org/cbrs/world#"
BASE_PLACED = "svc:P3DX01 home:x 3.8 ; home:y 0.9 ; home:yaw 1.5707963267948966 ."


def _variant(tmp_path: Path, old: str, new: str) -> Path:
    text = HOME_FILE.read_text(encoding="utf-8")
    assert old in text
    path = tmp_path / "home.ttl"
    path.write_text(text.replace(old, new), encoding="utf-8")
    return path


@pytest.fixture(scope="module")
def bundled() -> SemanticMap:
    return SemanticMap.read(KnowledgeBase.open(":memory:"))


def test_the_flat_places_the_bundled_robots_and_keeps_what_they_are(bundled: SemanticMap) -> None:
    kb = KnowledgeBase.open(":memory:")
    report = kb.load([HOME_FILE], graph="map", replace=True)
    assert report.kept_robots == (SVC + "CytonDualArm01", SVC + "P3DX01")
    assert report.kept[GraphName.MAP.iri] > 0
    flat = SemanticMap.read(kb)
    base, was = flat.robots[SVC + "P3DX01"], bundled.robots[SVC + "P3DX01"]
    assert (base.start.x, base.start.y) == (3.8, 0.9)  # the flat's
    assert (base.footprint, base.marker, base.platform_height) == (was.footprint, was.marker, was.platform_height)
    for iri, arm in flat.arms.items():
        assert (arm.side, arm.reach, arm.mount[2]) == (bundled.arms[iri].side, bundled.arms[iri].reach, 0.65)
        assert flat.hands[iri] == bundled.hands[iri]
    kinect = flat.cameras[SVC + "Kinect01"]
    assert kinect.position == (6.15, 2.55, 1.45)  # its height and pitch are the robot's: kept
    assert (kinect.fov, kinect.pitch, kinect.far) == (45.0, bundled.cameras[SVC + "Kinect01"].pitch, 4.0)
    torso = flat.things[SVC + "CytonDualArm01"].box
    assert (torso.min_x, torso.max_y, torso.max_z) == (5.9, 2.8, 0.65)
    room = PREFIXES["home"] + "isLocated"
    assert flat.facts[SVC + "CytonDualArm01"][room] == ["https://example.org/studio-flat#Kitchenette"]
    assert WORLD + "Kitchen" not in flat.things  # the old home's room is not named by a kept statement


def test_the_cli_says_what_it_kept(tmp_path: Path) -> None:
    done = CliRunner().invoke(
        cli, ["--store", str(tmp_path / "s"), "load", "--graph", "map", "--replace", str(HOME_FILE)]
    )
    assert done.exit_code == 0, done.output
    assert re.search(
        r"kept in graph:map: the robots' own descriptions \(svc:CytonDualArm01, svc:P3DX01; \d+ triples\)", done.output
    )


def test_a_second_home_keeps_the_robots_of_the_first(tmp_path: Path) -> None:
    kb = KnowledgeBase.open(":memory:")
    kb.load([HOME_FILE], graph="map", replace=True)
    kb.update(  # the lab's base has a larger footprint
        "DELETE { GRAPH graph:map { svc:P3DX01 home:sizeX ?x } } "
        "INSERT { GRAPH graph:map { svc:P3DX01 home:sizeX 0.5 } } "
        "WHERE { GRAPH graph:map { svc:P3DX01 home:sizeX ?x } }"
    )
    moved = _variant(tmp_path, BASE_PLACED, "svc:P3DX01 home:x 2.0 ; home:y 1.0 ; home:yaw 0.0 .")
    kb.load([moved], graph="map", replace=True)
    base = SemanticMap.read(kb).robots[SVC + "P3DX01"]
    assert (base.start.x, base.start.y, base.footprint[0]) == (2.0, 1.0, 0.5)


def test_a_kept_robot_the_files_do_not_place_is_refused_and_the_map_kept(tmp_path: Path) -> None:
    kb = KnowledgeBase.open(":memory:")
    before = set(kb.store.quads(graph=GraphName.MAP.node))
    unplaced = _variant(tmp_path, BASE_PLACED, "svc:P3DX01 home:x 3.8 ; home:y 0.9 .")
    with pytest.raises(
        HomeError, match=r"P3DX01 .* the files do not say where it stands: give its home:yaw"
    ) as refused:
        kb.load([unplaced], graph="map", replace=True)
    assert "(in the map it replaces: home:yaw 0)" in str(refused.value)
    assert "nothing was loaded from" in " ".join(getattr(refused.value, "__notes__", []))
    assert set(kb.store.quads(graph=GraphName.MAP.node)) == before


def test_files_that_describe_a_robot_describe_them_all(tmp_path: Path) -> None:
    """A file stating a robot-making part (here the base's platform) keeps nothing: not the footprint of the
    base it names, and the map is refused for it as before."""
    own = _variant(
        tmp_path, BASE_PLACED, BASE_PLACED + "\nsvc:P3DX01 home:hasPlatform flat:Tray . flat:Tray home:maxZ 0.40 ."
    )
    kb = KnowledgeBase.open(":memory:")
    with pytest.raises(MapError, match=r"P3DX01 .* has no home:sizeX"):
        kb.load([own], graph="map", replace=True)
