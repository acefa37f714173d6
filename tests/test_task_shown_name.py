"""One rule names a task for a person: the pages (``cbrs.web.links.shown_task``, the plans page's heading)
and a run's events and record (``cbrs.tasks.shown_name``). Asked for by an IRI no prefix covers, the page
showed its tail and the events the whole IRI; both now show the tail, as every page shows such an IRI."""

from __future__ import annotations

from collections.abc import Iterator

import pytest

from cbrs.kb import KnowledgeBase
from cbrs.kb.derived_prefixes import StoreNames
from cbrs.kb.namespaces import PREFIXES, store_names
from cbrs.sparql_service import SparqlService
from cbrs.tasks import shown_name
from cbrs.web import create_app
from cbrs.web.links import shown_task

LAB = "https://example.org/lab#"
UNCOVERED = LAB + "Fetch(Pen)"  # its namespace derives lab:, but "Fetch(Pen)" is no prefixed name's local part
COVERED = LAB + "FetchPen"
OWN = PREFIXES["req"] + "FetchMyPen"


@pytest.fixture(scope="module")
def kb() -> Iterator[KnowledgeBase]:
    kb = KnowledgeBase.open(":memory:")
    kb.update(
        "INSERT DATA { GRAPH <https://w3id.org/cbrs/graph/requirements> {"
        " <https://example.org/lab#Fetch(Pen)> a <https://w3id.org/cbrs/core#Requirement> ."
        " <https://example.org/lab#FetchPen> a <https://w3id.org/cbrs/core#Requirement> } }"
    )
    yield kb
    kb.close()


ASKED = [
    (UNCOVERED, UNCOVERED, "lab#Fetch(Pen)"),
    (f"<{UNCOVERED}>", UNCOVERED, "lab#Fetch(Pen)"),
    ("FetchPen", COVERED, "lab:FetchPen"),
    (COVERED, COVERED, "lab:FetchPen"),
    ("lab:FetchPen", COVERED, "lab:FetchPen"),
    ("FetchMyPen", OWN, "FetchMyPen"),
    ("req:FetchMyPen", OWN, "req:FetchMyPen"),
    (OWN, OWN, "req:FetchMyPen"),
]


def test_the_pages_and_a_run_name_a_task_alike(kb: KnowledgeBase) -> None:
    with store_names(StoreNames(lambda: kb)):  # as the task runner names a run's task
        by_run = [shown_name(listed, iri) for listed, iri, _ in ASKED]
    app = create_app(SparqlService(kb))
    with app.test_request_context("/tasks"):
        by_pages = [shown_task(listed, iri) for listed, iri, _ in ASKED]
    assert by_run == by_pages == [shown for _, _, shown in ASKED]
