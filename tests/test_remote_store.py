"""The remote store: endpoint discovery, VALUES injection, the union check, errors, the CLI over HTTP.

What both backends must do alike is in the both_stores modules (test_store.py and the other kb tests);
this module holds what only a SPARQL server brings.
"""

from __future__ import annotations

import socket
import threading
from collections.abc import Callable, Iterator
from pathlib import Path
from urllib.parse import parse_qs

import httpx
import pyoxigraph as ox
import pytest
from click.testing import CliRunner

from cbrs.cli import cli
from cbrs.kb import (
    BindingError,
    KnowledgeBase,
    QuerySyntaxError,
    RemoteStoreError,
    Store,
    StoreError,
    StoreEvaluationError,
)
from cbrs.kb.namespaces import GraphName
from cbrs.kb.remote_store import OXIGRAPH_BATCH, Endpoints, RemoteStore, inject_values
from cbrs.kb.staged_writes import STAGED, STAGING, batches, publication
from tests.conftest import OxigraphServer
from tests.helpers_seeded import put_quads, seeded_quads
from tests.helpers_unsendable import unsendable_kept_by

DATA = Path(__file__).parent / "data"
LOCATE = "https://w3id.org/cbrs/service#LocateMobileRobot_CeilingCamera01"


# -- endpoint discovery -------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("location", "query", "update"),
    [
        pytest.param("http://h:7878", "http://h:7878/query", "http://h:7878/update", id="oxigraph"),
        pytest.param("http://h:7878/", "http://h:7878/query", "http://h:7878/update", id="oxigraph-slash"),
        pytest.param("http://h:7878/query", "http://h:7878/query", "http://h:7878/update", id="oxigraph-query"),
        pytest.param("https://h/fuseki/ds", "https://h/fuseki/ds/query", "https://h/fuseki/ds/update", id="fuseki"),
        pytest.param("http://h:3030/ds/sparql", "http://h:3030/ds/sparql", "http://h:3030/ds/update", id="sparql"),
        pytest.param(
            "http://h:7200/repositories/r http://h:7200/repositories/r/statements",
            "http://h:7200/repositories/r",
            "http://h:7200/repositories/r/statements",
            id="explicit-pair",
        ),
    ],
)
def test_endpoints_are_discovered_from_the_url(location: str, query: str, update: str) -> None:
    assert Endpoints.discover(location) == Endpoints(query, update)


@pytest.mark.parametrize("location", ["http://", "http://a b c", "ftp://h/x http://h/y"])
def test_a_bad_endpoint_url_is_refused(location: str) -> None:
    with pytest.raises(StoreError):
        Endpoints.discover(location)


# -- VALUES injection ---------------------------------------------------------------------------------

X = {"x": ox.NamedNode("http://e/x")}
VALUES = " VALUES (?x) { (<http://e/x>) } "


@pytest.mark.parametrize(
    ("query", "expected"),
    [
        pytest.param("SELECT * WHERE { ?x ?p ?o }", "SELECT * WHERE {" + VALUES + " ?x ?p ?o }", id="select"),
        pytest.param("ASK{?x ?p ?o}", "ASK{" + VALUES + "?x ?p ?o}", id="ask-no-where"),
        pytest.param(
            "PREFIX e: <http://e/{> # a { comment\nSELECT ?x WHERE { ?x ?p '{' }",
            "PREFIX e: <http://e/{> # a { comment\nSELECT ?x WHERE {" + VALUES + " ?x ?p '{' }",
            id="iri-and-comment",
        ),
        pytest.param(
            "SELECT (\"{\" AS ?a) ('}' AS ?b) (\"\"\"{\"\"\" AS ?c) ('''}''' AS ?d) (EXISTS { ?x ?p ?o } AS ?e) {}",
            "SELECT (\"{\" AS ?a) ('}' AS ?b) (\"\"\"{\"\"\" AS ?c) ('''}''' AS ?d) (EXISTS { ?x ?p ?o } AS ?e) {"
            + VALUES
            + "}",
            id="four-quote-forms-and-exists",
        ),
        pytest.param(
            "SELECT ?x (COUNT(*) AS ?n) WHERE { ?x ?p ?o } GROUP BY ?x LIMIT 1 VALUES ?o { 1 }",
            "SELECT ?x (COUNT(*) AS ?n) WHERE {" + VALUES + " ?x ?p ?o } GROUP BY ?x LIMIT 1 VALUES ?o { 1 }",
            id="aggregate-limit-trailing-values",
        ),
        pytest.param(
            'CONSTRUCT { ?x <http://e/says> "}" } WHERE { ?x ?p ?o }',
            'CONSTRUCT { ?x <http://e/says> "}" } WHERE {' + VALUES + " ?x ?p ?o }",
            id="construct-template-skipped",
        ),
        pytest.param(
            "CONSTRUCT WHERE { ?x ?p ?o }",
            "CONSTRUCT { ?x ?p ?o } WHERE {" + VALUES + " ?x ?p ?o }",
            id="construct-where",
        ),
        pytest.param("DESCRIBE ?x", "DESCRIBE ?x\nWHERE {" + VALUES + "}", id="describe"),
        pytest.param("DESCRIBE ?x LIMIT 1", "DESCRIBE ?x WHERE {" + VALUES + "}\nLIMIT 1", id="describe-limit"),
        pytest.param(
            "SELECT ?where WHERE { ?x e:SELECT ?where }",
            "SELECT ?where WHERE {" + VALUES + " ?x e:SELECT ?where }",
            id="names",
        ),
    ],
)
def test_values_open_the_top_level_group(query: str, expected: str) -> None:
    assert inject_values(query, X) == expected


def test_blank_nodes_and_bad_names_cannot_be_bound() -> None:
    with pytest.raises(BindingError, match="blank node"):
        inject_values("SELECT * { ?x ?p ?o }", {"x": ox.BlankNode()})
    with pytest.raises(BindingError, match="variable name"):
        inject_values("SELECT * { ?x ?p ?o }", {"x y": ox.Literal("1")})
    with pytest.raises(QuerySyntaxError, match="no SELECT"):
        inject_values("INSERT DATA { }", X)


def _recording_server(server: str, sent: list[str]) -> httpx.MockTransport:
    """An endpoint that answers every query with no rows, as ``server`` says it is, keeping each text."""

    def answer(request: httpx.Request) -> httpx.Response:
        sent.append(parse_qs(request.content.decode("utf-8"))["query"][0])
        body = b'{"head": {"vars": []}, "results": {"bindings": []}}'
        return httpx.Response(
            200, headers={"Server": server, "Content-Type": "application/sparql-results+json"}, content=body
        )

    return httpx.MockTransport(answer)


@pytest.mark.parametrize(
    ("server", "query", "bindings", "in_order"),
    [
        pytest.param(
            "Virtuoso/07.20.3229", "SELECT * { ?t rdfs:subClassOf* cbrs:Port . ?x a ?t }", X, True, id="fixed"
        ),
        pytest.param(
            "Virtuoso/07.20.3229", "SELECT * { ?t rdfs:subClassOf* cbrs:Port . ?x a ?t }", {}, True, id="free"
        ),
        pytest.param("Virtuoso/07.20.3229", "SELECT * { ?t <urn:p>+ <urn:c> . ?x a ?t }", X, True, id="iri"),
        pytest.param("Virtuoso/07.20.3229", "SELECT * { ?x rdfs:subClassOf* ?c }", X, False, id="variable-end"),
        pytest.param(
            "Virtuoso/07.20.3229",
            'SELECT (GROUP_CONCAT(?t; separator=" ") AS ?ts) { ?t rdfs:subClassOf* cbrs:Port . ?x a ?t }',
            X,
            False,
            id="values-bound",
        ),
        pytest.param("Virtuoso/07.20.3229", "SELECT (COUNT(*) AS ?n) { ?x a cbrs:Port }", X, False, id="no-path"),
        pytest.param("Oxigraph/0.4.0", "SELECT * { ?t rdfs:subClassOf* cbrs:Port . ?x a ?t }", X, False, id="oxigraph"),
    ],
)
def test_virtuoso_joins_a_query_with_a_path_to_a_fixed_class_as_written(
    server: str, query: str, bindings: dict[str, ox.NamedNode], in_order: bool
) -> None:
    """On Virtuoso, its optimiser sometimes walked such a path from each row of an earlier pattern and
    answered short (the description of a service, 0 rows of 1): the written order walks it first."""
    sent: list[str] = []
    store = RemoteStore(
        "http://sparql.test/sparql", Endpoints("http://sparql.test/sparql", "http://sparql.test/sparql")
    )
    store._client = httpx.Client(transport=_recording_server(server, sent))
    try:
        store._query("ASK {}")  # the first answer tells the store what the server is
        store._union_verified = True
        store.query(query, bindings)
    finally:
        store.close()
    assert sent[-1].startswith('DEFINE sql:select-option "order"') is in_order
    assert all(str(value) in sent[-1] for value in bindings.values())


def test_every_named_query_with_parameters_gives_the_embedded_answer(
    remote_location: str, oxigraph_server: OxigraphServer
) -> None:
    """VALUES pre-binding against Oxigraph substitution, on the bundled data, for every parameter."""
    put_quads(oxigraph_server, seeded_quads())  # what a seed writes: test_dumps_are_byte_for_byte_...
    embedded, remote = KnowledgeBase.open(":memory:"), KnowledgeBase.open(remote_location)
    for kb in (embedded, remote):
        kb.load([DATA / "mini_world.ttl"], graph="world")
    values = {
        "action": ["act:PuttingSomethingSomewhere", "act:OpeningADoor"],
        "service": [LOCATE],
        "kind": ["cbrs:DynamicPerceptionComponent", "cbrs:PhysicalManipulationComponent"],
        "concept": ["home:Position", "home:RobotLocation"],
        "description": [LOCATE, "req:RobotSelfPosition", "act:PuttingSomethingSomewhere"],
        "requirement": ["req:RobotSelfPosition"],
        "resource": [LOCATE, "home:Position"],
        "thing": ["world:Pen", "world:Person", "world:Cup"],
        "relation": ["home:isLocatedOn", "home:isNear"],
        "class": ["home:Cup", "home:Drinkware"],
        "room": ["home:Kitchen", "world:Kitchen"],
        "robot": ["svc:CytonDualArm01"],
        "camera": ["svc:CeilingCamera01", "svc:Kinect01"],
        "graph": ["graph:ontology", "graph:world", "graph:map"],
        "component": [LOCATE],
        "namespace": ["https://w3id.org/cbrs/world#"],
        "predicate": ["cbrs:deviceName", "home:hasMarker"],  # fewer uses than predicate_uses.rq's LIMIT
        "ontology": ["https://w3id.org/cbrs/home", "https://w3id.org/cbrs/core"],
    }
    checked = 0
    for name in embedded.queries.names():
        parameters = embedded.queries.get(name).parameters
        for parameter in parameters:
            assert parameter in values, f"give test values for the parameter {parameter!r} of {name}.rq"
        required = {p: values[p][0] for p, spec in parameters.items() if spec.required}  # the others' first values
        for parameter in parameters:
            for value in [*values[parameter], "http://example.org/nothing"]:
                want, got = (_rows(kb, name, {**required, parameter: value}) for kb in (embedded, remote))
                assert got == want, f"{name}.rq with {parameter}={value}"
                checked += 1
    assert checked >= 30
    remote.close()


def test_dumps_are_byte_for_byte_those_of_the_embedded_store(remote_location: str) -> None:
    owls = DATA / "owls"
    dumps = []
    for location in (":memory:", remote_location):
        kb = KnowledgeBase.open(location)  # the bundled data, then doubles, language tags, UTF-16, OWL-S
        kb.load([DATA / "mini_world.ttl"], graph="world")
        kb.load([owls / "services" / "navigate.owls"], catalogue=owls / "ontology")
        kb.store.add([ox.Quad(ox.NamedNode("http://e/a"), ox.NamedNode("http://e/p"), ox.Literal("default graph"))])
        dumps.append(kb.store.dump())
        kb.close()
    assert dumps[0] == dumps[1] and dumps[0].count(b"\n") > 5000


def _rows(kb: KnowledgeBase, name: str, values: dict[str, str]) -> list[tuple[str, ...]]:
    rows = kb.select(name, values)
    keys = sorted({key for row in rows for key in row})
    return sorted(tuple(_canonical(row[k]) if k in row else "" for k in keys) for row in rows)


def _canonical(term: ox.NamedNode | ox.BlankNode | ox.Literal) -> str:
    # GROUP_CONCAT follows storage order, which differs between the backends: compare its parts as a set.
    if isinstance(term, ox.Literal) and " " in term.value:
        return " ".join(sorted(term.value.split(" ")))
    return str(term)


# -- the union default graph --------------------------------------------------------------------------


@pytest.fixture(scope="module")
def plain_server(oxigraph_servers: Callable[..., OxigraphServer]) -> OxigraphServer:
    """A server started without --union-default-graph, its data on disk."""
    return oxigraph_servers(union_default_graph=False, on_disk=True)


def test_a_server_without_a_union_default_graph_is_refused(plain_server: OxigraphServer) -> None:
    plain_server.clear()
    with pytest.raises(StoreError) as seeding:  # an empty server cannot tell before the seed is in
        KnowledgeBase.open(plain_server.url)
    with pytest.raises(StoreError) as caught:
        Store.open(plain_server.url)
    for message in (str(seeding.value), str(caught.value)):
        assert "--union-default-graph" in message and plain_server.url in message and "\n" not in message
    # the probe's result is let go of here: a server hands such an error to another thread to report
    assert unsendable_kept_by(seeding.value) == unsendable_kept_by(caught.value) == []


def test_an_empty_server_is_checked_again_before_a_query(plain_server: OxigraphServer) -> None:
    plain_server.clear()
    store = Store.open(plain_server.url)
    store.add([ox.Quad(ox.NamedNode("http://e/a"), ox.NamedNode("http://e/p"), ox.Literal("x"), GraphName.WORLD.node)])
    with pytest.raises(StoreError, match="union"):
        store.query("SELECT * WHERE { ?s ?p ?o }")
    store.close()


# -- errors -------------------------------------------------------------------------------------------


def _free_port() -> int:
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        return int(probe.getsockname()[1])


def test_connection_refused_is_one_line_naming_the_url() -> None:
    url = f"http://127.0.0.1:{_free_port()}"
    with pytest.raises(StoreError) as caught:
        Store.open(url)
    message = str(caught.value)
    assert "\n" not in message and f"cannot connect to {url}/query" in message and "oxigraph serve" in message


def test_a_silent_server_times_out() -> None:
    with socket.socket() as listener:  # accepts connections (the kernel does) but never answers
        listener.bind(("127.0.0.1", 0))
        listener.listen(4)
        url = f"http://127.0.0.1:{listener.getsockname()[1]}"
        with pytest.raises(StoreError, match=r"did not answer within 0\.2 s"):
            RemoteStore.open(url, timeout=0.2)


def test_the_cli_waits_for_a_silent_server_as_long_as_remote_timeout_says() -> None:
    with socket.socket() as listener:
        listener.bind(("127.0.0.1", 0))
        listener.listen(4)
        url = f"http://127.0.0.1:{listener.getsockname()[1]}"
        result = CliRunner().invoke(cli, ["--store", url, "services"], env={"CBRS_REMOTE_TIMEOUT": "0.3"})
    assert result.exit_code == 1
    assert result.output.count("\n") == 1 and "did not answer within 0.3 s" in result.output, result.output


def test_syntax_errors_read_as_on_the_embedded_store(remote_location: str) -> None:
    text = "SELECT ?x\nWHERE { ?x "
    messages = []
    for location in (":memory:", remote_location):
        with pytest.raises(QuerySyntaxError) as caught:
            Store.open(location).query(text)
        assert caught.value.query == text
        messages.append(str(caught.value))
    assert messages[0] == messages[1] and "error at 2:" in messages[0]


def test_a_server_failure_keeps_the_servers_message_and_the_request(remote_location: str) -> None:
    store = Store.open(remote_location)
    store.update("CREATE GRAPH graph:world")
    with pytest.raises(StoreEvaluationError) as caught:
        store.update("CREATE GRAPH graph:world")
    error = caught.value
    assert (error.status, error.endpoint, error.request) == (
        500,
        f"{remote_location}/update",
        "CREATE GRAPH graph:world",
    )
    assert "already exists" in error.message and isinstance(error, RuntimeError)  # as pyoxigraph's own are
    store.close()


def test_a_wrong_endpoint_is_a_remote_store_error(remote_location: str) -> None:
    store = RemoteStore(remote_location, Endpoints(f"{remote_location}/nowhere", f"{remote_location}/update"))
    with pytest.raises(RemoteStoreError) as caught:
        store.count()
    assert caught.value.status == 404 and f"{remote_location}/nowhere" in str(caught.value)
    store.close()


# -- writes -------------------------------------------------------------------------------------------


@pytest.fixture
def requests_seen(remote_location: str) -> Iterator[tuple[Store, list[httpx.Request]]]:
    store = Store.open(remote_location)
    assert isinstance(store, RemoteStore)
    seen: list[httpx.Request] = []
    store._http().event_hooks["request"].append(seen.append)
    yield store, seen
    store.close()


def test_an_add_within_the_batch_is_one_request(remote_location: str) -> None:
    store = RemoteStore.open(remote_location, batch=20_000)
    seen: list[httpx.Request] = []
    store._http().event_hooks["request"].append(seen.append)
    p = ox.NamedNode("http://e/p")
    quads = [
        ox.Quad(ox.NamedNode(f"http://e/s{i}"), p, ox.Literal("x" * 100 + str(i)), GraphName.WORLD.node)
        for i in range(20_000)
    ]
    store.add(quads)
    assert [(r.method, r.url.path) for r in seen] == [("POST", "/update")]
    assert len(seen[0].content) > 2_000_000
    assert store.count(GraphName.WORLD) == 20_000
    store.close()


def test_a_refused_replace_sends_nothing(requests_seen: tuple[Store, list[httpx.Request]]) -> None:
    store, seen = requests_seen
    p = ox.NamedNode("http://e/p")
    kept = ox.Quad(ox.NamedNode("http://e/a"), p, ox.Literal("kept"), GraphName.WORLD.node)
    store.add([kept])
    before, sent = store.dump(), len(seen)
    with pytest.raises(ValueError, match="blank node"):  # a DELETE DATA / INSERT DATA pair cannot name it
        store.replace([kept], [ox.Quad(ox.BlankNode(), p, ox.Literal("new"), GraphName.WORLD.node)])
    assert len(seen) == sent and store.dump() == before


def test_the_seed_is_one_request_to_oxigraph(requests_seen: tuple[Store, list[httpx.Request]]) -> None:
    store, seen = requests_seen  # remote_batch auto: 100,000 quads a request on Oxigraph
    assert isinstance(store, RemoteStore) and store.batch == OXIGRAPH_BATCH
    KnowledgeBase(store).seed()
    seed, *entailed = (r.content.decode() for r in seen if r.url.path == "/update")
    assert seed.count("INSERT DATA") == 1 and 500_000 < len(seed) < 2_000_000  # about 0.8 MB
    assert entailed and all("graph/entailed" in write for write in entailed) and store.is_seeded()


def test_the_seed_is_staged_in_batches(remote_location: str) -> None:
    store = RemoteStore.open(remote_location, batch=1000)
    seen: list[httpx.Request] = []
    store._http().event_hooks["request"].append(seen.append)
    quads = sum(len(parsed.quads) for parsed in KnowledgeBase(store).seed())
    writes = [r.content.decode() for r in seen if r.url.path == "/update"]
    batches = -(-quads // 1000)
    seed, entailed = writes[: batches + 2], writes[batches + 2 :]
    assert [w.count("INSERT DATA") for w in seed] == [1] * batches + [0, 0]  # the batches, publish, drop
    assert entailed and all("graph/entailed" in w or "staging" in w for w in entailed)  # then graph:entailed
    assert store.is_seeded() and not [g for g in store.graphs() if g.startswith(STAGING)]
    store.close()


def test_batches_keep_each_blank_nodes_quads_together() -> None:
    p = ox.NamedNode("http://e/p")
    a, b, c = ox.BlankNode("a"), ox.BlankNode("b"), ox.BlankNode("c")
    linked = [ox.Quad(a, p, b), ox.Quad(b, p, ox.Literal("1")), ox.Quad(ox.NamedNode("http://e/x"), p, a)]
    alone = [ox.Quad(c, p, ox.Literal("2"))]
    plain = [ox.Quad(ox.NamedNode(f"http://e/s{i}"), p, ox.Literal(str(i))) for i in range(5)]
    found = batches([*linked[:1], *plain, *alone, *linked[1:]], 3)
    assert sorted(map(len, found)) == [1, 2, 3, 3]  # 3 + 2 plain quads, the linked three, the lone one
    assert any(set(linked) <= set(part) for part in found)
    assert [len(part) for part in batches(linked, 2)] == [3]  # a group larger than a batch stays whole


def test_the_publication_is_one_operation_naming_every_staging_graph() -> None:
    stages = {
        ox.NamedNode(f"https://w3id.org/cbrs/graph/{g}"): ox.NamedNode(f"{STAGING}run/{i}") for i, g in enumerate("ab")
    }
    text = publication(stages)
    assert text.count("INSERT") == 1 and ";" not in text
    assert f"(<{STAGING}run/0> <https://w3id.org/cbrs/graph/a>)" in text and f'"{STAGED}"' in text


def test_one_store_serves_many_threads(remote_location: str, oxigraph_server: OxigraphServer) -> None:
    put_quads(oxigraph_server, seeded_quads())
    kb = KnowledgeBase.open(remote_location)
    expected = kb.select("description", {"description": LOCATE})
    failures: list[BaseException] = []

    def work() -> None:
        try:
            for _ in range(10):
                assert kb.select("description", {"description": LOCATE}) == expected
        except BaseException as error:  # reported below, from the main thread
            failures.append(error)

    threads = [threading.Thread(target=work) for _ in range(6)]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join()
    assert failures == []
    kb.close()


# -- the command line ---------------------------------------------------------------------------------


def test_the_cli_works_against_a_server(remote_location: str, oxigraph_server: OxigraphServer) -> None:
    put_quads(oxigraph_server, seeded_quads())  # as cbrs init leaves a server (test_remote_servers.py)
    runner = CliRunner()
    services = runner.invoke(cli, ["--store", remote_location, "services"])
    assert services.exit_code == 0, services.output
    assert "svc:LocateMobileRobot_CeilingCamera01" in services.output
    named = runner.invoke(
        cli,
        [
            "--store",
            remote_location,
            "query",
            "--name",
            "advertisements",
            "--bind",
            "kind=cbrs:DynamicPerceptionComponent",
        ],
    )
    assert named.exit_code == 0, named.output
    assert "svc:LocateMobileRobot_CeilingCamera01" in named.output and "PhysicalManipulation" not in named.output
    text = runner.invoke(
        cli, ["--store", remote_location, "query", "CONSTRUCT WHERE { ?c rdfs:subClassOf home:Position }"]
    )
    assert text.exit_code == 0, text.output
    assert "rdfs:subClassOf home:Position" in text.output


def test_the_cli_names_an_unreachable_server() -> None:
    url = f"http://127.0.0.1:{_free_port()}"
    result = CliRunner().invoke(cli, ["--store", url, "services"])
    assert result.exit_code == 1
    assert result.output.count("\n") == 1 and url in result.output and "Traceback" not in result.output
