"""A class on one server (docs/web.md, "Tried by a teacher with a class"): what the SPARQL editor says when
others' queries hold every worker or a query runs out of time, and the camera's still asked for by number."""

from __future__ import annotations

import contextlib
import re
import socket
import threading
from pathlib import Path
from typing import Any

import pytest
from flask.testing import FlaskClient

import cbrs.web
from cbrs import home_canvas
from cbrs.kb import KnowledgeBase
from cbrs.kb.errors import QuerySyntaxError
from cbrs.kb.query_guard import QueryGuard
from cbrs.kb.remote_access import RemoteAccessError
from cbrs.sparql_service import EndpointBusyError, EndpointConfig, QueryTimeoutError, SparqlService
from cbrs.tasks import CameraFrame, TaskRunner
from cbrs.web import create_app, diagram
from tests.test_tasks_negotiation import _Held

EXAMPLES = Path(__file__).resolve().parents[1] / "docs" / "examples"
CROSS = "SELECT (COUNT(*) AS ?n) WHERE { ?a ?b ?c . ?d ?e ?f . ?g ?h ?i }"


@pytest.fixture(scope="module")
def service(bundled_kb: KnowledgeBase) -> SparqlService:
    return SparqlService(bundled_kb, EndpointConfig(workers=4, timeout=30.0))


@pytest.fixture(scope="module")
def client(service: SparqlService) -> FlaskClient:
    return create_app(service).test_client()


def test_every_worker_taken_says_the_query_is_fine_and_to_run_it_again(
    client: FlaskClient, service: SparqlService
) -> None:
    held = [service._admit(f"10.0.0.{n}") for n in range(4)]  # four other students' long queries
    try:
        page = client.get("/query", query_string={"query": CROSS})
    finally:
        for release in held:
            release()
    text = page.get_data(as_text=True)
    assert page.status_code == 503
    assert "all 4 query workers are busy" in text  # the endpoint's words, kept
    assert "Nothing is wrong with this query" in text and "run it again in a few seconds" in text
    assert 'id="query-advice"' in text and "Run it again</a>" in text


def test_a_typo_sent_while_every_worker_is_taken_gets_its_syntax_error(
    client: FlaskClient, service: SparqlService
) -> None:
    """A text that does not parse was answered "busy" while others' queries held the workers (11 of the
    class's typos and cross products were), so the page said nothing was wrong with it; a long one is
    parsed by the query guard's checker, as any long text is."""
    long_typo = "SELEKT * WHERE { ?s ?p ?o " + "FILTER(?o != 1) " * 40 + "}"
    held = [service._admit(f"10.0.0.{n}") for n in range(4)]
    try:
        for typo in ("SELEKT * WHERE { ?s ?p ?o }", long_typo):
            with pytest.raises(QuerySyntaxError, match="SELEKT"):
                service.query(typo, client="10.0.1.1")
        with pytest.raises(EndpointBusyError):
            service.query(CROSS, client="10.0.1.1")
        page = client.get("/query", query_string={"query": "SELECT * WHERE { ?s ?p ?o"})
    finally:
        for release in held:
            release()
    assert page.status_code == 400 and "busy" not in page.get_data(as_text=True)


def test_a_service_sent_while_every_worker_is_taken_reaches_nothing(service: SparqlService) -> None:
    """The busy path parses a text on an empty store of its own to find a typo, and Oxigraph sends a
    ``SERVICE``'s query as it parses (a SELECT's too): that path reached a loopback port the endpoint refuses
    to reach when idle (federation_allow is empty). It is refused as an idle endpoint refuses it."""
    listener = socket.socket()
    listener.bind(("127.0.0.1", 0))
    listener.listen(4)
    listener.settimeout(0.05)
    reached: list[bytes] = []
    stop = threading.Event()

    def accept() -> None:  # a connection is noted and closed at once: the query never waits on it
        while not stop.is_set():
            with contextlib.suppress(TimeoutError):
                connection, _ = listener.accept()
                with connection:
                    reached.append(connection.recv(64))

    thread = threading.Thread(target=accept, daemon=True)
    thread.start()
    port = listener.getsockname()[1]
    held = [service._admit(f"10.0.0.{n}") for n in range(4)]
    try:
        with pytest.raises(RemoteAccessError):
            service.query(f"SELECT * WHERE {{ SERVICE <http://127.0.0.1:{port}/sparql> {{ ?s ?p ?o }} }}")
    finally:
        for release in held:
            release()
        stop.set()
        thread.join(5)
        listener.close()
    assert reached == []


def test_a_cross_product_sent_while_every_worker_is_taken_runs_in_no_request(
    service: SparqlService, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Oxigraph evaluates an ASK as it parses it: the busy path's parse on an empty store of its own ran this
    cross product of ``VALUES`` (20^6 rows, minutes) on the request's thread, with no worker and no deadline,
    for any anonymous client. The text is parsed in the query guard's checker process, stopped at its time
    limit, and the query is answered busy."""
    guard = QueryGuard(timeout=1.0)
    monkeypatch.setattr(service.kb.store, "guard", guard)
    values = " ".join(str(n) for n in range(20))
    clauses = " ".join(f"VALUES ?v{k} {{ {values} }}" for k in range(6))
    ask = f"ASK {{ {clauses} FILTER(?v0 + ?v1 + ?v2 + ?v3 + ?v4 + ?v5 < 0) }}"
    assert len(ask) <= guard.direct_chars  # a short text: parsed in the request's own process before
    answered: list[BaseException] = []

    def send() -> None:
        try:
            service.query(ask, client="10.0.1.2")
        except BaseException as error:  # what the client is told
            answered.append(error)

    held = [service._admit(f"10.0.0.{n}") for n in range(4)]
    sending = threading.Thread(target=send, daemon=True)
    try:
        sending.start()
        sending.join(60)  # a bound for a test that fails, not a timing: the checker stops it after 1 s
    finally:
        for release in held:
            release()
        guard.close()
    assert not sending.is_alive(), "the cross product runs in the server's own process"
    assert len(answered) == 1 and isinstance(answered[0], EndpointBusyError), answered


def test_a_query_out_of_time_says_how_to_narrow_it(client: FlaskClient, monkeypatch: pytest.MonkeyPatch) -> None:
    def stopped(*args: Any, **kwargs: Any) -> Any:
        raise QueryTimeoutError(30.0, stopped=True)

    monkeypatch.setattr(SparqlService, "query", stopped)
    text = client.get("/query", query_string={"query": CROSS}).get_data(as_text=True)
    assert "did not finish within 30 s" in text
    assert "share no variable multiply" in text and "LIMIT 100" in text


def test_a_busy_answer_of_one_client_says_it_is_theirs(client: FlaskClient, monkeypatch: pytest.MonkeyPatch) -> None:
    def busy(*args: Any, **kwargs: Any) -> Any:
        raise EndpointBusyError(4, "127.0.0.1", 2)

    monkeypatch.setattr(SparqlService, "query", busy)
    text = client.get("/query", query_string={"query": CROSS}).get_data(as_text=True)
    assert "Your computer already runs 2 queries" in text


def test_a_still_asked_for_by_number_asks_the_run_for_none(bundled_kb: KnowledgeBase) -> None:
    runner = TaskRunner(bundled_kb, threading.RLock(), camera=object())  # type: ignore[arg-type]
    runner._frame = CameraFrame(7, b"\xff\xd8seven\xff\xd9", "run-1")

    asked: list[float] = []

    def current_frame(timeout: float) -> CameraFrame | None:
        asked.append(timeout)
        return runner._frame

    runner.current_frame = current_frame  # type: ignore[method-assign]
    client = create_app(SparqlService(bundled_kb), tasks=runner).test_client()
    still = client.get("/camera.jpg?frame=7")
    assert still.status_code == 200 and still.headers["X-Frame"] == "7" and still.data.endswith(b"seven\xff\xd9")
    assert client.get("/camera.jpg?frame=6").headers["X-Frame"] == "7"
    assert asked == []  # a frame the page knows of is answered at once
    client.get("/camera.jpg?frame=8")  # newer than any: the run is asked, as for a plain still
    client.get("/camera.jpg")
    assert len(asked) == 2


def _luminance(colour: str) -> float:
    channels = [int(colour[i : i + 2], 16) / 255 for i in (1, 3, 5)]
    r, g, b = (c / 12.92 if c <= 0.03928 else ((c + 0.055) / 1.055) ** 2.4 for c in channels)
    return 0.2126 * r + 0.7152 * g + 0.0722 * b


def _contrast(one: str, other: str) -> float:
    light, dark = sorted((_luminance(one), _luminance(other)), reverse=True)
    return (light + 0.05) / (dark + 0.05)


def test_the_pages_colours_read_on_a_projector() -> None:
    """Text and its background at 7:1 at least (WCAG's AAA), as a projector in a lit room washes contrast out:
    the links (4.6:1), the muted notes (5.3:1 on the page's wash) and the status badges (4.6:1) were at AA."""
    css = (Path(cbrs.web.__file__).parent / "static" / "cbrs.css").read_text(encoding="utf-8")
    root = dict(re.findall(r"--(\w+):\s*(#[0-9a-fA-F]{6});", css.split("}", 1)[0]))
    pairs = [(root[text], root[ground]) for text in ("ink", "muted", "accent") for ground in ("paper", "wash")]
    for rule, text in (
        (".badge.good", "good"),
        (".badge.bad", "bad"),
        (".badge.warn", "warn"),
        (".error-box", "bad"),
        (".status-queued", "accent"),
    ):
        ground = re.search(re.escape(rule) + r"[^{]*\{[^}]*background: (#[0-9a-fA-F]{6})", css)
        assert ground is not None, rule
        pairs.append((root[text], ground.group(1)))
    pairs.append(("#ffffff", root["accent"]))  # a button's label
    pairs += [(ink, fill) for fill, _, ink in diagram.COLOURS.values()]  # the pictures' boxes
    pairs += [(home_canvas.MUTED, fill) for fill in ("#ffffff", *home_canvas.ROOM_FILLS)]  # the home map's labels
    weak = [(text, ground, round(_contrast(text, ground), 2)) for text, ground in pairs if _contrast(text, ground) < 7]
    assert weak == []


def test_an_actions_sub_actions_are_drawn_level_by_level_in_their_order() -> None:
    """The lab's two-level action (docs/tasks.md, fifteenth round): its sub-actions, and the first one's own,
    each numbered where it comes, a box and an arrow each; FetchMyPen's four on one level; a class that is no
    action with sub-actions has no such picture."""
    kb = KnowledgeBase.open(":memory:")
    kb.load([EXAMPLES / "lab15_place_setting.ttl"], graph="ontology")
    for name in ("lab15_set_the_table.ttl", "lab15_set_the_table_and_call_me.ttl"):
        kb.load([EXAMPLES / name], graph="requirements")
    client = create_app(SparqlService(kb)).test_client()
    twin = client.get("/taxonomy/class.json", query_string={"iri": "lab15:SetTheTableAndCallMe"}).get_json()
    tree = [(n["name"], n["order"], [(m["name"], m["order"]) for m in n["sub_actions"]]) for n in twin["sub_actions"]]
    assert tree == [
        ("lab15:SetTheTableForOne", 1, [("lab15:PutSaucerOnMat", 1), ("lab15:PutCupOnMat", 2)]),
        ("lab15:CallToTheTable", 2, []),
    ]
    page = client.get("/taxonomy/class", query_string={"iri": "lab15:SetTheTableAndCallMe"}).get_data(as_text=True)
    picture = page[page.index('id="hierarchy-heading"') :].split("</svg>")[0]
    boxes = re.findall(r'<tspan x="[\d.]+" y="[\d.]+">([^<]+)</tspan>', picture)
    assert boxes[0] == "lab15:SetTheTableAndCallMe"
    assert sorted(boxes[1:]) == sorted(
        ["1. lab15:SetTheTableForOne", "2. lab15:CallToTheTable", "1.1. lab15:PutSaucerOnMat", "1.2. lab15:PutCupOnMat"]
    )
    assert "4 sub-actions on 2 levels" in picture and picture.count("<polyline") >= 4
    fetch = client.get("/taxonomy/class", query_string={"iri": "act:FetchMyPen"}).get_data(as_text=True)
    assert "4. act:Delivering" in fetch and "4 sub-actions on 1 level," in fetch
    cup = client.get("/taxonomy/class.json", query_string={"iri": "home:Cup"}).get_json()
    assert "sub_actions" not in cup
    assert 'id="hierarchy-heading"' not in client.get("/taxonomy/class?iri=home:Cup").get_data(as_text=True)


def test_a_page_stops_only_the_runs_its_own_computer_started(bundled_kb: KnowledgeBase) -> None:
    """Every tasks page shows Stop for the run going: a student's click stopped the teacher's run. Another
    computer's page is refused, saying why and how; the token typed beside Stop, or the starter, stops it."""
    service = SparqlService(bundled_kb, EndpointConfig(update_token="teacher"))
    runner = _Held(bundled_kb, service.lock)
    runner.release.clear()  # the run goes until released
    client = create_app(service, tasks=runner).test_client()
    teacher, student = {"REMOTE_ADDR": "10.0.0.1"}, {"REMOTE_ADDR": "10.0.0.2"}
    try:
        started = client.post("/tasks.json", data={"task": "FetchMyPen"}, environ_base=teacher)
        assert started.status_code == 202
        run_id = started.get_json()["started"]["id"]
        refused = client.post(f"/tasks/{run_id}/cancel.json", environ_base=student)
        assert refused.status_code == 403
        assert "started from another computer" in refused.get_json()["message"]
        assert "update token typed beside Stop this run" in refused.get_json()["message"]
        assert not runner.get(run_id).cancel_requested.is_set()
        wrong = client.post(f"/tasks/{run_id}/cancel.json", data={"token": "guess"}, environ_base=student)
        assert wrong.status_code == 403 and not runner.get(run_id).cancel_requested.is_set()
        page = client.get(f"/tasks/{run_id}", environ_base=student).get_data(as_text=True)
        assert 'id="stop-token"' in page and 'name="token"' in page
        typed = client.post(f"/tasks/{run_id}/cancel.json", data={"token": "teacher"}, environ_base=student)
        assert typed.status_code == 202 and runner.get(run_id).cancel_requested.is_set()
    finally:
        runner.release.set()
    assert runner.get(run_id).done.wait(10)
    runner.release.clear()
    try:
        own = client.post("/tasks.json", data={"task": "FetchMyPen"}, environ_base=student).get_json()["started"]["id"]
        assert client.post(f"/tasks/{own}/cancel.json", environ_base=student).status_code == 202
    finally:
        runner.release.set()


def test_more_options_open_when_one_of_them_is_wrong_or_set(bundled_kb: KnowledgeBase) -> None:
    service = SparqlService(bundled_kb)
    client = create_app(service, tasks=_Held(bundled_kb, service.lock)).test_client()
    folded = client.get("/tasks").get_data(as_text=True)
    assert '<details class="more-options" id="more-options">' in folded
    wrong = client.post("/tasks", data={"task": "FetchMyPen", "fault_rate": "2"}, headers={"Accept": "text/html"})
    assert wrong.status_code == 400
    assert '<details class="more-options" id="more-options" open>' in wrong.get_data(as_text=True)
    assert 'id="more-options" open>' in client.get("/tasks?objective=cost").get_data(as_text=True)
