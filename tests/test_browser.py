"""The knowledge browser in a real browser: Playwright driving Debian's Chromium against ``cbrs serve``.

Each test walks one page as a user would and takes a screenshot: into a temporary folder, or into
``$CBRS_SCREENSHOTS`` when set (``CBRS_SCREENSHOTS=docs/screenshots pytest tests/test_browser.py``
refreshes the README's pictures). Skipped, saying why, where Chromium or Playwright is missing;
``.ci/run`` installs Chromium with apt.
"""

from __future__ import annotations

import os
import re
import shutil
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

from cbrs.kb import KnowledgeBase
from cbrs.server import ServeConfig, Server

CHROMIUM = os.environ.get("CBRS_CHROMIUM") or shutil.which("chromium") or "/usr/bin/chromium"
pytestmark = pytest.mark.skipif(
    not Path(CHROMIUM).exists(), reason=f"Chromium is not installed at {CHROMIUM} (apt-get install chromium)"
)
playwright_api = pytest.importorskip("playwright.sync_api", reason="Playwright is not installed (pip install .[test])")

# The flags a headless Chromium needs as root on a machine without a network beyond loopback.
FLAGS = [
    "--no-sandbox",
    "--disable-gpu",
    "--disable-quic",
    "--no-first-run",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
]
WAIT_MS = 15_000


@pytest.fixture(scope="module")
def server() -> Iterator[Server]:
    running = Server(KnowledgeBase.open(":memory:"), ServeConfig(port=0, bridge_port=0))
    running.start()
    yield running
    running.stop(timeout=10)


@pytest.fixture(scope="module")
def browser() -> Iterator[Any]:
    with playwright_api.sync_playwright() as playwright:
        launched = playwright.chromium.launch(executable_path=CHROMIUM, headless=True, args=FLAGS)
        yield launched
        launched.close()


@pytest.fixture
def page(browser: Any, server: Server) -> Iterator[Any]:
    base = f"http://127.0.0.1:{server.http_port}"
    context = browser.new_context(base_url=base, viewport={"width": 1280, "height": 860})
    context.set_default_timeout(WAIT_MS)
    opened = context.new_page()
    errors: list[str] = []
    opened.on("pageerror", lambda error: errors.append(str(error)))
    yield opened
    context.close()
    assert errors == [], f"JavaScript errors on the page: {errors}"


@pytest.fixture
def shots(tmp_path: Path) -> Path:
    folder = Path(os.environ.get("CBRS_SCREENSHOTS") or tmp_path)
    folder.mkdir(parents=True, exist_ok=True)
    return folder


def snap(page: Any, folder: Path, name: str) -> None:
    target = folder / f"{name}.png"
    page.screenshot(path=str(target), full_page=True)
    assert target.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_overview_shows_the_store(page: Any, shots: Path) -> None:
    page.goto("/")
    assert page.locator("h1").inner_text() == "Overview"
    assert int(page.locator("[data-count=services]").inner_text()) == 53
    assert page.get_by_role("link", name="graph:ontology").is_visible()
    snap(page, shots, "overview")


def test_taxonomy_leads_to_the_ceiling_camera_locating_robots(page: Any, shots: Path) -> None:
    page.goto("/")
    page.get_by_role("navigation").get_by_role("link", name="Taxonomy").click()
    page.locator("#q").fill("RobotLocation")
    page.locator("#q").press("Enter")
    page.wait_for_url("**/taxonomy?q=RobotLocation")
    snap(page, shots, "taxonomy")
    page.locator("#classes").get_by_role("link", name="home:RobotLocation").first.click()
    page.wait_for_url("**/taxonomy/class?iri=*")
    snap(page, shots, "class")
    page.get_by_role("link", name="svc:LocateMobileRobot_CeilingCamera01").first.click()
    assert "LocateMobileRobot" in page.locator("main").inner_text()
    assert "home:MarkerColour" in page.locator("main").inner_text()
    snap(page, shots, "service")


def test_sparql_editor_runs_a_query_into_a_table(page: Any, shots: Path) -> None:
    page.goto("/query")
    page.locator("#query").fill("SELECT ?class WHERE { ?class rdfs:subClassOf home:Position } ORDER BY ?class")
    page.get_by_role("button", name="Run").click()
    page.wait_for_url("**/query?query=*")
    cells = page.locator("table.result-table tbody tr")
    assert cells.count() >= 3
    assert "home:RobotPosition" in page.locator("table.result-table").inner_text()
    assert page.locator("a[data-format=csv]").get_attribute("href").startswith("/sparql?")
    snap(page, shots, "sparql")
    page.locator("#query").fill("SELECT ?x WHERE {")
    with page.expect_navigation(wait_until="load"):  # the form's GET: focus asked of a page still loading was lost
        page.get_by_role("button", name="Run").click()
    assert page.locator("#query-error").is_visible()  # the parser's message beside the editor
    # Tab indents in the editor, so a keyboard user leaves it with Esc then Tab; the help (which describes
    # the editor to a screen reader) says so: a user tabbing forward was held in the editor, unaware.
    assert "Esc then Tab leaves the editor" in page.locator("#query-help").inner_text()
    page.locator("#query").focus()
    page.keyboard.press("Tab")
    assert page.evaluate("document.activeElement.id") == "query"
    page.keyboard.press("Escape")
    page.keyboard.press("Tab")
    assert page.evaluate("document.activeElement.textContent") == "Run"


def test_matchmaking_ranks_the_ceiling_camera_first(page: Any, shots: Path) -> None:
    page.goto("/match")
    page.locator("#requirement").select_option("req:RobotSelfPosition")
    page.locator("#methods").select_option(["sem-str", "wu-palmer"])
    page.get_by_role("button", name="Rank").click()
    page.wait_for_url("**/match?*")
    first = page.locator("#ranking-sem-str").locator("xpath=..").locator("ol.candidates > li").first
    assert "LocateMobileRobot_CeilingCamera01" in first.locator(".name").inner_text()
    first.locator("summary").click()  # its explanation: the entity pairs
    assert "home:RobotLocation" in first.locator(".explanation").inner_text()
    assert page.locator("#ranking-wu-palmer").is_visible()  # the baseline beside it
    heights = page.locator("#ranking-sem-str ~ ol summary.candidate .rank, #ranking-sem-str ~ * summary .rank")
    tall = heights.evaluate_all("marks => marks.map(mark => mark.getBoundingClientRect().height)")
    assert len(tall) == 10 and len(set(tall)) == 1  # "10 ▸" on one line, as "1 ▸" is (it wrapped)
    snap(page, shots, "matchmaking")


def test_fetch_my_pen_started_from_the_page_succeeds_while_the_camera_updates(page: Any, shots: Path) -> None:
    page.goto("/tasks")
    frame_before = int(page.locator("#frame").inner_text())
    page.locator("#task").select_option("FetchMyPen")  # by value: the option reads "FetchMyPen · Fetch my pen"
    page.locator("#start-button").click()
    # expect() polls without evaluating text in the page, which its Content-Security-Policy forbids
    playwright_api.expect(page.locator("#run-status")).to_have_text(
        re.compile("running|succeeded|failed|error|no-plan"), timeout=30_000
    )
    playwright_api.expect(page.locator("#run-status")).to_have_text(
        re.compile("succeeded|failed|error|no-plan"), timeout=120_000
    )
    assert page.locator("#run-status").inner_text().strip() == "succeeded"
    assert int(page.locator("#frame").inner_text()) > frame_before + 5  # a frame after every step
    assert page.locator("#steps tr").count() >= 15
    assert page.locator("#camera").evaluate("image => image.naturalWidth") > 0  # the MJPEG stream shows
    snap(page, shots, "tasks")


def test_plans_page_shows_the_plan_and_draws_the_graph(page: Any, shots: Path) -> None:
    page.goto("/plans")
    page.locator("#task").select_option("req:FetchMyPen")
    page.get_by_role("button", name="Plan").click()
    page.wait_for_url("**/plans?*")
    assert page.locator("tr[id^=step-]").count() == 15
    table = page.locator(".plan-scroll")  # all six columns in view at 1280 px: the alternatives were not
    assert table.evaluate("e => e.scrollWidth <= e.clientWidth")
    lines = (
        "cells => cells.map(cell => { const r = document.createRange(); r.selectNodeContents(cell);"
        " return r.getClientRects().length; })"
    )
    assert set(table.locator("td.num").evaluate_all(lines)) == {1}  # "10" to "15" on one line, as "1" is
    drawing = page.locator("img.drawing")
    drawing.scroll_into_view_if_needed()
    for _ in range(300):  # bounded: 30 s for the SVG to arrive and decode
        if drawing.evaluate("image => image.complete"):
            break
        page.wait_for_timeout(100)
    assert drawing.evaluate("image => image.naturalWidth") > 0  # the SVG arrived and decoded
    snap(page, shots, "plans")


def test_a_task_written_on_the_editor_is_checked_and_planned_from_the_keyboard(
    browser: Any, server: Server, shots: Path
) -> None:
    """The task editor (/tasks/new) at a phone's width: its bundled example checked with Ctrl+Enter from the
    text area shows its plan, and nothing scrolls sideways at 390 px."""
    for width, name in ((1280, "task_editor"), (390, "task_editor-narrow")):
        context = browser.new_context(
            base_url=f"http://127.0.0.1:{server.http_port}", viewport={"width": width, "height": 860}
        )
        context.set_default_timeout(WAIT_MS)
        opened = context.new_page()
        errors: list[str] = []
        opened.on("pageerror", lambda error, errors=errors: errors.append(str(error)))
        try:
            opened.goto("/tasks")
            opened.locator("#new-task").click()
            opened.wait_for_url("**/tasks/new")
            opened.get_by_label("Task in Turtle").focus()
            # the checked page has this page's URL, so wait for its load (its stylesheet: laid out without
            # it, the plan's table was 801 px wide at 390 on a loaded machine), not for the URL
            with opened.expect_navigation(wait_until="load"):
                opened.keyboard.press("Control+Enter")
            badge = opened.locator(".badge.good")
            playwright_api.expect(badge).to_have_text("planned", timeout=30_000)  # composed cold, on a loaded machine
            assert opened.locator("tr[id^=step-]").count() >= 1
            assert opened.evaluate("document.documentElement.scrollWidth") <= width
            drawing = opened.locator("img.drawing")
            if width > 390:  # drawn once: the picture is the same at any width
                drawing.scroll_into_view_if_needed()
                for _ in range(300):  # bounded: 30 s for the SVG to arrive and decode
                    if drawing.evaluate("image => image.complete"):
                        break
                    opened.wait_for_timeout(100)
                assert drawing.evaluate("image => image.naturalWidth") > 0  # the draft's drawing, kept for it
            snap(opened, shots, name)
        finally:
            context.close()
        assert errors == [], f"JavaScript errors on the page: {errors}"


NARROW_PAGES = (
    "/",
    "/taxonomy",
    "/taxonomy/class?iri=home:Position",
    "/services",
    "/service?iri=svc:LocateMobileRobot_CeilingCamera01",
    "/search?q=camera",
    "/match?requirement=req:FetchMyPen",
    "/plans?task=FetchMyPen",
    "/resource?iri=svc:LocateMobileRobot_CeilingCamera01",  # its "Out:" heading scrolled 57 px sideways
    "/resource?iri=http://example.org/" + "a" * 400,  # a 404 whose message held the IRI unbroken: 3,700 px
    "/query?query=CONSTRUCT+WHERE+{+?s+?p+?o+}",
)


def test_pages_fit_a_phone_and_pictures_open_on_their_middle(browser: Any, server: Server, shots: Path) -> None:
    """At 400 px no page scrolls sideways (wide tables and pictures scroll in their own box), and a
    picture wider than its box opens scrolled to its middle, where the class is drawn."""
    context = browser.new_context(
        base_url=f"http://127.0.0.1:{server.http_port}", viewport={"width": 400, "height": 800}
    )
    context.set_default_timeout(WAIT_MS)
    opened = context.new_page()
    try:
        for path in NARROW_PAGES:
            opened.goto(path)
            assert opened.evaluate("document.documentElement.scrollWidth") <= 400, path
        opened.goto("/taxonomy/class?iri=home:Position")
        scroller = opened.locator(".diagram-scroll")
        assert scroller.evaluate("e => e.scrollWidth > e.clientWidth")
        assert scroller.evaluate("e => Math.abs(e.scrollLeft - (e.scrollWidth - e.clientWidth) / 2) <= 1")
        focus = opened.locator("svg.diagram a.box").filter(has_text="home:Position").first
        assert focus.is_visible() and focus.bounding_box()["x"] >= 0
        snap(opened, shots, "class-narrow")
    finally:
        context.close()


def test_the_services_table_keeps_each_kind_on_one_line(page: Any) -> None:
    page.goto("/services")
    kinds = page.locator("table#advertisements tbody td:nth-child(1) a")
    lines = kinds.evaluate_all("links => links.map(link => link.getClientRects().length)")
    assert len(lines) == 53 and set(lines) == {1}  # "PhysicalManipulation" broke after its 19th letter


def test_search_from_the_header_with_the_slash_key(page: Any, shots: Path) -> None:
    page.goto("/services")
    page.locator("body").press("Escape")
    page.keyboard.press("/")
    assert page.evaluate("document.activeElement.id") == "filter"  # the page's own search box first
    page.goto("/")
    page.keyboard.press("/")
    assert page.evaluate("document.activeElement.id") == "site-search"
    page.keyboard.type("ceiling camera")
    page.keyboard.press("Enter")
    page.wait_for_url("**/search?q=ceiling+camera")
    page.get_by_role("link", name="LocateMobileRobot").first.click()
    page.wait_for_url("**/service?iri=*")
    assert "CeilingCamera" in page.locator("main").inner_text()
    snap(page, shots, "search")
