"""A link of the map (a camera's ``home:mountedOn``, a robot's ``home:hasMarker`` and ``home:hasPlatform``, a
marker's ``home:hasColour``, furniture's ``home:dockingPose``) that names something graph:map says nothing
of is refused, naming the thing, the property, what it names and what it may mean, and an update that
writes one is undone. A camera mounted on a misspelt thing was taken as mounted (no mast, and the
mapping's obstacles left it out), and a robot with a misspelt marker lost its colours, without a word;
a misspelt platform or docking pose was said to "have no home:maxZ" or "no home:x". No world is built."""

from __future__ import annotations

from collections.abc import Iterator

import pytest

from cbrs.kb import KnowledgeBase
from cbrs.kb.namespaces import PREFIXES
from cbrs.kb.semantic_map import MapError

RELINK = (
    "DELETE {{ GRAPH graph:map {{ {thing} home:{prop} ?v }} }} INSERT {{ GRAPH graph:map {{ {thing} home:{prop} "
    "{new} }} }} WHERE {{ GRAPH graph:map {{ {thing} home:{prop} ?v }} }}"
)


@pytest.fixture(scope="module")
def kb() -> Iterator[KnowledgeBase]:
    """One seeded store for the module: every update its tests send is refused and undone."""
    opened = KnowledgeBase.open(":memory:")
    yield opened
    opened.close()


@pytest.mark.parametrize(
    ("thing", "prop", "new", "meant"),
    [
        pytest.param("svc:Kinect01", "mountedOn", "svc:CytonDualArm1", "CytonDualArm01", id="a-camera-mount"),
        pytest.param("svc:P3DX01", "hasMarker", "world:P3DX01Markr", "P3DX01Marker", id="a-robot-marker"),
        pytest.param("svc:P3DX01", "hasPlatform", "world:P3DXPlatform", "P3DX01Platform", id="a-robot-platform"),
        pytest.param(
            "world:P3DX01Marker", "hasColour", "world:P3DX01MarkerColors", "P3DX01MarkerColours", id="marker-colours"
        ),
        pytest.param("world:KitchenTable", "dockingPose", "world:KitchenTableDok", "KitchenTableDock", id="a-dock"),
    ],
)
def test_a_link_to_nothing_the_map_describes_is_refused_and_undone(
    kb: KnowledgeBase, thing: str, prop: str, new: str, meant: str
) -> None:
    before = kb.store.dump()
    with pytest.raises(MapError) as refused:
        kb.update(RELINK.format(thing=thing, prop=prop, new=new))
    prefix, _, local = thing.partition(":")
    assert refused.value.thing == PREFIXES[prefix] + local
    named = new.partition(":")[2]
    assert f"has home:{prop} {named} (" in str(refused.value)
    assert f"of which graph:map says nothing (did you mean {meant}?)" in str(refused.value)
    assert kb.store.dump() == before
