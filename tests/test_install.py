"""A plain (non-editable) install works from any directory: the bundled data travels with it."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]


@pytest.mark.slow
def test_plain_install_runs_from_another_directory(tmp_path: Path) -> None:
    venv = tmp_path / "venv"
    subprocess.run([sys.executable, "-m", "venv", str(venv)], check=True)
    pip = subprocess.run(
        [str(venv / "bin" / "pip"), "install", "-q", "--disable-pip-version-check", str(ROOT)],
        capture_output=True,
        text=True,
        check=False,
    )
    assert pip.returncode == 0, pip.stderr[-3000:]
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    env = {**os.environ, "CBRS_STORE": str(tmp_path / "store")}
    env.pop("PYTHONPATH", None)
    cbrs = str(venv / "bin" / "cbrs")

    init = subprocess.run([cbrs, "init"], cwd=elsewhere, env=env, capture_output=True, text=True, check=False)
    assert init.returncode == 0, init.stderr
    assert "advertisements" in init.stdout

    query = subprocess.run(
        [cbrs, "query", "--name", "advertisements", "--format", "json"],
        cwd=elsewhere,
        env=env,
        capture_output=True,
        text=True,
        check=False,
    )
    assert query.returncode == 0, query.stderr
    bindings = json.loads(query.stdout)["results"]["bindings"]
    by_service = {b["service"]["value"].rsplit("#", 1)[1]: b for b in bindings}
    locate = by_service["LocateMobileRobot_CeilingCamera01"]
    assert locate["inputs"]["value"].endswith("#MarkerColour")
    assert locate["outputs"]["value"].endswith("#RobotLocation")

    # The installed copy, not the checkout, answered.
    where = subprocess.run(
        [str(venv / "bin" / "python"), "-c", "import kb.resources as r; print(r.query_dir())"],
        cwd=elsewhere,
        env=env,
        capture_output=True,
        text=True,
        check=True,
    )
    assert str(venv) in where.stdout
