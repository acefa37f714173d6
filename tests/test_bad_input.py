"""Bad input, tried systematically: every file of ``tests/data/bad`` through every entry point it can reach.

``tests/data/bad/manifest.toml`` says what each file must be told. A load goes through ``cbrs load`` in
process after good data, and must print one line, exit non-zero and leave the store's dump byte for
byte as it was; a query goes to ``/sparql`` (an update to ``/update``) and ``cbrs query``; a frame goes
to a live bridge on loopback, whose connection must keep working. Hypothesis then throws random bytes,
text mutations, JSON values and query strings at the same entry points.
"""

from __future__ import annotations

import json
import string
import subprocess
import sys
import threading
import tomllib
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pyoxigraph as ox
import pytest
from click.testing import CliRunner
from flask.testing import FlaskClient
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from websockets.sync.client import ClientConnection, connect

from cbrs.bridge_services import KnowledgeServices, attach
from cbrs.cli import cli
from cbrs.kb import GraphName, KnowledgeBase, KnowledgeBaseError, Store
from cbrs.kb import loader as kb_loader
from cbrs.kb.errors import InvalidDescriptionError, PartCycleError, RdfParseError
from cbrs.kb.resources import ontology_dir
from cbrs.rosbridge import Bridge, RunningBridge
from cbrs.sparql_service import EndpointConfig, SparqlService
from cbrs.tasks import TaskRunner
from cbrs.web import create_app

DATA = Path(__file__).parent / "data"
BAD = DATA / "bad"
MANIFEST = tomllib.loads((BAD / "manifest.toml").read_text(encoding="utf-8"))
GOOD = [DATA / "mini_ontology.ttl", DATA / "mini_services.ttl", DATA / "mini_requirements.ttl"]
TOKEN = "bad-input-token"
WAIT = 3.0  # seconds any one network answer may take
FAST = settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])


def cases(section: str, path: Path = BAD) -> list[Any]:
    return [pytest.param(path / name, expected, id=name) for name, expected in MANIFEST[section].items()]


def corpus_files() -> set[str]:
    return {str(p.relative_to(BAD)) for p in BAD.rglob("*") if p.is_file() and p.name != "manifest.toml"}


def test_every_bad_file_has_an_expectation_and_a_line_in_the_readme() -> None:
    readme = (DATA / "README.md").read_text(encoding="utf-8")
    listed = {
        *MANIFEST["load"],
        *(f"sparql/{n}" for n in MANIFEST["sparql"]),
        *(f"rosbridge/{n}" for n in MANIFEST["rosbridge"]),
    }
    assert corpus_files() == listed
    missing = [name for name in sorted(listed | {"manifest.toml"}) if f"`bad/{name}`" not in readme]
    assert missing == []


# -- files through `cbrs load` and `cbrs register` --------------------------------------------------


@pytest.fixture(scope="module")
def store(tmp_path_factory: pytest.TempPathFactory) -> str:
    """An on-disk store holding good data first, so an unchanged dump means something."""
    location = str(tmp_path_factory.mktemp("bad") / "store")
    code, out = run("load", *map(str, [ontology_dir() / "core.ttl", *GOOD]), store=location)
    assert code == 0, out
    return location


@pytest.fixture(scope="module")
def stored(store: str) -> bytes:
    """The module store's dump as loaded, read once: every refusal must leave the store byte for byte so."""
    return dump(store)


def run(*args: str, store: str) -> tuple[int, str]:
    result = CliRunner().invoke(cli, ["--store", store, *args])
    return result.exit_code, result.output


def dump(location: str) -> bytes:
    opened = Store.open(location)
    try:
        return opened.dump()
    finally:
        opened.close()


@pytest.fixture(autouse=True)
def quick_canonicalisation(monkeypatch: pytest.MonkeyPatch) -> None:
    """The look-alike blank nodes must be refused in seconds, not the production limit's ten."""
    monkeypatch.setattr(kb_loader, "CANONICAL_SECONDS", 2.0)
    monkeypatch.setattr(kb_loader, "CANONICAL_BYTES", 512 << 20)


LOAD_ERRORS = [case for case in cases("load") if "error" in case.values[1]]
LOAD_WARNINGS = [case for case in cases("load") if "warning" in case.values[1]]


@pytest.mark.parametrize(("path", "expected"), LOAD_ERRORS)
def test_a_bad_file_is_refused_in_one_line_and_changes_nothing(
    store: str, stored: bytes, path: Path, expected: dict[str, str]
) -> None:
    code, out = run("load", str(path), store=store)
    assert dump(store) == stored
    assert code == 1
    assert out.startswith(f"Error: {path}") and out.count("\n") == 1, out
    assert expected["error"] in out


@pytest.mark.parametrize(("path", "expected"), LOAD_ERRORS)
def test_a_bad_file_with_a_good_one_loads_neither(
    store: str, stored: bytes, path: Path, expected: dict[str, str]
) -> None:
    good = DATA / "composition" / "chain.ttl"
    code, out = run("load", str(good), str(path), store=store)
    assert (code, dump(store)) == (1, stored)
    assert expected["error"] in out


@pytest.mark.parametrize("path", [c.values[0] for c in LOAD_ERRORS if c.values[0].suffix == ".ttl"], ids=str)
def test_register_refuses_a_bad_turtle_file_in_one_line(store: str, stored: bytes, path: Path) -> None:
    code, out = run("register", str(path), store=store)
    assert dump(store) == stored
    assert code == 1 and out.count("\n") == 1 and str(path) in out, out


@pytest.mark.parametrize(("path", "expected"), LOAD_WARNINGS)
def test_a_usable_file_with_flaws_loads_and_names_them(tmp_path: Path, path: Path, expected: dict[str, str]) -> None:
    location = str(tmp_path / "store")
    assert run("load", *map(str, GOOD), store=location)[0] == 0
    code, out = run("load", str(path), store=location)
    assert code == 0, out
    assert expected["warning"] in out
    assert expected.get("also", "") in out


def test_rdfxml_cut_off_mid_element_loads_nothing_even_alone(tmp_path: Path) -> None:
    """Oxigraph returns the triples before the cut; the loader must not store them."""
    with pytest.raises(RdfParseError) as caught:
        kb_loader.parse_file(BAD / "rdfxml_truncated.rdf")
    assert caught.value.line == 6


def test_look_alike_blank_nodes_canonicalise_the_same_in_the_child(tmp_path: Path) -> None:
    """A small graph of look-alikes goes through the child process and gets the names it gets in process."""
    p = ox.NamedNode("http://example.org/p")
    ring = [ox.Quad(ox.BlankNode(f"b{i}"), p, ox.BlankNode(f"b{j}")) for i in range(4) for j in range(4) if i != j]
    assert kb_loader._has_look_alikes(ring)
    dataset = ox.Dataset(ring)
    dataset.canonicalize(ox.CanonicalizationAlgorithm.RDFC_1_0)
    assert kb_loader._canonical_in_child(ring, "ring") == sorted(dataset, key=str)
    assert kb_loader.skolemise(ring) == kb_loader.skolemise(list(reversed(ring)))


# -- hasPart cycles: refused at load, and what the reader and the taxonomy make of one -------------

PART = "http://www.ontologydesignpatterns.org/ont/dul/DUL.owl#hasPart"
PREFIXES = f"""@prefix ex: <http://example.org/c#> . @prefix owl: <http://www.w3.org/2002/07/owl#> .
@prefix rdfs: <http://www.w3.org/2000/01/rdf-schema#> . @prefix dul: <{PART.split("#")[0]}#> .
"""


def has_part(whole: str, part: str) -> str:
    return (
        f"ex:{whole} a owl:Class ; rdfs:subClassOf "
        f"[ a owl:Restriction ; owl:onProperty dul:hasPart ; owl:someValuesFrom ex:{part} ] .\n"
    )


def turtle(tmp_path: Path, name: str, body: str) -> Path:
    path = tmp_path / name
    path.write_text(PREFIXES + body, encoding="utf-8")
    return path


@pytest.mark.parametrize(
    ("body", "cycle"),
    [
        pytest.param(has_part("A", "A"), ["A", "A"], id="own-part"),
        pytest.param(has_part("A", "B") + has_part("B", "C") + has_part("C", "A"), ["A", "B", "C", "A"], id="three"),
        pytest.param(has_part("B", "A") + "ex:A rdfs:subClassOf ex:B .\n", ["A", "A"], id="inherited"),
    ],
)
def test_a_part_cycle_is_refused_naming_it(tmp_path: Path, body: str, cycle: list[str]) -> None:
    knowledge = KnowledgeBase(Store.open(":memory:"))
    before = knowledge.store.dump()
    with pytest.raises(PartCycleError) as caught:
        knowledge.load([turtle(tmp_path, "c.ttl", body)])
    assert caught.value.cycle == [f"http://example.org/c#{c}" for c in cycle]
    assert knowledge.store.dump() == before


def test_a_cycle_closed_by_a_second_file_names_it_and_the_first_stays(tmp_path: Path) -> None:
    knowledge = KnowledgeBase(Store.open(":memory:"))
    knowledge.load([turtle(tmp_path, "first.ttl", has_part("A", "B"))])
    before = knowledge.store.dump()
    second = turtle(tmp_path, "second.ttl", has_part("B", "A"))
    with pytest.raises(PartCycleError, match=r"second\.ttl: hasPart cycle"):
        knowledge.load([second])
    assert knowledge.store.dump() == before


def test_a_narrowed_part_is_no_cycle(tmp_path: Path) -> None:
    """B narrows A's part (its own restriction on the same property wins), so A is not B's part."""
    body = has_part("A", "B") + has_part("B", "Leaf") + "ex:B rdfs:subClassOf ex:A .\n"
    knowledge = KnowledgeBase(Store.open(":memory:"))
    knowledge.load([turtle(tmp_path, "narrow.ttl", body)])
    assert [child.concept for child in knowledge.part_tree("http://example.org/c#A").children] == [
        "http://example.org/c#B"
    ]


def test_a_stored_cycle_is_refused_by_the_reader_and_broken_by_the_taxonomy() -> None:
    """What happens to a cycle that got in another way (an update): both terminate, one refuses clearly."""
    from cbrs.reasoner.taxonomy import TaxonomyIndex

    knowledge = KnowledgeBase(Store.open(":memory:"))
    knowledge.load([ontology_dir() / "core.ttl"], graph="ontology")
    quads = ox.parse((BAD / "requirement_haspart_cycle.ttl").read_bytes(), format=ox.RdfFormat.TURTLE)
    graph = GraphName.ONTOLOGY.node
    knowledge.store.add(kb_loader.skolemise([ox.Quad(q.subject, q.predicate, q.object, graph) for q in quads]))
    with pytest.raises(InvalidDescriptionError, match="hasPart cycle"):
        knowledge.part_tree("http://example.org/cycle#Wheel")
    index = TaxonomyIndex.from_kb(knowledge)
    wheel, hub = "http://example.org/cycle#Wheel", "http://example.org/cycle#Hub"
    assert (hub in index.parts_of(wheel)) != (wheel in index.parts_of(hub))  # one link of the two dropped


@FAST
@given(
    links=st.lists(st.tuples(st.integers(0, 4), st.integers(0, 4), st.booleans()), min_size=1, max_size=7),
)
def test_a_load_is_refused_exactly_when_a_part_tree_would_be_endless(
    tmp_path: Path, links: list[tuple[int, int, bool]]
) -> None:
    """The reader is the oracle: a load goes in only if every concept's part tree can be built."""
    body = "".join(
        has_part(f"C{a}", f"C{b}") if part else f"ex:C{a} rdfs:subClassOf ex:C{b} .\n" for a, b, part in links
    )
    path = turtle(tmp_path, "random.ttl", body)
    knowledge = KnowledgeBase(Store.open(":memory:"))
    try:
        knowledge.load([path])
        refused = False
    except PartCycleError:
        refused = True
        quads = ox.parse(path.read_bytes(), format=ox.RdfFormat.TURTLE)
        graph = GraphName.ONTOLOGY.node
        knowledge.store.add(kb_loader.skolemise([ox.Quad(q.subject, q.predicate, q.object, graph) for q in quads]))
    endless = False
    for n in range(5):
        try:
            knowledge.part_tree(f"http://example.org/c#C{n}")
        except InvalidDescriptionError as error:
            endless = endless or "cycle" in str(error)
    assert refused == endless


# -- random bytes and mutations through the loader -------------------------------------------------

VALID_TURTLE = (DATA / "mini_services.ttl").read_bytes()
VALID_RDFXML = ox.serialize(list(ox.parse(VALID_TURTLE, format=ox.RdfFormat.TURTLE)), format=ox.RdfFormat.RDF_XML)
assert VALID_RDFXML is not None
SYNTAX = [*b'<>"{}[]().;,:@#\\ \n^_', 0, 0xFF, 0xC3]


@st.composite
def mutated(draw: st.DrawFn, valid: bytes) -> bytes:
    """A valid file with a few bytes deleted, inserted or replaced, or cut short."""
    data = bytearray(valid)
    for _ in range(draw(st.integers(1, 4))):
        at = draw(st.integers(0, len(data)))
        action = draw(st.sampled_from(["delete", "insert", "replace", "truncate"]))
        if action == "truncate":
            del data[at:]
        elif action == "delete":
            del data[at : at + draw(st.integers(1, 8))]
        else:
            byte = draw(st.sampled_from(SYNTAX))
            data[at : at + (action == "replace")] = bytes([byte])
    return bytes(data)


@pytest.fixture(scope="module")
def baseline() -> list[ox.Quad]:
    knowledge = KnowledgeBase(Store.open(":memory:"))
    knowledge.load(GOOD)
    return list(knowledge.store.quads())


def load_or_refuse(baseline: list[ox.Quad], path: Path, data: bytes) -> None:
    """Load ``data`` over the baseline: it goes in, or a typed error leaves the store as it was."""
    path.write_bytes(data)
    knowledge = KnowledgeBase(Store.open(":memory:"))
    knowledge.store.add(baseline)
    before = knowledge.store.dump()
    try:
        knowledge.load([path])
    except KnowledgeBaseError as error:
        assert knowledge.store.dump() == before
        assert str(path) in str(error) and "\n" not in str(error)
    else:
        assert knowledge.store.count() >= len(baseline)


@FAST
@given(data=st.binary(max_size=300), suffix=st.sampled_from([".ttl", ".rdf", ".nt", ".jsonld", ".owls"]))
def test_random_bytes_load_or_are_refused_cleanly(
    tmp_path: Path, baseline: list[ox.Quad], data: bytes, suffix: str
) -> None:
    load_or_refuse(baseline, tmp_path / f"random{suffix}", data)


@FAST
@given(data=mutated(VALID_TURTLE))
def test_mutated_turtle_loads_or_is_refused_cleanly(tmp_path: Path, baseline: list[ox.Quad], data: bytes) -> None:
    load_or_refuse(baseline, tmp_path / "mutated.ttl", data)


@FAST
@given(data=mutated(VALID_RDFXML))
def test_mutated_rdfxml_loads_or_is_refused_cleanly(tmp_path: Path, baseline: list[ox.Quad], data: bytes) -> None:
    load_or_refuse(baseline, tmp_path / "mutated.rdf", data)


# -- queries through /sparql, /update and `cbrs query` ---------------------------------------------


@pytest.fixture(scope="module")
def endpoint() -> tuple[FlaskClient, KnowledgeBase]:
    knowledge = KnowledgeBase(Store.open(":memory:"))
    knowledge.load([ontology_dir() / "core.ttl"], graph="ontology")
    knowledge.load(GOOD)
    service = SparqlService(knowledge, EndpointConfig(update_token=TOKEN, timeout=5.0))
    return create_app(service).test_client(), knowledge


def send(client: FlaskClient, path: Path) -> Any:
    text = path.read_text(encoding="utf-8")
    if path.suffix == ".ru":
        return client.post(
            "/update", data=text.encode(), content_type="application/sparql-update",
            headers={"Authorization": f"Bearer {TOKEN}"},
        )  # fmt: skip
    return client.get("/sparql", query_string={"query": text})


@pytest.mark.parametrize(("path", "expected"), cases("sparql", BAD / "sparql"))
def test_a_bad_query_is_400_with_json_naming_the_problem(
    endpoint: tuple[FlaskClient, KnowledgeBase], path: Path, expected: dict[str, str]
) -> None:
    client, knowledge = endpoint
    before = knowledge.store.dump()
    response = send(client, path)
    assert knowledge.store.dump() == before
    assert response.status_code == 400
    body = response.get_json()
    assert body["error"] == expected.get("kind", "QuerySyntaxError")
    assert expected["error"] in body["message"]


@pytest.mark.parametrize(("path", "expected"), cases("sparql", BAD / "sparql"))
def test_cbrs_query_refuses_a_bad_query_in_one_line(store: str, path: Path, expected: dict[str, str]) -> None:
    code, out = run("query", "--file", str(path), store=store)
    assert code == 1 and out.count("\n") == 1, out
    if path.suffix == ".ru":
        assert "this is a SPARQL update" in out and "cbrs query runs queries only" in out
    elif "kind" in expected:  # refused before any parser: the refusal's own words
        assert out.startswith("Error: ") and expected["error"][:40] in out, out
    else:
        assert out.startswith("Error: SPARQL syntax error") and expected["error"].split(": ")[-1][:30] in out


def test_an_oversized_query_is_413_with_json(endpoint: tuple[FlaskClient, KnowledgeBase]) -> None:
    client, _ = endpoint
    huge = "SELECT * WHERE { ?s ?p ?o } # " + "x" * (1 << 20)
    for response in (
        client.post("/sparql", data=huge.encode(), content_type="application/sparql-query"),
        client.post("/sparql", data={"query": huge}),
    ):
        assert response.status_code == 413
        assert response.get_json()["error"] == "request-too-large"
        assert "max_query_bytes" in response.get_json()["message"]


NESTED = "SELECT * WHERE { FILTER(" + "(" * 10_000 + "1" + ")" * 10_000 + ") }"  # 20 KB, far below the size limit
NESTED_PROBE = """
import sys
from cbrs.sparql_service import EndpointConfig, SparqlService
from cbrs.web import create_app
from cbrs.kb import KnowledgeBase, Store
client = create_app(SparqlService(KnowledgeBase(Store.open(":memory:")), EndpointConfig())).test_client()
response = client.get("/sparql", query_string={"query": sys.stdin.read()})
print(response.status_code, response.get_json()["error"])
"""


def test_a_deeply_nested_query_is_refused_not_fatal() -> None:
    done = subprocess.run(
        [sys.executable, "-c", NESTED_PROBE], input=NESTED, capture_output=True, text=True, timeout=60, check=False
    )
    assert done.returncode == 0, f"the endpoint's process died with {done.returncode}"
    assert done.stdout.split() == ["400", "QuerySyntaxError"]


@FAST
@given(text=st.text(alphabet=st.characters(codec="utf-8"), max_size=200))
def test_random_query_strings_get_200_or_a_json_4xx(endpoint: tuple[FlaskClient, KnowledgeBase], text: str) -> None:
    client, _ = endpoint
    check_answer(client.get("/sparql", query_string={"query": text}))


QUERY = "SELECT ?s ?o WHERE { ?s a cbrs:Requirement ; rdfs:label ?o } LIMIT 5"


@FAST
@given(data=mutated(QUERY.encode()))
def test_mutated_queries_get_200_or_a_json_4xx(endpoint: tuple[FlaskClient, KnowledgeBase], data: bytes) -> None:
    client, _ = endpoint
    check_answer(client.post("/sparql", data=data, content_type="application/sparql-query"))


def check_answer(response: Any) -> None:
    """200, or a client error as JSON; 503 only as the endpoint's own bounded timeout, never a 500."""
    assert (
        response.status_code == 200
        or 400 <= response.status_code < 500
        or (response.status_code == 503 and response.get_json()["error"] in ("timeout", "busy"))
    ), response.get_data(as_text=True)[:300]
    if response.status_code != 200:
        body = response.get_json()
        assert body["error"] and body["message"]


# -- frames through a live bridge ------------------------------------------------------------------


@pytest.fixture(scope="module")
def bridge(endpoint: tuple[FlaskClient, KnowledgeBase]) -> Iterator[RunningBridge]:
    """A bridge with the knowledge base's services, on a free loopback port."""
    _, knowledge = endpoint
    bridge = Bridge(call_timeout=WAIT)
    lock = threading.RLock()
    sparql = SparqlService(knowledge, EndpointConfig(timeout=WAIT))
    detach = attach(bridge, KnowledgeServices(sparql, TaskRunner(knowledge, lock, camera=None, read_only=True)))
    running = bridge.start(host="127.0.0.1", port=0)
    yield running
    detach()
    assert running.stop(timeout=5.0)


@pytest.fixture
def ws(bridge: RunningBridge) -> Iterator[ClientConnection]:
    with connect(bridge.url, open_timeout=WAIT, close_timeout=1) as connection:
        yield connection


def receive(ws: ClientConnection) -> dict[str, Any]:
    message = json.loads(ws.recv(timeout=WAIT))
    assert isinstance(message, dict)
    return message


def answer_to(ws: ClientConnection, call_id: str) -> dict[str, Any]:
    """Read until the service_response to ``call_id``; everything before it must be a well-formed message."""
    while True:
        message = receive(ws)
        assert isinstance(message.get("op"), str), message
        if message["op"] == "status":
            assert message["level"] in ("error", "warning", "info") and isinstance(message["msg"], str)
        if message["op"] == "service_response" and message.get("id") == call_id:
            return message


def still_works(ws: ClientConnection) -> None:
    """The same connection subscribes, publishes to itself and calls a service."""
    ws.send(json.dumps({"op": "subscribe", "topic": "/bad_input/echo", "type": "std_msgs/String"}))
    ws.send(json.dumps({"op": "advertise", "topic": "/bad_input/echo", "type": "std_msgs/String"}))
    ws.send(json.dumps({"op": "publish", "topic": "/bad_input/echo", "msg": {"data": "still here"}}))
    echoed = receive(ws)
    assert (echoed["op"], echoed["msg"]) == ("publish", {"data": "still here"})
    ws.send(json.dumps({"op": "call_service", "service": "/rosapi/get_time", "id": "after"}))
    assert answer_to(ws, "after")["result"] is True


@pytest.mark.parametrize(("path", "expected"), cases("rosbridge", BAD / "rosbridge"))
def test_a_bad_frame_gets_a_status_error_and_the_connection_stays_up(
    ws: ClientConnection, path: Path, expected: dict[str, str]
) -> None:
    data = path.read_bytes()
    ws.send(data if path.suffix == ".bin" else data.decode("utf-8"))
    status = receive(ws)
    assert (status["op"], status["level"]) == ("status", "error")
    assert expected["status"] in status["msg"]
    assert status.get("id") == expected.get("id")
    if b'"call_service"' in data and "id" in expected:  # a call the bridge cannot read is answered too
        failed = receive(ws)  # (roslibjs and roslibpy wait for the answer, not for a status)
        assert (failed["op"], failed["id"], failed["result"]) == ("service_response", expected["id"], False)
    still_works(ws)


def test_a_huge_payload_gets_a_status_error_and_the_connection_stays_up(ws: ClientConnection) -> None:
    ws.send(json.dumps({"op": "publish", "topic": "/bad_input/echo", "msg": {"data": "x" * (1 << 20)}}))
    status = receive(ws)
    assert status["op"] == "status" and "exceeds the limit of 1048576 bytes (max_message_bytes)" in status["msg"]
    still_works(ws)


@pytest.mark.parametrize(("path", "expected"), cases("sparql", BAD / "sparql")[:7])
def test_a_bad_query_to_cbrs_query_fails_the_call_naming_it(
    ws: ClientConnection, path: Path, expected: dict[str, str]
) -> None:
    call = {"op": "call_service", "service": "/cbrs/query", "args": {"query": path.read_text()}, "id": path.name}
    ws.send(json.dumps(call))
    response = answer_to(ws, path.name)
    assert response["result"] is False
    assert "SPARQL syntax error" in response["values"] and expected["error"].split(": ")[-1][:30] in response["values"]
    still_works(ws)


OPS = ["advertise", "unadvertise", "publish", "subscribe", "unsubscribe", "call_service", "service_response",
       "advertise_service", "unadvertise_service", "set_level", "fragment", "teleport"]  # fmt: skip
JSON = st.recursive(
    st.none() | st.booleans() | st.integers() | st.floats(allow_nan=False, allow_infinity=False) | st.text(max_size=20),
    lambda inner: st.lists(inner, max_size=4) | st.dictionaries(st.text(max_size=8), inner, max_size=4),
    max_leaves=12,
)
FIELDS = ["topic", "type", "msg", "service", "args", "id", "result", "values", "throttle_rate", "queue_length", "level"]
FRAME = JSON | st.fixed_dictionaries(
    {"op": st.sampled_from(OPS)}, optional={name: JSON | st.sampled_from(["/a", "/rosapi/topics"]) for name in FIELDS}
)


@FAST
@given(frame=FRAME)
def test_random_json_frames_never_close_the_connection(bridge: RunningBridge, frame: Any) -> None:
    with connect(bridge.url, open_timeout=WAIT, close_timeout=1) as ws:
        ws.send(json.dumps(frame))
        ws.send(json.dumps({"op": "call_service", "service": "/rosapi/get_time", "id": "sync-after-random"}))
        assert answer_to(ws, "sync-after-random")["result"] is True


@FAST
@given(text=st.text(alphabet=string.printable, max_size=80))
def test_random_text_frames_never_close_the_connection(bridge: RunningBridge, text: str) -> None:
    with connect(bridge.url, open_timeout=WAIT, close_timeout=1) as ws:
        ws.send(text)
        ws.send(json.dumps({"op": "call_service", "service": "/rosapi/get_time", "id": "sync-after-text"}))
        assert answer_to(ws, "sync-after-text")["result"] is True
