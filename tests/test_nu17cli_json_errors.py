"""With --json (or cbrs query --format json) a failing command prints a JSON error object on standard
output, beside the one line on standard error, and exits non-zero (new-user CLI repro 05: a program
reading the output got nothing to parse)."""

from __future__ import annotations

import json

import pytest
from click.testing import CliRunner

from cbrs.cli import cli
from cbrs.reasoner.config import MatchConfig


@pytest.mark.parametrize(
    ("args", "says"),
    [
        pytest.param(["match", "req:NoSuch", "--json"], "no service description", id="match"),
        pytest.param(["show", "svc:NoSuch", "--json"], "nothing in the store mentions", id="show"),
        pytest.param(["query", "--name", "advertisements", "--bind", "x=1", "--format", "json"], "no such", id="bind"),
        pytest.param(["query", "SELECT ?x WHERE { ?x a }", "--format=json"], "syntax error", id="syntax"),
        pytest.param(["query", "--format", "json"], "exactly one of", id="usage"),
    ],
)
def test_error_is_json_on_stdout(args: list[str], says: str) -> None:
    result = CliRunner().invoke(cli, ["--store", ":memory:", *args])
    assert result.exit_code in (1, 2)
    error = json.loads(result.stdout)
    assert says in error["error"] and error["exit_code"] == result.exit_code
    assert says in result.stderr  # the line for a person stays


def test_format_from_the_environment_counts_for_query() -> None:
    result = CliRunner().invoke(cli, ["--store", ":memory:", "query", "SELECT ?x WHERE {"], env={"CBRS_FORMAT": "json"})
    assert result.exit_code == 1
    assert "syntax error" in json.loads(result.stdout)["error"]


def test_without_json_an_error_is_one_line_on_stderr_only() -> None:
    result = CliRunner().invoke(cli, ["--store", ":memory:", "show", "svc:NoSuch"])
    assert result.exit_code == 1
    assert result.stdout == ""


def test_the_list_of_named_queries_is_json_when_asked() -> None:
    result = CliRunner().invoke(cli, ["--store", ":memory:", "query", "--list", "--format", "json"])
    assert result.exit_code == 0
    listed = {q["name"]: q for q in json.loads(result.stdout)}
    assert {"name": "kind", "kind": "iri", "required": False}.items() <= listed["advertisements"]["parameters"][
        1
    ].items()


def test_the_matchmaking_parameters_are_json_when_asked() -> None:
    result = CliRunner().invoke(cli, ["--store", ":memory:", "match", "--params", "--json"])
    assert result.exit_code == 0
    assert json.loads(result.stdout) == {name: getattr(MatchConfig(), name) for name in MatchConfig.parameter_names()}
    missing = CliRunner().invoke(cli, ["--store", ":memory:", "match", "--json"])
    assert missing.exit_code == 2 and "Missing argument 'REQUIREMENT'" in missing.stderr
    assert json.loads(missing.stdout)["exit_code"] == 2
