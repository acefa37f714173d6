"""The knowledge browser's header keeps to one line at every width, every page link reachable: in line
where they fit, behind the Menu button where they do not (site.js measures them laid out in full; docs/web.md,
"The header at every width"). It wrapped to two or three lines between 641 and about 1,220 px wide.
Without JavaScript the links show at every width, wrapping as they must. Chromium, as tests/test_browser.py
(skipped, saying why, where it or Playwright is missing); one server and one browser for the module.
"""

from __future__ import annotations

from collections.abc import Iterator
from typing import Any

import pytest

from cbrs.web import PAGES
from tests.test_browser import CHROMIUM, FLAGS, WAIT_MS, pytestmark, server  # noqa: F401  (the same skip)

playwright_api = pytest.importorskip("playwright.sync_api", reason="Playwright is not installed (pip install .[test])")

WIDTHS = (375, 700, 900, 1000, 1280)
HEIGHT = 800
# "/" has the header's search box; /search has none (its own box is in the page), so the line differs
PATHS = ("/", "/search")
# The header's items as a reader meets them (the button only where shown; a link hidden in the closed menu
# is no item of the line)
ITEMS = """header => Array.from(header.querySelectorAll(':scope > a, :scope > button, :scope > form input, nav a'))
    .map(item => item.getBoundingClientRect()).filter(box => box.width > 0)
    .map(box => ({top: box.top, bottom: box.bottom, left: box.left, right: box.right, height: box.height}))"""
INNER = """h => { const style = getComputedStyle(h);
    return h.clientHeight - parseFloat(style.paddingTop) - parseFloat(style.paddingBottom); }"""


@pytest.fixture(scope="module")
def pages(server: Any) -> Iterator[dict[bool, Any]]:  # noqa: F811  (tests.test_browser's fixture)
    """A page with JavaScript (True) and one without (False); no JavaScript error on either."""
    with playwright_api.sync_playwright() as playwright:
        browser = playwright.chromium.launch(executable_path=CHROMIUM, headless=True, args=FLAGS)
        found, errors, contexts = {}, [], []
        for script in (True, False):
            context = browser.new_context(
                base_url=f"http://127.0.0.1:{server.http_port}",
                viewport={"width": 1280, "height": HEIGHT},
                java_script_enabled=script,
            )
            context.set_default_timeout(WAIT_MS)
            found[script] = context.new_page()
            found[script].on("pageerror", lambda error: errors.append(str(error)))
            contexts.append(context)
        yield found
        for context in contexts:
            context.close()
        browser.close()
    assert errors == [], f"JavaScript errors on the page: {errors}"


def _at(page: Any, width: int, path: str | None = None, script: bool = True) -> Any:
    """The page at ``width`` (loaded from ``path`` when given), with a script once a frame has been drawn
    (its resize handler has run; without scripts no frame callback runs); its header."""
    page.set_viewport_size({"width": width, "height": HEIGHT})
    if path is not None:
        page.goto(path)
    if script:
        page.evaluate("() => new Promise(done => requestAnimationFrame(() => done()))")
    return page.locator("header.top")


def _one_line(page: Any, header: Any, width: int) -> None:
    """The header's items share one row and its height is one item's, with nothing out of the window."""
    items = header.evaluate(ITEMS)
    assert max(item["top"] for item in items) < min(item["bottom"] for item in items), items
    assert header.evaluate(INNER) <= 1.5 * max(item["height"] for item in items)
    assert all(item["left"] >= 0 and item["right"] <= width for item in items), items
    assert page.evaluate("document.documentElement.scrollWidth") <= width


def _in_view(links: Any, width: int) -> None:
    boxes = links.evaluate_all("links => links.map(link => link.getBoundingClientRect().toJSON())")
    assert len(boxes) == len(PAGES)
    assert all(box["width"] > 0 and box["left"] >= 0 and box["right"] <= width for box in boxes), boxes
    assert all(box["top"] >= 0 and box["bottom"] <= HEIGHT for box in boxes), boxes


@pytest.mark.parametrize("path", PATHS)
@pytest.mark.parametrize("width", WIDTHS)
def test_the_header_is_one_line_with_every_link_reachable(pages: dict[bool, Any], width: int, path: str) -> None:
    page = pages[True]
    header = _at(page, width, path)
    _one_line(page, header, width)
    links, toggle = header.locator("nav a"), header.locator("#menu-toggle")
    if width == 375:  # nine links cannot share a phone's line, whatever the font
        assert toggle.is_visible()
    if width == 1280:  # nor are they put away where they fit (the widest common font, DejaVu Sans, fits)
        assert not toggle.is_visible()
    if toggle.is_visible():
        assert links.evaluate_all("links => links.every(link => link.getBoundingClientRect().width === 0)")
        toggle.click()
        assert toggle.get_attribute("aria-expanded") == "true"
        _in_view(links, width)
        page.keyboard.press("Escape")
        assert toggle.get_attribute("aria-expanded") == "false" and not links.first.is_visible()
    else:
        _in_view(links, width)


def test_resizing_folds_and_unfolds_the_links(pages: dict[bool, Any]) -> None:
    """The measure is taken again as the window changes; a menu left open closes when the links unfold."""
    page = pages[True]
    header = _at(page, 1280, "/")
    toggle, links = header.locator("#menu-toggle"), header.locator("nav a")
    assert not toggle.is_visible() and links.first.is_visible()
    _at(page, 700)
    assert toggle.is_visible() and not links.first.is_visible()
    toggle.click()
    assert links.first.is_visible()
    _at(page, 1280)
    assert not toggle.is_visible() and toggle.get_attribute("aria-expanded") == "false"
    _one_line(page, header, 1280)
    _at(page, 375)
    assert toggle.is_visible() and not links.first.is_visible()  # closed, as it was left
    _one_line(page, header, 375)


@pytest.mark.parametrize("width", WIDTHS)
def test_without_javascript_the_links_show_at_every_width(pages: dict[bool, Any], width: int) -> None:
    header = _at(pages[False], width, "/", script=False)
    assert not header.locator("#menu-toggle").is_visible()
    _in_view(header.locator("nav a"), width)
    assert pages[False].evaluate("document.documentElement.scrollWidth") <= width
