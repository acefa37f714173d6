"""The browser's home page (/home and its twin /home.json) says who lives in the home and whether a task
for each of them runs, as ``cbrs home`` does (kb.person_choice.people_check; docs/web.md "The home"). No
simulation: in-memory stores."""

from __future__ import annotations

import json

from click.testing import CliRunner

from cbrs.app import App
from cbrs.cli_home import home
from cbrs.kb import KnowledgeBase
from cbrs.sparql_service import SparqlService
from cbrs.web import create_app

WORLD = "https://w3id.org/cbrs/world#"
CAREGIVER = """INSERT DATA { GRAPH graph:map {
    world:Caregiver a home:Caregiver ; home:colourName "%s" ; home:rgba "0.5 0.5 0.5 1" ;
        home:x 4.6 ; home:y 3.9 ; home:yaw 0.0 } }"""


def _recoloured(colour: str) -> str:
    return (
        "DELETE { GRAPH graph:map { world:Person home:colourName ?c } } "
        f'INSERT {{ GRAPH graph:map {{ world:Person home:colourName "{colour}" }} }} '
        "WHERE { GRAPH graph:map { world:Person home:colourName ?c } }"
    )


def test_the_page_and_its_twin_say_who_lives_there(bundled_kb: KnowledgeBase) -> None:
    client = create_app(SparqlService(bundled_kb)).test_client()
    body = client.get("/home.json").get_json()
    assert body["people"] == "Person (yellow shirt)"
    (person,) = body["persons"]
    assert (person["iri"], person["colour"], person["task"], person["refusal"], person["clashes"]) == (
        WORLD + "Person",
        "yellow",
        "runs",
        None,
        [],
    )
    html = client.get("/home").get_data(as_text=True)
    assert '<h2 id="people-heading">People</h2>' in html and "<p>Person (yellow shirt)</p>" in html
    assert '<span class="badge good">runs</span>' in html


def test_look_alikes_and_a_shirt_in_the_marker_s_colour_are_named_with_why() -> None:
    kb = KnowledgeBase.open(":memory:")
    kb.update(CAREGIVER % "yellow")
    client = create_app(SparqlService(kb)).test_client()
    body = client.get("/home.json").get_json()
    assert body["verdict"] == "ok"  # the home is built; a task for either of them is refused
    assert "Caregiver and Person wear yellow: the tracker cannot tell them apart" in body["people"]
    assert [(p["name"], p["task"], p["refusal"]["kind"]) for p in body["persons"]] == [
        ("Caregiver", "refused", "LookAlikePeopleError"),
        ("Person", "refused", "LookAlikePeopleError"),
    ]
    assert "wears a yellow shirt, as Person does" in body["persons"][0]["refusal"]["message"]
    html = client.get("/home").get_data(as_text=True)
    assert "<strong>LookAlikePeopleError</strong>" in html

    kb.update(_recoloured("magenta"))
    body = client.get("/home.json").get_json()
    caregiver, resident = body["persons"]
    assert caregiver["task"] == "runs" and caregiver["refusal"] is None
    assert resident["refusal"]["kind"] == "LookAlikeMarkerError"
    assert [(c["kind"], c["other"], c["patch"]) for c in resident["clashes"]] == [
        ("marker", WORLD + "P3DX01Marker", "rear")
    ]
    assert "Person wears magenta, the colour of P3DX01Marker's rear patch" in body["people"]
    html = client.get("/home").get_data(as_text=True)
    assert "<strong>LookAlikeMarkerError</strong>" in html and "rear patch" in html
    said = json.loads(CliRunner().invoke(home, ["--json"], obj=App(":memory:", kb)).output)
    assert said["persons"] == body["persons"] and said["people"] == body["people"], "one library, two layers"
    done = CliRunner().invoke(home, [], obj=App(":memory:", kb))
    assert done.exit_code == 0, done.output  # the home is built: only a task that tracks the resident is refused
    assert "; Person wears magenta, the colour of P3DX01Marker's rear patch: a task that tracks them is refused" in (
        done.output
    )


def test_nobody_and_an_unreadable_map() -> None:
    kb = KnowledgeBase.open(":memory:")
    kb.update("DELETE WHERE { GRAPH graph:map { world:Person ?p ?o } }")
    client = create_app(SparqlService(kb)).test_client()
    body = client.get("/home.json").get_json()
    assert body["people"].startswith("none: a task that tracks, goes to or hands something to a person is refused")
    assert body["persons"] == []
    kb.update(
        f'INSERT DATA {{ GRAPH graph:map {{ <{WORLD}Pen> <https://w3id.org/cbrs/home#yaw> "north" }} }}',
        check_map=False,
    )
    body = client.get("/home.json").get_json()
    assert body["verdict"] == "unreadable" and body["people"] is None and body["persons"] == []
