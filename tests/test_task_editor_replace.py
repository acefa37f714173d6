"""The task editor's Replace removes what the previously saved text of the task added, not only the task's
own description (cbrs.task_drafts.save; docs/web.md, "Writing a task on a page"): extra triples the old
text wrote stayed in graph:requirements. What another saved task's text states, or a load put there, stays.

Through the library call the page makes, on a fresh store; nothing is composed.
"""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

import pyoxigraph as ox
import pytest

from cbrs import task_drafts
from cbrs.kb import KnowledgeBase
from cbrs.kb.errors import KnowledgeBaseError
from cbrs.kb.namespaces import PREFIXES, GraphName
from cbrs.sparql_service import EndpointConfig, SparqlService

TOKEN = "replace-test-token"
PENCIL = (Path(__file__).parent / "data" / "tasks" / "fetch_my_pencil.ttl").read_text(encoding="utf-8")
HOME = PREFIXES["home"]
COMMENT = ox.NamedNode("http://www.w3.org/2000/01/rdf-schema#comment")


def _extra(text: str) -> str:
    """A triple about something other than the task, as a lab's text may add one."""
    return f'\nhome:Pencil rdfs:comment "{text}"@en .\n'


def _said(text: str) -> ox.Quad:
    return ox.Quad(ox.NamedNode(HOME + "Pencil"), COMMENT, ox.Literal(text, language="en"), GraphName.REQUIREMENTS.node)


@pytest.fixture(scope="module")
def sparql() -> Iterator[SparqlService]:
    kb = KnowledgeBase.open(":memory:")
    yield SparqlService(kb, EndpointConfig(update_token=TOKEN))
    kb.close()


def _task(name: str, label: str = "Fetch my pencil", extra: str = "") -> str:
    return PENCIL.replace("req:FetchMyPencil", f"req:{name}").replace('"Fetch my pencil"', f'"{label}"') + extra


def _save(sparql: SparqlService, text: str, replace: bool = False) -> task_drafts.TaskDraft:
    draft = task_drafts.read(sparql.kb, text, PREFIXES)
    task_drafts.save(sparql, draft, TOKEN, replace)
    return draft


def _stored(draft: task_drafts.TaskDraft) -> set[ox.Quad]:
    """The draft's triples as the store keeps them (Oxigraph writes ``10.0`` as ``10``)."""
    scratch = ox.Store()
    scratch.extend(draft.quads)
    return set(scratch)


def _requirements(sparql: SparqlService) -> set[ox.Quad]:
    return set(sparql.kb.store.quads(graph=GraphName.REQUIREMENTS.node))


def test_replace_removes_what_the_old_text_added_and_keeps_what_the_new_one_says(sparql: SparqlService) -> None:
    before = _requirements(sparql)
    _save(sparql, _task("PencilOnce", extra=_extra("blue, from the lab")))
    assert _said("blue, from the lab") in _requirements(sparql)
    new = _save(sparql, _task("PencilOnce", "Bring the pencil", _extra("the red one")), replace=True)
    assert _requirements(sparql) == before | _stored(new)  # the old label and comment gone, nothing else


def test_a_triple_another_saved_task_states_stays_until_no_saved_text_states_it(sparql: SparqlService) -> None:
    before = _requirements(sparql)
    shared = _extra("shared by two tasks")
    _save(sparql, _task("PencilFirst", extra=shared))
    _save(sparql, _task("PencilSecond", extra=shared))
    first = _save(sparql, _task("PencilFirst", "Pencil, first"), replace=True)
    assert _said("shared by two tasks") in _requirements(sparql)  # the second text says it still
    second = _save(sparql, _task("PencilSecond", "Pencil, second"), replace=True)
    assert _requirements(sparql) == before | _stored(first) | _stored(second)


def test_a_triple_a_load_put_there_is_not_the_editors_to_remove(sparql: SparqlService, tmp_path: Path) -> None:
    loaded = tmp_path / "loaded.ttl"
    loaded.write_text(f'<{HOME}Pencil> <{COMMENT.value}> "loaded by the lab"@en .\n', encoding="utf-8")
    sparql.kb.load([loaded], graph="requirements")
    _save(sparql, _task("PencilLoaded", extra=_extra("loaded by the lab")))
    _save(sparql, _task("PencilLoaded", "Pencil, loaded"), replace=True)
    assert _said("loaded by the lab") in _requirements(sparql)


def test_a_refused_replace_changes_nothing(sparql: SparqlService) -> None:
    _save(sparql, _task("PencilKept", extra=_extra("kept whole")))
    everything = set(sparql.kb.store.quads())
    draft = task_drafts.read(sparql.kb, _task("PencilKept", "Pencil, refused"), PREFIXES)
    with pytest.raises(KnowledgeBaseError):
        task_drafts.save(sparql, draft, "another token", replace=True)
    with pytest.raises(task_drafts.TaskExistsError):
        task_drafts.save(sparql, draft, TOKEN)
    assert set(sparql.kb.store.quads()) == everything
