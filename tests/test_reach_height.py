"""The reach check before a run counts an object's height (sim/run_checks.py): an arm reaches as far up
and down as across, from its mount, so the mug on a wall cabinet's shelf 65 cm above the mounts
(docs/examples/wall_cabinet.ttl) is out of reach though 0.65 m away on the floor plan
(tests/test_blind_tasks3.py), and the same cabinet 30 cm above the mounts is within it."""

from __future__ import annotations

import math
from pathlib import Path

import pytest

from cbrs.sim.run_checks import PlanChecks
from cbrs.sim.sight import OutOfViewError
from tests.test_grasp_thin import refused_before_moving

EXAMPLES = Path(__file__).parent.parent / "docs" / "examples"


def test_the_distance_to_a_grasp_point_counts_its_height_above_the_mount() -> None:
    mount = (7.57, 2.55, 0.65)
    spot = (7.25, 7.25, 3.12, 3.12)
    across = math.hypot(7.25 - 7.57, 3.12 - 2.55)
    assert PlanChecks._distance(spot, None, mount) == pytest.approx(across)  # a place: the floor plan
    assert PlanChecks._distance(spot, 0.65, mount) == pytest.approx(across)  # level with the mount
    assert PlanChecks._distance(spot, 1.37, mount) == pytest.approx(math.hypot(across, 0.72))
    assert PlanChecks._distance(spot, -0.07, mount) == pytest.approx(math.hypot(across, 0.72))  # as far down


def test_a_mug_on_a_lower_cabinet_passes_the_reach_check(tmp_path: Path) -> None:
    """The shelf at 0.95 m: the grasp point 0.75 m from the left mount, within its 0.85 m; with the mug
    6.5 cm across (the example's 8 cm do not fit the jaws), what refuses the task then is a later check:
    the Kinect's, which cannot see that far west (the camera's advice is right for it, as it was not for
    the shelf at 1.30 m)."""
    lower = tmp_path / "wall_cabinet.ttl"
    text = (EXAMPLES / "wall_cabinet.ttl").read_text(encoding="utf-8")
    text = text.replace("home:minZ 1.25 ; home:maxZ 1.30", "home:minZ 0.90 ; home:maxZ 0.95")
    text = text.replace("home:sizeX 0.08 ; home:sizeY 0.08", "home:sizeX 0.065 ; home:sizeY 0.065")  # fits the jaws
    lower.write_text(text, encoding="utf-8")
    # refused by the check after the reach check's
    refused = refused_before_moving([lower], EXAMPLES / "mug_from_the_cabinet.ttl", "MugFromTheCabinet", OutOfViewError)
    assert "Mug1" in str(refused) and "Kinect01" in str(refused)
