"""A lab's own device, as docs/components.md's "A lab's own device" runs it: the kitchen scale of
docs/examples/lab_kitchen_scale.py in a child process, a speaker written with the SDK in this one,
both registered on a loopback server whose store has the examples' ontology, map and task loaded.
One run of TellMeMyCupsWeight through /cbrs/run_task: the arm puts the cup on the scale, the scale
weighs it, and the speaker is told the weight the scale answered."""

from __future__ import annotations

import importlib.util
import os
import re
import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path
from typing import TYPE_CHECKING, Any, cast

import pytest

from cbrs.actions.remote_errors import RemoteCallError
from cbrs.bridge_client import BridgeClient
from cbrs.component import Component
from cbrs.kb import KnowledgeBase
from cbrs.kb.namespaces import HOME, PREFIXES
from cbrs.server import ServeConfig, Server
from cbrs.sim_sensors import SensorsTakenError, provide_sensors
from cbrs.sparql_service import EndpointConfig
from tests.test_live_components import eventually

if TYPE_CHECKING:
    from cbrs.sim.world import HomeWorld

TOKEN = "lab-kitchen-scale-token"
EXAMPLES = Path(__file__).resolve().parents[1] / "docs" / "examples"
LAB = "https://example.org/lab#"
SCALE = LAB + "WeighObject_KitchenScale01"
WORLD = PREFIXES["world"]


@pytest.fixture(scope="module")
def server() -> Iterator[Server]:
    kb = KnowledgeBase.open(":memory:")
    kb.load([EXAMPLES / "lab_kitchen_scale.ttl"], graph="ontology")
    kb.load([EXAMPLES / "lab_kitchen_scale.ttl"], graph="map")
    kb.load([EXAMPLES / "lab_tell_me_my_cups_weight.ttl"], graph="requirements")
    endpoint = EndpointConfig(update_token=TOKEN, isolate=False)
    running = Server(kb, ServeConfig(port=0, bridge_port=0, endpoint=endpoint))
    running.start()
    try:
        yield running
    finally:
        running.stop()


def test_the_scale_s_weight_is_the_answer_and_reaches_the_speaker(server: Server) -> None:
    bridge = f"ws://127.0.0.1:{server.bridge_port}"
    program = [sys.executable, str(EXAMPLES / "lab_kitchen_scale.py"), "--bridge", bridge]
    scale = subprocess.Popen(program, env={**os.environ, "CBRS_UPDATE_TOKEN": TOKEN}, stderr=subprocess.PIPE)
    heard: list[dict[str, Any]] = []
    plate: list[dict[str, Any]] = []  # what the simulation's load cell under the plate read meanwhile
    speaker = Component((EXAMPLES / "lab_living_room_speaker.ttl").read_text(encoding="utf-8"))
    sensor = BridgeClient(bridge, TOKEN)

    @speaker.handler
    def announce(request: dict[str, Any]) -> dict[str, Any]:
        heard.append(request)
        plate.append(sensor.call_sync("/sim/load", {"place": LAB + "KitchenScale01Plate"}))
        return {}

    try:
        states = server.kb.liveness.states
        assert eventually(lambda: SCALE in states() and states()[SCALE].live, 20.0), "the scale never registered"
        with speaker.connect(bridge, TOKEN), BridgeClient(bridge, TOKEN, timeout=120.0) as client:
            run = client.call_sync("/cbrs/run_task", {"task": "TellMeMyCupsWeight"}, timeout=120.0)
    finally:
        sensor.close()
        scale.terminate()
        _, errors = scale.communicate(timeout=10)
    assert scale.returncode == 0, errors.decode()
    assert run["status"] == "succeeded", run
    result = run["result"]
    components = [step["component"] for step in result["plan"]["steps"]]
    weighing = components.index(SCALE)
    assert components.index(PREFIXES["svc"] + "PutDownObject_CytonDualArm01") < weighing
    assert components.index(LAB + "AnnounceWeight_LivingRoomSpeaker01") > weighing
    (mass,) = [row["value"].value for row in server.kb.select("map_facts") if _is_cup_mass(row)]
    (answer,) = result["answers"]
    assert answer["component"] == SCALE
    weight = answer["value"]
    assert weight == {"@type": HOME + "ObjectWeight", "object": WORLD + "Cup", "grams": weight["grams"]}
    # the scale read the physics (/sim/load), not the map: the plate bore the cup, and the reading is the
    # load its contacts bear (the simulated cup weighs its map mass and its 1 g water surface)
    (reading,) = plate
    assert reading["resting"] == [WORLD + "Cup"]
    assert weight["grams"] == round(reading["load_kg"] * 1000, 1) == pytest.approx(float(mass) * 1000, rel=0.01)
    assert heard == [{"weight": weight, "listener": {"@id": WORLD + "Person", "@type": HOME + "Person"}}]


def test_the_scale_refuses_an_empty_plate_and_another_plate() -> None:
    program = _example("lab_kitchen_scale")
    weigh = program.weigher(lambda: 0.04)  # the load cell reads next to nothing
    cup = {"object": {"@id": WORLD + "Cup"}, "plate": {"@id": program.PLATE}}
    with pytest.raises(program.EmptyPlateError, match=r"reads 0\.0 g: nothing is on it"):
        weigh(cup)
    with pytest.raises(ValueError, match="not on urn:other-plate"):
        program.weigher(lambda: 150.0)({**cup, "plate": {"@id": "urn:other-plate"}})
    assert program.weigher(lambda: 150.04)(cup)["weight"]["grams"] == 150.0


def test_the_simulation_s_sensors_answer_only_while_a_world_runs(server: Server) -> None:
    with BridgeClient(f"ws://127.0.0.1:{server.bridge_port}", TOKEN) as client:
        for service, args in (("/sim/load", {"place": "KitchenTable"}), ("/sim/capture", {"camera": "Kinect01"})):
            with pytest.raises(RemoteCallError, match=f"service '{service}' does not exist"):
                client.call_sync(service, args)


def test_one_world_at_a_time_answers_the_sensors_and_the_second_is_told_whose_they_are(
    server: Server, caplog: pytest.LogCaptureFixture
) -> None:
    """A cbrs run --bridge (here its provide_sensors) holds them against the server's run, and the other
    way round; neither waits, and the second runs on without offering its own (a run needs them only if
    a device reads the simulation). No world is simulated: neither side reads it."""
    world = cast("HomeWorld", object())
    bridge = f"ws://127.0.0.1:{server.bridge_port}"
    with BridgeClient(bridge, TOKEN) as client, BridgeClient(bridge, TOKEN) as other:
        with provide_sensors(client, world):
            holder = server.bridge.provider("/sim/load")
            assert holder is not None
            with caplog.at_level("WARNING", logger="cbrs.sim_sensors"), server.sensors.watching(world):
                assert server.bridge.provider("/sim/load") == server.bridge.provider("/sim/capture") == holder
            assert re.search(r"/sim/capture.*already provided by client.*does not offer its own", caplog.text)
            with pytest.raises(SensorsTakenError, match=r"client \d+ \(.*\) provides /sim/capture from a"):
                provide_sensors(other, world).__enter__()  # another cbrs run --bridge does not take them over
        with server.sensors.watching(world):  # withdrawn: the server's run takes them
            with pytest.raises(SensorsTakenError, match="provided by the server and cannot be advertised"):
                provide_sensors(client, world).__enter__()
            assert dict(server.bridge.services())["/sim/load"] == "cbrs/MeasureLoad"
        assert "/sim/load" not in dict(server.bridge.services())


def _example(name: str) -> Any:
    spec = importlib.util.spec_from_file_location(name, EXAMPLES / f"{name}.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def _is_cup_mass(row: Any) -> bool:
    return bool(row["thing"].value == WORLD + "Cup" and row["property"].value == HOME + "massKg")
