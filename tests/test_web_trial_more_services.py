"""A service page asked for what is not a service description, and ``cbrs services`` on a terminal.

``/service?iri=home:Pen`` (a class) answered 404 "no service description" and nothing else, and a typo in
a service's name the same. ``cbrs services`` joined every input and output of a row on one line: 221
columns on the bundled store, 1,223 with OWLS-TC.
"""

from __future__ import annotations

import io
import json
from typing import Any

import pytest
from click.testing import CliRunner
from flask.testing import FlaskClient

from cbrs.cli import cli
from cbrs.kb import KnowledgeBase
from cbrs.kb.namespaces import shorten
from cbrs.output import LEAST_CUT, elided, fitted_table, output_width, shortened
from cbrs.sparql_service import SparqlService
from cbrs.web import create_app

# -- the service page of something else ------------------------------------------------------------------


@pytest.fixture(scope="module")
def client(bundled_kb: KnowledgeBase) -> FlaskClient:
    return create_app(SparqlService(bundled_kb)).test_client()


def _missing(client: FlaskClient, iri: str) -> dict[str, Any]:
    answer = client.get("/service.json", query_string={"iri": iri})
    assert answer.status_code == 404, iri
    body: dict[str, Any] = answer.get_json()
    return body


@pytest.mark.parametrize(
    "iri",
    ["home:Pen", "home:RobotPosition", "rdf:type", "graph:plans", "svc:NoSuchService", "svc:DeadReckonng_P3DX01"],
)
def test_a_non_service_links_its_own_page_when_there_is_one(client: FlaskClient, iri: str) -> None:
    body = _missing(client, iri)
    has_page = client.get("/resource.json", query_string={"iri": iri}).status_code == 200
    assert (body["resource"] is not None) == has_page, body
    page = client.get("/service", query_string={"iri": iri})
    assert page.status_code == 404 and 'role="alert"' in page.text
    if has_page:
        assert client.get(body["resource"]).status_code == 200
        assert f'href="{body["resource"]}"' in page.text and "is in the store, but not as a service" in body["message"]
    else:
        assert "nothing else of that name" in body["message"]


def test_a_class_is_not_offered_services_by_name(client: FlaskClient) -> None:
    body = _missing(client, "home:Pen")
    assert body["resource"] == "/resource?iri=home:Pen" and body["meant"] == []
    assert client.get(body["services"]).status_code == 200


@pytest.mark.parametrize(
    ("asked", "meant", "role"),
    [
        ("svc:DeadReckonng_P3DX01", "svc:DeadReckoning_P3DX01", "advertisement"),
        ("svc:drivebase_p3dx01", "svc:DriveBase_P3DX01", "advertisement"),  # case does not count
        ("req:RobotSelfPositon", "req:RobotSelfPosition", "requirement"),
    ],
)
def test_a_near_miss_is_offered_the_services_meant(client: FlaskClient, asked: str, meant: str, role: str) -> None:
    body = _missing(client, asked)
    first = body["meant"][0]
    assert (first["name"], first["role"]) == (meant, role) and len(body["meant"]) <= 3
    assert client.get(first["href"]).status_code == 200
    page = client.get("/service", query_string={"iri": asked}).text
    assert "Did you mean" in page and f'href="{first["href"]}"' in page


def test_a_name_like_no_service_is_offered_none(client: FlaskClient) -> None:
    assert _missing(client, "svc:Zzzzzzzzzzz")["meant"] == []


# -- cbrs services cut to a width -------------------------------------------------------------------------


def test_elided_keeps_whole_names_and_counts_the_others() -> None:
    names = ["home:A", "home:Bb", "home:Ccc", "home:Dddd"]
    assert elided(names, 100) == ("home:A home:Bb home:Ccc home:Dddd", 0)
    text, lost = elided(names, 24)
    assert text == "home:A home:Bb +2 more" and lost == 2 and len(text) <= 24
    text, lost = elided(["http://127.0.0.1/ontology/my_ontology.owl#FourWheeledCar", "x:B"], 30)
    assert text.endswith("#FourWheeledCar +1 more") and "…" in text and len(text) <= 30 and lost == 2


def test_shortened_keeps_the_local_name() -> None:
    iri = "http://127.0.0.1/ontology/my_ontology.owl#FourWheeledCar"
    assert shortened(iri, len(iri)) == iri
    for width in (20, 30, 40):
        cut = shortened(iri, width)
        assert len(cut) == width and cut.endswith("#FourWheeledCar") and cut.startswith("http")
    assert shortened(iri, 8) == "…eledCar"


def test_fitted_table_without_a_width_is_the_whole_table() -> None:
    rows: list[list[str | list[str]]] = [["s1", ["a", "b"], []], ["s2", [], ["c"]]]
    text, cut = fitted_table(["service", "inputs", "outputs"], rows, None)
    assert cut == 0 and text.splitlines()[2:] == ["s1       a b     -", "s2       -       c"]


def test_output_width_cuts_only_a_terminal(monkeypatch: pytest.MonkeyPatch) -> None:
    class Terminal(io.StringIO):
        def isatty(self) -> bool:
            return True

    monkeypatch.setenv("COLUMNS", "77")
    assert output_width(None, Terminal()) == 77
    assert output_width(None, io.StringIO()) is None  # a pipe or a file: whole lines
    assert output_width(50, io.StringIO()) == 50 and output_width(0, Terminal()) is None


@pytest.fixture(scope="module")
def advertisements() -> dict[str, dict[str, Any]]:
    listed = CliRunner().invoke(cli, ["--store", ":memory:", "services", "--json"])
    assert listed.exit_code == 0, listed.output
    return {shorten(row["service"]): row for row in json.loads(listed.output)}


def _services(*args: str) -> str:
    result = CliRunner().invoke(cli, ["--store", ":memory:", "services", *args])
    assert result.exit_code == 0, result.output
    return result.output


def _check_cell(cell: str, iris: list[str]) -> int:
    """That a list as shown is the list's first names, whole, and the count of the others; 1 if cut."""
    names = [shorten(i) for i in iris]
    tokens = cell.split()
    if not names:
        assert tokens == ["-"]
        return 0
    if tokens[-1:] != ["more"] and not any("…" in t for t in tokens):
        assert tokens == names
        return 0
    left = int(tokens[-2].lstrip("+")) if tokens[-1:] == ["more"] else 0
    shown = tokens[:-2] if tokens[-1:] == ["more"] else tokens
    whole = [t for t in shown if "…" not in t]
    assert whole == names[: len(whole)] and len(shown) + left == len(names), (cell, names)
    return 1


def test_a_row_on_one_line_cuts_its_lists_and_counts_the_rest(advertisements: dict[str, dict[str, Any]]) -> None:
    text = _services("--width", "160")
    lines = text.splitlines()
    assert max(len(line) for line in lines) <= 160
    starts = [i for i, ch in enumerate(lines[1]) if ch == "-" and (i == 0 or lines[1][i - 1] == " ")]
    cut = 0
    for line in lines[2:-1]:
        cells = [line[a:b].strip() for a, b in zip(starts, [*starts[1:], None], strict=True)]
        row = advertisements[cells[0]]
        cut += _check_cell(cells[3], row["inputs"]) + _check_cell(cells[4], row["outputs"])
    assert len(lines) - 3 == len(advertisements) and cut > 0
    note = f"({len(advertisements)} advertisements; {cut} lists cut to 160 columns: --full prints them whole)"
    assert lines[-1] == note


def test_a_narrow_width_gives_each_row_two_lines(advertisements: dict[str, dict[str, Any]]) -> None:
    text = _services("--width", "80")
    lines = text.splitlines()
    assert lines[:2] == ["service", "    kind  device  inputs -> outputs"]
    body = lines[3:-1]
    assert len(body) == 2 * len(advertisements)
    cut = 0
    for name, line in zip(body[::2], body[1::2], strict=True):
        row = advertisements[name]
        kind = shorten(row["kind"]).replace("cbrs:", "").replace("Component", "")
        front = f"    {kind}  {row['deviceName']}  "
        assert line.startswith(front) and (len(line) <= 80 or len(front) + 2 * LEAST_CUT + 4 > 80), line
        inputs, outputs = line[len(front) :].split(" -> ")
        cut += _check_cell(inputs, row["inputs"]) + _check_cell(outputs, row["outputs"])
    assert cut > 0 and f"; {cut} lists cut to 80 columns" in lines[-1]


def test_full_width_zero_and_json_are_never_cut() -> None:
    whole = _services()  # not a terminal: whole lines
    assert _services("--full", "--width", "40") == whole == _services("--width", "0")
    assert "more" not in whole and "…" not in whole and "cut to" not in whole
    assert _services("--json", "--width", "40") == _services("--json")
