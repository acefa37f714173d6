"""A misspelt optional property of a map thing (home:yaww for home:yaw) is declared nowhere, so the load takes
it and the reader used to ignore it, the thing keeping its default. Reading the map now refuses any property
of the home namespace the vocabulary does not declare, naming the thing, the property, its value and the
near spelling (kb/semantic_map.py, the named query declared_properties)."""

from __future__ import annotations

from pathlib import Path

import pytest

from cbrs.kb.semantic_map import SemanticMap
from tests.test_nu16_map_checks import bottle, refusal, store

WORLD = "https://w3id.org/cbrs/world#"


@pytest.mark.parametrize(
    ("mine", "meant"),
    [
        pytest.param("home:yaww 0.5", "yaw", id="object-yaw"),
        pytest.param("home:masKg 0.2", "massKg", id="object-mass"),
    ],
)
def test_a_misspelt_optional_property_of_an_object_is_refused_with_the_one_it_may_mean(
    tmp_path: Path, mine: str, meant: str
) -> None:
    error = refusal(store(tmp_path, bottle().replace(" .\n", f" ; {mine} .\n")))
    wrong, value = mine.split()
    assert error.thing == WORLD + "Bottle1"
    assert f"has {wrong} '{value}', a property the home vocabulary does not declare" in str(error)
    assert f"(did you mean home:{meant}?)" in str(error)


def test_a_misspelt_property_of_a_place_is_refused(tmp_path: Path) -> None:
    place = (
        "world:Shelf1 a home:Region ; home:minX 7.0 ; home:maxX 7.2 ; home:minY 3.0 ; home:maxY 3.2 ; home:maxz 0.8 .\n"
    )
    error = refusal(store(tmp_path, place))  # a region's heights are required (tests/test_map_missing_heights.py)
    assert error.thing == WORLD + "Shelf1" and "lacks home:minZ, home:maxZ" in str(error)
    assert "(did you mean home:maxZ for its home:maxz?)" in str(error)


def test_a_property_near_no_declared_one_is_refused_without_a_guess(tmp_path: Path) -> None:
    error = refusal(store(tmp_path, bottle().replace(" .\n", ' ; home:favouriteSong "none" .\n')))
    assert "home:favouriteSong 'none', a property the home vocabulary does not declare" in str(error)
    assert "did you mean" not in str(error)


def test_properties_of_other_namespaces_and_the_shipped_map_pass(tmp_path: Path) -> None:
    lab = '@prefix lab: <http://example.org/lab#> .\nworld:Bottle1 lab:yaww "a lab\'s own" .\n'
    assert WORLD + "Bottle1" in SemanticMap.read(store(tmp_path, bottle(), lab)).objects
