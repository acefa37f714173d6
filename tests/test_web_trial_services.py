"""``cbrs services`` and the services page list each advertisement's inputs and outputs in IRI order.

They listed them in the order the store concatenated them (``GROUP_CONCAT``), which SPARQL leaves to
the store: on the bundled in-memory store 11 of the lists were out of IRI order, and on a store that
also held OWLS-TC 16 of the bundled advertisements' lists came in another order than on the bundled one.
"""

from __future__ import annotations

import json
from typing import Any

import pyoxigraph as ox
import pytest
from click.testing import CliRunner
from flask.testing import FlaskClient

from cbrs.cli import cli
from cbrs.kb import KnowledgeBase
from cbrs.kb.namespaces import shorten
from cbrs.output import sorted_lists
from cbrs.sparql_service import SparqlService
from cbrs.web import create_app


def test_sorted_lists_sorts_the_named_columns_only() -> None:
    row = {
        "service": ox.NamedNode("http://a/s"),
        "inputs": ox.Literal("http://a/Z http://a/B http://b/A"),
        "label": ox.Literal("z b a"),
    }
    (found,) = sorted_lists([row], ("inputs", "outputs"))
    assert found["inputs"] == ox.Literal("http://a/B http://a/Z http://b/A")
    assert found["label"] == row["label"] and "outputs" not in found
    assert row["inputs"] == ox.Literal("http://a/Z http://a/B http://b/A")  # the rows given are left as they are


@pytest.fixture(scope="module")
def listed() -> tuple[list[dict[str, Any]], str]:
    runner = CliRunner()
    as_json = runner.invoke(cli, ["--store", ":memory:", "services", "--json"])
    as_text = runner.invoke(cli, ["--store", ":memory:", "services"])
    assert as_json.exit_code == 0 and as_text.exit_code == 0, as_json.output + as_text.output
    return json.loads(as_json.output), as_text.output


def test_cbrs_services_json_lists_inputs_and_outputs_in_iri_order(listed: tuple[list[dict[str, Any]], str]) -> None:
    rows, _ = listed
    several = [row for row in rows if len(row["inputs"]) > 1]
    assert len(several) > 10
    for row in rows:
        for column in ("inputs", "outputs"):
            values = row[column]  # a list, empty when none (docs/web.md, "cbrs services --json")
            assert isinstance(values, list) and values == sorted(values), (row["service"], column)


def test_cbrs_services_text_lists_them_as_the_json_does(listed: tuple[list[dict[str, Any]], str]) -> None:
    rows, text = listed
    lines = {line.split()[0]: line for line in text.splitlines()[2:] if line.startswith("svc:")}
    for row in rows:
        if row.get("inputs"):
            shown = " ".join(shorten(iri) for iri in row["inputs"])
            assert f"  {shown}  " in lines[shorten(row["service"])], row["service"]


@pytest.fixture(scope="module")
def client(bundled_kb: KnowledgeBase) -> FlaskClient:
    return create_app(SparqlService(bundled_kb)).test_client()


def test_the_services_page_lists_them_in_iri_order(client: FlaskClient) -> None:
    body = client.get("/services.json").get_json()
    for group in ("advertisements", "requirements"):
        assert body[group], group
        for row in body[group]:
            for column in ("inputs", "outputs"):
                assert row[column] == sorted(row[column]), (group, row.get("service") or row.get("iri"), column)
