"""The bridge's ``/cbrs/plan`` takes ``near_misses`` as ``cbrs plan --near-misses`` and ``/cbrs/run_task``
take it: how many components that come close to an unmet need its "no plan" answer names, -1 (a typed
client's "not given") or none given the default, 0 none, and a bad value refused in the words a run's is
refused with (``cbrs.tasks.check_near_misses``, ``RunOptionError``). The lab's fridge sensor that nearly
gives WatchTheFridge its output (tests/test_near_misses_along.py) is the near miss; no simulation."""

from __future__ import annotations

from collections.abc import Iterator
from typing import Any

import pytest

from cbrs.actions.composer import ComposeConfig, Composer
from cbrs.bridge_services import KnowledgeServices
from cbrs.kb import KnowledgeBase
from cbrs.rosbridge import ServiceError
from cbrs.sparql_service import EndpointConfig, SparqlService
from cbrs.tasks import RunOptionError, TaskRunner, check_near_misses
from tests.helpers_examples import EXAMPLES

SENSOR = "https://example.org/lab6#CheckFridgeDoor_FridgeDoorSensor01"


@pytest.fixture(scope="module")
def fridge() -> Iterator[KnowledgeBase]:
    kb = KnowledgeBase.open(":memory:")
    for graph in ("ontology", "map"):
        kb.load([EXAMPLES / "lab6_fridge.ttl"], graph=graph)
    kb.load([EXAMPLES / "lab6_door_status_informs.ttl"], graph="ontology")
    kb.load([EXAMPLES / "lab6_watch_the_fridge.ttl"], graph="requirements")
    kb.registry.register((EXAMPLES / "lab6_mistake_sensor_output.ttl").read_text(encoding="utf-8"))
    kb.registry.register((EXAMPLES / "lab6_caregiver_phone.ttl").read_text(encoding="utf-8"))
    yield kb
    kb.close()


@pytest.fixture(scope="module")
def services(fridge: KnowledgeBase) -> KnowledgeServices:
    sparql = SparqlService(fridge, EndpointConfig(read_only=True))  # nothing recorded, no run started
    return KnowledgeServices(sparql, TaskRunner(fridge, sparql.lock, camera=None))


def _plan(services: KnowledgeServices, **args: Any) -> dict[str, Any]:
    """A call as the bridge makes it: through the handler that refuses a field /cbrs/plan does not read."""
    return services.handlers()["/cbrs/plan"][1]({"task": "WatchTheFridge", **args})


def _named(answer: dict[str, Any]) -> list[str]:
    assert answer["status"] == "unsolvable" and not answer["recorded"]
    return [miss["component"] for need in answer["unsatisfied"] for miss in need.get("near_misses", [])]


def test_the_default_names_the_near_miss_as_cbrs_plan_does(fridge: KnowledgeBase, services: KnowledgeServices) -> None:
    expected = Composer(fridge).compose("WatchTheFridge").to_dict()["unsatisfied"]
    assert _named(_plan(services)) == [SENSOR]
    assert _plan(services)["unsatisfied"] == expected
    assert _named(_plan(services, near_misses=-1)) == [SENSOR]  # a typed client's "not given"


def test_zero_names_none_and_the_cached_composers_keep_the_counts_apart(services: KnowledgeServices) -> None:
    assert _named(_plan(services, near_misses=0)) == []
    assert _named(_plan(services)) == [SENSOR]  # the composer of 0 is not the default's
    assert _named(_plan(services, near_misses=1)) == [SENSOR]
    assert _named(_plan(services, near_misses=0, objective="cost")) == []


@pytest.mark.parametrize("value", [-2, 1.5, "3", True, -1.0])
def test_a_bad_count_is_refused_in_the_words_a_run_is(services: KnowledgeServices, value: object) -> None:
    with pytest.raises(ServiceError) as refused:
        _plan(services, near_misses=value)
    with pytest.raises(RunOptionError) as checked:
        check_near_misses(value)
    with pytest.raises(ServiceError) as run_refused:  # /cbrs/run_task's refusal, before anything starts
        services.handlers()["/cbrs/run_task"][1]({"task": "WatchTheFridge", "near_misses": value})
    words = f"near_misses {value!r} is not a whole number, 0 or more"
    assert str(refused.value) == str(checked.value) == str(run_refused.value) == words
    assert services.tasks.runs() == []


def test_none_given_is_the_compose_configs_default() -> None:
    assert check_near_misses(None) == ComposeConfig().near_misses
    assert check_near_misses(0) == 0
