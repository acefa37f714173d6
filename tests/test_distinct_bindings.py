"""A step that takes several inputs of one class means several things: each is bound to a different
one of the things of that class the task or the earlier steps give, where there are as many; only where
there are fewer do two share one (docs/composition.md, "Extracting the plan"). A researcher's fare
between two stations (docs/matchmaking.md, "Tried by a researcher") was planned with the lookup's two
stations both given the first station of the task. Planning only: no simulation."""

from __future__ import annotations

from pathlib import Path

import pytest

from cbrs.actions.composer import Composer
from cbrs.actions.plan import Plan
from cbrs.cli_actions import _unused_note
from cbrs.kb import KnowledgeBase
from cbrs.kb.catalog import Catalogue
from tests.helpers_examples import EXAMPLES

COLLECTION = EXAMPLES / "lab13_collection"
FARE = "http://127.0.0.1/queries/lab13/train_fare.owls#TrainFareService-request"
LOOKUP = "http://127.0.0.1/services/lab13/train_fare_lookup.owls#TrainFareLookupService"

# the researcher's ontology and two tasks of our own: a fare from one station alone (fewer things than
# the lookup's inputs), and a fare for a journey whose two ends a step of its own gives
OWN = """
@prefix cbrs: <https://w3id.org/cbrs/core#> .
@prefix transit: <http://127.0.0.1/ontology/lab13_transit.owl#> .
@prefix t: <https://example.org/distinct#> .

t:FareFromOneStation a cbrs:Requirement ;
    cbrs:serviceName "FareFromOneStation" ;
    cbrs:hasOWLSModel [ a cbrs:OWLSModel ;
        cbrs:hasInput [ a cbrs:Parameter ; cbrs:parameterName "station" ; cbrs:parameterType transit:TrainStation ] ;
        cbrs:hasOutput [ a cbrs:Parameter ; cbrs:parameterName "fare" ; cbrs:parameterType transit:Fare ] ] .

t:FareViaThreeStations a cbrs:Requirement ;
    cbrs:serviceName "FareViaThreeStations" ;
    cbrs:hasOWLSModel [ a cbrs:OWLSModel ;
        cbrs:hasInput [ a cbrs:Parameter ; cbrs:parameterName "a" ; cbrs:parameterType transit:TrainStation ] ;
        cbrs:hasInput [ a cbrs:Parameter ; cbrs:parameterName "b" ; cbrs:parameterType transit:TrainStation ] ;
        cbrs:hasInput [ a cbrs:Parameter ; cbrs:parameterName "c" ; cbrs:parameterType transit:TrainStation ] ;
        cbrs:hasOutput [ a cbrs:Parameter ; cbrs:parameterName "fare" ; cbrs:parameterType transit:Fare ] ] .

t:TicketToTheCoast a cbrs:Requirement ;
    cbrs:serviceName "TicketToTheCoast" ;
    cbrs:hasOWLSModel [ a cbrs:OWLSModel ;
        cbrs:hasInput [ a cbrs:Parameter ; cbrs:parameterName "Departure" ; cbrs:parameterType transit:TrainStation ] ;
        cbrs:hasInput [ a cbrs:Parameter ; cbrs:parameterName "coast" ; cbrs:parameterType transit:TrainStation ] ;
        cbrs:hasOutput [ a cbrs:Parameter ; cbrs:parameterName "ticket" ; cbrs:parameterType t:Ticket ] ] .

t:FareOfMyJourney a cbrs:Requirement ;
    cbrs:serviceName "FareOfMyJourney" ;
    cbrs:hasOWLSModel [ a cbrs:OWLSModel ;
        cbrs:hasInput [ a cbrs:Parameter ; cbrs:parameterName "booking" ; cbrs:parameterType transit:Passenger ] ;
        cbrs:hasOutput [ a cbrs:Parameter ; cbrs:parameterName "fare" ; cbrs:parameterType transit:Fare ] ] .
"""

ENDS = """
@prefix cbrs: <https://w3id.org/cbrs/core#> .
@prefix owl: <http://www.w3.org/2002/07/owl#> .
@prefix transit: <http://127.0.0.1/ontology/lab13_transit.owl#> .
@prefix t: <https://example.org/distinct#> .

t:Ticket a owl:Class .

t:Tickets_Booking01 a cbrs:MethodInvocationComponent ;
    cbrs:deviceName "Booking01" ;
    cbrs:serviceName "Tickets" ;
    cbrs:hasOWLSModel [ a cbrs:OWLSModel ;
        cbrs:hasInput [ a cbrs:Parameter ; cbrs:parameterName "arrival" ; cbrs:parameterType transit:TrainStation ] ;
        cbrs:hasInput [ a cbrs:Parameter ; cbrs:parameterName "departure" ; cbrs:parameterType transit:TrainStation ] ;
        cbrs:hasOutput [ a cbrs:Parameter ; cbrs:parameterName "ticket" ; cbrs:parameterType t:Ticket ] ] .

t:JourneyEnds_Booking01 a cbrs:MethodInvocationComponent ;
    cbrs:deviceName "Booking01" ;
    cbrs:serviceName "JourneyEnds" ;
    cbrs:hasOWLSModel [ a cbrs:OWLSModel ;
        cbrs:hasInput [ a cbrs:Parameter ; cbrs:parameterName "passenger" ; cbrs:parameterType transit:Passenger ] ;
        cbrs:hasOutput [ a cbrs:Parameter ; cbrs:parameterName "station0" ; cbrs:parameterType transit:TrainStation ] ;
        cbrs:hasOutput [ a cbrs:Parameter ; cbrs:parameterName "station1" ;
            cbrs:parameterType transit:TrainStation ] ] .
"""


@pytest.fixture(scope="module")
def kb(tmp_path_factory: pytest.TempPathFactory) -> KnowledgeBase:
    """The bundled store with the researcher's services and queries, and the two tasks and step above."""
    folder = tmp_path_factory.mktemp("distinct")
    (folder / "tasks.ttl").write_text(OWN, encoding="utf-8")
    (folder / "ends.ttl").write_text(ENDS, encoding="utf-8")
    store = KnowledgeBase.open(":memory:")
    ontology = Catalogue.open(COLLECTION / "ontology")
    store.load([COLLECTION / "services"], catalogue=ontology)
    store.load([Path(folder / "ends.ttl")])
    store.load([COLLECTION / "queries"], graph="requirements", catalogue=ontology)
    store.load([Path(folder / "tasks.ttl")], graph="requirements")
    return store


def _lookup_inputs(plan: Plan | None) -> dict[str, tuple[int | None, str]]:
    """The fare lookup's inputs: name -> (producing step, or None for the task; the value's name)."""
    assert plan is not None
    (step,) = [s for s in plan.steps if s.component == LOOKUP]
    return {b.name: (b.source.step, b.source.name) for b in step.bindings if b.role == "input"}


def test_two_stations_the_task_gives_go_one_to_each_input_in_order(kb: KnowledgeBase) -> None:
    result = Composer(kb).compose(FARE)
    assert _lookup_inputs(result.plan) == {
        "_TrainStation0": (None, "_TrainStation0"),
        "_TrainStation1": (None, "_TrainStation1"),
    }
    assert result.unused_inputs == ()


def test_one_station_is_shared_by_both_inputs(kb: KnowledgeBase) -> None:
    result = Composer(kb).compose("https://example.org/distinct#FareFromOneStation")
    assert _lookup_inputs(result.plan) == {"_TrainStation0": (None, "station"), "_TrainStation1": (None, "station")}


def test_two_stations_a_step_gives_go_one_to_each_input(kb: KnowledgeBase) -> None:
    result = Composer(kb).compose("https://example.org/distinct#FareOfMyJourney")
    assert result.plan is not None
    ends = next(s.index for s in result.plan.steps if s.component.endswith("JourneyEnds_Booking01"))
    assert _lookup_inputs(result.plan) == {"_TrainStation0": (ends, "station0"), "_TrainStation1": (ends, "station1")}


def test_a_third_station_left_aside_is_said_to_be_passed_over_for_the_other_two(kb: KnowledgeBase) -> None:
    """Three stations, a lookup of two: the first two are taken, one each, and the note names both."""
    result = Composer(kb).compose("https://example.org/distinct#FareViaThreeStations")
    assert _lookup_inputs(result.plan) == {"_TrainStation0": (None, "a"), "_TrainStation1": (None, "b")}
    assert [name for name, _ in result.unused_inputs] == ["c"]
    note = _unused_note(result.unused_inputs, result)
    assert "no step takes the task's input c (" in note
    assert "was given a, b, the task's other inputs of the class" in note


def test_twin_inputs_take_the_values_named_as_they_are(kb: KnowledgeBase) -> None:
    """A component's twin inputs ``arrival`` and ``departure`` and a task's ``Departure`` and ``coast``: in the
    order of the names, ``arrival`` took the departure and ``departure`` the coast. The value named as an input
    (the case aside) goes to it, and the one named as neither to the other."""
    result = Composer(kb).compose("https://example.org/distinct#TicketToTheCoast")
    assert result.plan is not None
    (step,) = [s for s in result.plan.steps if s.component.endswith("Tickets_Booking01")]
    found = {b.name: (b.source.step, b.source.name) for b in step.bindings if b.role == "input"}
    assert found == {"departure": (None, "Departure"), "arrival": (None, "coast")}
