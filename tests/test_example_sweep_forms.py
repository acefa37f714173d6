"""The example sweep's server forms (bench/example_tasks.py) against a served app whose runs are held until
the test lets them end (no simulation): the tasks page's Start form submitted as a browser does, a second
start refused while a run goes (over the page and over /tasks.json), the New task page's check and save,
and a posted file the store refuses, with the store's digest compared. A check of the bench that passed
whatever the server said would fail here."""

from __future__ import annotations

import threading
import time
from collections.abc import Iterator
from pathlib import Path
from types import ModuleType
from typing import Any

import pytest
from waitress import wasyncore
from waitress.server import create_server

from cbrs.kb import KnowledgeBase
from cbrs.sparql_service import EndpointConfig, SparqlService
from cbrs.tasks import TaskRun, TaskRunner
from cbrs.web import create_app
from tests.test_example_sweep_data import _bench

TOKEN = "sweep-forms-token"
BUSY = "one task runs at a time"


class _Held(TaskRunner):
    """A runner whose runs go until ``release`` is set (bounded), then succeed in 12.5 simulated seconds;
    one asked to stop first ends cancelled after its first of three steps, the others pending."""

    release = threading.Event()

    def _run(self, run: TaskRun) -> None:
        deadline = time.monotonic() + 30
        while not (self.release.is_set() or run.cancel_requested.is_set()) and time.monotonic() < deadline:
            self.release.wait(0.05)
        if run.cancel_requested.is_set():
            steps = [
                {"index": n, "attempts": [], "seconds": 0.0, "effects": [], "outcome": outcome}
                for n, outcome in enumerate(("succeeded", "pending", "pending"), 1)
            ]
            execution = {"status": "cancelled", "reason": "cancelled on request after 1 of 3 steps", "steps": steps}
            run.result = {"plan": {"status": "planned"}, "execution": execution, "sim_seconds": 4.0}
            run.status = "cancelled"
        else:
            run.result = {"plan": {"status": "planned"}, "execution": {"status": "succeeded", "steps": []}}
            run.result["sim_seconds"] = 12.5
            run.status = "succeeded"
        run.finished = time.time()
        run.done.set()


@pytest.fixture(scope="module")
def bench() -> ModuleType:
    return _bench()


@pytest.fixture(scope="module")
def served() -> Iterator[str]:
    """The app on waitress at a free loopback port, its own origin that port's; stopped after the module."""
    kb = KnowledgeBase.open(":memory:")
    sparql = SparqlService(kb, EndpointConfig(update_token=TOKEN))
    runner = _Held(kb, sparql.lock, camera=None)
    port: list[int] = []
    app = create_app(sparql, tasks=runner, own_origins=lambda: [f"http://127.0.0.1:{port[0]}"])
    sockets: dict[int, Any] = {}
    server = create_server(app, host="127.0.0.1", port=0, map=sockets, threads=4)
    port.append(int(server.effective_port))  # type: ignore[union-attr]
    thread = threading.Thread(target=server.run, daemon=True)
    thread.start()
    yield f"http://127.0.0.1:{port[0]}"
    _Held.release.set()
    server.task_dispatcher.shutdown(timeout=5)  # type: ignore[union-attr]
    server.trigger.pull_trigger(lambda: wasyncore.close_all(sockets))  # type: ignore[union-attr]
    thread.join(5)
    kb.close()


def _trial(bench: ModuleType, via: str, busy: str = BUSY) -> Any:
    runs = [bench.Run("FetchMyPen", ["succeeded"], [12.5]), bench.Run("RobotSelfPosition", ["succeeded"], [12.5])]
    return bench.Trial("x", "", [], [3], runs, via=via, busy=busy)


def test_a_second_start_while_a_run_goes_is_refused_and_one_after_it_ends_is_taken(
    bench: ModuleType, served: str
) -> None:
    browser = bench._Browser(served)
    _Held.release.clear()
    begun = bench._page_start(browser, "FetchMyPen", 3)
    assert begun.run.startswith("run-") and begun.where == f"/tasks/{begun.run}"
    said, miss = bench.busy_check(_trial(bench, "page"), begun, "RobotSelfPosition", 3, browser, TOKEN)
    assert miss == "" and ": 409: " in said and begun.run in said
    said, miss = bench.busy_check(_trial(bench, "http"), begun, "RobotSelfPosition", 3, browser, TOKEN)
    assert miss == "" and said.startswith("POST /tasks.json RobotSelfPosition")
    _, miss = bench.busy_check(_trial(bench, "http", "two at a time"), begun, "RobotSelfPosition", 3, browser, TOKEN)
    assert "without 'two at a time'" in miss
    _Held.release.set()
    ended = bench._page_follow(browser, begun)
    assert ended["status"] == "succeeded" and ended["sim_seconds"] == 12.5
    again = bench._page_start(browser, "RobotSelfPosition", 3)  # taken once the run has ended
    assert again.run != begun.run
    assert bench._page_follow(browser, again)["status"] == "succeeded"


def test_a_start_taken_while_it_should_be_refused_is_a_deviation(bench: ModuleType) -> None:
    assert "202, the docs say 409" in bench.busy_deviation("s", 202, "started run-2", BUSY, "run-1", False)
    lost = bench.busy_deviation("s", 202, "started run-2", BUSY, "run-1", True)
    assert "no two at once" in lost
    assert "without 'run-1'" in bench.busy_deviation("s", 409, f"a run goes; {BUSY}", BUSY, "run-1", False)


def test_the_start_form_offers_only_the_store_s_tasks(bench: ModuleType, served: str) -> None:
    with pytest.raises(bench._NotStarted, match="offers no 'FetchMyPne'"):
        bench._page_start(bench._Browser(served), "FetchMyPne", 0)


def test_a_task_written_on_the_new_task_page_is_saved_and_a_misspelt_one_refused(
    bench: ModuleType, served: str, tmp_path: Path
) -> None:
    browser = bench._Browser(served)
    said = bench._editor_save(browser, bench.Step("requirements", "load_pen_onto_base.ttl"), TOKEN, tmp_path)
    assert "saved as https://example.org/lab#LoadPenOntoBase" in said and "ASK shows true" in said
    assert "checked (planned)" in said
    said = bench._editor_save(browser, bench.Step("requirements", "fetch_my_keys.ttl"), TOKEN, tmp_path)
    assert "saved as req:FetchMyKeys" in said and "ASK shows true" in said  # a name in cbrs's own namespace
    misspelt = (("cbrs:parameterType home:Pen ]", "cbrs:parameterType home:Pne ]"),)
    step = bench.Step("requirements", "load_pen_onto_base.ttl", misspelt, says="did you mean home:Pen?")
    said, miss = bench.editor_refusal(browser, step, TOKEN, tmp_path)
    assert miss == "" and "Check 422" in said and "Save 422" in said
    wrong = bench.Step("requirements", "load_pen_onto_base.ttl", misspelt, says="did you mean home:Pencil?")
    assert "without 'did you mean home:Pencil?'" in bench.editor_refusal(browser, wrong, TOKEN, tmp_path)[1]


def test_the_page_s_line_must_be_where_the_term_is_written(bench: ModuleType) -> None:
    text = "# home:Pne, a typo\nlab:T a cbrs:Requirement ;\n  cbrs:parameterType home:Pne .\n"
    page = '<a href="#turtle" data-line="{}">line {}</a>: <code>home:Pne</code>: no class'
    assert bench.misplaced_lines(page.format(3, 3), text) == []
    assert "line 1 is not where home:Pne is written" in bench.misplaced_lines(page.format(1, 1), text)[0]


def test_a_posted_file_the_store_refuses_leaves_it_as_it_was(bench: ModuleType, served: str, tmp_path: Path) -> None:
    step = bench.Step("map", "lab4_mistake_mug_without_size.ttl", says="has no home:sizeX")
    said, miss = bench.post_refusal(served, step, TOKEN, tmp_path)
    assert miss == "" and ": 422: " in said
    other = bench.Step("map", "lab4_mistake_mug_without_size.ttl", says="has no home:sizeY")
    assert "without 'has no home:sizeY'" in bench.post_refusal(served, other, TOKEN, tmp_path)[1]
    taken = bench.Step("map", "lab4_trolley.ttl", says="anything")
    assert "accepted (204), the docs say refused" in bench.post_refusal(served, taken, TOKEN, tmp_path)[1]


def test_a_refusal_that_changed_the_store_or_broke_the_server_is_a_deviation(bench: ModuleType) -> None:
    step = bench.Step("map", "x.ttl", says="no size")
    same = ("d1", {"g": 3})
    assert bench.refused_post_deviation(step, 422, "Mug1 has no size", same, same) == ""
    assert "the store changed: g 3 -> 4" in bench.refused_post_deviation(step, 422, "no size", same, ("d2", {"g": 4}))
    assert "the same sizes, other quads" in bench.refused_post_deviation(step, 422, "no size", same, ("d2", {"g": 3}))
    assert "a server error" in bench.refused_post_deviation(step, 500, "no size", same, same)


def test_a_form_is_read_as_a_browser_submits_it(bench: ModuleType) -> None:
    page = (
        '<form id="f" method="post" action="/x"><textarea name="t">\nline one\n</textarea>'
        '<select name="s"><option value="a">A</option><option value="b" selected>B</option></select>'
        '<select name="m" multiple><option value="1">1</option></select>'
        '<input type="checkbox" name="c" value="1"><input name="n" value="&lt;v&gt;">'
        '<button type="submit" name="action" value="go">Go</button></form>'
    )
    form = bench.read_form(page, "f")
    assert form.fields == [["t", "line one\n"], ["s", "b"], ["n", "<v>"]]
    assert form.buttons == [("action", "go")] and form.options["s"] == ["a", "b"]
    form.choose("s", "a")
    assert form.chosen("s") == ["a"]
    with pytest.raises(bench._NotStarted, match="offers no 'z'"):
        form.choose("s", "z")


def test_the_stop_button_stops_a_run_and_is_refused_once_it_has_ended(bench: ModuleType, served: str) -> None:
    """The run's page shows Stop this run while the run goes; pressed, 303 to its page, the run cancelled with the steps
    not taken pending; pressed again, 409 and the run as it was. A phrase the pages do not say is a miss."""
    browser = bench._Browser(served)
    _Held.release.clear()
    stop = bench.StopAt(0, "asked to stop after the step under way", "has already ended: cancelled")
    said, miss, found = bench.stop_run(browser, bench._page_start(browser, "FetchMyPen", 3), stop, TOKEN)
    assert miss == "" and ": 303, cancelled after 1 of 3 steps; again 409" in said
    assert found["status"] == "cancelled" and found["steps"] == 1 and "cancelled on request" in found["reason"]
    wrong = bench.StopAt(0, "stopped at once", "has already ended: cancelled")
    _, miss, _ = bench.stop_run(browser, bench._page_start(browser, "FetchMyPen", 3), wrong, TOKEN)
    assert "the docs say 303 to the run's page saying 'stopped at once'" in miss
    _Held.release.set()
    begun = bench._page_start(browser, "FetchMyPen", 3)
    bench._page_follow(browser, begun)
    _, miss, found = bench.stop_run(browser, begun, stop, TOKEN)  # ended before the button could be pressed
    assert found["status"] == "succeeded" and "the run was succeeded before 0 steps ended" in miss


def test_the_pages_get_forms_are_submitted_and_their_answers_read(bench: ModuleType, served: str) -> None:
    """A form found by its id or its field's, typed into or chosen from, sent as a GET; the answer's status
    and words compared, each miss said; the next form on the page the one before answered."""
    forms = (
        bench.PageForm("site-search", "/", (("q", "FetchMyPen"),), says=("req:FetchMyPen",)),
        bench.PageForm("q", fill=(("q", "x" * 201),), status=400, says=("at most 200 characters",)),
        bench.PageForm("task", "/plans", choose=(("task", "req:FetchMyPen"),), says=("no such words",)),
        bench.PageForm("kind", "/services", lacks=("req:FetchMyPen",)),
        bench.PageForm("no-such-form", "/"),
        bench.PageForm("task", "/plans", choose=(("task", "req:FetchMyPne"),)),
    )
    (search, long, plans, services, missing, unoffered) = bench.form_checks(bench._Browser(served), forms)
    assert search[1] == "" and search[0].startswith("/: the form 'site-search' (q=FetchMyPen): 200")
    assert long[1] == "" and long[0].startswith("/search?q=FetchMyPen: the form 'q'") and "xxx...): 400" in long[0]
    assert plans[1].endswith(": without 'no such words'")
    assert "with 'req:FetchMyPen'" in services[1]  # the services page lists the requirements too
    assert "has no form 'no-such-form'" in missing[1] and "offers no 'req:FetchMyPne'" in unoffered[1]


def test_a_form_is_found_by_the_id_of_a_field_in_it_and_a_hidden_one_is_known(bench: ModuleType) -> None:
    page = (
        '<form method="get" action="/a"><input id="first" name="q"></form>'
        '<form method="get" action="/b"><select id="second" name="k"><option value="1">1</option></select></form>'
        '<form id="cancel" method="post" action="/c" hidden><button type="submit">Stop</button></form>'
    )
    assert bench.find_form(page, "second").action == "/b" and bench.find_form(page, "first").fields == [["q", ""]]
    assert bench.find_form(page, "cancel").hidden and not bench.find_form(page, "first").hidden
    with pytest.raises(RuntimeError, match="it has \\['cancel', 'first', 'second'\\]"):
        bench.find_form(page, "third")
