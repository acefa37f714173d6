"""While the server stands still (SIGSTOP, a suspended host, a call that holds the GIL) no heartbeat can
be read: the time is not charged to the leases of the components that beat all along, and their leases
are written to the store again at the next beat. Time that passes while the server runs is charged as
before. The lease clock is a stub moved by the test; the watchdog runs."""

from __future__ import annotations

from collections.abc import Iterator

import pytest

from cbrs.kb import KnowledgeBase
from cbrs.live_components import LiveComponents
from cbrs.sparql_service import EndpointConfig, SparqlService
from tests.test_live_components import THERMOMETER, TOKEN, thermometer


class Clock:
    def __init__(self) -> None:
        self.now = 1000.0

    def __call__(self) -> float:
        return self.now

    def run(self, seconds: float, live: LiveComponents) -> None:
        """Time passing while the server runs: its watchdog keeps looking every tenth of a second."""
        for _ in range(round(seconds * 10)):
            self.now += 0.1
            live.expire_lapsed()


@pytest.fixture
def live() -> Iterator[tuple[LiveComponents, Clock]]:
    clock = Clock()
    kb = KnowledgeBase.open(":memory:")
    components = LiveComponents(SparqlService(kb, EndpointConfig(update_token=TOKEN, isolate=False)), 3.0, clock=clock)
    components.start()
    try:
        components.register(thermometer(), "session 1", over_bridge=True)
        yield components, clock
    finally:
        components.stop()


def test_a_server_that_stood_still_does_not_lapse_the_leases_of_components_that_beat_meanwhile(
    live: tuple[LiveComponents, Clock],
) -> None:
    components, clock = live
    kb = components.sparql.kb
    written = kb.liveness.states()[THERMOMETER].lease_until
    clock.now += 5.0  # stopped for more than the lease: the beats sent meanwhile wait in the socket
    assert components.renew("session 1") == [THERMOMETER]  # the first beat read keeps the lease
    assert components.expire_lapsed() == []
    state = kb.liveness.states()[THERMOMETER]
    assert state.live and written is not None and state.lease_until is not None and state.lease_until > written


def test_time_the_server_runs_is_charged_as_before(live: tuple[LiveComponents, Clock]) -> None:
    components, clock = live
    clock.run(2.0, components)
    assert components.renew("session 1") == [THERMOMETER]
    clock.run(3.5, components)  # no beat for longer than the lease, the server running
    assert components.renew("session 1") == []
    assert components.sparql.kb.liveness.states()[THERMOMETER].reason == "its lease lapsed"


def test_a_renewal_writes_the_session_again_where_the_store_says_another(live: tuple[LiveComponents, Clock]) -> None:
    """A restore or an update to graph:liveness may name a session that is gone (docs/backup.md, "Live
    components"): the next renewal written to the store names the live one again."""
    components, clock = live
    kb = components.sparql.kb
    live_session = kb.liveness.states()[THERMOMETER].registered_by
    assert live_session is not None and live_session.endswith("session 1")
    kb.liveness.renew(THERMOMETER, 3.0, registered_by="cbrs session of a backup")
    clock.run(2.0, components)  # past half a lease: the next beat writes the lease
    assert components.renew("session 1") == [THERMOMETER]
    assert kb.liveness.states()[THERMOMETER].registered_by == live_session
