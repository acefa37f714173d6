"""A failed staged write whose staging graphs could not be dropped says so, and how to drop them, all the
way to the command line (new-user CLI repro 02: the note was added to the error, and the CLI left it out)."""

from __future__ import annotations

from pathlib import Path

import pyoxigraph as ox
import pytest
from click.testing import CliRunner

from cbrs.cli import cli
from cbrs.kb import KnowledgeBase
from cbrs.kb.errors import StoreError
from cbrs.kb.staged_writes import STAGING, write_staged

QUADS = [
    ox.Quad(
        ox.NamedNode(f"https://example.org/lab#t{i}"),
        ox.NamedNode("https://example.org/lab#i"),
        ox.Literal(str(i)),
        ox.NamedNode("https://w3id.org/cbrs/graph/services"),
    )
    for i in range(5)
]


def _dying_server(sent: list[str]) -> object:
    """A send that takes the batches, then fails as a server that went away: the publication and every drop."""

    def send(text: str) -> None:
        if text.startswith("INSERT DATA"):
            sent.append(text)
            return
        raise StoreError("http://127.0.0.1:1", "request failed: Server disconnected")

    return send


def test_note_names_the_staging_graphs_and_the_update_that_drops_them() -> None:
    sent: list[str] = []
    with pytest.raises(StoreError) as caught:
        write_staged("http://127.0.0.1:1", QUADS, 2, _dying_server(sent))  # type: ignore[arg-type]
    assert len(sent) == 3
    (note,) = caught.value.__notes__
    stage = sent[0].split("GRAPH ", 1)[1].split(" ", 1)[0]
    assert stage.startswith(f"<{STAGING}")
    assert f"DROP SILENT GRAPH {stage}" in note


def test_cli_shows_the_note(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    data = tmp_path / "lab.ttl"
    data.write_text("@prefix lab: <https://example.org/lab#> .\nlab:a lab:b lab:c .\n", encoding="utf-8")

    def failing_load(self: KnowledgeBase, *args: object, **kwargs: object) -> None:
        error = StoreError("http://127.0.0.1:1", "request failed")
        error.add_note("the staging graphs <g> could not be dropped")
        raise error

    monkeypatch.setattr(KnowledgeBase, "load", failing_load)
    result = CliRunner().invoke(cli, ["--store", ":memory:", "load", str(data)])
    assert result.exit_code == 1
    assert "request failed; the staging graphs <g> could not be dropped" in result.output


def test_init_lists_a_staging_graph_left_behind(tmp_path: Path) -> None:
    store = tmp_path / "store"
    kb = KnowledgeBase.open(store)
    left = ox.NamedNode(f"{STAGING}0123/1")
    kb.store.add(
        [
            ox.Quad(
                ox.NamedNode("https://example.org/lab#a"),
                ox.NamedNode("https://w3id.org/cbrs/staged/x"),
                ox.Literal("1"),
                left,
            )
        ]
    )
    kb.close()
    result = CliRunner().invoke(cli, ["--store", str(store), "init"])
    assert result.exit_code == 0
    assert (
        f"{left.value}  1 triples (left by a write that failed: inert; the update DROP SILENT GRAPH {left} removes it)"
        in result.output
    )
