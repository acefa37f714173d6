"""A round by a researcher in service matchmaking, from the docs alone (docs/examples/lab13_*,
docs/matchmaking.md "Tried by a researcher"): their own OWL-S 1.1 collection of public transport
services with graded relevance, evaluated by ``cbrs eval owls-tc``, ranked and composed, with a
newcomer's mistakes in it. Each mistake is made on a copy of the collection in a temporary folder."""

from __future__ import annotations

import json
import re
import shutil
import subprocess
import sys
from pathlib import Path
from typing import Any

import pytest
from click.testing import CliRunner

from cbrs.actions.composer import Composer
from cbrs.cli import cli
from cbrs.cli_actions import plan_text
from cbrs.kb import KnowledgeBase
from cbrs.kb.catalog import Catalogue
from cbrs.reasoner import owlstc
from cbrs.reasoner.config import MatchConfig, MatchParameterError
from cbrs.reasoner.matchmaker import Matchmaker
from cbrs.reasoner.owlstc import CollectionError, evaluate_collection, read_relevance
from cbrs.sparql_service import SparqlService
from cbrs.web import create_app
from tests.helpers_examples import EXAMPLES

COLLECTION = EXAMPLES / "lab13_collection"
FARE = "http://127.0.0.1/queries/lab13/train_fare.owls#TrainFareService-request"
TICKET = "http://127.0.0.1/queries/lab13/get_me_a_train_ticket.owls#GetMeATrainTicketService-request"


def _copy(tmp_path: Path) -> Path:
    """The collection copied, to be spoilt."""
    return Path(shutil.copytree(COLLECTION, tmp_path / "collection"))


def _replace(path: Path, old: str, new: str, count: int = 1) -> None:
    text = path.read_text(encoding="utf-8")
    assert old in text
    path.write_text(text.replace(old, new, count), encoding="utf-8")


def test_the_collection_as_written_is_read_whole() -> None:
    judged = read_relevance(COLLECTION / "relevance.xml")
    assert len(judged.binary) == len(judged.graded) == 3
    assert judged.graded["http://127.0.0.1/queries/lab13/train_fare.owls"] == {
        "http://127.0.0.1/services/lab13/train_fare_lookup.owls": 3,
        "http://127.0.0.1/services/lab13/buy_train_ticket.owls": 1,
        "http://127.0.0.1/services/lab13/train_journey_planner.owls": 0,
    }


@pytest.mark.parametrize(
    ("old", "new", "said"),
    [
        # a grade out of OWLS-TC's scale: taken, it raised NDCG
        (
            "<grade><value>3</value></grade>",
            "<grade><value>5</value></grade>",
            "rates http://127.0.0.1/services/lab13/door_to_door_route_planner.owls '5' in the graded relevance "
            "(relevancegrades): expected a whole number from 0 to 3",
        ),
        # a word for a binary judgement: Python's "invalid literal for int() with base 10: 'yes'"
        (
            "<relevant>1</relevant>",
            "<relevant>yes</relevant>",
            "request http://127.0.0.1/queries/lab13/trip_between_addresses.owls rates "
            "http://127.0.0.1/services/lab13/door_to_door_route_planner.owls 'yes' in the binary relevance set: "
            "expected 0 or 1",
        ),
    ],
)
def test_a_relevance_value_out_of_its_scale_is_refused_naming_it(tmp_path: Path, old: str, new: str, said: str) -> None:
    root = _copy(tmp_path)
    _replace(root / "relevance.xml", old, new)
    with pytest.raises(CollectionError) as refused:
        read_relevance(root / "relevance.xml")
    assert str(refused.value).startswith(f"{root}: relevance.xml: ") and said in str(refused.value)
    result = CliRunner().invoke(cli, ["--store", ":memory:", "eval", "owls-tc", str(root), "--json"])
    assert result.exit_code == 1 and said in result.output and "Traceback" not in result.output


def _without_grades(root: Path, request: str | None) -> None:
    """relevance.xml without the graded set's entry of ``request`` (None: without the graded set)."""
    text = (root / "relevance.xml").read_text(encoding="utf-8")
    graded = text.index("<relevancegrades>")
    if request is None:
        cut = re.sub(r"<relevancegrades>.*</relevancegrades>", "", text[graded:], flags=re.S)
    else:
        cut = re.sub(
            rf"<request id=\"\d+\">\s*<name>{request}</name>.*?</request>", "", text[graded:], count=1, flags=re.S
        )
    (root / "relevance.xml").write_text(text[:graded] + cut, encoding="utf-8")


def test_a_request_the_graded_set_leaves_out_is_refused(tmp_path: Path) -> None:
    """Its NDCG was 0 without a word."""
    root = _copy(tmp_path)
    _without_grades(root, "train_fare")
    with pytest.raises(
        CollectionError,
        match=re.escape(
            "request http://127.0.0.1/queries/lab13/train_fare.owls is in the binary relevance set "
            "and not in the graded one"
        ),
    ):
        read_relevance(root / "relevance.xml")


def test_a_collection_that_grades_nothing_has_no_ndcg(tmp_path: Path) -> None:
    """Binary relevance alone is read; NDCG was 0.0000, as if every ranking were the worst."""
    root = _copy(tmp_path)
    _without_grades(root, None)
    result = CliRunner().invoke(cli, ["--store", ":memory:", "eval", "owls-tc", str(root), "--method", "logic"])
    assert result.exit_code == 0, result.output
    assert "relevance.xml grades nothing (no relevancegrades): NDCG is not computed" in result.stdout
    assert re.search(r"\| logic \| 0\.\d{4} \| - \|", result.stdout)
    as_json = CliRunner().invoke(
        cli, ["--store", ":memory:", "eval", "owls-tc", str(root), "--method", "logic", "--json"]
    )
    figures = json.loads(as_json.stdout)["methods"]["logic"]
    assert figures["ndcg"] is None and figures["map"] > 0


@pytest.mark.parametrize(
    ("old", "new", "said"),
    [
        # a query misspelt: the request was dropped, 2 queries evaluated, "1 requests not found" unnamed
        (
            "queries/lab13/train_fare.owls",
            "queries/lab13/train_fares.owls",
            "request http://127.0.0.1/queries/lab13/train_fares.owls: queries/ holds no train_fares.owls "
            "(did you mean train_fare.owls",
        ),
        # a judged service misspelt: counted as not there, the figures of another collection
        (
            "services/lab13/train_fare_lookup.owls",
            "services/lab13/train_fare_look_up.owls",
            "judged offer http://127.0.0.1/services/lab13/train_fare_look_up.owls: services/ holds no "
            "train_fare_look_up.owls (did you mean train_fare_lookup.owls?)",
        ),
    ],
)
def test_relevance_naming_a_file_the_collection_lacks_is_refused(tmp_path: Path, old: str, new: str, said: str) -> None:
    root = _copy(tmp_path)
    _replace(root / "relevance.xml", old, new, count=-1)
    with pytest.raises(CollectionError) as refused:
        evaluate_collection(root, ["sem-str"])
    assert "relevance.xml names what the collection does not hold: " in str(refused.value)
    assert said in str(refused.value)


def test_the_owls_upper_ontologies_are_not_reported_as_unresolved_imports(tmp_path: Path) -> None:
    """Each service imports OWL-S's Service, Profile and Process ontologies, which the reader knows: a
    collection without copies of them was told of 3 unresolved imports per load ('6 imports unresolved' in
    cbrs eval owls-tc), beside the one that mattered."""
    kb = KnowledgeBase.open(":memory:")
    ontology = Catalogue.open(COLLECTION / "ontology")
    assert kb.load([COLLECTION / "services"], catalogue=ontology).unresolved_imports == []
    root = _copy(tmp_path)
    _replace(root / "services" / "address_geocoder.owls", "lab13_transit.owl", "lab13_transport.owl", count=-1)
    report = KnowledgeBase.open(":memory:").load([root / "services"], catalogue=Catalogue.open(root / "ontology"))
    assert [(u.iri, Path(u.needed_by).name) for u in report.unresolved_imports] == [
        ("http://127.0.0.1/ontology/lab13_transport.owl", "address_geocoder.owls")
    ]


def test_the_evaluation_names_what_is_unresolved(tmp_path: Path) -> None:
    """A misnamed import of the collection's own ontology: '2 concepts and 7 imports unresolved', naming
    none, and the figures printed as if nothing were wrong."""
    root = _copy(tmp_path)
    _replace(root / "services" / "address_geocoder.owls", "lab13_transit.owl", "lab13_transport.owl", count=-1)
    result = CliRunner().invoke(cli, ["--store", ":memory:", "eval", "owls-tc", str(root), "--method", "logic"])
    assert result.exit_code == 0, result.output
    assert (
        "unresolved import http://127.0.0.1/ontology/lab13_transport.owl, owl:imports of "
        "services/address_geocoder.owls: ontology/ has no lab13_transport.owl (it holds lab13_transit.owl)"
    ) in result.stdout
    assert (
        "unresolved concept http://127.0.0.1/ontology/lab13_transport.owl#Address, parameter type of "
        "http://127.0.0.1/services/lab13/address_geocoder.owls#AddressGeocoderService: no loaded ontology declares it"
    ) in result.stdout
    as_json = CliRunner().invoke(
        cli, ["--store", ":memory:", "eval", "owls-tc", str(root), "--method", "logic", "--json"]
    )
    unresolved = json.loads(as_json.stdout)["unresolved"]
    assert len(unresolved) == 3 and unresolved[0].startswith(
        "unresolved import http://127.0.0.1/ontology/lab13_transport"
    )


def test_an_explicit_text_weight_is_used_or_refused_beside_another(monkeypatch: pytest.MonkeyPatch) -> None:
    """CBRS_MATCH_PARAMS=text_weight=0.5 replaced --text-weight 0.1 without a word (the figures were
    0.5's), and --param text_weight=0.5 did too."""
    used: list[float] = []

    def evaluate(root: Path, methods: Any, config: MatchConfig, *rest: Any) -> Any:
        used.append(config.text_weight)
        raise CollectionError(root, "stopped here")

    monkeypatch.setattr(owlstc, "evaluate_collection", evaluate)
    monkeypatch.setenv("CBRS_MATCH_PARAMS", "text_weight=0.5")
    command = ["eval", "owls-tc", str(COLLECTION), "--method", "sem-str-text", "--text-weight", "0.1"]
    result = CliRunner().invoke(cli, command)
    assert used == [0.1] and "--text-weight 0.1 is used, not the text_weight=0.5 of CBRS_MATCH_PARAMS" in result.output
    refused = CliRunner().invoke(cli, [*command, "--param", "text_weight=0.5"])
    assert refused.exit_code == 2 and used == [0.1]
    assert "--text-weight 0.1 and --param text_weight=0.5 set the same parameter to two values" in refused.output
    monkeypatch.delenv("CBRS_MATCH_PARAMS")
    CliRunner().invoke(cli, command[:-2])  # the default, and the setting absent
    assert used == [0.1, MatchConfig().text_weight]


@pytest.fixture(scope="module")
def transit_kb() -> KnowledgeBase:
    """The bundled store with the researcher's services and queries loaded, as docs/owls.md loads them."""
    kb = KnowledgeBase.open(":memory:")
    ontology = Catalogue.open(COLLECTION / "ontology")
    kb.load([COLLECTION / "services"], catalogue=ontology)
    kb.load([COLLECTION / "queries"], graph="requirements", catalogue=ontology)
    kb.load([EXAMPLES / "lab13_bus_ticket.ttl"], graph="requirements")
    return kb


def test_the_fare_lookup_takes_both_stations(transit_kb: KnowledgeBase) -> None:
    """The fare between two stations: the lookup takes two stations and was given the first for both
    (the tie-break by name), and the note said of the second 'no component takes a thing of that class'
    (ffc72ff made it 'was given _TrainStation0'); now each input takes one (tests/test_distinct_bindings.py)."""
    result = Composer(transit_kb).compose(FARE)
    assert result.plan is not None and result.unused_inputs == ()
    (step,) = result.plan.steps
    assert [(b.name, b.source.name) for b in step.bindings] == [
        ("_TrainStation0", "_TrainStation0"),
        ("_TrainStation1", "_TrainStation1"),
    ]
    assert "no step takes" not in plan_text(result)


def test_an_output_that_reports_nothing_asked_is_not_said_to_report(transit_kb: KnowledgeBase) -> None:
    """The ticket query's second candidate, the bundled fall detector, outputs a FallDownEvent, no kind
    of anything the ticket's effect is about: its explanation said 'output FallDownEvent reports
    Passenger (0.00)' with the degree 'Reports'. Its score (the inputs part alone) is as it was."""
    result = Matchmaker(transit_kb).rank(TICKET, explain=3)
    fall = next(c for c in result.candidates[:3] if c.advertisement.endswith("DetectFallDown_CeilingCamera01"))
    (pair,) = [p for p in fall.pairs if p.role == "effect"]
    assert pair.shown_degree() == "Fail" and "reports Passenger" not in pair.how
    assert pair.how.startswith("no effect; no output reports it (") and pair.similarity == 0.0
    assert fall.score == pytest.approx(0.2) and fall.parts == {"inputs": 0.5, "effects": 0.0}
    # the inputs part's lost half said: it showed 'inp=0.50' and no line about inputs
    assert [lack for lack in fall.lacks if lack.startswith("provided input")] == [
        "provided input Passenger: it takes no input",
        "provided input PaymentCard: it takes no input",
        "provided input TrainItinerary: it takes no input",
    ]
    assert [c.advertisement for c in result.candidates[:1]] == [
        "http://127.0.0.1/services/lab13/buy_train_ticket.owls#BuyTrainTicketService"
    ]


def test_the_bus_ticket_in_turtle_has_no_chain_and_says_why(transit_kb: KnowledgeBase) -> None:
    """No service issues a bus ticket: no plan, and the unmet need is the requirement's effect."""
    result = Composer(transit_kb).compose("BuyMeABusTicket")
    assert result.plan is None and result.status.value != "planned"
    (unmet,) = result.unsatisfied
    transit = "http://127.0.0.1/ontology/lab13_transit.owl#"
    assert unmet.text().startswith(
        f"no component provides effect ({transit}BusTicket, {transit}isIssuedTo, {transit}Passenger) of the requirement"
    )


def test_the_python_example_ranks_and_evaluates_the_collection() -> None:
    """docs/examples/lab13_rank_from_python.py, as matchmaking.md's "From Python" shows the library."""
    done = subprocess.run(
        [sys.executable, str(EXAMPLES / "lab13_rank_from_python.py")], capture_output=True, text=True, timeout=120
    )
    assert done.returncode == 0, done.stderr
    assert (
        "train_fare.owls by sem-str: matched\n  0.987 train_fare_lookup (acceptable): output SubClassOf 0.98"
        in done.stdout
    )
    assert re.search(r"\| sem-str \| 0\.7310 \| 0\.8892 \|", done.stdout)


def test_matchmaking_md_from_python_runs_as_written() -> None:
    """The researcher found the library API by reading the source: matchmaking.md now shows it."""
    page = (EXAMPLES.parents[1] / "docs" / "matchmaking.md").read_text(encoding="utf-8")
    section = page.split("### From Python\n", 1)[1].split("\n#", 1)[0]
    found = re.search(r"^```python\n(.*?)^```", section, re.MULTILINE | re.DOTALL)
    assert found is not None
    done = subprocess.run(
        [sys.executable, "-c", found.group(1)], cwd=EXAMPLES.parents[1], capture_output=True, text=True, timeout=120
    )
    assert done.returncode == 0, done.stderr
    assert done.stdout.startswith("0.987 train_fare_lookup True {'outputs': 0.98, 'inputs': 1.0}\n")
    assert "| logic | 0.7448 | 0.9422 |" in done.stdout


def test_a_parameter_out_of_range_is_quoted_as_written() -> None:
    """CBRS_MATCH_PARAMS=text_weight=2 was refused as "text_weight='2.0'", a value the researcher never wrote."""
    with pytest.raises(MatchParameterError) as refused:
        MatchConfig().with_params(["accept_score=0.6", "text_weight=2"])
    assert str(refused.value) == "matchmaking parameter text_weight='2': text_weight must lie in [0, 1], got 2.0"
    assert refused.value.value == "2"


def test_a_query_relevance_xml_does_not_judge_is_named_as_not_evaluated(tmp_path: Path) -> None:
    """A fourth query written and never graded: '3 queries against 9 services', and nothing else."""
    root = _copy(tmp_path)
    text = (root / "queries" / "train_fare.owls").read_text(encoding="utf-8")
    (root / "queries" / "train_fare_return.owls").write_text(text.replace("train_fare", "train_fare_return"), "utf-8")
    result = CliRunner().invoke(cli, ["--store", ":memory:", "eval", "owls-tc", str(root), "--method", "logic"])
    assert result.exit_code == 0, result.output
    assert result.stdout.startswith("3 queries against 9 services")
    assert "not evaluated, judged by no request of relevance.xml: queries/train_fare_return.owls" in result.stdout


def test_the_plans_page_shows_each_station_given(transit_kb: KnowledgeBase) -> None:
    """The browser's plan of the fare showed both stations of the lookup '<- requirement._TrainStation0'
    and nothing of the second station the task gives (e970ae5 added 'Taken by no step'); now each is taken."""
    client = create_app(SparqlService(transit_kb)).test_client()
    page = client.get("/plans", query_string={"task": FARE})
    assert page.status_code == 200
    text = re.sub(r"\s+", " ", re.sub(r"<[^>]+>", " ", page.get_data(as_text=True)))
    assert "Taken by no step" not in text
    assert "_TrainStation1 ← requirement ._TrainStation1" in text
