"""A round by a lab's integrators and its administrator, from the docs alone (docs/examples/lab12_*,
docs/serving.md "Tried by a lab's integrators"): a desk fan's smart plug written with the websockets
package from components.md's "The protocol", a run log that follows the server's topics, rdflib and curl
against the endpoint, and the administrator's token file, restarts and limits. Nothing is simulated here:
the fan's steps call the program over the bridge, and the plans are composed without a world."""

from __future__ import annotations

import json
import logging
import os
import subprocess
import sys
import threading
import urllib.error
import urllib.parse
import urllib.request
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
from click.testing import CliRunner
from websockets.sync.client import connect

from cbrs.actions.base_choice import choose_in_map
from cbrs.actions.composer import Composer
from cbrs.cli import cli
from cbrs.kb import KnowledgeBase
from cbrs.server import ServeConfig, Server
from cbrs.settings import setting
from cbrs.sparql_service import EndpointBusyError, EndpointConfig
from cbrs.tasks import TaskRun, TaskRunner
from tests.helpers_examples import EXAMPLES

LAB12 = "https://example.org/lab12#"
SWITCH_ON, SWITCH_OFF = LAB12 + "SwitchOnDeskFan_FanPlug01", LAB12 + "SwitchOffDeskFan_FanPlug01"
TOKEN = "lab12-test-token"


@pytest.fixture(scope="module")
def fan_kb() -> Iterator[KnowledgeBase]:
    """The desk fan in the ontology and the map, its two tasks, and its plug's two components."""
    kb = KnowledgeBase.open(":memory:")
    for graph in ("ontology", "map"):
        kb.load([EXAMPLES / "lab12_desk_fan.ttl"], graph=graph)
    for task in ("lab12_switch_on_the_fan.ttl", "lab12_switch_off_the_fan.ttl"):
        kb.load([EXAMPLES / task], graph="requirements")
    kb.registry.register((EXAMPLES / "lab12_fan_switch.ttl").read_text("utf-8"))
    yield kb
    kb.close()


def test_a_plan_names_the_labs_component_whose_program_is_down(fan_kb: KnowledgeBase) -> None:
    """The plug's program stopped (its lease lapsed): `cbrs run` said "lab12:SwitchOffDeskFan_FanPlug01 was
    planned for it but cannot run here: unavailable: its lease lapsed", but `cbrs plan`, the plans page and
    the bridge's /cbrs/plan (all through choose_in_map) said only "no component provides ...; register a
    component whose effect is ...", to an integrator who had registered one."""
    for iri in (SWITCH_ON, SWITCH_OFF):
        fan_kb.liveness.renew(iri, 600.0)
    composer = Composer(fan_kb)
    live, _ = choose_in_map(composer, LAB12 + "SwitchOffTheDeskFan", composer.compose(LAB12 + "SwitchOffTheDeskFan"))
    assert live.plan is not None and live.plan.steps[0].component == SWITCH_OFF
    for iri in (SWITCH_ON, SWITCH_OFF):
        fan_kb.liveness.expire(iri, "its lease lapsed")
    composer = Composer(fan_kb)
    task = LAB12 + "SwitchOffTheDeskFan"
    gone, _ = choose_in_map(composer, task, composer.compose(task))
    assert gone.plan is None
    (unmet,) = gone.unsatisfied
    assert unmet.unrunnable == ((SWITCH_OFF, "unavailable: its lease lapsed"),)
    assert "SwitchOffDeskFan_FanPlug01 was planned for it but cannot run here: unavailable: its lease lapsed" in (
        unmet.text()
    )
    assert json.dumps(gone.to_dict()).count("its lease lapsed") >= 1


@pytest.fixture(scope="module")
def served() -> Iterator[Server]:
    """A cbrs serve of the desk fan's store (ontology, map, the two tasks), with an update token."""
    kb = KnowledgeBase.open(":memory:")
    for graph in ("ontology", "map"):
        kb.load([EXAMPLES / "lab12_desk_fan.ttl"], graph=graph)
    for task in ("lab12_switch_on_the_fan.ttl", "lab12_switch_off_the_fan.ttl"):
        kb.load([EXAMPLES / task], graph="requirements")
    server = Server(kb, ServeConfig(port=0, bridge_port=0, endpoint=EndpointConfig(update_token=TOKEN, isolate=False)))
    server.start()
    yield server
    server.stop()
    kb.close()


def test_the_websockets_plug_is_called_by_the_servers_run_which_the_run_log_follows(served: Server) -> None:
    """lab12_fan_switch.py (the protocol by hand) registered and answered the server's own run, which
    lab12_follow_runs.py started over the bridge and followed on the topics; its publish on /cbrs/task was
    refused, as the server's topics are; a second copy of the plug was refused, "is its program running
    twice?"."""
    bridge = f"ws://127.0.0.1:{served.bridge_port}"
    env = {**os.environ, "CBRS_UPDATE_TOKEN": TOKEN}
    plug = [sys.executable, str(EXAMPLES / "lab12_fan_switch.py"), "--bridge", bridge]
    child = subprocess.Popen(plug, stderr=subprocess.PIPE, text=True, env=env)
    try:
        assert child.stderr is not None
        assert "registered" in child.stderr.readline()
        twice = subprocess.run(plug, capture_output=True, text=True, env=env, timeout=60)
        assert twice.returncode == 2 and "is its program running twice?" in twice.stderr
        follow = [sys.executable, str(EXAMPLES / "lab12_follow_runs.py"), "--bridge", bridge]
        log = subprocess.run(
            [*follow, "--start", "SwitchOnTheDeskFan", "--spoof", "--seconds", "120"],
            capture_output=True,
            text=True,
            env=env,
            timeout=180,
        )
    finally:
        child.kill()  # stopped by its PID
        child.wait(timeout=10)
    assert log.returncode == 0, log.stdout + log.stderr
    assert "topic '/cbrs/task' belongs to this server" in log.stdout
    assert f"step_succeeded 1 {SWITCH_ON}" in log.stdout
    assert f"{LAB12}SwitchOnTheDeskFan succeeded" in log.stdout


def test_a_token_with_a_line_end_or_a_space_at_its_end_is_the_token() -> None:
    """The token file written on Windows (CRLF) and handed on as CBRS_UPDATE_TOKEN=$(cat token): the
    server reads the file's first line without its CR, but the variable kept it, and every request of
    `cbrs --store URL`, queries too, failed "Illegal header value b'Bearer secret\\r'", printing the token;
    `cbrs serve` given the variable so took the CR into its token, which no client could then send."""
    for raw in ("secret\r", "secret\r\n", " secret ", "secret\n"):
        assert setting("update_token").resolve(environ={"CBRS_UPDATE_TOKEN": raw}) == "secret"


def test_a_program_reading_the_token_file_whole_is_served(served: Server) -> None:
    """KnowledgeBase.open(URL, remote_token=Path(file).read_text()) keeps the file's line end: every request
    failed "Illegal header value", the token printed in the error; and the bridge's auth op refused the
    same text as "not this server's update token"."""
    url = f"http://127.0.0.1:{served.http_port}"
    kb = KnowledgeBase.open(url, remote_token=TOKEN + "\r\n")
    try:
        kb.update("INSERT DATA { GRAPH <https://example.org/lab12/notes> { <urn:lab12:n> <urn:lab12:says> 1 } }")
        assert kb.query("ASK { GRAPH <https://example.org/lab12/notes> { <urn:lab12:n> ?p ?o } }")
    finally:
        kb.close()
    with connect(f"ws://127.0.0.1:{served.bridge_port}") as ws:
        ws.send(json.dumps({"op": "set_level", "level": "info"}))
        ws.send(json.dumps({"op": "auth", "mac": TOKEN + "\n"}))
        said = json.loads(ws.recv(timeout=10))
    assert said["level"] == "info" and "authorised" in said["msg"], said


def test_a_token_file_whose_first_line_is_blank_is_said_so(tmp_path: Path) -> None:
    """The administrator's token file began with a blank line, the token on the second: `cbrs serve
    --update-token-file` said the file "is empty"."""
    token = tmp_path / "token"
    token.write_text("\nsecret\n", encoding="utf-8")
    refused = CliRunner().invoke(cli, ["--store", ":memory:", "serve", "--update-token-file", str(token)])
    assert refused.exit_code == 2
    assert "is empty" not in refused.output
    assert "its first line is blank, and line 2 is not: the token must be on the first line" in refused.output


def test_a_server_stopped_during_a_run_says_how_the_run_ended(caplog: pytest.LogCaptureFixture) -> None:
    """`cbrs serve` stopped with SIGTERM while FetchMyPen ran (step 5 of 16) printed "stopped" and exited 0
    after 5 s: the run had ended meanwhile (its world graph written), but neither the log nor any client
    said so, since the listeners close first; a run that outlives the wait stopped mid-step unsaid."""
    kb = KnowledgeBase.open(":memory:")
    runner = TaskRunner(kb, threading.RLock(), camera=None)
    for seconds, said in ((0.2, "task run run-7 (FetchMyPen) ended: succeeded"), (5.0, "did not end within 0.5 s")):
        run = TaskRun("run-7", "FetchMyPen", 0, ())
        done = threading.Event()

        def work(run: TaskRun = run, seconds: float = seconds, done: threading.Event = done) -> None:
            if not done.wait(seconds):
                run.status = "succeeded"

        thread = threading.Thread(target=work, daemon=True)
        thread.start()
        runner._active = (run, thread)
        caplog.clear()
        with caplog.at_level(logging.INFO, logger="cbrs.tasks"):
            runner.close(timeout=0.5)
        done.set()
        thread.join(timeout=5)
        assert "task run run-7 (FetchMyPen) is still going: waiting up to 0.5 s for it to end" in caplog.text
        assert said in caplog.text
    kb.close()


def test_a_registration_after_a_refused_token_says_the_token_was_refused(served: Server) -> None:
    """The plug started with another server's token: the auth op's error status said so, but the
    registration that followed was refused "send it first with the auth op", which the program had done
    (the SDK reads the status back; a program of the protocol by hand, as components.md writes it, does
    not); /cbrs/run_task likewise said "send the update token first"."""
    with connect(f"ws://127.0.0.1:{served.bridge_port}") as ws:
        ws.send(json.dumps({"op": "auth", "mac": "another-servers-token"}))
        description = (EXAMPLES / "lab12_fan_switch.ttl").read_text("utf-8")
        calls = {"/cbrs/register": {"description": description}, "/cbrs/run_task": {"task": "SwitchOnTheDeskFan"}}
        for service, args in calls.items():
            ws.send(json.dumps({"op": "call_service", "service": service, "args": args, "id": service}))
        answers: dict[str, dict[str, Any]] = {}
        while len(answers) < len(calls):
            frame = json.loads(ws.recv(timeout=30))
            if frame.get("op") == "service_response":
                answers[frame["id"]] = frame
    for service, answer in answers.items():
        assert answer["result"] is False, service
        assert "the token this connection sent with the auth op is not this server's update token" in answer["values"]
        assert "send it first" not in answer["values"] and "send the update token first" not in answer["values"]


def test_a_busy_answer_says_when_to_try_again(served: Server, monkeypatch: pytest.MonkeyPatch) -> None:
    """The dashboard's heavy query from 3 and 4 threads got 503 `busy` for 25 of 60 and 40 of 80 requests,
    "retry when one has ended", with no Retry-After header for a client's retry policy (urllib3's, say) to
    wait by; the plain query the front answers and one Flask answers alike."""

    def busy(*args: object, **kwargs: object) -> None:
        raise EndpointBusyError(4, "127.0.0.1", 2)

    monkeypatch.setattr(served.sparql, "query_here", busy)
    monkeypatch.setattr(served.sparql, "query", busy)
    base = f"http://127.0.0.1:{served.http_port}/sparql?" + urllib.parse.urlencode({"query": "ASK { ?s ?p ?o }"})
    for url in (base, base + "&default-graph-uri="):  # the front's plain request, and one it hands to Flask
        with pytest.raises(urllib.error.HTTPError) as refused:
            urllib.request.urlopen(url, timeout=30)
        assert refused.value.code == 503
        assert json.loads(refused.value.read())["error"] == "busy"
        assert refused.value.headers.get("Retry-After") == "1", url
