"""The suite includes the static checks: ruff (lint and format) and mypy (strict types) over the packages."""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
PACKAGES = ["kb", "reasoner", "actions", "sim", "cbrs"]


@pytest.mark.slow
def test_ruff_is_clean() -> None:
    run = subprocess.run(
        [sys.executable, "-m", "ruff", "check", *PACKAGES, "tests", "bench"],
        cwd=ROOT,
        capture_output=True,
        text=True,
        check=False,
    )
    assert run.returncode == 0, run.stdout + run.stderr


@pytest.mark.slow
def test_ruff_format_is_clean() -> None:
    """The code, the example programs a lab copies from, and the README's Python, as ``ruff format`` leaves them."""
    run = subprocess.run(
        [sys.executable, "-m", "ruff", "format", "--check", *PACKAGES, "tests", "bench", "docs/examples"],
        cwd=ROOT,
        capture_output=True,
        text=True,
        check=False,
    )
    assert run.returncode == 0, run.stdout + run.stderr
    readme = (ROOT / "README.md").read_text(encoding="utf-8")
    blocks = re.findall(r"^```python\n(.*?)^```", readme, re.MULTILINE | re.DOTALL)
    assert blocks, "README.md has no Python block to check"
    for block in blocks:
        run = subprocess.run(
            [sys.executable, "-m", "ruff", "format", "--check", "--stdin-filename", "README.md.py", "-"],
            input=block,
            cwd=ROOT,
            capture_output=True,
            text=True,
            check=False,
        )
        assert run.returncode == 0, f"README.md's Python block is not formatted:\n{block}{run.stdout}{run.stderr}"


@pytest.mark.slow
def test_mypy_is_clean() -> None:
    run = subprocess.run([sys.executable, "-m", "mypy"], cwd=ROOT, capture_output=True, text=True, check=False)
    assert run.returncode == 0, run.stdout + run.stderr
