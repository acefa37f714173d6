"""The requests a plan and a run make against a remote store: a description, every advertisement, the
taxonomy, the action library and the map are read with one request each, the belief graph is written
with one, and the answers are those of the separate queries (docs/remote-store.md, "Requests of a plan
and a run"). Counting requests is deterministic: no timing here (bench/remote_run.py times them)."""

from __future__ import annotations

import collections
from collections.abc import Callable, Iterator
from typing import Any

import pyoxigraph as ox
import pytest
from click.testing import CliRunner

from cbrs.actions.belief import STATE, BeliefState, Observation
from cbrs.cli import cli
from cbrs.kb import GraphName, KnowledgeBase
from cbrs.kb.descriptions import PER_DESCRIPTION
from cbrs.kb.errors import NotFoundError
from cbrs.kb.queries import QueryLibrary
from cbrs.kb.remote_store import RemoteStore, _order_keys, union_of_selects
from cbrs.kb.resources import query_dir
from cbrs.kb.semantic_map import designate, designate_each
from cbrs.kb.store import EmbeddedStore
from cbrs.kb.update_delta import DataUpdate, data_operations
from cbrs.kb.vocab import CBRS
from tests.conftest import OxigraphServer

LOCATE = "https://w3id.org/cbrs/service#LocateMobileRobot_CeilingCamera01"
FETCH = "https://w3id.org/cbrs/requirement#FetchMyPen"
HOME = "https://w3id.org/cbrs/home#"


@pytest.fixture(scope="module")
def served(oxigraph_servers: Callable[..., OxigraphServer]) -> OxigraphServer:
    """A server of this module's own, seeded once (the session's is cleared before other tests)."""
    server = oxigraph_servers(on_disk=False)
    KnowledgeBase.open(server.url).close()
    return server


@pytest.fixture
def remote(served: OxigraphServer) -> Iterator[KnowledgeBase]:
    kb = KnowledgeBase.open(served.url)
    yield kb
    kb.close()


class Requests:
    """The requests a remote store sends, by kind: a named query asked alone by its name, else
    ``combined``, ``other`` or ``update``."""

    def __init__(self, kb: KnowledgeBase) -> None:
        self.kinds: collections.Counter[str] = collections.Counter()
        names = {kb.queries.get(name).text: name for name in kb.queries.names()}
        store = kb.store
        assert isinstance(store, RemoteStore)
        post = store._post

        def counted(url: str, body: str, content_type: str, original: str | None, *args: Any, **kw: Any) -> Any:
            if content_type == "application/sparql-update":
                self.kinds["update"] += 1
            elif original in names:
                self.kinds[names[original]] += 1
            else:
                self.kinds["combined" if "cbrs__part" in body else "other"] += 1
            return post(url, body, content_type, original, *args, **kw)

        store._post = counted  # type: ignore[method-assign]

    @property
    def total(self) -> int:
        return sum(self.kinds.values())


def test_a_description_is_read_from_the_store_in_one_request_as_the_embedded_store_reads_it(
    remote: KnowledgeBase, bundled_kb: KnowledgeBase
) -> None:
    remote.description(LOCATE)  # the part trees of the concepts, read once per knowledge base (concept_parts)
    for iri in (LOCATE, FETCH):
        sent = Requests(remote)
        assert remote.description(iri) == bundled_kb.description(iri)
        assert sent.kinds == {"combined": 1}


BENCH_CAMERA = """@prefix cbrs: <https://w3id.org/cbrs/core#> . @prefix home: <https://w3id.org/cbrs/home#> .
<https://w3id.org/cbrs/service#RequestsCamera> a cbrs:DynamicPerceptionComponent ;
    cbrs:deviceName "RequestsCamera" ; cbrs:serviceName "LocateMobileRobot" ;
    cbrs:hasOWLSModel [ cbrs:hasInput [ cbrs:parameterType home:MarkerColour ] ;
                        cbrs:hasOutput [ cbrs:parameterType home:RobotLocation ] ] .
"""


def test_a_description_deregistered_meanwhile_is_not_found_by_the_next_read(remote: KnowledgeBase) -> None:
    """Read again each time, in one request: a run reads a step's description after the step, so a
    component deregistered mid-run is noticed (its effects are not believed)."""
    (iri,) = remote.registry.register(BENCH_CAMERA)
    assert remote.description(iri).outputs[0].type == HOME + "RobotLocation"
    remote.registry.deregister(iri)
    sent = Requests(remote)
    with pytest.raises(NotFoundError):
        remote.description(iri)
    assert sent.kinds == {"combined": 1}


def test_every_advertisement_is_read_with_three_requests(remote: KnowledgeBase, bundled_kb: KnowledgeBase) -> None:
    remote.description(LOCATE)  # the part trees, read once per knowledge base
    sent = Requests(remote)
    assert remote.advertisements() == bundled_kb.advertisements()
    assert sent.kinds == {"advertisements": 1, "other": 1, "combined": 1}  # the other: the components' liveness


TOGETHER = (
    "taxonomy_links",
    "taxonomy_terms",
    "concept_usage",
    "taxonomy_disjoint",
    "actions",
    "action_ordering",
    "map_facts",
    "map_types",
    "world_positions",
)


def test_queries_asked_together_give_the_rows_and_order_each_gives_alone(remote: KnowledgeBase) -> None:
    """The queries the readers ask together (aggregates, GROUP_CONCAT, ORDER BY or none), and two more."""
    free = [*TOGETHER, "advertisements", "requirements"]
    assert all(union_of_selects([remote.queries.get(name).text]) is not None for name in free)
    alone = [remote.select(name) for name in free]
    sent = Requests(remote)
    together = remote.select_each(free)
    assert sent.kinds == {"combined": 1}
    for name, rows, expected in zip(free, together, alone, strict=True):
        assert _rows(rows) == _rows(expected), name
        keys = [key.variable.lstrip("?") for key in _order_keys(remote.queries.get(name).text) or []]
        assert [[row.get(key) for key in keys] for row in rows] == [[row.get(key) for key in keys] for row in expected]
    bound = {"description": LOCATE}
    assert remote.select_each(PER_DESCRIPTION, bound) == [remote.select(name, bound) for name in PER_DESCRIPTION]


def _rows(rows: list[dict[str, Any]]) -> list[str]:
    """The rows in an order of their own: a query without ORDER BY has none, and ties are in any order."""
    return sorted(repr(sorted((name, str(term)) for name, term in row.items())) for row in rows)


@pytest.mark.parametrize(
    "text",
    [
        pytest.param("ASK { ?s ?p ?o }", id="ask"),
        pytest.param("PREFIX x: <http://example.org/> SELECT ?s WHERE { ?s ?p x:o }", id="own-prefix"),
        pytest.param("SELECT ?s WHERE { ?s ?p ?o } ORDER BY DESC(UCASE(STR(?s)))", id="order-by-expression"),
        # ?o over IRIs only: Oxigraph's server once panicked sorting the whole store's mixed literals
        pytest.param("SELECT ?s WHERE { ?s a ?o } ORDER BY ?o", id="order-by-unprojected"),
        pytest.param("SELECT ?cbrs__x WHERE { ?cbrs__x ?p ?o }", id="own-variable"),
    ],
)
def test_a_query_that_cannot_be_a_branch_is_asked_alone(remote: KnowledgeBase, text: str) -> None:
    assert union_of_selects(["SELECT ?s WHERE { ?s ?p ?o } LIMIT 1", text]) is None
    if not text.startswith("ASK"):
        sent = Requests(remote)
        both = remote.store.select_each([("SELECT ?s WHERE { ?s a owl:Ontology } ORDER BY ?s", {}), (text, {})])
        assert sent.kinds == {"other": 2} and both[0]


def test_keys_of_a_variable_or_its_string_are_read_and_other_expressions_are_not() -> None:
    text = "SELECT ?a ?b ?c WHERE { ?a ?b ?c } ORDER BY ?a DESC(?b) STR(?c) DESC(STR(?a)) LIMIT 3"
    assert [tuple(key) for key in _order_keys(text) or []] == [
        ("ASC", "?a", "?a"),
        ("DESC", "?b", "?b"),
        ("ASC", "?c", "STR(?c)"),
        ("DESC", "?a", "STR(?a)"),
    ]
    for other in ("LCASE(?c)", "STR(?c, ?a)", "DESC(STR(?c) ?a", "STR(?c"):
        assert _order_keys("SELECT ?a ?c WHERE { ?a ?b ?c } ORDER BY " + other) is None, other


def test_order_by_descending_keys_is_kept(remote: KnowledgeBase) -> None:
    texts = [
        "SELECT ?s WHERE { ?s a owl:Ontology } ORDER BY DESC(?s)",
        "SELECT ?s WHERE { ?s a owl:Class } ORDER BY ?s",
    ]
    separate = [[row["s"] for row in remote.store.select_each([(text, {})])[0]] for text in texts]
    together = [[row["s"] for row in rows] for rows in remote.store.select_each([(text, {}) for text in texts])]
    assert together == separate and len(separate[0]) > 1


@pytest.mark.parametrize("where", ["embedded", "remote"])
def test_the_belief_replaces_the_world_graph_with_one_request(
    where: str, remote: KnowledgeBase, fresh_embedded: Callable[[], KnowledgeBase]
) -> None:
    kb = remote if where == "remote" else fresh_embedded()
    world = GraphName.WORLD.node
    stray = ox.Quad(ox.NamedNode(HOME + "Stray"), ox.NamedNode(HOME + "isOn"), ox.NamedNode(HOME + "Table"), world)
    kb.store.add([stray])  # another client's statement in the world graph: the belief replaces the graph
    observation = Observation({HOME + "Pen1": HOME + "Pen"}, frozenset({(HOME + "Pen1", HOME + "isOn", HOME + "Desk")}))
    sent = Requests(kb) if where == "remote" else None
    BeliefState(kb).write(observation)
    if sent is not None:
        assert sent.kinds == {"update": 1}
    held = set(kb.store.quads(graph=world))
    assert stray not in held
    assert {
        (q.subject.value, q.predicate.value, q.object.value) for q in held if q.predicate.value.startswith(HOME)
    } == {(HOME + "Pen1", HOME + "isOn", HOME + "Desk")}
    assert len(held) == 3  # the type, the relation, and when it was believed
    kb.store.replace_graph(world, [])
    assert next(kb.store.quads(graph=world), None) is None
    with pytest.raises(ValueError, match="another graph"):
        kb.store.replace_graph(world, [ox.Quad(stray.subject, stray.predicate, stray.object, GraphName.MAP.node)])


@pytest.fixture
def fresh_embedded() -> Iterator[Callable[[], KnowledgeBase]]:
    opened: list[KnowledgeBase] = []

    def make() -> KnowledgeBase:
        opened.append(KnowledgeBase.open(":memory:"))
        return opened[-1]

    yield make
    for kb in opened:
        kb.close()


PLAN_REQUESTS = {"req:RobotSelfPosition": 45, "act:RobotArmServeACup": 50}
"""What ``cbrs plan TASK --no-store`` sent on 2026-11-27 (35 and 39, of which 22 and 21 were the
store's upgrade check), and a margin; they sent 51 and 79 before."""


@pytest.mark.parametrize("task", list(PLAN_REQUESTS))
def test_a_plan_reads_the_taxonomy_actions_requirements_and_descriptions_in_few_requests(
    served: OxigraphServer, task: str
) -> None:
    kinds: collections.Counter[str] = collections.Counter()
    post = RemoteStore._post

    def counted(
        self: RemoteStore, url: str, body: str, content_type: str, original: str | None, *a: Any, **k: Any
    ) -> Any:
        kinds["update" if content_type == "application/sparql-update" else original or "cbrs's own"] += 1
        return post(self, url, body, content_type, original, *a, **k)

    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(RemoteStore, "_post", counted)
        result = CliRunner().invoke(cli, ["--store", served.url, "plan", task, "--no-store"])
    assert result.exit_code == 0, result.output
    library = QueryLibrary(query_dir())
    alone = {library.get(name).text: name for name in library.names()}
    asked = collections.Counter({alone[text]: n for text, n in kinds.items() if text in alone})
    for name in ("taxonomy_links", "taxonomy_terms", "actions", "action_ordering", *PER_DESCRIPTION):
        assert asked[name] == 0, f"{name} asked alone: {asked}"
    assert asked["map_facts"] == 1, asked  # once, for the notes of what the map lacks (cameras, things)
    assert asked["requirements"] <= 2, asked  # the task's name, and once for the whole composition
    assert sum(kinds.values()) <= PLAN_REQUESTS[task], kinds


def test_a_write_cbrs_spells_in_full_iris_goes_without_the_prefixes(remote: KnowledgeBase) -> None:
    """A cbrs server checks the descriptions after an update declaring prefixes (which could spell their
    graphs' names): a belief write, all full IRIs, goes without them; an update given as text keeps them."""
    store = remote.store
    assert isinstance(store, RemoteStore)
    bodies: list[str] = []
    post = store._post

    def kept(url: str, body: str, content_type: str, original: str | None, *args: Any, **kw: Any) -> Any:
        bodies.append(body)
        return post(url, body, content_type, original, *args, **kw)

    store._post = kept  # type: ignore[method-assign]
    BeliefState(remote).write(Observation({HOME + "Pen1": HOME + "Pen"}))
    remote.store.update("INSERT DATA { GRAPH graph:world { home:Pen1 home:isOn home:Desk } }")
    assert "PREFIX" not in bodies[0] and bodies[0].startswith("\n")  # one line, as the prefixes are
    assert bodies[1].startswith("PREFIX")
    assert len(list(remote.store.quads(graph=GraphName.WORLD.node))) == 3


@pytest.mark.parametrize("where", ["embedded", "remote"])
def test_a_later_belief_write_sends_only_the_difference_as_a_data_update(
    where: str, remote: KnowledgeBase, fresh_embedded: Callable[[], KnowledgeBase]
) -> None:
    """After its first write, a belief sends what changed as ``DELETE DATA`` then ``INSERT DATA`` in one
    request, which a cbrs server reads as a data update (graph:entailed followed statement by statement);
    a write asked whole, and the first after a restore, replace the graph, another client's statement too."""
    kb = remote if where == "remote" else fresh_embedded()
    world = GraphName.WORLD.node
    texts: list[str] = []
    store = kb.store
    if isinstance(store, RemoteStore):
        sent_update = store._update

        def sent_text(text: str, original: str | None) -> None:
            texts.append(text)
            sent_update(text, original)

        store._update = sent_text  # type: ignore[method-assign]
    else:
        applied = store._apply_own_update

        def applied_text(text: str) -> None:
            texts.append(text)
            applied(text)

        store._apply_own_update = applied_text  # type: ignore[method-assign]
    belief = BeliefState(kb)
    pen, desk, table = HOME + "Pen1", HOME + "Desk", HOME + "Table"
    belief.write(Observation({pen: HOME + "Pen"}, frozenset({(pen, HOME + "isOn", desk)}), time=1.0))
    assert data_operations(texts[-1]) is None  # the first write replaces the graph
    stray = ox.Quad(ox.NamedNode(HOME + "Stray"), ox.NamedNode(HOME + "isOn"), ox.NamedNode(table), world)
    kb.store.add([stray])
    sent = Requests(kb) if where == "remote" else None
    moved = Observation({pen: HOME + "Pen"}, frozenset({(pen, HOME + "isOn", table)}), time=2.0)
    belief.write(moved)
    if sent is not None:
        assert sent.kinds == {"update": 1}
    operations = data_operations(texts[-1])
    assert operations is not None and [op.insert for op in operations] == [False, True]
    changed = {(q.predicate.value, q.object.value) for op in operations for q in op.quads}
    assert changed == {
        (HOME + "isOn", desk),
        (HOME + "isOn", table),
        (CBRS.believedAt, "1.0"),
        (CBRS.believedAt, "2.0"),
    }  # the type of the pen, unchanged, is not sent
    assert DataUpdate.read(texts[-1], EmbeddedStore.open(":memory:")) is not None  # a server reads it as data
    held = set(kb.store.quads(graph=world))
    assert stray in held and len(held) == 4  # left until a whole write
    belief.write(moved, whole=True)
    assert stray not in set(kb.store.quads(graph=world)) and len(set(kb.store.quads(graph=world))) == 3
    kb.store.add([stray])
    belief.restore(belief.snapshot())
    belief.write(moved)  # after a restore, what the graph holds is not what this belief last wrote
    assert data_operations(texts[-1]) is None
    assert set(kb.store.quads(graph=world)) == {q for q in held if q != stray}


def test_a_belief_write_after_a_failed_one_replaces_the_graph(
    fresh_embedded: Callable[[], KnowledgeBase], monkeypatch: pytest.MonkeyPatch
) -> None:
    """A write that failed may or may not have reached the store: the next one does not trust its memory."""
    kb = fresh_embedded()
    belief = BeliefState(kb)
    pen = HOME + "Pen1"
    belief.write(Observation({pen: HOME + "Pen"}, time=1.0))
    stray = ox.Quad(ox.NamedNode(HOME + "Stray"), ox.NamedNode(HOME + "isOn"), ox.NamedNode(HOME + "Table"))
    kb.store.add([ox.Quad(stray.subject, stray.predicate, stray.object, GraphName.WORLD.node)])

    def refused(remove: Any, add: Any) -> None:
        raise OSError("the store went away")

    with monkeypatch.context() as patch:
        patch.setattr(kb.store, "replace", refused)
        with pytest.raises(OSError):
            belief.write(Observation({pen: HOME + "Pen"}, time=2.0))
    belief.write(Observation({pen: HOME + "Pen"}, time=3.0))
    held = {(q.subject.value, q.object.value) for q in kb.store.quads(graph=GraphName.WORLD.node)}
    assert held == {(pen, HOME + "Pen"), (STATE, "3")}  # the stray is gone (Oxigraph writes the double so)


def test_a_runs_inputs_are_designated_with_one_request(remote: KnowledgeBase) -> None:
    """The ``given`` step designates every input of a task at once (kb.semantic_map.designate_each): the
    same things as one by one, in one request to a remote store instead of one per input."""
    wanted = [(HOME + "Cup", None), (HOME + "Person", None), (HOME + "Table", None)]  # (a test above adds a pen)
    one_by_one = [designate(remote, concept) for concept, _ in wanted]
    requests = Requests(remote)
    assert designate_each(remote, wanted) == one_by_one
    assert requests.total == 1 and requests.kinds["designate"] == 0, requests.kinds
