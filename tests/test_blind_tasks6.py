"""The sixth round of tasks written from the docs alone (docs/examples/lab6_*, docs/tasks.md "A sixth round"):
a monitoring task served by the lab's own roslibpy program (a fridge door sensor and the resident's phone),
two things tidied onto a shelf in one run, the pen taken off the table (a delete effect) and fetched from the
shelf, and a newcomer's mistake with each. One run in the simulation (WatchTheFridge, its two remote steps);
the others are composed, refused at the load or called without a world. The failures this round found are
listed in docs/tasks.md, not pinned here."""

from __future__ import annotations

import os
import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path

import httpx
import pyoxigraph as ox
import pytest

from cbrs.actions.components import Status
from cbrs.actions.composer import Composer
from cbrs.actions.remote import RemoteComponent
from cbrs.actions.runner import run_task
from cbrs.bridge_client import BridgeClient
from cbrs.kb import KnowledgeBase
from cbrs.kb.errors import InvalidDescriptionError
from cbrs.kb.namespaces import PREFIXES, GraphName
from cbrs.kb.semantic_map import SemanticMap
from cbrs.server import Server
from cbrs.sim.components import SimEnvironment
from cbrs.sim.values import check
from cbrs.sim.world import open_world
from tests.helpers_examples import EXAMPLES
from tests.test_live_components import TOKEN, eventually, live_server

HOME, WORLD, SVC, LAB6 = PREFIXES["home"], PREFIXES["world"], PREFIXES["svc"], "https://example.org/lab6#"
SENSOR, PHONE = LAB6 + "CheckFridgeDoor_FridgeDoorSensor01", LAB6 + "AlertByPhone_ResidentPhone01"
CHECK = "/lab6_fridge_door_sensor_01/check"
KETTLE = LAB6 + "SwitchOnKettle_KettleSwitch01"


def _graph_sizes(kb: KnowledgeBase) -> dict[str, int]:
    rows = kb.query("SELECT ?g (COUNT(*) AS ?n) WHERE { GRAPH ?g { ?s ?p ?o } } GROUP BY ?g")
    assert isinstance(rows, ox.QuerySolutions)
    return {str(row["g"].value): int(row["n"].value) for row in rows if "liveness" not in str(row["g"].value)}


def _fridge_store(kb: KnowledgeBase, *, informs: bool = True) -> KnowledgeBase:
    for graph in ("ontology", "map"):
        kb.load([EXAMPLES / "lab6_fridge.ttl"], graph=graph)
    if informs:
        kb.load([EXAMPLES / "lab6_door_status_informs.ttl"], graph="ontology")
    kb.load([EXAMPLES / "lab6_watch_the_fridge.ttl"], graph="requirements")
    return kb


def _tidy_store(*requirements: str) -> KnowledgeBase:
    kb = KnowledgeBase.open(":memory:")
    for graph in ("ontology", "map"):
        kb.load([EXAMPLES / "lab6_tidy_shelf.ttl"], graph=graph)
    kb.load([EXAMPLES / name for name in requirements], graph="requirements")
    return kb


def _devices(server: Server, *options: str) -> subprocess.Popen[str]:
    """The lab's program as a child process, registered (a bounded wait), to be killed by its PID."""
    command = [
        sys.executable,
        str(EXAMPLES / "lab6_fridge_devices.py"),
        "--bridge",
        f"ws://127.0.0.1:{server.bridge_port}",
    ]
    env = {**os.environ, "CBRS_UPDATE_TOKEN": TOKEN}
    child = subprocess.Popen([*command, *options], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env)
    states = server.kb.liveness.states
    if not eventually(lambda: all(iri in states() and states()[iri].live for iri in (SENSOR, PHONE)), 20.0):
        child.kill()
        _, err = child.communicate(timeout=10)
        pytest.fail(f"the lab's program did not register: {err[-2000:]}")
    return child


def _stop(child: subprocess.Popen[str]) -> str:
    child.kill()  # stopped by its PID
    out, _ = child.communicate(timeout=10)
    return out


@pytest.fixture(scope="module")
def server() -> Iterator[Server]:
    with live_server() as running:
        _fridge_store(running.kb)
        yield running


def test_the_fridge_is_watched_by_the_labs_roslibpy_program(server: Server) -> None:
    """The sensor and the phone register from a program with no cbrs in it; WatchTheFridge is planned onto
    them, the sensor's answer is the run's answer, the phone sends the alert,
    which is not kept in the belief (tests/test_alert_not_kept.py)."""
    child = _devices(server)
    try:
        kb = server.kb
        plan = Composer(kb).compose("WatchTheFridge").plan
        assert plan is not None and plan.components() == [SENSOR, PHONE]
        url = f"ws://127.0.0.1:{server.bridge_port}"
        with open_world(seed=0, semantic_map=SemanticMap.read(kb)) as world, BridgeClient(url, TOKEN) as bridge:
            result = run_task(kb, "WatchTheFridge", SimEnvironment(world, kb, bridge), composer=Composer(kb))
        assert result.succeeded, result.report.reason if result.report else result.composition.unsatisfied
        [answer] = result.answers
        assert answer.value["@type"] == HOME + "Opened"
        # an alert is no lasting state of the person: not believed on the phone's word, nor kept (an alert-only
        # task would have had "nothing to do" the next time), as the speaker's inform of components.md
        assert [(goal.believed, goal.holds) for goal in result.goals] == [(None, None)]
        alerted = f"ASK {{ GRAPH <{GraphName.WORLD.iri}> {{ ?person <{LAB6}isAlertedOf> ?what }} }}"
        assert not bool(kb.query(alerted))
    finally:
        out = _stop(child)
    assert "phone: ALERT the fridge door is Opened" in out


def test_without_the_labs_mark_the_living_room_phone_serves_the_kitchen_fridge() -> None:
    """home.ttl marks home:Status to inform (a status is an observation's result), so a door's status given to
    the phone does not tie it to the fridge: the lab's own mark is no longer needed (tests/test_area_why.py
    has the refusal with the status made to lead, naming the input that leads)."""
    kb = _fridge_store(KnowledgeBase.open(":memory:"), informs=False)
    kb.registry.register((EXAMPLES / "lab6_fridge_door_sensor.ttl").read_text())
    kb.registry.register((EXAMPLES / "lab6_caregiver_phone.ttl").read_text())
    plan = Composer(kb).compose("WatchTheFridge").plan
    assert plan is not None and plan.components() == [SENSOR, PHONE]


@pytest.mark.parametrize(("misbehave", "says"), [("wrong-type", "wrong fridgeDoor"), ("silent", "did not answer")])
def test_a_sensor_that_answers_the_wrong_type_or_never_fails_its_call_and_writes_nothing(
    server: Server, misbehave: str, says: str
) -> None:
    child = _devices(server, "--misbehave", misbehave)
    before = _graph_sizes(server.kb)
    try:
        url = f"ws://127.0.0.1:{server.bridge_port}"
        with BridgeClient(url, TOKEN) as bridge:
            component = RemoteComponent(SENSOR, bridge, CHECK, {"fridgeDoor": HOME + "DoorStatus"}, check, 1.0)
            component.begin({"fridge": {"@id": LAB6 + "Fridge1", "@type": HOME + "Refrigerator"}})
            status = Status.RUNNING
            for _ in range(5000):  # ticks of at most a few milliseconds each
                status = component.update()
                if status is not Status.RUNNING:
                    break
        assert status is Status.FAILED and says in component.reason, component.reason
    finally:
        _stop(child)
    assert _graph_sizes(server.kb) == before


def test_a_sensor_whose_output_nobody_takes_leaves_no_plan_and_a_typo_is_refused_at_the_load() -> None:
    kb = _fridge_store(KnowledgeBase.open(":memory:"))
    kb.registry.register((EXAMPLES / "lab6_mistake_sensor_output.ttl").read_text())
    kb.registry.register((EXAMPLES / "lab6_caregiver_phone.ttl").read_text())
    composition = Composer(kb).compose("WatchTheFridge")
    assert composition.plan is None and composition.unsatisfied
    before = _graph_sizes(kb)
    with pytest.raises(InvalidDescriptionError, match="did you mean home:Refrigerator"):
        kb.load([EXAMPLES / "lab6_mistake_watch_the_fridgge.ttl"], graph="requirements")
    assert _graph_sizes(kb) == before


def test_the_browser_writes_the_requirement_and_refuses_typos(server: Server) -> None:
    """The match form takes the task as written (it ranks, it does not store); a misspelt task started from
    the tasks form and a misspelt class in a Graph Store POST are refused, naming the right one."""
    base = f"http://127.0.0.1:{server.http_port}"
    with httpx.Client(base_url=base, timeout=30) as client:
        written = {"inputs": "home:Refrigerator home:Person", "outputs": "home:DoorStatus"}
        effect = "home:Person lab6:isAlertedOf home:DoorStatus"
        ranked = client.get("/match.json", params={**written, "effects": effect})
        assert ranked.status_code == 200 and ranked.json()["rankings"], ranked.text
        typo = client.get("/match.json", params={"inputs": "home:Refridgerator"})
        assert typo.status_code == 400 and "did you mean home:Refrigerator" in typo.text
        started = client.post("/tasks", data={"task": "WatchTheFrige", "seed": "0"}, headers={"Origin": base})
        assert started.status_code == 400 and "did you mean WatchTheFridge" in started.text
        before = _graph_sizes(server.kb)
        stored = client.post(
            "/store",
            params={"graph": PREFIXES["graph"] + "requirements"},
            content=(EXAMPLES / "lab6_mistake_watch_the_fridgge.ttl").read_bytes(),
            headers={"Authorization": f"Bearer {TOKEN}", "Content-Type": "text/turtle"},
        )
        assert stored.status_code == 400 and "did you mean home:Refrigerator" in stored.text
        assert _graph_sizes(server.kb) == before


def test_two_things_to_the_shelf_are_planned_as_two_takes_and_a_typo_in_the_shelf_is_refused(tmp_path: Path) -> None:
    kb = _tidy_store("lab6_tidy_pen_and_eraser.ttl")
    plan = Composer(kb).compose("TidyPenAndEraser").plan
    assert plan is not None
    subjects = sorted(str(goal.statement.subject) for goal in plan.goals if goal.statement is not None)
    assert subjects == [LAB6 + "Eraser", HOME + "Pen"]
    typo = (EXAMPLES / "lab6_tidy_pen_and_eraser.ttl").read_text().replace("lab6:TidyShelf ]", "lab6:TidyShelff ]")
    (tmp_path / "typo.ttl").write_text(typo, encoding="utf-8")
    kb = _tidy_store()
    before = _graph_sizes(kb)
    with pytest.raises(InvalidDescriptionError, match=r"TidyShelff is declared nowhere .*did you mean .*TidyShelf"):
        kb.load([tmp_path / "typo.ttl"], graph="requirements")
    assert _graph_sizes(kb) == before


def test_the_pen_off_the_table_is_planned_the_pick_up_deleting_it() -> None:
    """A delete effect is a goal (tests/test_delete_goals.py): (Pen, isLocatedOn, Table), beside an effect
    or alone, is met by the pick-up, which deletes where the object stood (a place or a piece of furniture)."""
    kb = _tidy_store("lab6_pen_off_the_table.ttl", "lab6_mistake_delete_only.ttl")
    for task in ("ClearPenOffTheTable", "PenNotOnTheTable"):
        plan = Composer(kb).compose(task).plan
        assert plan is not None, task
        goals = {str(g.statement): plan.step(g.source.step or 0).component for g in plan.goals if g.role == "deletion"}
        assert list(goals.values()) == [SVC + "PickUpObject_CytonDualArm01"], task


def test_the_kettle_written_with_plain_websockets_registers_plans_and_answers(server: Server) -> None:
    """The protocol followed word for word (auth, register, advertise, heartbeats): SwitchOnTheKettle is
    planned onto it and its call answers the kettle switched on."""
    kb = server.kb
    for graph in ("ontology", "map"):
        kb.load([EXAMPLES / "lab6_kettle.ttl"], graph=graph)
    kb.load([EXAMPLES / "lab6_switch_on_the_kettle.ttl"], graph="requirements")
    url = f"ws://127.0.0.1:{server.bridge_port}"
    command = [sys.executable, str(EXAMPLES / "lab6_kettle.py"), "--bridge", url]
    env = {**os.environ, "CBRS_UPDATE_TOKEN": TOKEN}
    child = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env)
    try:
        states = kb.liveness.states
        assert eventually(lambda: KETTLE in states() and states()[KETTLE].live, 20.0)
        plan = Composer(kb).compose("SwitchOnTheKettle").plan
        assert plan is not None and plan.components() == [KETTLE]
        with BridgeClient(url, TOKEN) as bridge:
            outputs = {"kettleStatus": HOME + "DeviceStatus"}
            component = RemoteComponent(KETTLE, bridge, "/lab6_kettle_switch_01/switch_on", outputs, check, 5.0)
            component.begin({"kettle": {"@id": LAB6 + "Kettle1", "@type": LAB6 + "Kettle"}})
            status = Status.RUNNING
            for _ in range(5000):  # ticks of at most a few milliseconds each
                status = component.update()
                if status is not Status.RUNNING:
                    break
        assert status is Status.SUCCEEDED, component.reason
        assert component.outputs["kettleStatus"]["@type"] == HOME + "SwitchedOn"
    finally:
        out = _stop(child)
    assert "kettle: switched on" in out
