"""A command that makes the store it was pointed at says so, at a terminal (new-user CLI repro 15: a
mistyped store path gave a new store of the bundled data without a word)."""

from __future__ import annotations

from pathlib import Path

import pytest
from click.testing import CliRunner

from cbrs import cli_notes
from cbrs.cli import cli


def test_a_new_store_is_named_at_a_terminal(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(cli_notes, "_at_terminal", lambda: True)
    typo = tmp_path / "stroe"
    made = CliRunner().invoke(cli, ["--store", str(typo), "services"])
    assert made.exit_code == 0
    assert made.stderr == (
        f"note: there was no store at {typo}: a new one was made there, seeded with the bundled data "
        "(is the path right? cbrs init makes one on purpose)\n"
    )
    again = CliRunner().invoke(cli, ["--store", str(typo), "services"])
    assert again.stderr == ""
    initialised = CliRunner().invoke(cli, ["--store", str(tmp_path / "new"), "init"])
    assert initialised.stderr == ""


def test_nothing_said_to_a_script(tmp_path: Path) -> None:
    made = CliRunner().invoke(cli, ["--store", str(tmp_path / "fresh"), "services"])
    assert made.exit_code == 0 and made.stderr == ""
