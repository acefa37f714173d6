"""A task's term the ontology has no class for: a thing of the map is said to be one, with its classes;
a new class is offered the superclass its use suggests (actions/undeclared_terms.py).

A new lab's goal naming the trolley itself (``lab4:Trolley1``) was called "no class of the ontology" and
told to declare itself ``rdfs:subClassOf home:PersonalItem``; a bench, the object of an ``isLocated``
goal, was told the same class. Composition only: no world is built.
"""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

import pytest

from cbrs.actions.composer import Composer
from cbrs.actions.undeclared_terms import suggested_superclass
from cbrs.actions.unmet import Unsatisfied
from cbrs.kb import Advertisement, KnowledgeBase, Requirement, Statement
from cbrs.kb.namespaces import PREFIXES, shorten
from cbrs.reasoner.taxonomy import Link, TaxonomyIndex

EXAMPLES = Path(__file__).resolve().parents[1] / "docs" / "examples"
HOME, SVC, LAB = PREFIXES["home"], PREFIXES["svc"], "https://example.org/lab4#"
EX = "https://example.org/t#"


@pytest.fixture(scope="module")
def lab() -> Iterator[KnowledgeBase]:
    kb = KnowledgeBase.open(":memory:")
    kb.load([EXAMPLES / "lab4_trolley.ttl"], graph="ontology")
    kb.load([EXAMPLES / "lab4_trolley.ttl"], graph="map")
    kb.load(
        [EXAMPLES / "lab4_mistake_individual_in_goal.ttl", EXAMPLES / "lab4_put_pen_on_bench.ttl"],
        graph="requirements",
    )
    yield kb
    kb.close()


def _why(kb: KnowledgeBase, task: str, term: str) -> Unsatisfied:
    composition = Composer(kb).compose(task)
    assert composition.plan is None
    return next(u for u in composition.unsatisfied if term in u.undeclared)


def test_a_goal_naming_a_thing_of_the_map_says_it_is_one_and_names_its_class(lab: KnowledgeBase) -> None:
    trolley, its_class = LAB + "Trolley1", LAB + "Trolley"
    why = _why(lab, "PutPenOnTrolley1", trolley)
    assert why.individuals == ((trolley, (its_class,)),)
    text = why.text()
    assert f"{shorten(trolley)} is a thing of the map (an individual of {shorten(its_class)}), not a class" in text
    assert f"did you mean {shorten(its_class)}?" in text and "name classes" in text
    assert "is no class of the ontology" not in text and "rdfs:subClassOf" not in text


def test_a_new_class_is_offered_the_class_the_components_have_where_the_goal_uses_it(lab: KnowledgeBase) -> None:
    bench = LAB + "Bench"
    why = _why(lab, "PutPenOnBench", bench)
    # the goal (home:Pen, home:isLocated, lab4:Bench): the put-down's effect has a class at that side
    [put_down] = [ad for ad in lab.advertisements() if ad.iri == SVC + "PutDownObject_CytonDualArm01"]
    [placed] = [e.object for e in put_down.effects if e.predicate == HOME + "isLocated"]
    assert why.individuals == () and why.superclasses == ((bench, placed),)
    assert placed != HOME + "PersonalItem"
    assert f"{shorten(bench)} is no class of the ontology" in why.text()
    assert f"e.g. {shorten(bench)} rdfs:subClassOf {shorten(placed)}, loaded into the ontology graph" in why.text()


# -- the rule, on a small taxonomy ------------------------------------------------------------------


def _index() -> TaxonomyIndex:
    links = [
        (EX + "Region", EX + "Place"),
        (EX + "Shelf", EX + "Region"),
        (EX + "Room", EX + "Place"),
        (EX + "Cup", EX + "Thing"),
        (EX + "Robot", EX + "Agent"),
        (EX + "on", EX + "at"),
    ]
    terms = [EX + t for t in ("Place", "Thing", "Agent", "at", "with", "holds")]
    return TaxonomyIndex.from_links([Link(child, parent, "is-a") for child, parent in links], terms=terms)


def _ad(name: str, *effects: tuple[str, str, str]) -> Advertisement:
    return Advertisement(EX + name, (), effects=tuple(Statement(*(EX + t for t in e)) for e in effects))


ADS = [
    _ad("PutDown", ("Thing", "at", "Region")),
    _ad("Shelve", ("Cup", "at", "Shelf")),
    _ad("Move", ("Robot", "at", "Room")),
    _ad("Hand", ("Thing", "with", "Agent")),
]


@pytest.mark.parametrize(
    ("goal", "term", "expected"),
    [
        pytest.param(("Cup", "at", "Bench"), "Bench", "Region", id="most-general-object-of-the-property"),
        pytest.param(("Cup", "at", "Bench"), "Cup", "Thing", id="another-term-of-the-same-goal"),
        pytest.param(("Mug", "with", "Agent"), "Mug", "Thing", id="subject-side"),
        pytest.param(("Cup", "on", "Bench"), "Bench", "Region", id="a-super-property-when-none-uses-it"),
        pytest.param(("Cup", "holds", "Bench"), "Bench", None, id="no-condition-uses-the-property"),
    ],
)
def test_the_suggestion_follows_the_side_and_the_property(
    goal: tuple[str, str, str], term: str, expected: str | None
) -> None:
    requirement = Requirement(EX + "Task", (), effects=(Statement(*(EX + t for t in goal)),))
    found = suggested_superclass(EX + term, requirement, _index(), ADS)
    assert found == (EX + expected if expected else None)


def test_among_unrelated_classes_the_most_used_wins_and_an_input_alone_gets_none() -> None:
    requirement = Requirement(EX + "Task", (), effects=(Statement(EX + "Cup", EX + "at", EX + "Bench"),))
    # Region and Room are each above no other: Region covers two uses (its own, Shelf's), Room one
    assert suggested_superclass(EX + "Bench", requirement, _index(), ADS) == EX + "Region"
    ads = [*ADS, _ad("Park", ("Robot", "at", "Room")), _ad("Dock", ("Robot", "at", "Room"))]
    assert suggested_superclass(EX + "Bench", requirement, _index(), ads) == EX + "Room"  # 3 uses against 2
    given = Requirement(EX + "Task", ())
    assert suggested_superclass(EX + "Bench", given, _index(), ads) is None
    why = Unsatisfied("input bench (t:Bench)", "SRI", undeclared=(EX + "Bench",))
    assert "rdfs:subClassOf the class it is a kind of" in why.text()
