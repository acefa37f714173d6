"""cbrs eval paper: the figures' shape, the chart, and the claims the docs make about them."""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import pyoxigraph as ox
import pytest
from click.testing import CliRunner, Result

from cbrs.cli import cli
from cbrs.kb import KnowledgeBase, Store
from cbrs.reasoner import evaluation
from cbrs.reasoner.evaluation import Report
from cbrs.reasoner.methods import METHODS


@dataclass
class PaperRun:
    """``cbrs eval paper --json --plot``: what it printed and wrote, the Report behind it, and the
    testbed as it loaded it."""

    result: Result
    chart: Path
    report: Report
    testbed: list[ox.Quad]


@pytest.fixture(scope="module")
def paper_run(tmp_path_factory: pytest.TempPathFactory) -> PaperRun:
    """The command run once: the figure tests read its Report rather than evaluating the testbed again,
    and the text run ranks in a copy of the testbed it loaded rather than loading it again."""
    chart = tmp_path_factory.mktemp("eval") / "chart.png"
    printed: list[Report] = []
    testbed: list[ox.Quad] = []
    evaluate, open_testbed = evaluation.evaluate_paper, evaluation.open_testbed_kb

    def keep(*args: Any, **kwargs: Any) -> Report:
        printed.append(evaluate(*args, **kwargs))
        return printed[-1]

    def keep_testbed(*args: Any, **kwargs: Any) -> KnowledgeBase:
        kb = open_testbed(*args, **kwargs)
        testbed.extend(kb.store.quads())
        return kb

    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(evaluation, "evaluate_paper", keep)
        patch.setattr(evaluation, "open_testbed_kb", keep_testbed)
        patch.delenv("CBRS_MATCH_PARAMS", raising=False)  # the figures are the defaults'
        result = CliRunner().invoke(cli, ["eval", "paper", "--json", "--plot", str(chart)])
    assert result.exit_code == 0, result.output
    assert len(printed) == 1 and testbed
    return PaperRun(result, chart, printed[0], testbed)


@pytest.fixture(scope="module")
def report(paper_run: PaperRun) -> Report:
    return paper_run.report


def test_json_shape(paper_run: PaperRun) -> None:
    data = json.loads(paper_run.result.stdout)
    assert data == paper_run.report.to_json()
    assert data["requirements"] == 20 and data["services"] == 100
    assert set(data["methods"]) == set(METHODS)
    for figures in data["methods"].values():
        assert set(figures) == {"top1", "p_at_5", "mrr", "map", "pair_correct_rate"}
        assert all(0.0 <= value <= 1.0 for value in figures.values())
    assert paper_run.chart.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_text_report_names_every_method_and_the_machine(paper_run: PaperRun, monkeypatch: pytest.MonkeyPatch) -> None:
    def copy(*_: Any, **__: Any) -> KnowledgeBase:  # the testbed as the JSON run loaded it (the run closes it)
        kb = KnowledgeBase(Store.open(":memory:"))
        kb.store.add(paper_run.testbed)
        return kb

    monkeypatch.setattr(evaluation, "open_testbed_kb", copy)
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
