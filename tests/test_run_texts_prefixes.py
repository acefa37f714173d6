"""A run started in the background (the browser's tasks form, ``TaskRunner``) writes its texts with the
store's derived prefixes, as ``cbrs run`` prints them and the pages show them: the lab's IRIs were whole
in the run's JSON and on its page (docs/tasks.md, "A sixth round"). IRI fields keep whole IRIs."""

from __future__ import annotations

import json
import threading

from cbrs.kb import KnowledgeBase
from cbrs.tasks import TaskRunner
from tests.helpers_examples import EXAMPLES

LAB6 = "https://example.org/lab6#"


def test_a_background_runs_texts_use_the_derived_prefixes() -> None:
    kb = KnowledgeBase.open(":memory:")
    for graph in ("ontology", "map"):
        kb.load([EXAMPLES / "lab6_fridge.ttl"], graph=graph)
    kb.load([EXAMPLES / "lab6_watch_the_fridge.ttl"], graph="requirements")  # no sensor, no phone: no plan
    run = TaskRunner(kb, threading.RLock(), camera=None).run("WatchTheFridge", timeout=60)
    assert run.status == "no-plan" and run.result is not None, run.error
    plan = run.result["plan"]
    texts = " ".join(need["text"] for need in plan["unsatisfied"])
    assert "lab6:isAlertedOf" in texts and LAB6 not in texts, texts
    assert plan["requirement"] == LAB6 + "WatchTheFridge"  # an IRI field: whole
    assert LAB6 + "isAlertedOf" not in json.dumps([need["text"] for need in plan["unsatisfied"]])
