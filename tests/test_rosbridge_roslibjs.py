"""roslibjs (the npm package ``roslib``), unchanged, against the cbrs rosbridge server.

tests/js/roundtrip.mjs does the round trips in node and prints what it saw as JSON. Install its
dependencies once with ``npm ci --prefix tests/js``; without node or them, the test is skipped.
"""

from __future__ import annotations

import json
import shutil
import subprocess
import threading
from pathlib import Path
from typing import Any

import pytest

from cbrs.rosbridge import Bridge, ServiceError
from tests.helpers_threads import assert_threads_end

JS = Path(__file__).parent / "js"
NODE = shutil.which("node")


@pytest.mark.skipif(NODE is None, reason="node is not installed (roslibjs runs on node >= 20)")
@pytest.mark.skipif(
    not (JS / "node_modules" / "roslib").is_dir(), reason="roslibjs is not installed: run npm ci --prefix tests/js"
)
def test_roslibjs_round_trips() -> None:
    def refuse(args: dict[str, Any]) -> dict[str, Any]:
        raise ServiceError("the robot is busy")

    bridge = Bridge(call_timeout=5.0, params={"/robot/speed": 0.5})
    bridge.add_service("/test/add", "test/Add", lambda args: {"sum": args["a"] + args["b"]})
    bridge.add_service("/test/refuse", "test/Refuse", refuse)
    bridge.add_topic("/test/events", "test/Event")
    threads = threading.active_count()
    with bridge.start(port=0) as running:
        assert NODE is not None
        child = subprocess.run(
            [NODE, str(JS / "roundtrip.mjs"), str(running.port)], capture_output=True, text=True, timeout=60
        )
    assert child.returncode == 0, child.stderr
    assert json.loads(child.stdout.strip().splitlines()[-1]) == {
        "connected": True,
        "subscribed": True,
        "heard": ["one", "two", "three"],
        "topics": ["/chatter", "/test/events"],
        "topic_type": "std_msgs/String",
        "add": {"sum": 5},
        "refuse": {"failed": "the robot is busy"},
        "advertised": True,
        "upper": {"text": "HELLO"},
        "fold": {"failed": "Error: the arm is folded"},  # advertiseAsync's error text, relayed
        "service_type": "test/Upper",
        "param": {"k": [1, 2.5], "on": True},
        "params": ["/robot/speed", "/test/gain/k", "/test/gain/on"],
        "deleted": {"failed": "parameter '/test/gain' is not set"},  # roslibjs reads successful/reason
    }
    assert bridge.topics() == [("/test/events", "test/Event")]
    assert_threads_end(threads, 5.0)
