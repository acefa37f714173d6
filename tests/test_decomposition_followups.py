"""The fifteenth round's follow-ups on a written decomposition (docs/tasks.md, "A fifteenth round"): a plan
planned goal by goal names its parts shortened in ``cbrs plan``; the plans page shows the composition's notes;
an ordering constraint the plan cannot follow is a reason of no plan, not an error. Composed only, no run."""

from __future__ import annotations

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

LAB15 = "https://example.org/lab15#"


def _variant(directory: Path, old: str, new: str) -> KnowledgeBase:
    """The place setting and the set-the-table task with one substitution made (``old`` empty: ``new`` added)."""
    text = (EXAMPLES / "lab15_set_the_table.ttl").read_text("utf-8")
    changed = text.replace(old, new) if old else text + new
    assert changed != text
    kb = KnowledgeBase.open(":memory:")
    for graph in ("ontology", "map"):
        kb.load([EXAMPLES / "lab15_place_setting.ttl"], graph=graph)
    written = directory / "lab15_set_the_table.ttl"
    written.write_text(changed, encoding="utf-8")
    kb.load([written], graph="requirements")
    return kb


@pytest.fixture(scope="module")
def misspelt(tmp_path_factory: pytest.TempPathFactory) -> KnowledgeBase:
    """The cup's sub-action misspelt: the table is set goal by goal, with a note."""
    return _variant(
        tmp_path_factory.mktemp("misspelt"), "someValuesFrom lab15:PutCupOnMat ]", "someValuesFrom lab15:PutCupOnMatt ]"
    )


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
