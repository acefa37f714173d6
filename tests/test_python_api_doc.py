"""docs/execution.md's "A task run from Python" works as written: its Python block, taken from the page and
run from the checkout (its one simulation run: WhereIsMyPen, under a simulated second), prints the run's
success and the pen's position; and the names it imports are the package's public ones."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

import cbrs.actions

ROOT = Path(__file__).resolve().parents[1]
PAGE = (ROOT / "docs" / "execution.md").read_text(encoding="utf-8")


def _block(heading: str) -> str:
    """The first Python block under ``heading`` (as tests/test_readme.py finds the README's blocks)."""
    section = PAGE.split(heading + "\n", 1)[1].split("\n#", 1)[0]
    found = re.search(r"^```python\n(.*?)^```", section, re.MULTILINE | re.DOTALL)
    assert found is not None, f"no python block under {heading!r}"
    return found.group(1)


SNIPPET = _block("### A task run from Python")


def test_the_snippet_imports_public_names() -> None:
    imported = set(re.findall(r"^from cbrs\.actions import (.+)$", SNIPPET, re.MULTILINE)[0].split(", "))
    assert imported <= set(cbrs.actions.__all__)


def test_the_snippet_runs_a_task(monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]) -> None:
    monkeypatch.chdir(ROOT)  # it reads docs/examples/ from the checkout; its store is in memory
    exec(compile(SNIPPET, "docs/execution.md", "exec"), {})
    first, *answers = capsys.readouterr().out.splitlines()
    assert first.startswith("succeeded in ")
    (answer,) = answers
    name, x, y = answer.split()
    assert name == "penPosition"
    assert 0.0 < float(x) < 10.0 and 0.0 < float(y) < 9.0  # within the home's plan
