"""`cbrs run`'s progress lines (cbrs/cli_actions.py `_progress`): every event the runner publishes on
/cbrs/task_progress gets a line; the events that name no step (the bridge's components passed over after
their calls timed out, a base chosen) used to stop the text output with a KeyError."""

from __future__ import annotations

from cbrs.cli_actions import _progress
from cbrs.kb.namespaces import PREFIXES

SVC = PREFIXES["svc"]


def test_components_passed_over_are_said_one_a_line() -> None:
    line = _progress(
        {
            "event": "passed_over",
            "components": {SVC + "OpenDoor_Motor01": "3 calls timed out", SVC + "Beep_Buzzer01": "1 call timed out"},
        }
    )
    assert line.splitlines() == [
        "  passing over svc:Beep_Buzzer01: 1 call timed out",
        "  passing over svc:OpenDoor_Motor01: 3 calls timed out",
    ]


def test_an_event_with_no_step_is_said_as_it_is() -> None:
    assert _progress({"event": "paused", "reason": "asked"}) == "  paused: reason asked"


def test_a_step_event_keeps_its_form() -> None:
    started = {"event": "step_started", "step": 3, "component": SVC + "PickUpObject_CytonDualArm01"}
    assert _progress(started) == "  step  3  svc:PickUpObject_CytonDualArm01 ..."
