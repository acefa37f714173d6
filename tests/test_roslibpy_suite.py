"""roslibpy's own integration tests, unchanged, against a running cbrs server.

.ci/run fetches roslibpy's source distribution from PyPI into tests/.roslibpy (run the same pip
download by hand to have it locally). Its ROS 1 and ROS 2 tests expect a rosbridge server on 127.0.0.1:9090;
a cbrs server is started there and the tests that need nothing but a rosbridge server run in a
child process; ``LEFT_OUT`` names the others with their reasons.

Its ROS 2 action tests (``ros2/test_actions.py``) send goals to ``/fibonacci``, which in roslibpy's CI is
ROS's tutorial action server. Here a client of the bridge provides it (``advertise_action``), as ROS's
server behaves: feedback ``{sequence}`` growing from [0, 1] every ``FibonacciProvider.STEP`` seconds, the
sequence as the result, and a cancel honoured between steps.
"""

from __future__ import annotations

import json
import os
import re
import socket
import subprocess
import sys
import threading
from collections.abc import Iterator
from contextlib import ExitStack
from pathlib import Path
from typing import Any

import pytest
from websockets.exceptions import ConnectionClosed
from websockets.sync.client import connect

from cbrs.kb import KnowledgeBase
from cbrs.server import ServeConfig, Server
from cbrs.sparql_service import EndpointConfig

SDISTS = sorted((Path(__file__).parent / ".roslibpy").glob("roslibpy-*/tests"))
PORT = 9090  # what roslibpy's tests connect to
LEFT_OUT = {
    "test_tf.py": "needs ROS's tf2_web_republisher node",
    "test_action_preemt": "needs ROS message definitions: a preempted result filled with the type's defaults",
}


def _port_free() -> bool:
    with socket.socket() as probe:
        probe.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)  # as the server binds: TIME_WAIT is no user
        try:
            probe.bind(("127.0.0.1", PORT))
        except OSError:
            return False
    return True


class FibonacciProvider:
    """``/fibonacci`` (example_interfaces/action/Fibonacci) provided over the bridge, as ROS 2's tutorial
    action server computes it; a thread reads the bridge and one thread runs each goal."""

    STEP = 0.5  # seconds between feedbacks; roslibpy's cancel test cancels a 10-step goal after 2 s

    def __init__(self, url: str) -> None:
        self._closing = ExitStack()
        self._ws = self._closing.enter_context(connect(url, open_timeout=10, close_timeout=1))
        self._send_lock = threading.Lock()
        self._stop = threading.Event()
        self._cancelled: dict[str, threading.Event] = {}
        self._send(op="advertise_action", action="/fibonacci", type="example_interfaces/action/Fibonacci")
        self._send(op="call_service", service="/rosapi/action_servers", id="ready")
        while json.loads(self._ws.recv(timeout=10)).get("id") != "ready":  # advertised once this answer comes
            pass
        self._reader = threading.Thread(target=self._read, name="fibonacci-provider", daemon=True)
        self._reader.start()

    def close(self) -> None:
        self._stop.set()
        self._reader.join(10)
        self._closing.close()

    def _send(self, **message: Any) -> None:
        with self._send_lock:
            self._ws.send(json.dumps(message))

    def _read(self) -> None:
        while not self._stop.is_set():
            try:
                message = json.loads(self._ws.recv(timeout=0.2))
            except TimeoutError:
                continue
            except ConnectionClosed:
                return
            if message.get("op") == "send_action_goal":
                self._cancelled[message["id"]] = threading.Event()
                threading.Thread(target=self._run, args=(message,), daemon=True).start()
            elif message.get("op") == "cancel_action_goal" and message.get("id") in self._cancelled:
                self._cancelled[message["id"]].set()

    def _run(self, goal: dict[str, Any]) -> None:
        key, sequence = goal["id"], [0, 1]
        cancelled = self._cancelled[key]
        for i in range(1, int(goal["args"].get("order", 0))):
            if cancelled.is_set() or self._stop.is_set():
                self._send(
                    op="action_result",
                    id=key,
                    action="/fibonacci",
                    values={"sequence": sequence},
                    status=5,
                    result=True,
                )
                return
            sequence.append(sequence[i] + sequence[i - 1])
            self._send(op="action_feedback", id=key, action="/fibonacci", values={"sequence": sequence})
            cancelled.wait(self.STEP)
        self._send(
            op="action_result", id=key, action="/fibonacci", values={"sequence": sequence}, status=4, result=True
        )


@pytest.fixture
def server() -> Iterator[Server]:
    if not SDISTS:
        pytest.skip("roslibpy's sdist is not in tests/.roslibpy (.ci/run fetches it with pip download)")
    if not _port_free():
        pytest.skip(f"port {PORT}, which roslibpy's tests connect to, is in use")
    running = Server(
        KnowledgeBase.open(":memory:"),
        ServeConfig(port=0, bridge_port=PORT, endpoint=EndpointConfig(isolate=False)),
    )
    running.start()
    try:
        provider = FibonacciProvider(f"ws://127.0.0.1:{PORT}")
        try:
            yield running
        finally:
            provider.close()
    finally:
        running.stop()


def test_roslibpys_own_integration_tests_pass_against_cbrs(server: Server) -> None:
    folder = SDISTS[-1]
    tests = [*sorted(folder.glob("ros1/test_*.py")), *sorted(folder.glob("ros2/test_*.py")), *folder.glob("test_*.py")]
    files = [str(path) for path in tests if path.name not in LEFT_OUT]
    deselect = " and ".join(f"not {name}" for name in LEFT_OUT if not name.endswith(".py"))
    command = [sys.executable, "-m", "pytest", "-v", "-rA", "-p", "no:cacheprovider", "-k", deselect, *files]
    environment = {**os.environ, "ROSLIBPY_TRANSPORT": "twisted"}
    try:
        child = subprocess.run(command, cwd=folder.parent, capture_output=True, text=True, timeout=300, env=environment)
    except subprocess.TimeoutExpired as late:  # say which of roslibpy's tests it was in (22 s when all is well)
        shown = late.stdout.decode(errors="replace") if isinstance(late.stdout, bytes) else late.stdout or ""
        pytest.fail(f"roslibpy's tests did not end within 300 s; the last they printed: {shown[-3000:]}")
    summary = child.stdout.strip().splitlines()[-1] if child.stdout.strip() else child.stderr
    assert child.returncode == 0, child.stdout[-3000:] + child.stderr[-2000:]
    passed = re.search(r"(\d+) passed", summary)
    assert passed is not None and int(passed.group(1)) >= 40, summary
    for test in ("test_fibonacci", "test_cancel"):  # the ROS 2 action tests ran, and passed
        assert f"PASSED tests/ros2/test_actions.py::{test}" in child.stdout, child.stdout[-3000:]
