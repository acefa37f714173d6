"""A queued run's page follows it (its place in line) until it starts, then the run; a Start queued on the
tasks page says so and links the run (docs/web.md, "Waiting in the run queue").

One page session against ``cbrs serve`` with ``CBRS_RUN_QUEUE=2`` whose runs are ones no plan comes of,
each held until the test lets it end (``refusal_in_home`` stubbed: no planner, no simulation). Skipped
where Chromium or Playwright is missing, as ``tests/test_browser.py`` is.
"""

from __future__ import annotations

import threading
from collections.abc import Iterator
from types import SimpleNamespace
from typing import Any

import pytest

import cbrs.tasks
from cbrs.kb import KnowledgeBase
from cbrs.server import ServeConfig, Server
from tests.test_browser import CHROMIUM, FLAGS, WAIT_MS, pytestmark  # noqa: F401  (the same skip)

playwright_api = pytest.importorskip("playwright.sync_api", reason="Playwright is not installed (pip install .[test])")

GATES: dict[str, threading.Event] = {}


def _held(*_: Any, **__: Any) -> Any:
    """A run no plan comes of, held until its gate (by its thread's name, ``cbrs-run-N``) opens."""
    gate = GATES.setdefault(threading.current_thread().name.removeprefix("cbrs-"), threading.Event())
    gate.wait(WAIT_MS / 1000)
    return SimpleNamespace(report=None, to_dict=dict)


@pytest.fixture(scope="module")
def server() -> Iterator[Server]:
    with pytest.MonkeyPatch.context() as patch:
        patch.setenv("CBRS_RUN_QUEUE", "2")
        patch.setattr(cbrs.tasks, "refusal_in_home", _held)
        patch.setattr(cbrs.tasks, "require", lambda *_: None)
        running = Server(KnowledgeBase.open(":memory:"), ServeConfig(port=0, bridge_port=0))
        running.start()
        try:
            yield running
        finally:
            for gate in GATES.values():
                gate.set()
            running.stop(timeout=10)


def test_a_queued_runs_page_follows_it_until_it_starts(server: Server) -> None:
    runner = server.tasks
    assert runner.queue_size == 2
    first = runner.start("FetchMyPen")
    GATES.setdefault(first.id, threading.Event())
    with playwright_api.sync_playwright() as playwright:
        browser = playwright.chromium.launch(executable_path=CHROMIUM, headless=True, args=FLAGS)
        context = browser.new_context(base_url=f"http://127.0.0.1:{server.http_port}")
        context.set_default_timeout(WAIT_MS)
        page = context.new_page()
        errors: list[str] = []
        page.on("pageerror", lambda error: errors.append(str(error)))
        try:
            page.goto("/tasks")
            playwright_api.expect(page.locator("#run-status")).to_have_text("running")
            page.locator("#start-button").click()  # the page's script posts the form: queued, not followed
            note = page.locator(".form-message")
            playwright_api.expect(note).to_contain_text("queued")
            playwright_api.expect(note).to_contain_text("next in line")
            queued = runner.waiting()[0]
            GATES.setdefault(queued.id, threading.Event())
            playwright_api.expect(page.locator("#runs tr").first).to_contain_text("next in line")
            playwright_api.expect(page.locator("#run-name")).to_contain_text(first.id)  # still the run going
            page.locator(".form-message a").click()
            playwright_api.expect(page.locator("#run-status")).to_have_text("queued")
            playwright_api.expect(page.locator("#in-line")).to_have_text("next in line")
            assert page.locator("#cancel").is_visible()  # Stop shows for a queued run
            GATES[first.id].set()  # the run going ends: the queued run starts, and its page follows it
            playwright_api.expect(page.locator("#run-status")).to_have_text("running")
            assert not page.locator("#in-line").is_visible()
            GATES[queued.id].set()
            playwright_api.expect(page.locator("#run-status")).to_have_text("no-plan")
            assert not page.locator("#cancel").is_visible()
        finally:
            context.close()
            browser.close()
    assert errors == [], f"JavaScript errors on the page: {errors}"
