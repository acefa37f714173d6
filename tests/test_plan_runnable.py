"""``cbrs plan`` says which of its steps ``cbrs run`` cannot run in the simulated home now (the runner's own
check, ``actions.runner.unrunnable_steps``), and which it reaches only over a bridge: the plan composes
over every advertisement, the run over those it can run. No simulation is run."""

from __future__ import annotations

from pathlib import Path

import pytest

from cbrs.kb import KnowledgeBase
from cbrs.kb.namespaces import PREFIXES
from tests.helpers_plan_cli import plan, planned

EXAMPLES = Path(__file__).resolve().parents[1] / "docs" / "examples"
LAB = "https://example.org/lab#"
SCALE = LAB + "WeighObject_KitchenScale01"
SPEAKER = LAB + "AnnounceWeight_LivingRoomSpeaker01"
LASER = {PREFIXES["svc"] + "StreamLaserScan_LaserScanner01", PREFIXES["svc"] + "DetectPersonByLaser_LaserScanner01"}


@pytest.fixture(scope="module")
def store(tmp_path_factory: pytest.TempPathFactory) -> str:
    """The caregiver in the bedroom (no tracker there: the laser scanner's components are planned for
    them) and the lab's kitchen scale and speaker, registered but not live."""
    location = str(tmp_path_factory.mktemp("plan_runnable") / "store")
    kb = KnowledgeBase.open(location)
    try:
        kb.load([EXAMPLES / "caregiver_in_the_bedroom.ttl"], graph="map")
        kb.load([EXAMPLES / "fetch_pen_for_caregiver.ttl"], graph="requirements")
        kb.load([EXAMPLES / "lab_kitchen_scale.ttl"], graph="ontology")
        kb.load([EXAMPLES / "lab_kitchen_scale.ttl"], graph="map")
        kb.load([EXAMPLES / "lab_tell_me_my_cups_weight.ttl"], graph="requirements")
        for name in ("lab_weigh_object.ttl", "lab_living_room_speaker.ttl"):
            kb.registry.register((EXAMPLES / name).read_text(encoding="utf-8"))
    finally:
        kb.close()
    return location


def test_a_plan_names_the_steps_the_simulation_has_no_skill_for(store: str) -> None:
    code, text = plan(store, "FetchPenForCaregiver")
    assert code == 0, text  # it is a plan; the notes say what the run will do about it
    for component in sorted(LASER):
        name = component.rsplit("#", 1)[1]
        (row,) = [line for line in text.splitlines() if line.split()[1:2] == [f"svc:{name}"]]
        step = row.split()[0]
        assert f"note: step {step} svc:{name} cannot run in the simulated home now: " in text
        assert f"no skill for its service name {name.split('_')[0]!r}" in text
    assert text.count("cbrs run plans without it") == len(LASER)


def test_a_component_in_another_process_counts_once_it_is_registered_live(store: str) -> None:
    found = planned(store, "TellMeMyCupsWeight")
    steps = {step["index"]: step["component"] for step in found["steps"]}
    assert {entry["component"] for entry in found["unrunnable"]} == {SCALE, SPEAKER}
    assert all(steps[entry["step"]] == entry["component"] for entry in found["unrunnable"])
    assert all("cbrs run --bridge" in entry["why"] for entry in found["unrunnable"])
    assert found["over_bridge"] == []
    _renew(store, live=True)  # as the lab's programs do when they register over the bridge
    try:
        live = planned(store, "TellMeMyCupsWeight")
        _, text = plan(store, "TellMeMyCupsWeight")
    finally:
        _renew(store, live=False)
    assert live["unrunnable"] == []  # the bundled components it plans are all simulated
    assert {entry["component"] for entry in live["over_bridge"]} == {SCALE, SPEAKER}
    assert "cannot run" not in text
    assert "lab:WeighObject_KitchenScale01 is a live component in another process" in text and "--bridge" in text


def _renew(store: str, live: bool) -> None:
    kb = KnowledgeBase.open(store)  # not while a command has it open: the store takes one process at a time
    try:
        for component in (SCALE, SPEAKER):
            if live:
                kb.liveness.renew(component, 600.0)
            else:
                kb.liveness.forget(component)
    finally:
        kb.close()
