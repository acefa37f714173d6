"""Two values of a grasp property are refused naming the class that stated them (an object's class may
inherit them), and both values: the map author fixes that class."""

from __future__ import annotations

import pytest

from cbrs.kb import KnowledgeBase
from cbrs.kb.namespaces import PREFIXES
from cbrs.kb.semantic_map import MapError, SemanticMap

HOME = PREFIXES["home"]
SUBCLASS = PREFIXES["rdfs"] + "subClassOf"


def refusal(statements: str) -> MapError:
    kb = KnowledgeBase.open(":memory:")
    kb.update(f"INSERT DATA {{ GRAPH graph:ontology {{ {statements} }} }}")
    with pytest.raises(MapError) as refused:
        SemanticMap.read(kb)
    return refused.value


def test_two_approach_lists_inherited_are_named_by_the_class_that_stated_them() -> None:
    refused = refusal(f"<{HOME}Drinkware> <{HOME}graspApproach> 'top' .")  # beside the bundled "side top"
    assert refused.thing == HOME + "Drinkware"
    assert "'side top' and 'top'" in str(refused) and "the nearest class above Cup that says" in str(refused)


def test_two_grasp_heights_inherited_are_named_by_the_class_that_stated_them() -> None:
    refused = refusal(f"<{HOME}Drinkware> <{HOME}graspHeightRatio> 0.5 .")
    assert refused.thing == HOME + "Drinkware" and "'0.5' and '0.7'" in str(refused)


def test_two_classes_as_near_are_both_named_with_what_each_says() -> None:
    tool = f"<{HOME}Tool> <{HOME}graspApproach> 'top' ; <{HOME}graspHeightRatio> 0.7 ."
    refused = refusal(f"<{HOME}Cup> <{SUBCLASS}> <{HOME}Tool> . {tool}")
    assert refused.thing == HOME + "Drinkware"
    assert "Drinkware has 'side top'; Tool has 'top'" in str(refused)


def test_a_class_stating_two_itself_is_named_as_before() -> None:
    refused = refusal(f"<{HOME}Cup> <{HOME}graspApproach> 'side' , 'top' ; <{HOME}graspHeightRatio> 0.7 .")
    assert refused.thing == HOME + "Cup" and "'side' and 'top'" in str(refused)
