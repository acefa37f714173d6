"""cbrs eval paper: the figures' shape, the chart, and the claims the docs make about them."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest
from click.testing import CliRunner, Result

from cbrs.cli import cli
from cbrs.reasoner import evaluation
from cbrs.reasoner.evaluation import Report
from cbrs.reasoner.methods import METHODS


@pytest.fixture(scope="module")
def paper_run(tmp_path_factory: pytest.TempPathFactory) -> tuple[Result, Path, Report]:
    """``cbrs eval paper --json --plot`` run once, with the Report the command printed: the figure tests
    read that Report rather than evaluating the testbed again."""
    chart = tmp_path_factory.mktemp("eval") / "chart.png"
    printed: list[Report] = []
    evaluate = evaluation.evaluate_paper

    def keep(*args: Any, **kwargs: Any) -> Report:
        printed.append(evaluate(*args, **kwargs))
        return printed[-1]

    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(evaluation, "evaluate_paper", keep)
        patch.delenv("CBRS_MATCH_PARAMS", raising=False)  # the figures are the defaults'
        result = CliRunner().invoke(cli, ["eval", "paper", "--json", "--plot", str(chart)])
    assert result.exit_code == 0, result.output
    assert len(printed) == 1
    return result, chart, printed[0]


@pytest.fixture(scope="module")
def report(paper_run: tuple[Result, Path, Report]) -> Report:
    return paper_run[2]


def test_json_shape(paper_run: tuple[Result, Path, Report]) -> None:
    result, chart, printed = paper_run
    data = json.loads(result.stdout)
    assert data == printed.to_json()
    assert data["requirements"] == 20 and data["services"] == 100
    assert set(data["methods"]) == set(METHODS)
    for figures in data["methods"].values():
        assert set(figures) == {"top1", "p_at_5", "mrr", "map", "pair_correct_rate"}
        assert all(0.0 <= value <= 1.0 for value in figures.values())
    assert chart.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_text_report_names_every_method_and_the_machine() -> None:
    result = CliRunner().invoke(cli, ["eval", "paper", "--method", "sem-str", "--method", "string"])
    assert result.exit_code == 0
    assert "correct testing pairs" in result.output and "machine:" in result.output
    assert "wu-palmer" not in result.output


def test_paper_method_finds_the_right_component_first(report: Report) -> None:
    assert report.methods["sem-str"]["top1"] >= 0.95


def test_paper_method_ranks_relevant_components_above_every_baseline(report: Report) -> None:
    # MAP and per-pair correctness judge every relevant component, not only the easiest one.
    ours = report.methods["sem-str"]
    assert report.pair_correct_rate("sem-str") >= 0.85
    for baseline in ("string", "wu-palmer", "lin", "logic"):
        assert ours["map"] > report.methods[baseline]["map"]
        assert report.pair_correct_rate("sem-str") > report.pair_correct_rate(baseline)
    assert report.methods["string"]["top1"] < ours["top1"]
