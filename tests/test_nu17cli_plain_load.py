"""A large file of plain data loaded into a seeded store is parsed once and not indexed for descriptions
it has none of (new-user CLI: a 100 MB Turtle file took 5 min 40 s with no word; of 72 s for 600,000
triples, a wasted first pass took 4.7 s and building description indexes 8.9 s)."""

from __future__ import annotations

from pathlib import Path

import pytest

from cbrs.kb import KnowledgeBase, loader, shapes


def test_no_wasted_pass_or_index(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    data = tmp_path / "plain.ttl"
    data.write_text(
        "@prefix lab: <https://example.org/lab#> .\n" + "".join(f"lab:t{i} lab:index {i} .\n" for i in range(50)),
        encoding="utf-8",
    )
    monkeypatch.setattr(loader, "BULK_BYTES", 1)  # every file counts as large

    def refused(*args: object) -> object:
        raise AssertionError("called")

    monkeypatch.setattr(loader, "_scan", refused)  # every graph it could go to holds data: no bulk path
    monkeypatch.setattr(shapes, "quads_by_subject", refused)  # nothing with an OWLS model: no index
    kb = KnowledgeBase.open(":memory:")
    report = kb.load([data])
    assert report.added_quads == 50
