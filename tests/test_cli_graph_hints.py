"""A --graph that names no graph (``graph:mapp``) is refused with the graphs it may mean, written as the
command takes them (cbrs.graph_names.graph_hint): ``cbrs export`` said only "the store has no graph
graph:mapp", ``cbrs check``, ``cbrs load`` and ``cbrs restore`` listed every name or nothing near. And
``cbrs check --timeout SECONDS`` gives HermiT this run's time limit, over the check_timeout setting."""

from __future__ import annotations

import os
from pathlib import Path

import pytest
from click.testing import CliRunner

from cbrs.cli import cli
from cbrs.graph_names import graph_hint
from cbrs.kb.namespaces import GraphName
from tests.test_owl_numbers import _gone, stalling_java  # noqa: F401  (a fixture: pytest finds it by its name)

OWN = [graph.iri for graph in GraphName]
LAB = "https://example.org/lab/graphs/kitchen"


@pytest.mark.parametrize(
    ("given", "prefixed", "hint"),
    [
        pytest.param("graph:mapp", True, "'graph:mapp': did you mean graph:map?", id="prefixed"),
        pytest.param("graph:mapp", False, "'graph:mapp': did you mean map?", id="prefix-not-taken"),
        pytest.param("graph:map", False, "'graph:map': did you mean map?", id="a-right-name-the-command-reads-not"),
        pytest.param("servics", True, "'servics': did you mean services?", id="name"),
        pytest.param(LAB[:-2] + "n", True, f"'{LAB[:-2]}n': did you mean {LAB}?", id="iri-the-best-alone"),
        pytest.param("graph:map", True, None, id="held"),
        pytest.param("lab:x", True, None, id="nothing-near"),
    ],
)
def test_the_hint_writes_the_graphs_as_the_person_and_the_command_do(
    given: str, prefixed: bool, hint: str | None
) -> None:
    assert graph_hint([given], [*OWN, LAB], prefixed=prefixed) == hint


def _cli(*args: str, env: dict[str, str] | None = None) -> tuple[int, str]:
    result = CliRunner().invoke(cli, ["--store", ":memory:", *args], env=env)
    return result.exit_code, result.stderr


@pytest.mark.parametrize(
    ("args", "said"),
    [
        pytest.param(
            ["export", "--graph", "graph:mapp", "-"], "nothing was exported; 'graph:mapp': did you mean graph:map?"
        ),
        pytest.param(["export", "--graph", "mapp", "-"], "'mapp': did you mean map?", id="export-name"),
        pytest.param(["check", "--graph", "graph:mapp"], "'graph:mapp': did you mean map?", id="check"),
        pytest.param(
            ["check", "--graph", GraphName.MAP.iri + "p"], f"did you mean {GraphName.MAP.iri}?", id="check-iri"
        ),
        pytest.param(["load", "--graph", "mapp", os.devnull], "'mapp': did you mean map?", id="load"),
    ],
)
def test_a_misspelt_graph_is_offered_the_nearest(args: list[str], said: str) -> None:
    code, err = _cli(*args)
    assert code == 1, err
    assert said in err


def test_restore_offers_the_files_graphs(tmp_path: Path) -> None:
    export = tmp_path / "store.nq"
    assert _cli("export", str(export))[0] == 0
    args = ["--store", str(tmp_path / "new"), "restore", "--yes", "--graph", "graph:mapp", str(export)]
    result = CliRunner().invoke(cli, args)
    assert result.exit_code == 1
    assert "lacks the graphs asked for graph:mapp" in result.stderr
    assert "'graph:mapp': did you mean graph:map?" in result.stderr
    assert not (tmp_path / "new").exists()  # refused before a store was made


def test_check_takes_its_time_limit_from_timeout_over_the_setting(stalling_java: Path) -> None:  # noqa: F811
    code, err = _cli("check", "--graph", "ontology", "--timeout", "0.5", env={"CBRS_CHECK_TIMEOUT": "300"})
    assert code == 1, err
    assert "HermiT did not finish over graph:ontology" in err and "within 0.5 s, and was stopped" in err
    assert "or give this check longer: cbrs check --timeout SECONDS" in err
    assert _gone(stalling_java)


@pytest.mark.parametrize("given", ["0", "-1", "soon"])
def test_a_timeout_that_is_no_positive_number_is_a_usage_error(given: str) -> None:
    code, err = _cli("check", "--timeout", given)
    assert code == 2 and "Invalid value for '--timeout'" in err
