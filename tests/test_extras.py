"""Optional parts: a command that needs one that is not installed says which extra to install."""

from __future__ import annotations

import importlib.util
from typing import Any

import pytest
from click.testing import CliRunner

from cbrs.cli import cli
from cbrs.extras import EXTRAS, MissingExtraError, installed, require

_find_spec = importlib.util.find_spec


def without(monkeypatch: pytest.MonkeyPatch, *modules: str) -> None:
    """Make ``modules`` look uninstalled to the extras check."""

    def find_spec(name: str, *args: Any, **kwargs: Any) -> Any:
        return None if name in modules else _find_spec(name, *args, **kwargs)

    monkeypatch.setattr(importlib.util, "find_spec", find_spec)


def test_every_extra_is_installed_in_the_test_environment() -> None:
    assert all(installed(extra) for extra in EXTRAS)


def test_a_missing_extra_is_named_with_its_install_command(monkeypatch: pytest.MonkeyPatch) -> None:
    without(monkeypatch, "pybullet")
    assert not installed("sim")
    with pytest.raises(MissingExtraError, match=r"cbrs run needs the optional part \[sim\].*pip install 'cbrs\[sim\]'"):
        require("sim", "cbrs run")


def test_cbrs_run_and_plan_drawing_say_which_extra_they_need(monkeypatch: pytest.MonkeyPatch, tmp_path: Any) -> None:
    without(monkeypatch, "pybullet", "matplotlib")
    ran = CliRunner().invoke(cli, ["--store", ":memory:", "run", "FetchMyPen"])
    assert ran.exit_code != 0 and "pip install 'cbrs[sim]'" in ran.output
    drawn = CliRunner().invoke(cli, ["--store", ":memory:", "plan", "FetchMyPen", "--draw", str(tmp_path / "g.svg")])
    assert drawn.exit_code != 0 and "pip install 'cbrs[eval]'" in drawn.output
    matched = CliRunner().invoke(cli, ["--store", ":memory:", "match", "req:RobotSelfPosition"])
    assert matched.exit_code == 0, matched.output  # matchmaking needs no extra
