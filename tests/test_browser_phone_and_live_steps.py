"""The tasks page in a real browser at a phone's size (375 x 667): the header keeps to one line with every
page behind its Menu button, and the steps table the script builds live from the run's events says what
the page the server renders for the same run says, failure reasons kept after a failover succeeded.

One page session, against ``cbrs serve`` whose task runner plays a scripted run (a failover, a failure, a
re-plan) through the real event stream: no planner, no simulation (docs/web.md, "Live updates and the
camera"). Skipped where Chromium or Playwright is missing, as ``tests/test_browser.py`` is.
"""

from __future__ import annotations

import os
import re
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

import cbrs.server
from cbrs.kb import KnowledgeBase
from cbrs.server import ServeConfig, Server
from cbrs.tasks import RUN_TOPIC, TaskRun, TaskRunner
from tests.test_browser import CHROMIUM, FLAGS, WAIT_MS, pytestmark, snap  # noqa: F401  (the same skip)

playwright_api = pytest.importorskip("playwright.sync_api", reason="Playwright is not installed (pip install .[test])")

SVC = "https://w3id.org/cbrs/service#"
FIRST, SECOND = (SVC + f"LocateMobileRobot_CeilingCamera0{n}" for n in (1, 2))
GRASP = SVC + "GraspObject_CytonDualArm01"
DELIVER = SVC + "DeliverObject_P3DX01"
PROGRESS = "/cbrs/task_progress"
# As the executor says it (actions/runner.py): step 1 fails over from one camera to the other, step 2
# fails for good, a re-plan follows, and the new plan's step 1 succeeds; two events that are no step's.
SCRIPT: list[dict[str, Any]] = [
    {"event": "base_chosen", "base": SVC + "P3DX01", "why": "the only base"},
    {"event": "step_started", "step": 1, "component": FIRST},
    {
        "event": "step_failed",
        "step": 1,
        "component": FIRST,
        "reason": f"injected failure of {FIRST}",
        "failover": SECOND,
    },
    {"event": "step_started", "step": 1, "component": SECOND},
    {"event": "step_succeeded", "step": 1, "component": SECOND},
    {"event": "step_started", "step": 2, "component": GRASP},
    {"event": "step_failed", "step": 2, "component": GRASP, "reason": f"{GRASP} dropped the pen"},
    {"event": "replanning", "plan": 2, "reason": "step 2 failed"},
    {"event": "passed_over", "components": [GRASP]},
    {"event": "step_started", "step": 1, "component": DELIVER},
    {"event": "step_succeeded", "step": 1, "component": DELIVER},
]


class _Scripted(TaskRunner):
    """A runner whose every run publishes SCRIPT, as a run's events are published, and succeeds; no camera."""

    def __init__(self, kb: KnowledgeBase, lock: Any, read_only: bool = False, queue: int | None = None) -> None:
        super().__init__(kb, lock, camera=None, read_only=read_only, queue=queue)

    def _run(self, run: TaskRun) -> None:
        for event in SCRIPT:
            message = dict(event, run=run.id)
            run.events.append({"topic": PROGRESS, **message})
            self._emit(PROGRESS, message)
        run.result = {"plan": {"status": "planned"}, "execution": {"status": "succeeded", "steps": []}}
        run.status = "succeeded"
        run.done.set()
        self._emit(RUN_TOPIC, {"event": "run_finished", "run": run.id, "task": run.task, "status": run.status})


@pytest.fixture(scope="module")
def server() -> Iterator[Server]:
    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(cbrs.server, "TaskRunner", _Scripted)
        running = Server(KnowledgeBase.open(":memory:"), ServeConfig(port=0, bridge_port=0))
    running.start()
    yield running
    running.stop(timeout=10)


@pytest.fixture(scope="module")
def phone(server: Server) -> Iterator[Any]:
    """One page at 375 x 667 for the module's tests; no JavaScript error on it."""
    with playwright_api.sync_playwright() as playwright:
        browser = playwright.chromium.launch(executable_path=CHROMIUM, headless=True, args=FLAGS)
        context = browser.new_context(
            base_url=f"http://127.0.0.1:{server.http_port}", viewport={"width": 375, "height": 667}
        )
        context.set_default_timeout(WAIT_MS)
        page = context.new_page()
        errors: list[str] = []
        page.on("pageerror", lambda error: errors.append(str(error)))
        page.goto("/tasks")
        yield page
        context.close()
        browser.close()
    assert errors == [], f"JavaScript errors on the page: {errors}"


@pytest.fixture
def shots(tmp_path: Path) -> Path:
    folder = Path(os.environ.get("CBRS_SCREENSHOTS") or tmp_path)
    folder.mkdir(parents=True, exist_ok=True)
    return folder


# Each row of the steps table as a reader sees it: its plan and step, its classes, and each cell's text
# and the IRIs its links stand for.
ROWS = """rows => rows.map(row => [row.dataset.plan, row.dataset.step, row.className,
    ...Array.from(row.cells, cell => [cell.innerText.trim(),
        Array.from(cell.querySelectorAll('[title]'), node => node.title)])])"""


def test_the_header_keeps_to_one_line_on_a_phone_and_hides_no_page(phone: Any, shots: Path) -> None:
    header = phone.locator("header.top")
    toggle = phone.get_by_role("button", name="Menu")
    line = toggle.evaluate("button => button.getBoundingClientRect().height")  # one line of the header
    inner = header.evaluate("h => h.clientHeight - parseFloat(getComputedStyle(h).paddingTop) * 2")
    assert inner <= 2 * line  # four lines of links and one of the search box before (212 px)
    assert phone.evaluate("document.documentElement.scrollWidth") <= 375
    links = header.locator("nav a")
    assert links.count() == 9 and not links.first.is_visible()
    toggle.click()
    assert toggle.get_attribute("aria-expanded") == "true"
    assert toggle.get_attribute("aria-controls") == header.locator("nav").get_attribute("id")
    boxes = links.evaluate_all("links => links.map(link => link.getBoundingClientRect())")
    assert all(box["width"] > 0 and box["left"] >= 0 and box["right"] <= 375 for box in boxes)  # every page
    snap(phone, shots, "header-phone-menu")
    phone.keyboard.press("Escape")
    assert toggle.get_attribute("aria-expanded") == "false" and not links.first.is_visible()
    assert phone.evaluate("document.activeElement.id") == "menu-toggle"


def test_the_live_steps_table_keeps_what_the_server_renders(phone: Any, server: Server, shots: Path) -> None:
    playwright_api.expect(phone.locator("#stream-state")).to_have_text("· live")  # subscribed
    run = server.tasks.start("FetchMyPen")
    playwright_api.expect(phone.locator("#run-status")).to_have_text("succeeded")
    live = phone.locator("#steps tr").evaluate_all(ROWS)
    snap(phone, shots, "tasks-phone")
    phone.goto(f"/tasks/{run.id}")
    rendered = phone.locator("#steps tr").evaluate_all(ROWS)
    assert live == rendered
    first, second, replanned = rendered
    assert first[2] == "step-succeeded failover" and first[4][1] == [FIRST, SECOND]
    assert re.fullmatch(r"succeeded\s+injected failure of svc:LocateMobileRobot_CeilingCamera01", first[5][0])
    assert second[:3] == ["1", "2", "step-failed"] and "svc:GraspObject_CytonDualArm01 dropped the pen" in second[5][0]
    assert replanned[:4] == ["2", "1", "step-succeeded", ["2.1", ["plan 2, after a re-plan"]]]
