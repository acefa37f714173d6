"""A named query bound to an IRI the store mentions nowhere says so on standard error (new-user CLI
repro 11: a misspelt class gave "(0 rows)" and no word of why); its output stays as it was."""

from __future__ import annotations

import json

from click.testing import CliRunner

from cbrs.cli import cli


def _query(*bind: str, fmt: str = "table") -> tuple[str, str]:
    args = ["--store", ":memory:", "query", "--name", "advertisements", "--format", fmt]
    for value in bind:
        args += ["--bind", value]
    result = CliRunner().invoke(cli, args)
    assert result.exit_code == 0, result.output
    return result.stdout, result.stderr


def test_a_misspelt_class_is_named() -> None:
    out, err = _query("kind=cbrs:DynamicPerceptonComponent")
    assert out.endswith("(0 rows)\n")
    assert err == (
        "note: nothing in the store mentions <https://w3id.org/cbrs/core#DynamicPerceptonComponent> (bound to kind)"
        "; did you mean cbrs:DynamicPerceptionComponent?\n"
    )


def test_an_unknown_prefix_is_refused_and_json_stays_json() -> None:
    """``lab:Camera`` with no prefix lab: declared is refused (tests/test_unknown_prefix.py); it was bound
    as an IRI of scheme ``lab`` and gave "(0 rows)" with a note."""
    args = ["query", "--name", "advertisements", "--format", "json", "--bind", "kind=lab:Camera"]
    result = CliRunner().invoke(cli, ["--store", ":memory:", *args])
    assert result.exit_code == 1
    answer = json.loads(result.stdout)
    assert "binding kind='lab:Camera'" in answer["error"] and "lab: is declared nowhere" in answer["error"]


def test_a_known_class_says_nothing_more() -> None:
    out, err = _query("kind=cbrs:DynamicPerceptionComponent")
    assert err == "" and "rows)" in out
