"""A home of two mobile bases, each with its own components (docs/simulation.md, "A home with no mobile
base"): a plan works one base, composed once per base with the other's components left out and the best
taken; a requirement requested by a base is composed for it; a re-plan keeps the base; the recorder tracks
the base chosen. No world is built: the choice is the composer's and the store's."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from types import SimpleNamespace
from typing import Any, cast

import pytest

from cbrs.actions.base_choice import BaseChoice, choose_base, named_base
from cbrs.actions.composer import Composer, CompositionResult
from cbrs.actions.runner import Environment, _kept_base
from cbrs.cli_actions import _progress
from cbrs.kb import KnowledgeBase
from cbrs.kb.namespaces import PREFIXES
from cbrs.kb.semantic_map import SemanticMap
from cbrs.sim.recording import Recorder
from cbrs.sim.run_checks import base_components
from cbrs.sim.world import HomeWorld
from tests.helpers_examples import EXAMPLES

SVC, HOME, LAB6 = PREFIXES["svc"], PREFIXES["home"], "https://example.org/lab6#"
P1, P2 = SVC + "P3DX01", SVC + "P3DX02"
COMPONENTS = "lab6_second_base_components.ttl"

# FetchMyPen asked by nobody: no base named, so the plans' costs decide
ANYONES = """@prefix cbrs: <https://w3id.org/cbrs/core#> . @prefix home: <https://w3id.org/cbrs/home#> .
@prefix act: <https://w3id.org/cbrs/action#> . @prefix lab6: <https://example.org/lab6#> .
lab6:FetchMyPenAnyBase a cbrs:Requirement ; cbrs:serviceName "FetchMyPenAnyBase" ; cbrs:forTask act:FetchMyPen ;
  cbrs:hasOWLSModel [ a cbrs:OWLSModel ;
    cbrs:hasInput [ a cbrs:Parameter ; cbrs:parameterName "pen" ; cbrs:parameterType home:Pen ] ;
    cbrs:hasInput [ a cbrs:Parameter ; cbrs:parameterName "person" ; cbrs:parameterType home:Person ] ;
    cbrs:hasInput [ a cbrs:Parameter ; cbrs:parameterName "colourOfMarker" ; cbrs:parameterType home:ColourOfMarker ] ;
    cbrs:hasPrecondition [ a cbrs:Precondition ; cbrs:conditionSubject home:MobileRobot ;
      cbrs:conditionPredicate home:hasMarker ; cbrs:conditionObject home:ColourMarker ] ;
    cbrs:hasEffect [ a cbrs:Effect ; cbrs:conditionSubject home:Pen ; cbrs:conditionPredicate home:isWith ;
      cbrs:conditionObject home:Person ] ] .
"""

# a lab's class of which P3DX02 is the one thing: an input of that class names the base
SECOND_PIONEER = """PREFIX lab6: <https://example.org/lab6#> PREFIX svc: <https://w3id.org/cbrs/service#>
INSERT DATA { GRAPH <https://w3id.org/cbrs/graph/map> { svc:P3DX02 a lab6:SecondPioneer } }"""


def _store(tmp: Path) -> KnowledgeBase:
    """Two bases with the lab's components and requirements, P3DX02's delivery advertised at 10 s instead
    of P3DX01's 15 s, so that a plan over every component mixes the bases."""
    kb = KnowledgeBase.open(":memory:")
    kb.update((EXAMPLES / "lab6_two_bases.ru").read_text(encoding="utf-8"))
    text = (EXAMPLES / COMPONENTS).read_text(encoding="utf-8")
    assert text.count("cbrs:responseTime 15.0") == 1  # the delivery's
    kb.registry.register(text.replace("cbrs:responseTime 15.0", "cbrs:responseTime 10.0"))
    anyone = tmp / "anyone.ttl"
    anyone.write_text(ANYONES, encoding="utf-8")
    kb.load([EXAMPLES / "lab6_second_base_fetch.ttl", anyone], graph="requirements")
    kb.update(SECOND_PIONEER)
    return kb


@pytest.fixture(scope="module")
def faster(tmp_path_factory: pytest.TempPathFactory) -> KnowledgeBase:
    return _store(tmp_path_factory.mktemp("faster"))


def _world(kb: KnowledgeBase) -> HomeWorld:
    """What :func:`base_components` asks of the world: its bases."""
    smap = SemanticMap.read(kb)
    return cast(HomeWorld, SimpleNamespace(mobiles={r.name: r for r in smap.robots.values()}))


def _choose(kb: KnowledgeBase, task: str) -> tuple[CompositionResult, CompositionResult, BaseChoice | None]:
    """The plan over every component, the one a run takes, and the base chosen."""
    composer = Composer(kb)
    every = composer.compose(task)

    def without(avoid: frozenset[str]) -> CompositionResult:
        kept = [ad for ad in composer.advertisements if ad.iri not in avoid]
        return Composer(kb, composer.config, advertisements=kept).compose(task)

    found, chosen = choose_base(without, every, base_components(_world(kb), kb))
    return every, found, chosen


def _bases_of(result: CompositionResult) -> set[str]:
    assert result.plan is not None
    return {name[-6:] for name in result.plan.components() if name.endswith(("P3DX01", "P3DX02"))}


def test_each_base_has_its_own_components(faster: KnowledgeBase) -> None:
    groups = base_components(_world(faster), faster)
    assert sorted(groups) == [P1, P2]
    assert SVC + "DeliverObject_P3DX02" in groups[P2] and SVC + "DeliverObject_P3DX01" in groups[P1]
    assert not groups[P1] & groups[P2]
    # a home of one base: nothing is left out, and the store is not asked
    one = cast(HomeWorld, SimpleNamespace(mobiles={"P3DX01": object()}))
    assert base_components(one, cast(KnowledgeBase, None)) == {}


def test_a_mixed_plan_is_replaced_by_the_cheapest_one_base_plan(faster: KnowledgeBase) -> None:
    every, found, chosen = _choose(faster, LAB6 + "FetchMyPenAnyBase")
    assert _bases_of(every) == {"P3DX01", "P3DX02"}  # the matchmaker alone mixes them
    assert _bases_of(found) == {"P3DX02"}
    assert chosen is not None and chosen.base == P2
    assert chosen.why.startswith("its plan costs the least") and "P3DX01's" in chosen.why
    assert found.plan is not None and every.plan is not None and found.plan.cost <= every.plan.cost
    assert SVC + "DeliverObject_P3DX01" in chosen.left_out and SVC + "DeliverObject_P3DX02" not in chosen.left_out


def test_the_base_a_requirement_names_is_used(faster: KnowledgeBase) -> None:
    _, found, chosen = _choose(faster, LAB6 + "FetchMyPenForP3DX02")
    assert _bases_of(found) == {"P3DX02"}
    assert chosen is not None and chosen.base == P2 and "requested by P3DX02" in chosen.why


def _stub(cost: float, similarity: float, components: tuple[str, ...], by: str | None = None) -> CompositionResult:
    """What :func:`choose_base` reads of a composition: its steps' candidates, cost and similarity, and
    who requested the task."""
    steps = tuple(SimpleNamespace(candidates=(c,)) for c in components)
    plan = SimpleNamespace(steps=steps, cost=cost, similarity=similarity)
    attempt = SimpleNamespace(requirement=SimpleNamespace(requested_by=by))
    return cast(CompositionResult, SimpleNamespace(plan=plan, attempts=(attempt,)))


GROUPS = {P1: frozenset({"nav1", "deliver1"}), P2: frozenset({"nav2", "deliver2"})}


def _by_base(p1: CompositionResult, p2: CompositionResult) -> Callable[[frozenset[str]], CompositionResult]:
    return lambda avoid: p1 if "nav2" in avoid else p2


def test_cost_then_similarity_then_the_first_base() -> None:
    mixed = _stub(80.0, 0.9, ("arm", "nav1", "deliver2"))
    one, two = _stub(86.0, 0.9, ("nav1", "deliver1")), _stub(86.0, 0.95, ("nav2", "deliver2"))
    found, chosen = choose_base(_by_base(one, two), mixed, GROUPS)
    assert found is two and chosen is not None and chosen.base == P2 and "similarity is the greater" in chosen.why
    found, chosen = choose_base(_by_base(one, one), mixed, GROUPS)  # alike
    assert chosen is not None and chosen.base == P1 and "first base by IRI" in chosen.why
    assert chosen.left_out == GROUPS[P2]
    # requested by P3DX01: composed for it alone, though P3DX02's plan is the better
    asked = _stub(80.0, 0.9, ("nav1", "deliver2"), by=P1)
    found, chosen = choose_base(_by_base(one, two), asked, GROUPS)
    assert found is one and chosen is not None and "requested by P3DX01" in chosen.why


def test_a_plan_of_no_base_or_a_home_of_one_is_kept() -> None:
    arms = _stub(30.0, 0.9, ("arm", "kinect"))
    assert choose_base(_by_base(arms, arms), arms, GROUPS) == (arms, None)
    mixed = _stub(80.0, 0.9, ("nav1", "deliver2"))
    assert choose_base(_by_base(arms, arms), mixed, {P1: GROUPS[P1]}) == (mixed, None)


def test_an_input_designating_a_base_names_it(faster: KnowledgeBase) -> None:
    groups = base_components(_world(faster), faster)

    def asking(*types: str) -> CompositionResult:
        inputs = tuple(SimpleNamespace(type=t) for t in types)
        attempt = SimpleNamespace(requirement=SimpleNamespace(inputs=inputs, requested_by=None))
        return cast(CompositionResult, SimpleNamespace(attempts=(attempt,)))

    assert named_base(faster, asking(HOME + "Pen", LAB6 + "SecondPioneer"), groups) == P2
    assert named_base(faster, asking(HOME + "Pen", HOME + "CarrierRobot"), groups) is None  # both: ambiguous
    mixed = _stub(80.0, 0.9, ("nav1", "deliver2"))
    one, two = _stub(80.0, 0.9, ("nav1", "deliver1")), _stub(86.0, 0.9, ("nav2", "deliver2"))
    found, chosen = choose_base(_by_base(one, two), mixed, GROUPS, named=P2)
    assert found is two and chosen is not None and chosen.why == "an input of the task designates P3DX02"


def test_a_replan_keeps_the_base_with_components_registered_since(faster: KnowledgeBase) -> None:
    groups = base_components(_world(faster), faster)
    chosen = BaseChoice(P2, "why", groups[P1])
    later = {P1: groups[P1] | {SVC + "NavigateToPlace_P3DX01b"}, P2: groups[P2]}
    environment = cast(Environment, SimpleNamespace(base_components=lambda: later))
    kept = _kept_base(environment, chosen)
    assert SVC + "NavigateToPlace_P3DX01b" in kept and not kept & groups[P2]


def test_the_recorder_tracks_the_base_chosen_after_it_started() -> None:
    """A recorder started before any base was driven takes the one chosen at its next sample."""
    base = SimpleNamespace(body=7)
    world: Any = SimpleNamespace(mobile=None, time=0.0, base=base, name_of=lambda body: "P3DX02")
    world.pose = lambda name: SimpleNamespace(position=(0.0, 0.0, 0.0))
    recorder = Recorder.__new__(Recorder)
    recorder.world, recorder.track = world, {}
    recorder._base, recorder._movable, recorder._people = "", ["P3DX01", "P3DX02"], []
    recorder._sample()
    assert recorder._base == ""  # none driven yet
    world.mobile = object()  # HomeWorld.drive
    recorder._sample()
    assert recorder._base == "P3DX02"


def test_cbrs_run_says_the_base_chosen_among_its_progress_lines() -> None:
    line = _progress({"event": "base_chosen", "base": P2, "why": "an input of the task designates P3DX02"})
    assert line == "  the plans work svc:P3DX02: an input of the task designates P3DX02"
