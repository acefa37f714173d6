"""A class on one server (docs/web.md, "Tried by a teacher with a class"): the tasks page when every stream
slot is taken follows the run all the same, by asking for its JSON, and says why it is not live.

One page session against ``cbrs serve`` whose task runner plays a scripted run (no planner, no
simulation) and whose stream slots are all taken, as twenty open tasks pages take them. Skipped where
Chromium or Playwright is missing, as ``tests/test_browser.py`` is.
"""

from __future__ import annotations

import threading
from collections.abc import Iterator
from typing import Any

import pytest

import cbrs.server
from cbrs.kb import KnowledgeBase
from cbrs.server import ServeConfig, Server
from cbrs.tasks import TaskRun
from cbrs.web.context import StreamSlots
from tests.test_browser import CHROMIUM, FLAGS, WAIT_MS, pytestmark  # noqa: F401  (the same skip)
from tests.test_browser_phone_and_live_steps import _Scripted

playwright_api = pytest.importorskip("playwright.sync_api", reason="Playwright is not installed (pip install .[test])")


class _Holding(_Scripted):
    """The scripted run, held before it starts while ``hold`` is clear (a run going, for a second Start)."""

    hold = threading.Event()

    def _run(self, run: TaskRun) -> None:
        _Holding.hold.wait(WAIT_MS / 1000)
        super()._run(run)


_Holding.hold.set()


@pytest.fixture(scope="module")
def server() -> Iterator[Server]:
    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(cbrs.server, "TaskRunner", _Holding)
        running = Server(KnowledgeBase.open(":memory:"), ServeConfig(port=0, bridge_port=0))
    running.app.extensions["cbrs.streams"] = StreamSlots(limit=0)  # the class holds every slot
    running.start()
    yield running
    running.stop(timeout=10)


@pytest.fixture(scope="module")
def page(server: Server) -> Iterator[Any]:
    with playwright_api.sync_playwright() as playwright:
        browser = playwright.chromium.launch(executable_path=CHROMIUM, headless=True, args=FLAGS)
        context = browser.new_context(base_url=f"http://127.0.0.1:{server.http_port}")
        context.set_default_timeout(WAIT_MS)
        opened = context.new_page()
        errors: list[str] = []
        opened.on("pageerror", lambda error: errors.append(str(error)))
        opened.goto("/tasks")
        yield opened
        context.close()
        browser.close()
    assert errors == [], f"JavaScript errors on the page: {errors}"


def test_a_run_is_followed_without_a_stream_slot(page: Any) -> None:
    state = page.locator("#stream-state")
    playwright_api.expect(state).to_contain_text("live streams are all in use")
    page.locator("#start-button").click()
    # the scripted run ends at once; only the page's checks can tell it (before: "running" for good)
    playwright_api.expect(page.locator("#run-status")).to_have_text("succeeded")
    rows = page.locator("#steps tr")
    playwright_api.expect(rows).to_have_count(3)  # plan 1's steps 1 and 2, plan 2's step 1
    playwright_api.expect(rows.nth(0)).to_contain_text("→")
    playwright_api.expect(page.locator("#runs tr").first).to_contain_text("succeeded")


def test_the_run_and_the_camera_show_on_a_projectors_first_screen(page: Any) -> None:
    """At 1280 x 720 the start form's eight fields, stacked, filled the screen; the run panel and the camera
    began below it (at about 1,100 px). The options a class rarely changes are folded under More options."""
    page.goto("/tasks")
    top = page.locator("#live").evaluate("node => node.getBoundingClientRect().top")
    assert top < page.viewport_size["height"]
    assert not page.locator("#fault_rate").is_visible()
    page.locator("#more-options summary").click()
    assert page.locator("#fault_rate").is_visible()


def test_a_second_start_says_which_run_goes_and_what_to_do(page: Any) -> None:
    """The script wrote "task run run-2 is still going; one task runs at a time run-2", the link run on after
    the sentence; the page's own refusal says to follow that run, then start again."""
    page.goto("/tasks")
    _Holding.hold.clear()
    try:
        page.locator("#start-button").click()
        playwright_api.expect(page.locator("#run-status")).to_have_text("running")
        page.locator("#start-button").click()
        refused = page.locator("p.error-box.form-message")
        playwright_api.expect(refused).to_contain_text("one task runs at a time: follow run-")
        playwright_api.expect(refused).to_contain_text(", then start again.")
        assert refused.locator("a").get_attribute("href").startswith("/tasks/run-")
    finally:
        _Holding.hold.set()
    playwright_api.expect(page.locator("#run-status")).to_have_text("succeeded")
