"""``cbrs plan TASK --no-store`` on a store, as the tests of its notes read it: the exit code and the text,
or the JSON of a plan."""

from __future__ import annotations

import json
from typing import Any

from click.testing import CliRunner

from cbrs.cli import cli


def plan(store: str, task: str, *more: str) -> tuple[int, str]:
    result = CliRunner().invoke(cli, ["--store", store, "plan", task, "--no-store", *more])
    return result.exit_code, result.output


def planned(store: str, task: str) -> dict[str, Any]:
    code, out = plan(store, task, "--json")
    assert code == 0, out
    found: dict[str, Any] = json.loads(out)
    return found
