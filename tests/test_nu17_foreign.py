"""A component's registration describes that component only: a statement it makes about another
advertisement (a kitchen light's description giving the ceiling camera a second device name) is
refused whole, over the bridge as from Python, and the other advertisement stays as it was."""

from __future__ import annotations

import pytest

from cbrs.component import Component, RegistrationRefusedError
from cbrs.kb import KnowledgeBase
from cbrs.kb.errors import ForeignStatementError
from cbrs.kb.namespaces import PREFIXES
from cbrs.server import Server
from tests.test_live_components import READING, THERMOMETER, TOKEN, server, thermometer, url

__all__ = ["server"]  # the fixture, used by name

CAMERA = PREFIXES["svc"] + "LocateMobileRobot_CeilingCamera01"
RENAMES_THE_CAMERA = thermometer() + 'svc:LocateMobileRobot_CeilingCamera01 cbrs:deviceName "Thermometer07" .\n'
REPEATS_THE_CAMERA = thermometer() + 'svc:LocateMobileRobot_CeilingCamera01 cbrs:deviceName "CeilingCamera01" .\n'


def device_names(kb: KnowledgeBase, iri: str) -> list[str]:
    rows = kb.query(f"SELECT ?name WHERE {{ <{iri}> <{PREFIXES['cbrs']}deviceName> ?name }}")
    return sorted(str(row["name"].value) for row in rows)  # type: ignore[union-attr, index]


def test_a_live_registration_stating_something_of_another_advertisement_is_refused(server: Server) -> None:
    before = server.kb.store.count()
    made = Component(RENAMES_THE_CAMERA)
    made.handler(lambda request: READING)
    with pytest.raises(RegistrationRefusedError) as refused:
        made.connect(url(server), TOKEN)
    assert "LocateMobileRobot_CeilingCamera01" in refused.value.reason and "Thermometer07" in refused.value.reason
    assert server.kb.store.count() == before
    assert device_names(server.kb, CAMERA) == ["CeilingCamera01"]
    assert not server.kb.registry.is_registered(THERMOMETER)


def test_the_registry_refuses_it_from_python_too_and_lets_a_repeated_fact_pass() -> None:
    kb = KnowledgeBase.open(":memory:")
    with pytest.raises(ForeignStatementError) as refused:
        kb.registry.register(RENAMES_THE_CAMERA, "<registration>")
    assert refused.value.subject == CAMERA
    assert device_names(kb, CAMERA) == ["CeilingCamera01"]
    assert kb.registry.register(REPEATS_THE_CAMERA, "<registration>") == [THERMOMETER]  # it changes nothing
    assert device_names(kb, CAMERA) == ["CeilingCamera01"]
