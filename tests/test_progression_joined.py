"""A statement one part of a joined plan undoes for a later part (docs/composition.md, "A statement a
later step undoes"): a decomposed plan (sub-action after sub-action) and a per-goal plan (goal after
goal) are checked by progression as they will run, and the later part is composed again to achieve the
statement itself, or the plan is refused naming it.

The store is the composition catalogue's taxonomy (tests/data/composition/ontology.ttl) with a robot at
a shelf in the map. Putting an object away takes the robot from where it was (a delete effect); switching
the lamp on, a later part, needs the robot at the shelf. Each part alone takes that from the world, so
the joined plan switched the lamp on where the robot no longer was, and only the run found out.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import replace
from pathlib import Path

import pytest

from cbrs.actions.composer import ComposeConfig, Composer, CompositionResult, PlanStatus
from cbrs.actions.plan import Binding, Plan, PlanStep, Source
from cbrs.actions.progression import Clobbered, progress, progress_parts
from cbrs.kb import KnowledgeBase, Statement, Store
from cbrs.kb.resources import ontology_dir
from tests.test_composition import DATA, EX

AT_SHELF = Statement(EX + "Robot", EX + "at", EX + "Shelf")

PREFIXES = """@prefix cbrs: <https://w3id.org/cbrs/core#> . @prefix ex: <http://example.org/comp#> .
@prefix owl: <http://www.w3.org/2002/07/owl#> . @prefix rdfs: <http://www.w3.org/2000/01/rdf-schema#> .
@prefix act: <https://w3id.org/cbrs/action#> .
"""
MAP = PREFIXES + "ex:robot1 a ex:Robot ; ex:at ex:shelf1 . ex:shelf1 a ex:Shelf .\n"
"""The robot stands at the shelf when the plan starts."""


def _component(name: str, model: str, action: str = "") -> str:
    realizes = f"ex:{name} cbrs:realizesAction ex:{action} .\n" if action else ""
    return (
        f'ex:{name} a cbrs:PhysicalManipulationComponent ; rdfs:label "{name}" ; cbrs:serviceName "{name}" ;\n'
        f"    cbrs:hasOWLSModel [ a cbrs:OWLSModel ; {model} ] ;\n"
        "    cbrs:hasQoSModel [ a cbrs:QoSModel ; cbrs:responseTime 1.0 ] .\n" + realizes
    )


def _parameter(name: str, cls: str) -> str:
    return f'cbrs:hasInput [ a cbrs:Parameter ; cbrs:parameterName "{name}" ; cbrs:parameterType ex:{cls} ]'


def _condition(kind: str, subject: str, predicate: str, object_: str) -> str:
    prop = {"Precondition": "hasPrecondition", "Effect": "hasEffect", "DeleteEffect": "hasDeleteEffect"}[kind]
    return (
        f"cbrs:{prop} [ a cbrs:{kind} ; cbrs:conditionSubject ex:{subject} ; "
        f"cbrs:conditionPredicate ex:{predicate} ; cbrs:conditionObject ex:{object_} ]"
    )


def _requirement(name: str, inputs: dict[str, str], effects: list[tuple[str, str, str]], task: str = "") -> str:
    model = " ; ".join([_parameter(n, c) for n, c in inputs.items()] + [_condition("Effect", *e) for e in effects])
    for_task = f" ; cbrs:forTask ex:{task}" if task else ""
    head = f'ex:{name} a cbrs:Requirement ; rdfs:label "{name}"{for_task}'
    return f"{head} ; cbrs:hasOWLSModel [ a cbrs:OWLSModel ; {model} ] .\n"


LEAVES = _condition("DeleteEffect", "Robot", "at", "Place")
SWITCH_ON = _component(
    "SwitchOn",
    " ; ".join(
        [
            _parameter("lamp", "Lamp"),
            _condition("Precondition", "Robot", "at", "Shelf"),
            _condition("Effect", "Lamp", "hasStatus", "On"),
        ]
    ),
    "Light",
)
GO_TO_SHELF = _component("GoToShelf", _condition("Effect", "Robot", "at", "Shelf"))

DECOMPOSED = (
    PREFIXES
    + _component(
        "PutAway", " ; ".join([_parameter("obj", "Obj"), _condition("Effect", "Obj", "at", "Shelf"), LEAVES]), "Stow"
    )
    + SWITCH_ON
    + _requirement(
        "Req", {"obj": "Obj", "lamp": "Lamp"}, [("Obj", "at", "Shelf"), ("Lamp", "hasStatus", "On")], "Chores"
    )
    + _requirement("StowReq", {"obj": "Obj"}, [("Obj", "at", "Shelf")], "Stow")
    + _requirement("LightReq", {"lamp": "Lamp"}, [("Lamp", "hasStatus", "On")], "Light")
)
"""Stow the object, then switch the lamp on: a task its author decomposed into two sub-actions."""
ACTIONS = (
    PREFIXES
    + """ex:Item a owl:Class ; rdfs:subClassOf ex:Thing .
ex:Obj rdfs:subClassOf ex:Item . ex:Lamp rdfs:subClassOf ex:Item .
ex:Stow a owl:Class ; rdfs:subClassOf act:Action .
ex:Light a owl:Class ; rdfs:subClassOf act:Action .
ex:Chores a owl:Class ; rdfs:subClassOf act:Action ;
    rdfs:subClassOf [ a owl:Restriction ; owl:onProperty act:subAction ; owl:someValuesFrom ex:Stow ] ,
        [ a owl:Restriction ; owl:onProperty act:subAction ; owl:someValuesFrom ex:Light ] ;
    act:orderingConstraint ex:Chores_Order .
ex:Chores_Order a act:PartialOrderingStrict ; act:occursBefore ex:Stow ; act:occursAfter ex:Light .
"""
)
"""The decomposed task's actions, and the things a robot carries (not the robot), for the ontology graph."""

PER_GOAL = (
    PREFIXES
    + _component(
        "Shelve",
        " ; ".join(
            [
                _parameter("thing", "Item"),
                _condition("Precondition", "Robot", "at", "Shelf"),
                _condition("Effect", "Item", "at", "Shelf"),
                LEAVES,
            ]
        ),
    )
    + _requirement("Req", {"obj": "Obj", "lamp": "Lamp"}, [("Obj", "at", "Shelf"), ("Lamp", "at", "Shelf")])
)
"""The object and the lamp onto the shelf: one component shelves a thing of either class, so the direct plan
credits both goals to one step, and each goal is planned on its own."""


def _store(folder: Path, services: str, reachieve: bool) -> KnowledgeBase:
    """The store: the catalogue's taxonomy, ``services`` (components and requirements), with or without a
    component that takes the robot back to the shelf (``reachieve``)."""
    files = {"actions.ttl": ACTIONS, "map.ttl": MAP, "services.ttl": services + (GO_TO_SHELF if reachieve else "")}
    for name, text in files.items():
        (folder / name).write_text(text, encoding="utf-8")
    kb = KnowledgeBase(Store.open(":memory:"))
    kb.load([ontology_dir() / "core.ttl", DATA / "ontology.ttl", folder / "actions.ttl"], graph="ontology")
    kb.load([folder / "map.ttl"], graph="map")
    kb.load([folder / "services.ttl"])
    return kb


SCENARIOS = [
    pytest.param(DECOMPOSED, "SwitchOn", "PutAway", "sub-action ex:Light", id="decomposed"),
    pytest.param(PER_GOAL, "Shelve", "Shelve", "goal 2 (ex:Obj, ex:at, ex:Shelf)", id="per-goal"),
]


@pytest.fixture(scope="module")
def stores(tmp_path_factory: pytest.TempPathFactory) -> Iterator[dict[tuple[str, bool], KnowledgeBase]]:
    made = {
        (name, reachieve): _store(tmp_path_factory.mktemp("joined"), services, reachieve)
        for name, services in (("decomposed", DECOMPOSED), ("per-goal", PER_GOAL))
        for reachieve in (True, False)
    }
    yield made
    for kb in made.values():
        kb.close()


def _compose(
    stores: dict[tuple[str, bool], KnowledgeBase], services: str, reachieve: bool, **config: object
) -> CompositionResult:
    name = "decomposed" if services is DECOMPOSED else "per-goal"
    return Composer(stores[name, reachieve], ComposeConfig(**config)).compose(EX + "Req")  # type: ignore[arg-type]


def _names(plan: Plan) -> list[str]:
    return [c.removeprefix(EX) for c in plan.components()]


def _undone(stores: dict[tuple[str, bool], KnowledgeBase], plan: Plan) -> list[tuple[int | None, int | None]]:
    """(consumer, deleter) of each statement the joined plan needs that a step of it deleted."""
    matcher = Composer(stores["decomposed", True]).matcher
    return [(c.consumer, c.deleter) for c in progress(plan, [AT_SHELF], matcher) if c.deleter is not None]


@pytest.mark.parametrize(("services", "consumer", "deleter", "part"), SCENARIOS)
def test_unprotected_the_later_part_takes_from_the_world_what_the_earlier_part_undid(
    stores: dict[tuple[str, bool], KnowledgeBase], services: str, consumer: str, deleter: str, part: str
) -> None:
    """What the joined plan was before it was checked: the second part's step finds the robot at the shelf
    in the world, which the first part's step has taken it from; the run would fail there."""
    result = _compose(stores, services, True, protect=False)
    assert result.status is PlanStatus.PLANNED and result.plan is not None
    assert _names(result.plan) == [deleter, consumer]
    needed = next(b for b in result.plan.step(2).preconditions if b.statement == AT_SHELF)
    assert needed.source.step is None  # from the world
    assert _undone(stores, result.plan) == [(2, 1)]


@pytest.mark.parametrize(("services", "consumer", "deleter", "part"), SCENARIOS)
def test_the_later_part_achieves_again_what_the_earlier_part_undid(
    stores: dict[tuple[str, bool], KnowledgeBase], services: str, consumer: str, deleter: str, part: str
) -> None:
    result = _compose(stores, services, True)
    assert result.status is PlanStatus.PLANNED and result.plan is not None, [u.text() for u in result.unsatisfied]
    plan = result.plan
    assert plan.method == "decomposed"
    assert _names(plan) == [deleter, "GoToShelf", consumer]
    needed = next(b for b in plan.step(3).preconditions if b.statement == AT_SHELF)
    assert needed.source.step == 2  # the drive back, after the step that left
    assert _undone(stores, plan) == []
    assert plan.step(2).part_of == plan.step(3).part_of != plan.step(1).part_of  # the later part's own step


@pytest.mark.parametrize(("services", "consumer", "deleter", "part"), SCENARIOS)
def test_a_joined_plan_nothing_can_repair_is_refused_naming_the_statement_and_both_steps(
    stores: dict[tuple[str, bool], KnowledgeBase], services: str, consumer: str, deleter: str, part: str
) -> None:
    result = _compose(stores, services, False)
    assert result.status is PlanStatus.UNSOLVABLE and result.plan is None
    [reason] = result.unsatisfied
    assert (reason.need, reason.consumer, reason.deleted_by) == (
        "precondition (ex:Robot, ex:at, ex:Shelf)".replace("ex:", EX),
        EX + consumer,
        (EX + deleter,),
    )
    assert reason.chain == (part.replace("ex:", EX), EX + consumer) and not reason.cycle
    assert f"is deleted by {EX}{deleter} before it is needed" in reason.text()


@pytest.mark.parametrize(("services", "consumer", "deleter", "part"), SCENARIOS)
def test_past_max_reachieved_the_joined_plan_is_refused_saying_so(
    stores: dict[tuple[str, bool], KnowledgeBase], services: str, consumer: str, deleter: str, part: str
) -> None:
    result = _compose(stores, services, True, max_reachieved=0)
    assert result.status is PlanStatus.UNSOLVABLE
    [reason] = result.unsatisfied
    assert reason.cycle and reason.deleted_by == (EX + deleter,)
    assert "max_reachieved" in reason.remedy()


def _part(name: str, index: int, needs: Statement | None, effect: Statement, deletes: Statement | None) -> Plan:
    """A one-step plan by hand: its step needs ``needs`` from the world, states ``effect`` (its goal too)
    and deletes ``deletes``."""

    def bound(statement: Statement, step: int | None) -> Binding:
        return Binding(
            "precondition", "x", Source("x", step, None if step else "urn:req"), "Exact", 1.0, None, statement
        )

    step = PlanStep(
        index,
        EX + name,
        name,
        None,
        None,
        None,
        (bound(needs, None),) if needs else (),
        (),
        (effect,),
        1.0,
        deletes=(deletes,) if deletes else (),
    )
    return Plan(name, "urn:req", "direct", (step,), (bound(effect, index),), 1.0, 1.0)


def test_each_parts_goals_are_needed_when_that_part_ends(stores: dict[tuple[str, bool], KnowledgeBase]) -> None:
    """A sub-action's goal (the robot at the shelf, to stow from there) is for the parts after it: a later
    part that leaves undoes nothing the plan needs; a still later part that needs the robot there does."""
    matcher = Composer(stores["decomposed", True]).matcher
    away = Statement(EX + "Robot", EX + "at", EX + "Place")
    stowed, lit = Statement(EX + "Obj", EX + "at", EX + "Shelf"), Statement(EX + "Lamp", EX + "hasStatus", EX + "On")
    go, stow = _part("GoToShelf", 1, None, AT_SHELF, None), _part("PutAway", 1, None, stowed, away)
    assert progress_parts((go, stow), [], matcher) == []
    joined = Plan(
        "t", "urn:req", "decomposed", (go.steps[0], replace(stow.steps[0], index=2)), (*go.goals, *stow.goals), 1.0, 2.0
    )
    assert progress(joined, [], matcher) == [Clobbered(AT_SHELF, None, 2)]  # one plan: every goal at its end
    switch = _part("SwitchOn", 1, AT_SHELF, lit, None)
    assert progress_parts((go, stow, switch), [], matcher) == [Clobbered(AT_SHELF, 3, 2, part=2)]
