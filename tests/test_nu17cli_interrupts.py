"""Ctrl-C once a load's write has begun is held until the write (one transaction) ends, and said so; it
printed "Aborted!" over a load that was written all the same (new-user CLI repro 08)."""

from __future__ import annotations

import os
import signal
from pathlib import Path

import pytest
from click.testing import CliRunner

from cbrs.cli import cli
from cbrs.kb import KnowledgeBase
from cbrs.kb.store import EmbeddedStore


def test_ctrl_c_during_the_write_is_held_and_the_load_reported(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    data = tmp_path / "lab.ttl"
    data.write_text("@prefix lab: <https://example.org/lab#> .\nlab:a lab:b lab:c .\n", encoding="utf-8")
    add = EmbeddedStore.add

    def interrupted_add(self: EmbeddedStore, quads: object) -> None:
        os.kill(os.getpid(), signal.SIGINT)  # the user presses Ctrl-C while the transaction runs
        add(self, quads)  # type: ignore[arg-type]

    monkeypatch.setattr(EmbeddedStore, "add", interrupted_add)
    store = tmp_path / "store"
    before = signal.getsignal(signal.SIGINT)  # SIG_IGN where pytest was started in the background
    result = CliRunner().invoke(cli, ["--store", str(store), "load", str(data)])
    assert result.exit_code == 0, result.output
    assert "Ctrl-C while writing 1 triples" in result.stderr
    assert "the load stands" in result.stderr
    assert "added 1 triple into graph:services" in result.stdout
    assert signal.getsignal(signal.SIGINT) is before  # the command gives back the handler it found
    monkeypatch.setattr(EmbeddedStore, "add", add)
    kb = KnowledgeBase.open(store)
    try:
        assert kb.store.query("ASK { <https://example.org/lab#a> <https://example.org/lab#b> ?o }")
    finally:
        kb.close()


def test_ctrl_c_before_the_write_stops_the_load_and_writes_nothing(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    data = tmp_path / "lab.ttl"
    data.write_text("@prefix lab: <https://example.org/lab#> .\nlab:a lab:b lab:c .\n", encoding="utf-8")
    from cbrs.kb import loader

    def interrupted_check(*args: object, **kwargs: object) -> None:
        raise KeyboardInterrupt

    monkeypatch.setattr(loader, "check_loaded", interrupted_check)
    store = tmp_path / "store"
    result = CliRunner().invoke(cli, ["--store", str(store), "load", str(data)])
    assert result.exit_code == 1 and "Aborted!" in result.output
    monkeypatch.undo()
    kb = KnowledgeBase.open(store)
    try:
        assert not kb.store.query("ASK { <https://example.org/lab#a> ?p ?o }")
    finally:
        kb.close()
