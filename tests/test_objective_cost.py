"""``--objective cost`` ranks by the stated ``cbrs:cost`` where every candidate states one (docs/composition.md,
"Which cost"): the seventh round's cheaper planner (tasks.md), which states a lower cbrs:cost and a slower
response time than A*, is planned by it, and the plan says what decided each step. No world is built."""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import replace
from pathlib import Path
from typing import Any

import pytest
from click.testing import CliRunner

from cbrs.actions import ComposeConfig, Composer, Objective
from cbrs.actions.runner import run_task
from cbrs.cli import cli
from cbrs.cli_actions import plan_text
from cbrs.kb import Advertisement, KnowledgeBase
from cbrs.kb.vocab import CBRS

EXAMPLE = Path(__file__).resolve().parents[1] / "docs" / "examples" / "lab7_lab_planner.ttl"
LAB = "https://example.org/lab7#PlanPathAnyAngle_LabPlanner01"
ASTAR = "https://w3id.org/cbrs/service#PlanPathAStar_HomeServer01"


@pytest.fixture(scope="module")
def kb(tmp_path_factory: pytest.TempPathFactory) -> Iterator[KnowledgeBase]:
    """The bundled home with the lab's planner as the seventh round's cheaper variant: a cbrs:cost of 0.1
    (A*'s is 1.0) and a response time of 0.5 s (A*'s is 0.2 s)."""
    cheaper = tmp_path_factory.mktemp("lab") / "cheaper_planner.ttl"
    cheaper.write_text(EXAMPLE.read_text().replace("cbrs:responseTime 0.05", "cbrs:responseTime 0.5"))
    opened = KnowledgeBase.open(":memory:")
    opened.load([cheaper], graph="services")
    yield opened
    opened.close()


def _planners(kb: KnowledgeBase, config: ComposeConfig, ads: list[Advertisement] | None = None) -> Any:
    result = Composer(kb, config, advertisements=ads).compose("FetchMyPen")
    assert result.plan is not None
    return result, [s for s in result.plan.steps if s.component in (LAB, ASTAR)]


def test_cost_ranks_by_the_stated_cost_and_says_so(kb: KnowledgeBase) -> None:
    result, planners = _planners(kb, ComposeConfig(objective=Objective.COST))
    assert len(planners) == 2  # one for each drive
    assert {(s.component, s.ranked_by) for s in planners} == {(LAB, "cbrs:cost")}
    assert ASTAR in planners[0].alternatives
    found = result.to_dict()
    assert found["objective"] == "cost"
    assert {s["ranked_by"] for s in found["steps"] if s["component"] == LAB} == {"cbrs:cost"}
    assert "the stated cbrs:cost at step " + ", ".join(str(s.index) for s in planners) in plan_text(result)


def test_the_default_objective_is_unchanged(kb: KnowledgeBase) -> None:
    result, planners = _planners(kb, ComposeConfig())
    assert {s.component for s in planners} == {ASTAR}  # as similar; the quicker answer breaks the tie
    assert {s.ranked_by for s in planners} == {"responseTime"}
    assert result.to_dict()["objective"] == "similarity"
    assert "--objective" not in plan_text(result)  # the default's text is as it was


def test_a_candidate_stating_no_cost_is_not_compared_by_it(kb: KnowledgeBase) -> None:
    ads = [
        replace(ad, qos=tuple(q for q in ad.qos if q.metric != CBRS.cost)) if ad.iri == LAB else ad
        for ad in kb.advertisements()
    ]
    _, planners = _planners(kb, ComposeConfig(objective=Objective.COST), ads)
    assert {(s.component, s.ranked_by) for s in planners} == {(ASTAR, "responseTime")}
    # a configured cost for those that state none makes them comparable: 0 undercuts A*'s 1.0
    _, planners = _planners(kb, ComposeConfig(objective=Objective.COST, unstated_cost=0.0), ads)
    assert {(s.component, s.ranked_by) for s in planners} == {(LAB, "cbrs:cost")}


def test_run_task_refuses_an_objective_its_composer_does_not_rank_by(kb: KnowledgeBase) -> None:
    with pytest.raises(ValueError, match=r"'cost'.*'similarity'"):
        run_task(kb, "FetchMyPen", environment=None, composer=Composer(kb), objective=Objective.COST)  # type: ignore[arg-type]


def test_cbrs_run_takes_the_objective() -> None:
    shown = CliRunner().invoke(cli, ["run", "--help"], terminal_width=200)
    assert shown.exit_code == 0
    assert "--objective [similarity|cost]" in shown.output
