"""``cbrs services --json`` gives each advertisement's inputs and outputs as lists of IRIs in IRI order, empty
when it has none, as the browser's ``/services.json`` does; it gave each as one space-joined string (absent
when none), which every reader had to split (docs/web.md, "cbrs services --json")."""

from __future__ import annotations

import json
from typing import Any

import pyoxigraph as ox
from click.testing import CliRunner

from cbrs.cli import cli
from cbrs.kb.namespaces import PREFIXES
from cbrs.output import json_row

SVC, HOME = PREFIXES["svc"], PREFIXES["home"]


def test_services_json_lists_inputs_and_outputs() -> None:
    listed = CliRunner().invoke(cli, ["--store", ":memory:", "services", "--json"])
    assert listed.exit_code == 0, listed.output
    rows: dict[str, dict[str, Any]] = {row["service"]: row for row in json.loads(listed.output)}
    assert rows[SVC + "PlanPathAStar_HomeServer01"]["inputs"] == [
        HOME + "OccupancyGridMap",
        HOME + "Position",
        HOME + "RobotLocation",
    ]
    assert rows[SVC + "TrackPerson_CeilingCamera02"]["outputs"] == [HOME + "PersonLocation"]
    assert rows[SVC + "ProvideGridMap_HomeServer01"]["inputs"] == []  # needs nothing: an empty list, not absent
    assert all(isinstance(row["inputs"], list) and isinstance(row["outputs"], list) for row in rows.values())


def test_a_row_as_json_splits_and_sorts_the_lists_only() -> None:
    row = {
        "service": ox.NamedNode("http://a/S"),
        "inputs": ox.Literal("http://a/Z http://a/B"),
        "label": ox.Literal("x y"),
    }
    assert json_row(row, ("inputs", "outputs")) == {
        "service": "http://a/S",
        "label": "x y",
        "inputs": ["http://a/B", "http://a/Z"],
        "outputs": [],
    }
