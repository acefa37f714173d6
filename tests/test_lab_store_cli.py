"""What a lab that keeps a store for months meets besides backups: a map load that parses its files once and
reads the stored map once per store state, a hint that fits the server a store URL points at, and the
progress of an OWLS-TC evaluation."""

from __future__ import annotations

import io
from pathlib import Path
from typing import Any

import pytest

from cbrs.kb import KnowledgeBase, loader
from cbrs.kb.errors import StoreError
from cbrs.kb.namespaces import expand
from cbrs.kb.remote_store import CBRS_SERVE_PORT, RemoteStore, start_hint
from cbrs.kb.semantic_map import MapError, SemanticMap
from cbrs.output import ProgressLine
from cbrs.reasoner import owlstc
from cbrs.settings import setting
from tests.test_nu17cli_map_load import MUG


def test_a_map_load_parses_each_file_once_and_reads_an_unchanged_map_once(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    kb = KnowledgeBase.open(":memory:")
    reads: list[str] = []
    maps: list[int] = []
    real_read, real_map = loader._read, SemanticMap.read

    def counted_read(path: Path, *args: Any, **kwargs: Any) -> Any:
        reads.append(path.name)
        return real_read(path, *args, **kwargs)

    def counted_map(knowledge_base: KnowledgeBase) -> SemanticMap:
        maps.append(1)
        return real_map(knowledge_base)

    monkeypatch.setattr(loader, "_read", counted_read)
    monkeypatch.setattr(SemanticMap, "read", staticmethod(counted_map))
    mug = tmp_path / "mug.ttl"
    mug.write_text(MUG.format(on="KitchenTabel"), encoding="utf-8")
    with pytest.raises(MapError):
        kb.load([mug], graph="map")
    assert (reads, len(maps)) == (["mug.ttl"], 2)  # the stored map, then with the file's triples
    mug.write_text(MUG.format(on="KitchenTable"), encoding="utf-8")
    reads.clear()
    maps.clear()
    assert kb.load([mug], graph="map").added_quads == 12
    assert (reads, len(maps)) == (["mug.ttl"], 1)  # nothing written since: the stored map is not read again
    reads.clear()
    maps.clear()
    kb.load([mug], graph="map")  # the last load wrote: the stored map is read afresh
    assert (reads, len(maps)) == (["mug.ttl"], 2)


@pytest.mark.parametrize(
    ("url", "says", "not_says"),
    [
        pytest.param("http://127.0.0.1:8080", "is the cbrs server running? Start one with: cbrs", None, id="bare-8080"),
        pytest.param("http://h:9000/sparql", "cbrs --store DIR serve --port 9000", "oxigraph", id="sparql-path"),
        pytest.param("http://h:7878", "oxigraph serve --location DIR --bind h:7878", "cbrs", id="oxigraph-port"),
        pytest.param("http://h:9999/query", "oxigraph serve", "cbrs", id="query-path"),
        pytest.param("http://h:8890/sparql", "is Virtuoso running", "oxigraph", id="virtuoso"),
        pytest.param("http://h:9999", "oxigraph serve", None, id="bare-other-port"),
    ],
)
def test_the_start_hint_fits_the_url(url: str, says: str, not_says: str | None) -> None:
    hint = start_hint(url)
    assert says in hint
    assert not_says is None or not_says not in hint


def test_the_hint_names_cbrs_serve_for_a_stopped_cbrs_server() -> None:
    assert setting("port").default() == CBRS_SERVE_PORT
    with pytest.raises(StoreError, match=r"cannot connect to http://127\.0\.0\.1:1/sparql .*cbrs --store DIR serve"):
        RemoteStore.open("http://127.0.0.1:1/sparql", timeout=2.0)


class _Terminal(io.StringIO):
    def isatty(self) -> bool:
        return True


def test_the_progress_line_shows_each_stage_on_a_terminal_only() -> None:
    terminal, piped = _Terminal(), io.StringIO()
    for stream in (terminal, piped):
        shown = ProgressLine(stream, interval=0.0)
        shown("logic (1/2): ranking for query", 3, 10)
        shown.clear()
    assert "logic (1/2): ranking for query 3/10" in terminal.getvalue() and piped.getvalue() == ""


REQUEST = """<request><uri>http://127.0.0.1/queries/1.1/{query}</uri><ratings>
<offer><uri>http://127.0.0.1/services/1.1/a.owls</uri><relevant>1</relevant></offer></ratings></request>"""


def test_an_owls_tc_evaluation_tells_each_load_stage_and_query(
    tmp_path: Path, bundled_kb: KnowledgeBase, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Two judged queries over the bundled store (its loading stood in for: the real one takes seconds)."""
    for part in ("services", "queries", "ontology"):
        (tmp_path / part).mkdir()
    requests = "".join(REQUEST.format(query=query) for query in ("q1.owls", "q2.owls"))
    relevance = f"<relevancegradeexport><binaryrelevanceset>{requests}</binaryrelevanceset></relevancegradeexport>"
    (tmp_path / "relevance.xml").write_text(relevance, encoding="utf-8")
    told: list[tuple[str, int, int]] = []

    def loaded(root: Path, progress: owlstc.Progress | None = None) -> owlstc.LoadedCollection:
        assert progress is not None
        progress("services: reading", 0, 1)
        ads = {"a.owls": [expand("svc:LocateMobileRobot_CeilingCamera01")]}
        reqs = {"q1.owls": [expand("req:RobotSelfPosition")], "q2.owls": [expand("req:FetchMyPen")]}
        return owlstc.LoadedCollection(bundled_kb, ads, reqs, 0, 0, 0.0)

    monkeypatch.setattr(owlstc, "load_collection", loaded)
    report = owlstc.evaluate_collection(tmp_path, ["string", "logic"], progress=lambda *stage: told.append(stage))
    assert report.queries == 2
    assert told[0] == ("services: reading", 0, 1)
    assert [item for item in told if "ranking" in item[0]] == [
        (f"{method} ({n}/2): ranking for query", done, 2)
        for n, method in ((1, "string"), (2, "logic"))
        for done in (0, 1)
    ]
