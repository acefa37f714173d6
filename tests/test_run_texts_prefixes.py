"""A run started in the background (the browser's tasks form, ``TaskRunner``) writes its texts with the
store's derived prefixes, as ``cbrs run`` prints them and the pages show them: the lab's IRIs were whole
in the run's JSON and on its page (docs/tasks.md, "A sixth round"). IRI fields keep whole IRIs."""

from __future__ import annotations

import json
import threading
from pathlib import Path

import pytest

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


def test_a_shapes_error_in_a_web_request_uses_the_derived_prefixes() -> None:
    """The lab's misspelt shelf posted to /store: the 400 names the terms as the pages do."""
    from cbrs.kb.namespaces import GraphName
    from cbrs.sparql_service import EndpointConfig, SparqlService
    from cbrs.web import create_app

    kb = KnowledgeBase.open(":memory:")
    for graph in ("ontology", "map"):
        kb.load([EXAMPLES / "lab6_tidy_shelf.ttl"], graph=graph)
    client = create_app(SparqlService(kb, EndpointConfig(update_token="t", isolate=False))).test_client()
    typo = (EXAMPLES / "lab6_tidy_pen_and_eraser.ttl").read_text().replace("lab6:TidyShelf ", "lab6:TidyShelff ")
    assert "TidyShelff" in typo
    posted = client.post(
        f"/store?graph={GraphName.REQUIREMENTS.iri}",
        data=typo,
        content_type="text/turtle",
        headers={"Authorization": "Bearer t"},
    )
    assert posted.status_code == 400
    message = posted.get_json()["message"]
    assert "lab6:TidyShelff is declared nowhere" in message and "did you mean lab6:TidyShelf?" in message, message


def test_a_shapes_error_from_the_library_uses_the_derived_prefixes(tmp_path: Path) -> None:
    """Called from Python (no CLI around it), the library names the lab's terms as cbrs prints them; within
    names a caller set (the CLI's), those."""
    from cbrs.kb.errors import InvalidDescriptionError
    from cbrs.kb.namespaces import store_names

    kb = KnowledgeBase.open(":memory:")
    kb.load([EXAMPLES / "lab6_tidy_shelf.ttl"], graph="ontology")
    typo = tmp_path / "typo.ttl"
    typo.write_text(
        (EXAMPLES / "lab6_tidy_pen_and_eraser.ttl").read_text().replace("lab6:TidyShelf ", "lab6:TidyShelff ")
    )
    with pytest.raises(
        InvalidDescriptionError, match=r"lab6:TidyShelff is declared nowhere.*did you mean lab6:TidyShelf\?"
    ):
        kb.load([typo], graph="requirements")
    with (
        store_names(_Whole()),
        pytest.raises(InvalidDescriptionError, match=r"did you mean https://example\.org/lab6#TidyShelf\?"),
    ):
        kb.load([typo], graph="requirements")


class _Whole:
    """A caller's names that shorten nothing (the CLI's --json: whole IRIs, its text included)."""

    @property
    def prefixes(self) -> dict[str, str]:
        return {}

    def shorten(self, iri: str) -> str | None:
        return None

    def namespace_of(self, prefix: str) -> str | None:
        return None
