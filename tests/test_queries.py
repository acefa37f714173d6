"""Every named query against a known answer (tests/data/queries/manifest.toml), and binding checks."""

from __future__ import annotations

import tomllib
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import pytest

from cbrs.kb import BindingError, KnowledgeBase, Store, UnknownQueryError
from cbrs.kb.namespaces import PREFIXES
from cbrs.kb.resources import ontology_dir, query_dir

from .conftest import BACKENDS, OxigraphServer

DATA = Path(__file__).parent / "data"
MANIFEST = tomllib.loads((DATA / "queries" / "manifest.toml").read_text(encoding="utf-8"))["case"]
TEST_PREFIXES = {**PREFIXES, "ex": "http://example.org/mini#"}

pytestmark = pytest.mark.both_stores


def _expand(value: str) -> str:
    prefix, sep, local = value.partition(":")
    if sep and prefix in TEST_PREFIXES and not local.startswith("/"):
        return TEST_PREFIXES[prefix] + local
    return value


def _normalise(value: str) -> str:
    # Aggregated IRI lists come back space-separated; compare them as sets.
    return " ".join(sorted(_expand(v) for v in value.split(" "))) if " " in value else _expand(value)


DataSet = tuple[tuple[str, ...], str | None]  # a case's data files and the graph they go into


def _data_set(case: dict[str, Any]) -> DataSet:
    return tuple(case["data"]), case.get("graph")


class KnownAnswerStores:
    """The cases' stores, each data set loaded once: the named queries only read. Embedded stores are
    kept; the remote one (a server of this module's own) holds the last data set asked for and is
    cleared and loaded again when another is asked for (the cases are ordered by data set)."""

    def __init__(self, start: Callable[..., OxigraphServer]) -> None:
        self._start = start
        self._embedded: dict[DataSet, KnowledgeBase] = {}
        self._server: OxigraphServer | None = None
        self._remote: tuple[DataSet, KnowledgeBase] | None = None

    def get(self, backend: str, data: DataSet) -> KnowledgeBase:
        if backend == "embedded":
            if data not in self._embedded:
                self._embedded[data] = self._load(":memory:", data)
            return self._embedded[data]
        if self._remote is None or self._remote[0] != data:
            if self._server is None:
                self._server = self._start(on_disk=False)
            if self._remote is not None:
                self._remote[1].close()
                self._remote = None
            self._server.clear()
            self._remote = data, self._load(self._server.url, data)
        return self._remote[1]

    @staticmethod
    def _load(location: str, data: DataSet) -> KnowledgeBase:
        kb = KnowledgeBase(Store.open(location))
        kb.load([ontology_dir() / "core.ttl"], graph="ontology")
        kb.load([DATA / name for name in data[0]], graph=data[1])
        return kb

    def close(self) -> None:
        for kb in [*self._embedded.values(), *([self._remote[1]] if self._remote else [])]:
            kb.close()
        if self._server is not None:
            self._server.stop()  # stopped by its PID now, not at the end of the session


@pytest.fixture(scope="module")
def known_answer_stores(oxigraph_servers: Callable[..., OxigraphServer]) -> Iterator[KnownAnswerStores]:
    stores = KnownAnswerStores(oxigraph_servers)
    yield stores
    stores.close()


@pytest.mark.parametrize(
    "case", [pytest.param(c, id=c["id"]) for c in sorted(MANIFEST, key=lambda c: repr(_data_set(c)))]
)
@pytest.mark.parametrize("backend", BACKENDS)
def test_named_query_known_answer(case: dict[str, Any], backend: str, known_answer_stores: KnownAnswerStores) -> None:
    kb = known_answer_stores.get(backend, _data_set(case))
    rows = kb.select(case["query"], {k: _expand(v) for k, v in case.get("bind", {}).items()})
    if "only_prefix" in case:  # the case lists only rows whose first variable starts with this
        first = next(iter(case["rows"][0]))
        rows = [row for row in rows if row[first].value.startswith(case["only_prefix"])]
    expected = case["rows"]
    keys = sorted({key for row in expected for key in row})
    got = sorted(tuple(_normalise(row[k].value) if k in row else "" for k in keys) for row in rows)
    want = sorted(tuple(_normalise(row.get(k, "")) for k in keys) for row in expected)
    if keys and any(all(v == "" for v in w) for w in want):
        raise AssertionError("a manifest row names no values")
    if not keys:
        assert rows == []
    else:
        # Variables a case leaves out of a row are not compared for that row.
        assert len(got) == len(want)
        for want_row in want:
            match = [g for g in got if all(w in ("", gv) for w, gv in zip(want_row, g, strict=True))]
            assert match, f"no result row matches {dict(zip(keys, want_row, strict=True))}; got {got}"
            got.remove(match[0])


def test_manifest_covers_every_named_query() -> None:
    covered = {case["query"] for case in MANIFEST}
    named = {path.stem for path in query_dir().glob("*.rq")}
    assert named - covered == set()


def test_every_query_projects_its_parameters(mini_kb: KnowledgeBase) -> None:
    # Oxigraph substitutes only projected variables; a declared parameter must be one.
    for name in mini_kb.queries.names():
        query = mini_kb.queries.get(name)
        head = query.text.split("WHERE", 1)[0]
        for parameter in query.parameters:
            assert f"?{parameter}" in head, f"{name}.rq does not project ?{parameter}"


def test_unknown_query_lists_the_known_ones(mini_kb: KnowledgeBase) -> None:
    with pytest.raises(UnknownQueryError, match="advertisements"):
        mini_kb.run("advertisement")


def test_unknown_parameter_is_refused(mini_kb: KnowledgeBase) -> None:
    with pytest.raises(BindingError, match="takes no such parameter"):
        mini_kb.run("advertisements", {"servce": "ex:Locate"})


def test_missing_required_parameter_is_refused(mini_kb: KnowledgeBase) -> None:
    with pytest.raises(BindingError, match="needs this parameter"):
        mini_kb.run("description")


@pytest.mark.parametrize("value", ["not an iri", ":x", "http://e/a b", "<http://e/>} ; DROP ALL ; {"])
def test_malformed_iri_binding_is_refused(mini_kb: KnowledgeBase, value: str) -> None:
    before = mini_kb.store.dump()
    with pytest.raises(BindingError):
        mini_kb.run("description", {"description": value})
    assert mini_kb.store.dump() == before


def test_bound_values_are_not_pasted_into_the_text(mini_kb: KnowledgeBase) -> None:
    # A literal full of SPARQL syntax binds as a plain value and matches nothing.
    rows = mini_kb.select("description", {"description": "http://e/x"})
    assert rows == []
    query = mini_kb.queries.get("description")
    assert "http://e/x" not in query.text


def test_the_texts_that_skip_the_checks_pass_them() -> None:
    """cbrs's own query texts skip the store's checks (kb.store.check_query); each would pass them."""
    from cbrs.kb.remote_access import refuse_remote_access
    from cbrs.kb.store import bundled_query_texts, refuse_deep_nesting

    texts = bundled_query_texts()
    assert len(texts) > len(list(query_dir().glob("*.rq")))  # the named queries and the entailment rules
    for text in texts:
        refuse_deep_nesting(text)
        refuse_remote_access(text, ())


def test_a_text_not_ours_is_still_checked() -> None:
    from cbrs.kb.remote_access import RemoteAccessError

    store = Store.open(":memory:")
    with pytest.raises(RemoteAccessError):
        store.check_query("SELECT * WHERE { SERVICE <http://example.org/sparql> { ?s ?p ?o } }")
