"""Docs that must stay true: every setting documented, the generated vocabulary current."""

from __future__ import annotations

from pathlib import Path

from cbrs.kb import _vocabgen
from cbrs.settings import SETTINGS

ROOT = Path(__file__).resolve().parents[1]


def test_every_setting_is_documented() -> None:
    text = (ROOT / "docs" / "settings.md").read_text(encoding="utf-8")
    for setting in SETTINGS:
        assert f"| `{setting.name}` | `{setting.env}` |" in text


def test_generated_vocabulary_is_current() -> None:
    assert _vocabgen.TARGET.read_text(encoding="utf-8") == _vocabgen.render(), (
        "kb/vocab.py is stale: run python -m cbrs.kb._vocabgen"
    )


def test_readme_quick_start_commands_are_what_ci_runs() -> None:
    readme = (ROOT / "README.md").read_text(encoding="utf-8")
    ci = (ROOT / ".ci" / "run").read_text(encoding="utf-8")
    test_command = next(line for line in readme.splitlines() if line.endswith(".venv/bin/pytest"))
    assert test_command in ci.splitlines()
