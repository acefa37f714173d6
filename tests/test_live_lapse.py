"""A live component whose lease lapses while it executes a call: the call fails at once, with why, as
when its provider disconnects; its late answer acts on nothing. Loopback only; every wait bounded."""

from __future__ import annotations

import threading
from typing import Any

import pytest

from cbrs.actions.remote import RemoteCallError
from cbrs.bridge_client import BridgeClient
from cbrs.server import Server
from cbrs.sim.services import SKILLS
from tests.test_live_components import READING, THERMOMETER, TOKEN, server, thermometer, url

__all__ = ["server"]  # the fixture, used by name


def test_a_call_in_flight_fails_when_its_components_lease_lapses(server: Server) -> None:
    release = threading.Event()

    def stuck(request: dict[str, Any]) -> dict[str, Any]:
        release.wait(10.0)  # a blocked driver: no answer while the lease runs out
        return READING

    with BridgeClient(url(server), TOKEN) as component, BridgeClient(url(server), TOKEN) as caller:
        component.provide("/thermometer07/read", "cbrs_msgs/RoomTemperature", stuck)
        # registered without heartbeats: its lease lapses after 0.5 s
        registered = component.call_sync("/cbrs/register", {"description": thermometer(), "ttl": 0.5})
        assert registered["components"] == [THERMOMETER]
        call = caller.call("/thermometer07/read", {}, timeout=20.0)
        try:
            with pytest.raises(RemoteCallError, match="lease lapsed while '/thermometer07/read' was executing"):
                call.result(timeout=5.0)  # well before the call's own 20 s
            assert not server.kb.liveness.states()[THERMOMETER].live
        finally:
            release.set()


def test_a_run_waits_for_a_component_whose_program_restarts_and_uses_it_again(
    server: Server, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The thermometer's program dies in the middle of its call and its supervisor starts it again a
    moment later: the re-plan waits for it (ReplanPolicy.reconnect_grace) instead of finding no plan. In a
    home where it is the only room thermometer: the bundled sensor board's simulated temperature
    (sim.room_quantities) would take the step over."""
    from cbrs.actions.composer import Composer
    from cbrs.actions.events import Event
    from cbrs.actions.runner import run_task
    from cbrs.kb.namespaces import PREFIXES
    from cbrs.kb.semantic_map import SemanticMap
    from cbrs.sim.components import SimEnvironment
    from cbrs.sim.world import open_world
    from tests.test_live_components import sdk_thermometer

    monkeypatch.delitem(SKILLS, "MeasureTemperature")
    kb, restarted = server.kb, threading.Event()
    first = BridgeClient(url(server), TOKEN)

    def dies(request: dict[str, Any]) -> dict[str, Any]:
        def crash_and_restart() -> None:
            first.close()  # the program is killed: its call fails "the provider ... disconnected"
            restarted.wait(0.5)  # the supervisor's delay
            program = sdk_thermometer().connect(url(server), TOKEN)
            programs.append(program)

        threading.Thread(target=crash_and_restart, daemon=True).start()
        release.wait(5.0)
        return READING

    release, programs, events = threading.Event(), [], []
    first.provide("/thermometer07/read", "cbrs_msgs/RoomTemperature", dies)
    # A lease long enough for building the world under load (no heartbeats here): it is the disconnect,
    # not a lapse, that the run must live through.
    first.call_sync("/cbrs/register", {"description": thermometer(), "ttl": 60.0})
    try:
        with open_world(semantic_map=SemanticMap.read(kb)) as world, BridgeClient(url(server), TOKEN) as bridge:
            result = run_task(
                kb,
                PREFIXES["req"] + "RoomTemperature",
                SimEnvironment(world, kb, bridge),
                composer=Composer(kb),
                on_event=lambda event: events.append(event.message) if isinstance(event, Event) else None,
            )
    finally:
        release.set()
        for program in programs:
            program.stop()
    assert result.succeeded, result.report
    assert len(result.replans) == 1 and "disconnected" in result.replans[0].reason
    awaited = [m for m in events if m.get("event") == "awaiting"]
    assert awaited and awaited[0]["components"] == [THERMOMETER]
