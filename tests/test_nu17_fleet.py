"""Two servers of a fleet on one store: a component live through one is refused through the other, as a
second copy of its program on the same server is, so that neither server marks the other's live
component unavailable when its own copy goes."""

from __future__ import annotations

import pytest

from cbrs.component import RegistrationRefusedError
from cbrs.server import Server
from tests.test_fleet import TOKEN, fleet
from tests.test_live_components import THERMOMETER, eventually, sdk_thermometer, url

__all__ = ["fleet"]  # the fixture, used by name


def test_a_component_live_through_one_server_is_refused_through_another(fleet: tuple[Server, Server]) -> None:
    first, second = fleet
    with sdk_thermometer().connect(url(first), TOKEN):
        with pytest.raises(RegistrationRefusedError, match="running twice"):
            sdk_thermometer().connect(url(second), TOKEN)
        assert second.kb.liveness.states()[THERMOMETER].live
    assert eventually(lambda: not second.kb.liveness.states()[THERMOMETER].live)
    with sdk_thermometer().connect(url(second), TOKEN) as again:  # once it went, it registers anywhere
        assert again.registered == [THERMOMETER]
