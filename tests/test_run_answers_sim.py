"""``cbrs run`` of a task that asks where the robot is prints the position a simulated localiser gave:
it printed the step table and "succeeded", and no position (the one simulation run of the answers'
tests; the stubs in test_run_answers_remote.py cover the rest)."""

from __future__ import annotations

from click.testing import CliRunner

from cbrs.cli import cli


def test_cbrs_run_robot_self_position_prints_the_position_it_found() -> None:
    result = CliRunner().invoke(cli, ["--store", ":memory:", "run", "RobotSelfPosition"])
    assert result.exit_code == 0, result.output
    verdict, heading, line = result.output.splitlines()[-3:]
    assert verdict.startswith("req:RobotSelfPosition: succeeded")
    assert heading == "Answer:"
    assert line.startswith('  selfPosition (home:RobotPosition) = {"@type": "home:RobotLocation", "x": ')
    assert '"theta": ' in line and line.endswith("from svc:LocateMobileRobot_CeilingCamera01 (step 1)")
