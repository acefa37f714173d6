"""A service with two inputs of one class lists both, wherever the ``advertisements`` named query is
read: ``cbrs services`` (text and JSON) and the browser's services page. A researcher's fare lookup,
which takes two train stations, was listed as taking one TrainStation (docs/matchmaking.md, "Tried by a
researcher"): the query concatenated the classes with ``GROUP_CONCAT(DISTINCT ...)``."""

from __future__ import annotations

import json
import re
from pathlib import Path

import pytest
from click.testing import CliRunner

from cbrs.cli import cli
from cbrs.kb import KnowledgeBase
from cbrs.sparql_service import SparqlService
from cbrs.web import create_app
from tests.helpers_examples import EXAMPLES

COLLECTION = EXAMPLES / "lab13_collection"
LOOKUP = "http://127.0.0.1/services/lab13/train_fare_lookup.owls#TrainFareLookupService"
JOURNEYS = "http://127.0.0.1/services/lab13/train_journey_planner.owls#TrainJourneyPlannerService"
TRANSIT = "http://127.0.0.1/ontology/lab13_transit.owl#"


@pytest.fixture(scope="module")
def store(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A store on disk with the fare lookup and the train journey planner loaded as docs/owls.md says."""
    folder = tmp_path_factory.mktemp("repeated") / "store"
    names = ("train_fare_lookup.owls", "train_journey_planner.owls")
    services = [str(COLLECTION / "services" / name) for name in names]
    done = CliRunner().invoke(
        cli, ["--store", str(folder), "load", "--catalog", str(COLLECTION / "ontology"), *services]
    )
    assert done.exit_code == 0, done.output
    return folder


def test_cbrs_services_lists_each_input(store: Path) -> None:
    done = CliRunner().invoke(cli, ["--store", str(store), "services", "--json"])
    assert done.exit_code == 0, done.output
    rows = {row["service"]: row for row in json.loads(done.stdout)}
    assert rows[LOOKUP]["inputs"] == [f"{TRANSIT}TrainStation", f"{TRANSIT}TrainStation"]
    assert rows[LOOKUP]["outputs"] == [f"{TRANSIT}Fare"]
    assert rows[JOURNEYS]["inputs"] == [f"{TRANSIT}DepartureTime", f"{TRANSIT}TrainStation", f"{TRANSIT}TrainStation"]
    text = CliRunner().invoke(cli, ["--store", str(store), "services", "--full"]).stdout
    (line,) = [line for line in text.splitlines() if line.startswith("train_fare_lookup:")]
    assert re.search(r"lab13_transit:TrainStation lab13_transit:TrainStation\s+lab13_transit:Fare", line)


def test_the_services_page_lists_each_input(store: Path) -> None:
    kb = KnowledgeBase.open(store)
    try:
        client = create_app(SparqlService(kb)).test_client()
        rows = {row["service"]: row for row in client.get("/services.json").get_json()["advertisements"]}
    finally:
        kb.close()
    assert rows[LOOKUP]["inputs"] == [f"{TRANSIT}TrainStation", f"{TRANSIT}TrainStation"]
