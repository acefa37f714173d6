"""The warm-up of a big store reads the services page's rows itself, in page order (after the overview),
not only as a side effect of the overview counting them: the first services page on OWLS-TC spent 1.15 s
reading them when nothing had."""

from __future__ import annotations

import pytest

from cbrs.kb import KnowledgeBase
from cbrs.sparql_service import SparqlService
from cbrs.web import context, create_app, overview, warmup


def test_the_warm_up_reads_the_services_pages_rows_after_the_overview(
    bundled_kb: KnowledgeBase, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(overview, "at_a_glance", lambda: None)  # an overview that counts nothing
    app = create_app(SparqlService(bundled_kb))
    steps = warmup._steps()
    labels = [label for label, _ in steps]
    assert labels.index("the services page's rows") == labels.index("the overview's counts") + 1
    with app.app_context():
        for _, read in steps[: labels.index("the services page's rows") + 1]:
            read()
        assert context.kept("advertisement_rows") and context.kept("requirement_rows")
