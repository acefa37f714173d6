"""Follow-ups of the seventeenth blind round (docs/serving.md, "Tried by a lab's system administrator"):
what it left in files its helper did not own, each a test that failed before its fix."""

from __future__ import annotations

import sys

import pytest

from cbrs.app import App
from cbrs.cli import main
from cbrs.kb.errors import StoreError


def test_a_library_error_as_the_store_closes_is_an_error_not_an_internal_one(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    # A KnowledgeBaseError raised by the command's close (after its output) read "internal error", exit 2.
    def refuse(_: App) -> None:
        raise StoreError("/lab/store", "flushing it to disk failed: its disk is full")

    monkeypatch.setattr(App, "close", refuse)
    monkeypatch.setattr(sys, "argv", ["cbrs", "--store", ":memory:", "settings"])
    monkeypatch.delenv("CBRS_DEBUG", raising=False)
    with pytest.raises(SystemExit) as caught:
        main()
    assert caught.value.code == 1
    err = capsys.readouterr().err
    assert err == "Error: store /lab/store: flushing it to disk failed: its disk is full\n"
