"""The pages that act: matchmaking, plans and tasks (with their live event and camera streams).

Flask's test client throughout; streamed responses are read a bounded number of chunks, and every
wait on a run is bounded.
"""

from __future__ import annotations

import json
import threading
import time
from collections.abc import Iterator
from typing import Any

import pytest
from flask import Flask
from flask.testing import FlaskClient

from cbrs.kb import KnowledgeBase
from cbrs.kb.namespaces import expand
from cbrs.sparql_service import SparqlService
from cbrs.tasks import TaskRunner
from cbrs.web import create_app

RUN_WAIT = 120.0
CAMERA = "svc:LocateMobileRobot_CeilingCamera01"


@pytest.fixture(scope="module")
def shared_kb() -> Iterator[KnowledgeBase]:
    """One seeded store for the pages that only read (the plans page shows a plan without recording it)."""
    kb = KnowledgeBase.open(":memory:")
    yield kb
    kb.close()


@pytest.fixture(scope="module")
def client(shared_kb: KnowledgeBase) -> FlaskClient:
    sparql = SparqlService(shared_kb)
    return create_app(sparql, tasks=TaskRunner(shared_kb, sparql.lock)).test_client()


@pytest.fixture
def live(fresh_bundled_kb: KnowledgeBase) -> Iterator[tuple[Flask, TaskRunner]]:
    """An app over a fresh store whose streams live briefly."""
    sparql = SparqlService(fresh_bundled_kb)
    runner = TaskRunner(fresh_bundled_kb, sparql.lock)
    app = create_app(sparql, tasks=runner)
    app.config.update(
        CBRS_STREAM_SECONDS=60.0,
        CBRS_STREAM_IDLE_SECONDS=1.5,
        CBRS_HEARTBEAT_SECONDS=0.3,
        CBRS_CAMERA_REPEAT_SECONDS=0.2,
    )
    yield app, runner
    runner.close(RUN_WAIT)


def start(client: FlaskClient, task: str = "FetchMyPen", **form: Any) -> Any:
    return client.post("/tasks.json", data={"task": task, **form})


def wait_done(runner: TaskRunner, run_id: str) -> None:
    assert runner.get(run_id).done.wait(RUN_WAIT), f"{run_id} did not end within {RUN_WAIT:g} s"


# -- matchmaking -----------------------------------------------------------------------------------


def test_stored_requirement_ranks_the_ceiling_camera_first_with_explanations(client: FlaskClient) -> None:
    response = client.get("/match.json", query_string={"requirement": "req:RobotSelfPosition"})
    assert response.status_code == 200
    body = response.get_json()
    assert body["requirement"]["name"] == "req:RobotSelfPosition"
    [ranking] = body["rankings"]
    assert ranking["method"] == "sem-str" and ranking["status"] == "matched"
    best = ranking["candidates"][0]
    assert best["name"] == "svc:LocateMobileRobot_CeilingCamera01" and best["acceptable"]
    assert set(best["parts"]) == {"outputs", "inputs"}
    wanted = {(p["role"], p["wanted"], p["offered"]) for p in best["explanation"]}
    position, location = expand("home:RobotPosition"), expand("home:RobotLocation")
    assert ("output", position, location) in wanted
    assert all({"similarity", "degree", "how"} <= set(p) for p in best["explanation"])
    second_camera = next(c for c in ranking["candidates"] if c["name"] == "svc:LocateMobileRobot_CeilingCamera02")
    assert not second_camera["acceptable"] and second_camera["rejected_by"][0].startswith("SEA:")


def test_methods_side_by_side_give_one_ranking_each(client: FlaskClient) -> None:
    methods = ["sem-str", "wu-palmer", "string", "logic"]
    response = client.get("/match.json", query_string={"requirement": "req:RobotSelfPosition", "methods": methods})
    body = response.get_json()
    assert [r["method"] for r in body["rankings"]] == methods
    assert all(len(r["candidates"]) == 10 for r in body["rankings"])
    page = client.get("/match", query_string={"requirement": "req:RobotSelfPosition", "methods": methods}).text
    assert all(f'id="ranking-{m}"' in page for m in methods) and "<details>" in page


def test_a_written_requirement_is_ranked(client: FlaskClient) -> None:
    written = {"inputs": "home:MarkerColour", "outputs": "home:RobotPosition", "methods": ["sem-str", "lin"]}
    body = client.get("/match.json", query_string=written).get_json()
    assert body["requirement"]["written"] is True
    assert body["requirement"]["outputs"] == [expand("home:RobotPosition")]
    semstr, lin = body["rankings"]
    assert semstr["candidates"][0]["name"].startswith("svc:LocateMobileRobot_CeilingCamera")
    assert lin["method"] == "lin" and lin["candidates"][0]["name"] != semstr["candidates"][0]["name"]  # parts count


def test_a_written_requirement_may_ask_for_a_delete_effect(client: FlaskClient) -> None:
    written = {"deletes": "home:Cup home:isLocated home:Place"}
    body = client.get("/match.json", query_string=written).get_json()
    assert body["requirement"]["deletes"] == [[expand(t) for t in ("home:Cup", "home:isLocated", "home:Place")]]
    best = body["rankings"][0]["candidates"][0]
    assert best["name"] == "svc:PickUpObject_CytonDualArm01" and best["parts"]["deletes"] > 0.5
    assert best["degree"] == "HasSubClass"  # the delete effect's pair: the offer deletes it of any object
    page = client.get("/match", query_string=written).text
    assert "<dt>delete effects</dt>" in page and 'name="deletes"' in page
    bad = client.get("/match.json", query_string={"deletes": "home:Cup home:isLocated"})
    assert bad.status_code == 400 and "subject predicate object" in bad.get_json()["fields"]["deletes"]


@pytest.mark.parametrize(
    ("query", "field", "says"),
    [
        pytest.param(
            {"inputs": "home:MarkerColor", "outputs": "home:RobotPosition"}, "inputs", "home:MarkerColour", id="typo"
        ),
        pytest.param({"outputs": "nowhere:Thing"}, "outputs", "not a known prefix", id="prefix"),
        pytest.param({"effects": "home:Pen home:isWith"}, "effects", "subject predicate object", id="statement"),
        pytest.param({"inputs": "", "outputs": ""}, "requirement", "write one", id="empty"),
        pytest.param({"requirement": "req:NoSuchNeed"}, "requirement", "NoSuchNeed", id="unknown-requirement"),
        pytest.param({"requirement": "req:RobotSelfPosition", "methods": "magic"}, "methods", "magic", id="method"),
    ],
)
def test_bad_requirements_are_field_errors(client: FlaskClient, query: dict[str, str], field: str, says: str) -> None:
    response = client.get("/match.json", query_string=query)
    assert response.status_code == 400
    body = response.get_json()
    assert body["error"] == "invalid-form" and says in body["fields"][field]
    page = client.get("/match", query_string=query)
    assert page.status_code == 400 and "Traceback" not in page.text
    assert f'<span class="field-error" id="{field}-error" role="alert">' in page.text
    assert f'aria-describedby="{field}-error"' in page.text


# -- plans -----------------------------------------------------------------------------------------


def test_plan_page_gives_the_fifteen_step_plan_and_its_drawing(client: FlaskClient) -> None:
    body = client.get("/plans.json", query_string={"task": "FetchMyPen"}).get_json()
    plan = body["composition"]
    assert plan["status"] == "planned" and len(plan["steps"]) == 15
    assert plan["steps"][1]["component"] == expand(CAMERA)
    assert plan["steps"][1]["alternatives"] == [expand("svc:LocateMobileRobot_CeilingCamera02")]
    assert plan["goals"][0]["source"] == "#15"
    drawing = client.get(body["graph"])
    assert drawing.status_code == 200 and drawing.mimetype == "image/svg+xml"
    assert b"<svg" in drawing.data[:1000]
    page = client.get("/plans", query_string={"task": "FetchMyPen"}).text
    assert f'<img class="drawing" src="{body["graph"].replace("&", "&amp;")}"' in page and 'id="step-15"' in page


def test_unknown_task_is_a_field_error(client: FlaskClient) -> None:
    response = client.get("/plans.json", query_string={"task": "MakeCoffee"})
    assert response.status_code == 400 and "FetchMyPen" in response.get_json()["fields"]["task"]
    assert 'id="task-error"' in client.get("/plans", query_string={"task": "MakeCoffee"}).text
    assert client.get("/plans/graph.svg", query_string={"task": "MakeCoffee"}).status_code == 400


# -- tasks -----------------------------------------------------------------------------------------


def test_a_started_run_succeeds_and_a_second_is_refused_while_it_goes(live: tuple[Flask, TaskRunner]) -> None:
    app, runner = live
    client = app.test_client()
    frames_before = client.get("/tasks.json").get_json()["camera"]["frame"]
    response = start(client, seed="1", fail=CAMERA)
    assert response.status_code == 202, response.get_json()
    run_id = response.get_json()["started"]["id"]
    busy = start(client, "RobotArmServeACup")
    assert busy.status_code == 409 and busy.get_json()["running"] == run_id
    assert "one task runs at a time" in busy.get_json()["message"]
    assert "one task runs at a time" in client.post("/tasks", data={"task": "FetchMyPen"}).text
    # nobody watches the camera: the run renders no frame until a still is asked for, which it renders at once
    deadline = time.monotonic() + RUN_WAIT
    while not any(e.get("event") == "step_started" for e in runner.get(run_id).events) and time.monotonic() < deadline:
        time.sleep(0.05)
    assert runner.frame_number == frames_before
    still = client.get("/camera.jpg")
    assert runner.get(run_id).finished is None  # it came mid-run, not with the run's last frame
    assert still.status_code == 200 and int(still.headers["X-Frame"]) == frames_before + 1
    assert runner.frame() is not None and runner.frame().run == run_id and not runner.watched
    wait_done(runner, run_id)
    run = client.get(f"/tasks/{run_id}.json").get_json()["run"]
    assert run["status"] == "succeeded" and run["faults"] == [expand(CAMERA)]
    assert any(e["event"] == "step_failed" and e.get("failover") for e in run["events"] if "event" in e)
    failed_over = [s for s in run["steps"] if s["failed_over"]]
    assert failed_over and failed_over[0]["tried"][-1] == expand("svc:LocateMobileRobot_CeilingCamera02")
    # the failed localiser fails over to the other camera, which the later localisation takes directly
    cam1, cam2 = expand(CAMERA), expand("svc:LocateMobileRobot_CeilingCamera02")
    located = [s for s in run["result"]["execution"]["steps"] if s["planned"] == cam1]
    assert len(located) == 2
    first, second = located
    assert [(a["component"], a["outcome"]) for a in first["attempts"]] == [(cam1, "failed"), (cam2, "succeeded")]
    assert "injected failure" in first["attempts"][0]["reason"]
    assert [a["component"] for a in second["attempts"]] == [cam2]  # the broken camera is not tried again
    assert first["failover"] and second["failover"]
    assert len(run["steps"]) == len(run["result"]["plan"]["steps"])
    listing = client.get("/tasks.json").get_json()
    assert listing["runs"][0]["id"] == run_id and listing["runs"][0]["url"] == f"/tasks/{run_id}"
    assert listing["camera"]["frame"] == frames_before + 2  # the still and the home as the run left it
    page = client.get(f"/tasks/{run_id}").text
    assert "failover" in page and "status-succeeded" in page


def test_matchmaking_and_plans_answer_while_a_run_is_going(
    live: tuple[Flask, TaskRunner], monkeypatch: pytest.MonkeyPatch
) -> None:
    """A run holds the knowledge-base lock only while it reads its view, not while the robot moves."""
    app, runner = live
    moving, release = threading.Event(), threading.Event()

    def held_run(*_: object, **__: object) -> None:
        moving.set()
        release.wait(RUN_WAIT)  # the robot "moves" until the test has its answers
        raise RuntimeError("run stopped by the test")

    monkeypatch.setattr("cbrs.tasks.run_task", held_run)
    client = app.test_client()
    run_id = start(client).get_json()["started"]["id"]
    try:
        assert moving.wait(RUN_WAIT)
        answers: list[int] = []

        def ask() -> None:
            answers.append(client.get("/match.json", query_string={"requirement": "req:RobotSelfPosition"}).status_code)
            answers.append(client.get("/plans.json", query_string={"task": "FetchMyPen"}).status_code)

        asking = threading.Thread(target=ask)
        asking.start()
        asking.join(60.0)
        assert answers == [200, 200], "matchmaking or plans waited for the running task"
        assert not runner.get(run_id).done.is_set()
    finally:
        release.set()
    wait_done(runner, run_id)
    assert runner.get(run_id).status == "error" and "stopped by the test" in (runner.get(run_id).error or "")


@pytest.mark.parametrize(
    ("form", "field"),
    [
        pytest.param({"task": "MakeCoffee"}, "task", id="task"),
        pytest.param({"task": "FetchMyPen", "seed": "x"}, "seed", id="seed"),
        pytest.param({"task": "FetchMyPen", "fail": "svc:NoSuchThing"}, "fail", id="component"),
        pytest.param({"task": "FetchMyPen", "fault_rate": "often"}, "fault_rate", id="fault-rate-word"),
        pytest.param({"task": "FetchMyPen", "fault_rate": "1.5"}, "fault_rate", id="fault-rate-range"),
        pytest.param({"task": "FetchMyPen", "fault_rate": "nan"}, "fault_rate", id="fault-rate-nan"),
    ],
)
def test_bad_start_forms_are_field_errors(client: FlaskClient, form: dict[str, str], field: str) -> None:
    response = client.post("/tasks.json", data=form)
    assert response.status_code == 400 and field in response.get_json()["fields"]
    assert f'id="{field}-error"' in client.post("/tasks", data=form).text


def test_a_run_with_random_faults_says_which_requirement_it_could_not_meet(live: tuple[Flask, TaskRunner]) -> None:
    app, runner = live
    client = app.test_client()
    response = start(client, seed="5", fault_rate="1")  # every component breaks, within its first two ticks
    assert response.status_code == 202, response.get_json()
    run_id = response.get_json()["started"]["id"]
    wait_done(runner, run_id)
    run = client.get(f"/tasks/{run_id}.json").get_json()["run"]
    assert run["status"] == "failed" and run["fault_rate"] == 1.0
    unmet = run["result"]["execution"]["unmet"]
    assert unmet["requirement"] == run["result"]["plan"]["requirement"]
    assert all("injected failure" in a["reason"] for a in unmet["tried"])
    assert "requirement FetchMyPen not met" in client.get(f"/tasks/{run_id}").text


def test_a_run_stopped_from_the_page_ends_cancelled_before_its_last_step(live: tuple[Flask, TaskRunner]) -> None:
    app, runner = live
    client = app.test_client()
    run_id = start(client).get_json()["started"]["id"]
    assert 'id="cancel"' in client.get(f"/tasks/{run_id}").text
    stopping = client.post(f"/tasks/{run_id}/cancel.json")
    assert stopping.status_code == 202 and "asked to stop" in stopping.get_json()["message"]
    wait_done(runner, run_id)
    run = client.get(f"/tasks/{run_id}.json").get_json()["run"]
    assert run["status"] == "cancelled"
    outcomes = [step["outcome"] for step in run["result"]["execution"]["steps"]]
    assert outcomes[-1] == "pending" and outcomes.count("succeeded") < len(run["result"]["plan"]["steps"])
    again = client.post(f"/tasks/{run_id}/cancel.json")
    assert again.status_code == 409 and "already ended: cancelled" in again.get_json()["message"]
    assert "already ended" in client.post(f"/tasks/{run_id}/cancel").text


def test_other_sites_cannot_start_or_stop_a_run(client: FlaskClient) -> None:
    evil = {"Origin": "https://evil.example"}
    assert client.post("/tasks/run-1/cancel.json", headers=evil).status_code == 403
    assert client.post("/tasks/run-999/cancel.json").status_code == 404
    response = client.post("/tasks.json", data={"task": "FetchMyPen"}, headers={"Origin": "https://evil.example"})
    assert response.status_code == 403
    assert client.get("/tasks/run-999.json").status_code == 404


def sse_messages(chunks: Iterator[bytes]) -> list[dict[str, Any]]:
    """The JSON of every ``data:`` line in the rest of an event stream."""
    text = b"".join(chunks).decode()
    return [json.loads(line[6:]) for line in text.splitlines() if line.startswith("data: ")]


def test_the_event_and_camera_streams_follow_one_run_and_end_by_themselves(live: tuple[Flask, TaskRunner]) -> None:
    """Both streams open on one run: the event stream delivers its steps live, the camera stream sends
    JPEG parts whose frame numbers rise; each ends by itself once idle after the run."""
    app, runner = live
    app.config["CBRS_STREAM_IDLE_SECONDS"] = 3.0  # from the camera stream's start until the run's first frame
    client = app.test_client()
    camera = client.get("/camera.mjpg", buffered=False)
    assert camera.status_code == 200
    assert camera.headers["Content-Type"] == "multipart/x-mixed-replace; boundary=frame"
    body, numbers = b"", []
    parts = iter(camera.response)
    while len(numbers) < 2 and len(body) < 2_000_000:
        part = next(parts)
        body += part
        assert part.startswith(b"--frame\r\nContent-Type: image/jpeg\r\n")
        head, _, jpeg = part.partition(b"\r\n\r\n")
        assert jpeg.startswith(b"\xff\xd8") and jpeg.endswith(b"\xff\xd9\r\n")
        numbers.append(int(head.split(b"X-Frame: ")[1]))
    assert numbers == [1, 1]  # the idle home, then the same again (no run yet)
    stream = client.get("/tasks/events", buffered=False)
    assert stream.status_code == 200 and stream.mimetype == "text/event-stream"
    chunks = iter(stream.response)
    assert next(chunks).startswith(b"retry:")
    hello = json.loads(next(chunks).decode()[6:])
    assert hello["event"] == "hello" and hello["active"] is None
    run_id = start(client, "RobotArmServeACup").get_json()["started"]["id"]
    seen: list[int] = []
    reader = threading.Thread(target=lambda: seen.extend(int(p.split(b"X-Frame: ")[1].split(b"\r")[0]) for p in parts))
    reader.start()
    wait_done(runner, run_id)
    started = time.monotonic()
    messages = sse_messages(chunks)
    assert time.monotonic() - started < 10  # idle for 3 s after the run: ends
    kinds = [m.get("event") for m in messages]
    assert kinds[0] == "run_started" and "run_finished" in kinds and kinds[-1] == "end"
    steps = [m for m in messages if m.get("topic") == "/cbrs/task_progress"]
    assert steps and all(m["run"] == run_id for m in steps)
    assert {"step_started", "step_succeeded"} <= {m["event"] for m in steps}
    frames = [m["frame"] for m in messages if m.get("event") == "frame"]
    assert len(frames) >= 2 and frames == sorted(frames)
    stream.close()
    reader.join(30)
    assert not reader.is_alive(), "the camera stream did not end by itself"
    camera.close()
    assert not runner._listeners[1:] and not runner._frame_listeners  # both unsubscribed (the event log stays)
    assert not runner.watched  # the camera stream's watch ended with it
    assert max(seen) > 2 and seen == sorted(seen)
    still, latest = client.get("/camera.jpg"), runner.frame()
    assert latest is not None and still.mimetype == "image/jpeg"
    # the latest frame; the stream may have ended idle before it came (frames > 3 s apart under load)
    assert int(still.headers["X-Frame"]) == latest.number >= max(seen)


def test_the_steps_of_a_new_plan_follow_the_old_plans_steps() -> None:
    from cbrs.web.tasks import steps

    progress = "/cbrs/task_progress"
    events = [
        {"topic": progress, "event": "step_started", "step": 1, "component": "svc:A"},
        {"topic": progress, "event": "step_failed", "step": 1, "component": "svc:A", "reason": "blocked"},
        {"topic": progress, "event": "replanning", "plan": 2, "reason": "step 1 failed"},
        {"topic": progress, "event": "step_started", "step": 1, "component": "svc:B"},
        {"topic": progress, "event": "step_succeeded", "step": 1, "component": "svc:B"},
    ]
    rows = steps(events)
    assert [(r["plan"], r["step"], r["tried"], r["status"]) for r in rows] == [
        (1, 1, ["svc:A"], "failed"),
        (2, 1, ["svc:B"], "succeeded"),
    ]
