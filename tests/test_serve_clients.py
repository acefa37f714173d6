"""roslibpy and roslibjs, unchanged, against a running cbrs server: the knowledge base's own services.

Each client runs in a child process (roslibpy's reactor runs once per process; roslibjs runs in node):
this file, run as a script, is the roslibpy client; tests/js/cbrs_services.mjs is the roslibjs one.
Both print what they saw as one line of JSON, which the tests compare with the library's own answers.

    python tests/test_serve_clients.py PORT TOKEN

Running a task writes the store, so each client sends the update token with rosbridge's ``auth`` op
(``Ros.authenticate``, the token as its ``mac``); the roslibjs client is first refused without it.
"""

from __future__ import annotations

import json
import shutil
import subprocess
import sys
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

WAIT = 10.0
TOKEN = "clients-test-token"
JS = Path(__file__).parent / "js"
NODE = shutil.which("node")
QUERY = "SELECT ?d WHERE { ?s cbrs:deviceName ?d } ORDER BY ?d LIMIT 3"


def run_client(port: int, token: str) -> dict[str, Any]:
    """What a roslibpy user does with cbrs: list topics, query, match, run a task and follow it."""
    import roslibpy

    ros = roslibpy.Ros("127.0.0.1", port)
    ros.authenticate(token, "", "", "", 0, "", 0)  # sent when the connection is ready
    ros.run(timeout=WAIT)
    found: dict[str, Any] = {"topics": sorted(ros.get_topics())}
    progress: list[dict[str, Any]] = []
    roslibpy.Topic(ros, "/cbrs/task_progress", "cbrs/TaskProgress").subscribe(progress.append)
    time.sleep(0.3)  # the subscription travels before the run starts

    def call(service: str, kind: str, args: dict[str, Any], timeout: float = WAIT) -> dict[str, Any]:
        return dict(roslibpy.Service(ros, service, kind).call(roslibpy.ServiceRequest(args), timeout=timeout))

    rows = call("/cbrs/query", "cbrs/Query", {"query": QUERY})["result"]["results"]["bindings"]
    found["devices"] = [row["d"]["value"] for row in rows]
    found["best"] = call("/cbrs/match", "cbrs/Match", {"requirement": "RobotSelfPosition", "top": 1})["candidates"][0][
        "advertisement"
    ]
    run = call("/cbrs/run_task", "cbrs/RunTask", {"task": "RobotArmServeACup"}, timeout=120)
    found["run"] = run["status"]
    deadline = time.monotonic() + WAIT
    steps = len(run["result"]["plan"]["steps"])
    while sum(1 for p in progress if p["event"] == "step_succeeded") < steps and time.monotonic() < deadline:
        time.sleep(0.05)
    found["steps"] = steps
    found["progress"] = sum(1 for p in progress if p["event"] == "step_succeeded")
    found["heard"] = progress
    found["run_reply"] = run
    # the typedefs a form-building tool reads (roslibpy's blocking rosapi calls)
    found["match_request"] = ros.get_service_request_details("cbrs/Match")["typedefs"]
    found["run_response"] = ros.get_service_response_details("cbrs/RunTask")["typedefs"]
    found["progress_details"] = ros.get_message_details("cbrs/TaskProgress")["typedefs"]
    ros.close()
    return found


@pytest.fixture
def served(fresh_bundled_kb: Any) -> Iterator[tuple[int, Any]]:
    from cbrs.server import ServeConfig, Server
    from cbrs.sparql_service import EndpointConfig

    server = Server(fresh_bundled_kb, ServeConfig(port=0, bridge_port=0, endpoint=EndpointConfig(update_token=TOKEN)))
    server.start()
    yield server.bridge_port, fresh_bundled_kb
    server.stop(timeout=WAIT)


def expected(kb: Any) -> tuple[list[str], str]:
    from cbrs.kb.namespaces import expand
    from cbrs.reasoner.matchmaker import Matchmaker

    devices = [row["d"].value for row in kb.query(QUERY)]
    best = Matchmaker(kb).rank(expand("req:RobotSelfPosition")).candidates[0].advertisement
    return devices, best


def test_roslibpy_uses_the_knowledge_base_services(served: tuple[int, Any]) -> None:
    port, kb = served
    devices, best = expected(kb)
    child = subprocess.run([sys.executable, __file__, str(port), TOKEN], capture_output=True, text=True, timeout=180)
    assert child.returncode == 0, child.stderr
    found = json.loads(child.stdout.strip().splitlines()[-1])
    assert {"/cbrs/task_progress", "/cbrs/lifecycle", "/cbrs/task", "/cbrs/events"} <= set(found["topics"])
    assert found["devices"] == devices
    assert found["best"] == best
    assert found["run"] == "succeeded"
    assert found["progress"] == found["steps"] > 0
    from tests.test_rosapi_typedefs import cbrs_types, mismatches  # here: the child runs this file as a script

    types = cbrs_types()  # roslibpy reads the typedefs, and what it was sent is what they say
    assert found["match_request"] == types.request("cbrs/Match")
    assert found["run_response"] == types.response("cbrs/RunTask")
    assert found["progress_details"] == types.message("cbrs/TaskProgress")
    assert mismatches(found["run_response"], found["run_reply"]) == []
    assert [m for message in found["heard"] for m in mismatches(found["progress_details"], message)] == []


@pytest.mark.skipif(NODE is None, reason="node is not installed (roslibjs runs on node >= 20)")
@pytest.mark.skipif(
    not (JS / "node_modules" / "roslib").is_dir(), reason="roslibjs is not installed: run npm ci --prefix tests/js"
)
def test_roslibjs_uses_the_knowledge_base_services(served: tuple[int, Any]) -> None:
    port, kb = served
    devices, best = expected(kb)
    assert NODE is not None
    child = subprocess.run(
        [NODE, str(JS / "cbrs_services.mjs"), str(port), TOKEN], capture_output=True, text=True, timeout=180
    )
    assert child.returncode == 0, child.stderr
    found = json.loads(child.stdout.strip().splitlines()[-1])
    assert {"/cbrs/task_progress", "/cbrs/events"} <= set(found["topics"])
    assert found["devices"] == devices
    assert found["best"] == best
    assert found["run"] == "succeeded"
    assert found["progress"] == found["steps"] > 0
    assert found["refused"].startswith("missing field 'query'")
    assert "update token" in found["anonymous"]


if __name__ == "__main__":
    print(json.dumps(run_client(int(sys.argv[1]), sys.argv[2])), flush=True)
