"""The fifteenth round's follow-ups on a written decomposition (docs/tasks.md, "A fifteenth round"): a plan
planned goal by goal names its parts shortened in ``cbrs plan``; the plans page shows the composition's notes;
an ordering constraint the plan cannot follow is a reason of no plan, not an error. Composed only, no run."""

from __future__ import annotations

import json
import re
from html import unescape
from pathlib import Path

import pytest

from cbrs.actions.composer import Composer
from cbrs.cli_actions import plan_text
from cbrs.kb import KnowledgeBase
from cbrs.kb.derived_prefixes import StoreNames
from cbrs.kb.namespaces import store_names
from cbrs.sparql_service import EndpointConfig, SparqlService
from cbrs.web import create_app
from tests.helpers_examples import EXAMPLES
from tests.helpers_plan_cli import plan

LAB15 = "https://example.org/lab15#"


def _written(directory: Path, old: str, new: str) -> Path:
    """The set-the-table task with one substitution made (``old`` empty: ``new`` added), as a file."""
    text = (EXAMPLES / "lab15_set_the_table.ttl").read_text("utf-8")
    changed = text.replace(old, new) if old else text + new
    assert changed != text
    written = directory / "lab15_set_the_table.ttl"
    written.write_text(changed, encoding="utf-8")
    return written


def _loaded(kb: KnowledgeBase, task: Path) -> KnowledgeBase:
    """``kb`` with the place setting in the ontology and the map, and ``task`` in the requirements."""
    for graph in ("ontology", "map"):
        kb.load([EXAMPLES / "lab15_place_setting.ttl"], graph=graph)
    kb.load([task], graph="requirements")
    return kb


@pytest.fixture(scope="module")
def misspelt(tmp_path_factory: pytest.TempPathFactory) -> KnowledgeBase:
    """The cup's sub-action misspelt: the table is set goal by goal, with a note."""
    written = _written(tmp_path_factory.mktemp("misspelt"), "lab15:PutCupOnMat ]", "lab15:PutCupOnMatt ]")
    return _loaded(KnowledgeBase.open(":memory:"), written)


def test_goal_parts_are_named_shortened(misspelt: KnowledgeBase) -> None:
    """``cbrs plan`` said "decomposed into https://example.org/lab15#SetTheTableForOne/goal1, ...": the part's
    name has a slash, so it was never shortened as a whole. Now the task's name is, and the goal follows it."""
    result = Composer(misspelt).compose("SetTheTableForOne")
    assert result.plan is not None and result.plan.sub_actions == tuple(
        f"{LAB15}SetTheTableForOne/goal{n}" for n in (1, 2)
    )
    with store_names(StoreNames(lambda: misspelt)):
        text = plan_text(result)
    head = text.splitlines()[0]
    assert "decomposed into lab15:SetTheTableForOne/goal1, lab15:SetTheTableForOne/goal2" in head, head
    assert LAB15 not in head


def _page_text(html: str) -> str:
    html = re.sub(r"(?s)<(script|style)[^>]*>.*?</\1>", " ", html)
    return " ".join(unescape(re.sub(r"<[^>]+>", " ", html)).split())


def test_the_plans_page_shows_the_notes_by_the_names_the_pages_show(misspelt: KnowledgeBase) -> None:
    """``/plans.json`` had the notes (``composition.notes``), the page none: a lab member in the browser saw
    the table set goal by goal and not why. The page now says them where it says what the plan does without,
    with the lab's terms by their prefix, as the rest of the page names them."""
    app = create_app(SparqlService(misspelt, EndpointConfig(update_token="t")), tasks=None)
    client = app.test_client()
    notes = client.get("/plans.json?task=lab15:SetTheTableForOne").get_json()["composition"]["notes"]
    assert any(f"{LAB15}PutCupOnMatt" in note for note in notes), notes
    page = client.get("/plans?task=lab15:SetTheTableForOne", headers={"Accept": "text/html"})
    assert page.status_code == 200
    said = _page_text(page.text)
    assert (
        "lab15:SetTheTableForOne is not planned by its sub-actions, nor in their order: its sub-action"
        " lab15:PutCupOnMatt (no action class the store declares; did you mean lab15:PutCupOnMat?)" in said
    ), said
    assert "orders lab15:PutCupOnMat, no sub-action of it" in said
    assert LAB15 not in said.split("Data flow", 1)[0], said  # the parts too: lab15:SetTheTableForOne/goal1
    assert "decomposed into lab15:SetTheTableForOne/goal1 , lab15:SetTheTableForOne/goal2" in said


BACKWARDS = """
lab15:PutSaucerOnMat act:orderingConstraint lab15:PutSaucerOnMat_Order1 .
lab15:PutSaucerOnMat_Order1 a owl:NamedIndividual , act:PartialOrderingStrict ;
    act:occursBefore act:PuttingDownAnObject ; act:occursAfter act:ApproachToObject .
"""
UNFOLLOWED = (
    "the ordering constraint lab15:PutSaucerOnMat_Order1 of lab15:PutSaucerOnMat (act:occursBefore"
    " act:PuttingDownAnObject, act:occursAfter act:ApproachToObject) puts svc:PutDownObject_CytonDualArm01 before"
    " svc:ApproachToObject_CytonDualArm01, but the plan needs the opposite order"
)


@pytest.fixture(scope="module")
def backwards(tmp_path_factory: pytest.TempPathFactory) -> str:
    """A store whose saucer's sub-action orders its put-down before its approach: no plan can follow it."""
    directory = tmp_path_factory.mktemp("backwards")
    location = str(directory / "store")
    _loaded(KnowledgeBase.open(location), _written(directory, "", BACKWARDS)).close()
    return location


def test_an_ordering_no_plan_can_follow_is_a_reason_of_no_plan(backwards: str) -> None:
    """``cbrs plan`` ended with "Error: ordering constraint ... needs the opposite order" (an exception out of
    the extraction), where every other task that cannot be planned is answered "no plan" with its reasons.
    Now it is one, naming the constraint and what it orders, in the text and the JSON, with the same status."""
    code, out = plan(backwards, "PutSaucerOnMat")
    assert code == 1 and "Error" not in out, out
    assert out.startswith("lab15:PutSaucerOnMat: no plan. Why:\n"), out
    assert UNFOLLOWED in " ".join(out.split()), out
    code, out = plan(backwards, "PutSaucerOnMat", "--json")
    found = json.loads(out)
    assert code == 1 and found["status"] == "unsolvable"
    (reason,) = found["unsatisfied"]
    assert reason["need"] == f"{LAB15}PutSaucerOnMat_Order1" and reason["consumer"] == f"{LAB15}PutSaucerOnMat"
    assert "but the plan needs the opposite order" in reason["text"]


def test_a_task_whose_sub_action_cannot_be_followed_is_planned_otherwise_and_says_why(backwards: str) -> None:
    """The table set with that saucer's sub-action: by its parts it cannot be planned, so it is planned goal by
    goal, as a decomposition that cannot be followed is, and a note says why (it too was the error before)."""
    code, out = plan(backwards, "SetTheTableForOne")
    assert code == 0, out
    (note,) = [line for line in out.splitlines() if line.startswith("note: lab15:SetTheTableForOne is not planned")]
    assert UNFOLLOWED in note, note


def test_the_plans_page_says_the_ordering_as_the_reason(backwards: str) -> None:
    """The page answered the error's 409; it now shows no plan, and why, by the names the pages show."""
    kb = KnowledgeBase.open(backwards)
    try:
        client = create_app(SparqlService(kb, EndpointConfig(update_token="t")), tasks=None).test_client()
        page = client.get("/plans?task=lab15:PutSaucerOnMat", headers={"Accept": "text/html"})
        assert page.status_code == 200, page.text
        said = _page_text(page.text)
    finally:
        kb.close()
    assert f"No plan. Why: {UNFOLLOWED}" in said, said
