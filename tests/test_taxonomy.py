from __future__ import annotations

from cbrs.reasoner.taxonomy import ROOT, Link, TaxonomyIndex
from tests.reasoner_examples import E, figure5, isa, part, positions


def test_depth_and_common_superclass() -> None:
    index = positions()
    assert index.depth(E + "RobotPosition") == 4
    assert index.common_ancestor(E + "RobotPosition", E + "RobotLocation") == (E + "SpatialData", 2, 2)
    assert index.common_ancestor(E + "RobotPosition", E + "MarkerColour") == (ROOT, 4, 2)


def test_has_part_links_count_for_below_but_not_for_superclasses() -> None:
    index = positions()
    assert index.distance_down(E + "XCoordinate", E + "Position") == 1  # a part of Position
    assert E + "Position" not in index.is_a_ancestors(E + "XCoordinate")
    assert index.common_ancestor(E + "XCoordinate", E + "YCoordinate")[0] == E + "Coordinate"


def test_equivalent_classes_and_subclass_cycles_merge() -> None:
    index = TaxonomyIndex.from_links(
        [isa("A", "Thing"), Link(E + "B", E + "A", "same"), isa("C", "D"), isa("D", "C"), isa("X", "C")]
    )
    assert index.canonical(E + "B") == index.canonical(E + "A")
    assert index.canonical(E + "C") == index.canonical(E + "D")
    assert index.depth(E + "X") == 2


def test_part_cycle_is_broken_not_fatal() -> None:
    index = TaxonomyIndex.from_links([isa("A", "Thing"), isa("B", "A"), part("A", "B")])
    assert index.depth(E + "B") == 2
    assert index.distance_down(E + "B", E + "A") == 1


def test_every_part_cycle_is_broken_at_a_part_link_and_the_rest_of_the_graph_is_left_alone() -> None:
    chain = [isa(f"N{i}", f"N{i - 1}" if i else "Thing") for i in range(50)]  # acyclic, with parts
    chain += [part(f"N{i}", f"N{i + 10}") for i in range(0, 30, 10)]
    cycles = [isa("A", "Thing"), isa("B", "A"), part("A", "B"), isa("C", "Thing"), isa("D", "C"), part("C", "D")]
    index = TaxonomyIndex.from_links(chain + cycles)
    assert index.distance_down(E + "B", E + "A") == 1 and index.distance_down(E + "D", E + "C") == 1  # is-a kept
    assert index.depth(E + "B") == 2 and index.depth(E + "D") == 2
    assert index.depth(E + "N49") == 50


def test_multiple_parents_use_the_shortest_path() -> None:
    index = TaxonomyIndex.from_links([isa("A", "Thing"), isa("B", "A"), isa("C", "B"), isa("C", "Thing")])
    assert index.depth(E + "C") == 1
    assert index.ancestors(E + "C", is_a_only=True)[E + "A"] == 2


def test_figure5_shape() -> None:
    index = figure5()
    assert index.depth(E + "F") == 2
    assert index.common_ancestor(E + "C", E + "E") == (E + "F", 1, 1)


def test_index_from_the_bundled_store(bundled_kb) -> None:  # type: ignore[no-untyped-def]
    index = TaxonomyIndex.from_kb(bundled_kb)
    home = "https://w3id.org/cbrs/home#"
    assert len(index) > 300
    assert home + "Location" in index.is_a_ancestors(home + "RobotLocation")
    assert index.distance_down(home + "XCoordinate", home + "RobotLocation") == 1
    assert index.frequency.get(home + "RobotLocation", 0) >= 1
