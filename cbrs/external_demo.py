"""The ceiling cameras as programs of their own: FetchMyPen with one of them killed mid-run.

``cbrs demo --external`` (and ``tests/test_external_demo.py``): a server on loopback ports, the
simulated home offering its cameras' frames on the bridge, and one ``python -m cbrs.external_camera``
process per ceiling camera, which registers that camera's LocateMobileRobot component over the bridge
in place of the simulated one. When the run first asks the ``kill`` camera to locate the robot, that
process is killed with SIGKILL; the server sees its session close, marks it unavailable, and the
step fails over to the other camera.
"""

from __future__ import annotations

import os
import secrets
import signal
import subprocess
import sys
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass, field

from cbrs.actions.composer import Composer
from cbrs.actions.events import Event
from cbrs.actions.runner import RunResult, run_task
from cbrs.bridge_client import BridgeClient
from cbrs.external_camera import localisers
from cbrs.kb import KnowledgeBase
from cbrs.kb.semantic_map import SemanticMap
from cbrs.server import ServeConfig, Server
from cbrs.sim.components import SimEnvironment
from cbrs.sim.world import open_world
from cbrs.sparql_service import EndpointConfig

__all__ = ["IN_USE", "ExternalRun", "run_external_demo"]

IN_USE = "in use"
"""``kill=IN_USE``: kill whichever camera the run first asks to locate the robot."""
REGISTRATION_WAIT = 60.0
"""Seconds the camera programs have to start (import cbrs, seed their own knowledge) and register."""


@dataclass
class ExternalRun:
    """What happened: the run, the camera processes' ids, which was killed and how soon it was noticed."""

    pids: dict[str, int]
    lease: float
    result: RunResult | None = None
    killed: str | None = None
    detected_after: float | None = None
    """Seconds from the SIGKILL to the component being unavailable in the store."""
    log: list[str] = field(default_factory=list)


def run_external_demo(
    seed: int = 0, kill: str | None = IN_USE, lease: float = 1.0, say: Callable[[str], None] = print
) -> ExternalRun:
    """Run FetchMyPen on external cameras, killing ``kill``'s process at its first call (``IN_USE``: the
    first camera asked; None: none). The cameras are those of the semantic map with a LocateMobileRobot
    component."""
    kb = KnowledgeBase.open(":memory:")
    components = localisers(kb)
    for component in components.values():  # these run as programs of their own now
        kb.registry.deregister(component)
    token = secrets.token_urlsafe(16)
    endpoint = EndpointConfig(update_token=token, isolate=False)
    server = Server(kb, ServeConfig(port=0, bridge_port=0, endpoint=endpoint, component_lease=lease))
    processes: dict[str, subprocess.Popen[bytes]] = {}
    server.start()
    try:
        url = f"ws://127.0.0.1:{server.bridge_port}"
        with open_world(seed=seed, semantic_map=SemanticMap.read(kb)) as world, server.sensors.watching(world):
            environment = {**os.environ, "CBRS_UPDATE_TOKEN": token}
            for camera in sorted(components):
                command = [sys.executable, "-m", "cbrs.external_camera", camera, "--url", url]
                command += ["--heartbeat", str(lease / 3), "--lease", str(lease)]
                processes[camera] = subprocess.Popen(command, env=environment, stdout=subprocess.DEVNULL)
            started = ", ".join(f"{camera} (pid {process.pid})" for camera, process in processes.items())
            say(f"started {started}; waiting for them to register")
            _wait_registered(kb, components, processes)
            say("the cameras registered over the bridge; running FetchMyPen")
            run = ExternalRun({c: p.pid for c, p in processes.items()}, lease)
            watcher = _killer(kb, components, processes, kill, run, say) if kill else None
            with BridgeClient(url, token) as bridge:
                run.result = run_task(
                    kb, "FetchMyPen", SimEnvironment(world, kb, bridge), composer=Composer(kb), on_event=watcher
                )
            return run
    finally:
        for process in processes.values():  # stopped by their PID, whatever happened
            if process.poll() is None:
                process.kill()
            process.wait(timeout=10)
        server.stop()


def _wait_registered(
    kb: KnowledgeBase, components: dict[str, str], processes: dict[str, subprocess.Popen[bytes]]
) -> None:
    deadline = time.monotonic() + REGISTRATION_WAIT
    while time.monotonic() < deadline:
        states = kb.liveness.states()
        if all(components[c] in states and states[components[c]].live for c in processes):
            return
        dead = [c for c, p in processes.items() if p.poll() is not None]
        if dead:
            raise RuntimeError(f"the camera program of {', '.join(dead)} exited before it registered")
        time.sleep(0.05)
    raise TimeoutError(f"the camera programs did not register within {REGISTRATION_WAIT:g} s")


def _killer(
    kb: KnowledgeBase,
    components: dict[str, str],
    processes: dict[str, subprocess.Popen[bytes]],
    kill: str,
    run: ExternalRun,
    say: Callable[[str], None],
) -> Callable[[Event], None]:
    """An event handler that kills a camera's process when its component is first started: ``kill``'s,
    or with ``IN_USE`` the first camera's the run starts."""
    cameras = {component: camera for camera, component in components.items() if kill in (IN_USE, camera)}

    def on_event(event: Event) -> None:
        camera = cameras.get(str(event.message.get("component")))
        if run.killed or event.message.get("event") != "step_started" or camera is None:
            return
        run.killed = camera
        killed_at = time.monotonic()
        os.kill(processes[camera].pid, signal.SIGKILL)
        say(f"step {event.message.get('step')}: killed {camera} (pid {processes[camera].pid}) with SIGKILL")

        def watch() -> None:
            while time.monotonic() - killed_at < 10 * run.lease:
                state = kb.liveness.states().get(components[camera])
                if state is not None and not state.live:
                    run.detected_after = time.monotonic() - killed_at
                    say(f"{camera} unavailable after {run.detected_after * 1000:.0f} ms ({state.reason})")
                    return
                time.sleep(0.005)

        threading.Thread(target=watch, name="cbrs-demo-watch", daemon=True).start()

    return on_event
