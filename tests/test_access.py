"""Access and injection: who may write, where the server listens, and that no parameter of any endpoint,
bridge service or CLI option can reach SPARQL as text or a file outside its folder.

Every hostile value is tried on every entry point that takes user input and reaches a query; the store's
dump must be byte-for-byte what it was. Network use is loopback only, every wait bounded.
"""

from __future__ import annotations

import ast
import json
import os
import re
import socket
import threading
from collections.abc import Iterator
from pathlib import Path

import httpx
import pytest
from click.testing import CliRunner
from flask.testing import FlaskClient

from cbrs.cli import cli
from cbrs.kb import KnowledgeBase
from cbrs.kb.catalog import Catalogue
from cbrs.server import ServeConfig, Server
from cbrs.settings import setting
from cbrs.sparql_service import EndpointConfig, SparqlService
from cbrs.tasks import TaskRunner
from cbrs.web import create_app
from tests.helpers_threads import assert_threads_end
from tests.test_serve import bridge, call

ROOT = Path(__file__).resolve().parent.parent
WAIT = 10.0
TOKEN = "access-test-token"

# Each would change the store (or fail to parse) if it were pasted into a query instead of bound.
HOSTILE = (
    '"',
    "'",
    '"""',
    "} ; DROP ALL ; {",
    "<urn:x> } ; DROP ALL ; { ?s ?p ?o",
    'x" } ; DROP ALL ; { "',
    "urn:x> } ; DROP ALL ; { <urn:y",
    "req:RobotSelfPosition> . } ; DELETE WHERE { ?s ?p ?o } ; SELECT * WHERE { <urn:z",
    'home:Position" ; DROP ALL ; #',
    "\n} DROP ALL {\n",
    "\\",
    "?s",
    "%00",
    "../../../../etc/passwd",
)


@pytest.fixture(scope="module")
def kb() -> Iterator[KnowledgeBase]:
    opened = KnowledgeBase.open(":memory:")
    yield opened
    opened.close()


@pytest.fixture(scope="module")
def client(kb: KnowledgeBase) -> FlaskClient:
    sparql = SparqlService(kb, EndpointConfig(update_token=TOKEN))
    return create_app(sparql, tasks=TaskRunner(kb, sparql.lock, camera=None)).test_client()


# -- injection through the web pages and the endpoint ---------------------------------------------------

PAGES = (
    ("/taxonomy.json", "q"),
    ("/taxonomy/class.json", "iri"),
    ("/resource.json", "iri"),
    ("/service.json", "iri"),
    ("/services.json", "kind"),
    ("/match.json", "requirement"),
    ("/match.json", "inputs"),
    ("/match.json", "outputs"),
    ("/match.json", "preconditions"),
    ("/match.json", "effects"),
    ("/match.json", "methods"),
    ("/match.json", "top"),
    ("/plans.json", "task"),
    ("/plans.json", "objective"),
    ("/plans/graph.svg", "task"),
    ("/query.json", "example"),
    ("/tasks.json", "task"),
)


@pytest.mark.parametrize(("path", "name"), PAGES, ids=[f"{p}?{n}" for p, n in PAGES])
def test_hostile_values_in_page_parameters_change_nothing(
    client: FlaskClient, kb: KnowledgeBase, path: str, name: str
) -> None:
    before = kb.store.dump()
    for value in HOSTILE:
        response = client.get(path, query_string={name: value})
        assert response.status_code < 500, (path, name, value, response.get_data(as_text=True)[:300])
        if response.status_code >= 400 and path.endswith(".json"):
            assert response.is_json and response.get_json()  # a clear error, not a bare status
    assert kb.store.dump() == before


def test_hostile_values_in_form_posts_and_run_ids_change_nothing(client: FlaskClient, kb: KnowledgeBase) -> None:
    before = kb.store.dump()
    for value in HOSTILE:
        started = client.post("/tasks.json", data={"task": value})
        assert started.status_code == 400 and "task" in started.get_json()["fields"]
        failing = client.post("/tasks.json", data={"task": "FetchMyPen", "fail": value})
        assert failing.status_code == 400, failing.get_data(as_text=True)[:300]
        assert client.get(f"/tasks/{value}.json").status_code in (400, 404)
    assert kb.store.dump() == before


def test_the_endpoint_takes_queries_but_no_update_or_graph_through_other_parameters(
    client: FlaskClient, kb: KnowledgeBase
) -> None:
    before = kb.store.dump()
    for value in HOSTILE:
        as_query = client.get("/sparql", query_string={"query": value})
        assert as_query.status_code == 400 and as_query.is_json
        graph = client.get("/sparql", query_string={"query": "ASK {}", "default-graph-uri": value})
        assert graph.status_code == 400
        named = client.get("/sparql", query_string={"query": "ASK {}", "named-graph-uri": value})
        assert named.status_code == 400
        shaped = client.get("/sparql", query_string={"query": "ASK {}", "format": value})
        assert shaped.status_code in (200, 406)
        no_token = client.post("/update", data={"update": f'INSERT DATA {{ <urn:a> <urn:b> "{value}" }}'})
        assert no_token.status_code == 403
        if "\n" not in value:  # no header can carry a newline
            wrong_token = client.post(
                "/update", data={"update": "DROP ALL"}, headers={"Authorization": f"Bearer {value}"}
            )
            assert wrong_token.status_code == 403
    dropped = client.get("/sparql", query_string={"query": "DROP ALL"})  # an update sent as a query
    assert dropped.status_code == 400
    assert kb.store.dump() == before


# -- injection through the CLI -----------------------------------------------------------------------


@pytest.fixture(scope="module")
def store_dir(tmp_path_factory: pytest.TempPathFactory) -> str:
    location = str(tmp_path_factory.mktemp("access") / "store")
    done = CliRunner().invoke(cli, ["--store", location, "init"])
    assert done.exit_code == 0, done.output
    return location


def dump_of(location: str) -> bytes:
    opened = KnowledgeBase.open(location)
    try:
        return opened.store.dump()
    finally:
        opened.close()


@pytest.fixture(scope="module")
def stored(store_dir: str) -> bytes:
    """The module store's dump as initialised, read once: no hostile value may change it."""
    return dump_of(store_dir)


CLI = (
    ("match", "{}"),
    ("match", "RobotSelfPosition", "--method", "{}"),
    ("plan", "{}"),
    ("show", "{}"),
    ("deregister", "{}"),
    ("query", "--name", "description", "--bind", "description={}"),
    ("query", "--name", "resource_triples", "--bind", "resource={}"),
    ("run", "{}"),
    ("run", "FetchMyPen", "--fail", "{}"),
)


@pytest.mark.parametrize("template", CLI, ids=[" ".join(t) for t in CLI])
def test_hostile_values_in_cli_arguments_change_nothing(
    store_dir: str, stored: bytes, template: tuple[str, ...]
) -> None:
    runner = CliRunner()
    for value in HOSTILE:
        argv = ["--store", store_dir, *(part.replace("{}", value) for part in template)]
        done = runner.invoke(cli, argv)
        assert "Traceback" not in done.output, (argv, done.output)
        assert not isinstance(done.exception, Exception) or isinstance(done.exception, SystemExit), (
            argv,
            repr(done.exception),
        )
        if template[0] != "query":  # a bound named query may just find nothing
            assert done.exit_code != 0, (argv, done.output)
            assert done.output.strip(), argv  # it says why
    assert dump_of(store_dir) == stored


def test_a_hostile_value_bound_to_a_named_query_is_data(store_dir: str) -> None:
    value = "urn:x> } ; DROP ALL ; { <urn:y"
    done = CliRunner().invoke(cli, ["--store", store_dir, "show", value])
    assert done.exit_code != 0
    assert "nothing in the store mentions" in done.output or "IRI" in done.output


# -- injection through the rosbridge services ------------------------------------------------------------


@pytest.fixture
def server(fresh_bundled_kb: KnowledgeBase) -> Iterator[Server]:
    yield from _serve(fresh_bundled_kb, EndpointConfig(update_token=TOKEN))


@pytest.fixture
def read_only_server(fresh_bundled_kb: KnowledgeBase) -> Iterator[Server]:
    yield from _serve(fresh_bundled_kb, EndpointConfig(update_token=TOKEN, read_only=True))


def _serve(kb: KnowledgeBase, endpoint: EndpointConfig) -> Iterator[Server]:
    threads = threading.active_count()
    running = Server(kb, ServeConfig(port=0, bridge_port=0, endpoint=endpoint))
    running.start()
    yield running
    running.stop(timeout=WAIT)
    assert_threads_end(threads, WAIT)


def test_hostile_values_in_bridge_service_arguments_change_nothing(server: Server) -> None:
    before = server.kb.store.dump()
    calls = (
        ("/cbrs/match", "requirement", {}),
        ("/cbrs/match", "method", {"requirement": "RobotSelfPosition"}),
        ("/cbrs/plan", "task", {}),
        ("/cbrs/plan", "objective", {"task": "FetchMyPen"}),
        ("/cbrs/run_task", "task", {}),
        ("/cbrs/task_status", "run", {}),
        ("/cbrs/query", "query", {}),
    )
    with bridge(server, TOKEN) as ws:  # with the token, so the values reach as far as they can
        for service, name, extra in calls:
            for value in HOSTILE:
                response = call(ws, service, {**extra, name: value})
                assert response["result"] is False, (service, name, value, response)
                assert response["values"], (service, value)  # the error says what was wrong
        for value in HOSTILE:
            failing = call(ws, "/cbrs/run_task", {"task": "FetchMyPen", "fail": [value]})
            assert failing["result"] is False
            rate = call(ws, "/cbrs/run_task", {"task": "FetchMyPen", "fault_rate": value})
            assert rate["result"] is False and "fault_rate" in str(rate["values"])
        impossible = call(ws, "/cbrs/run_task", {"task": "FetchMyPen", "fault_rate": 2})
        assert impossible["result"] is False and "rate" in str(impossible["values"])
    assert server.kb.store.dump() == before


CALLED = re.compile(r"\b(query|update|select)\b")


def test_no_library_code_builds_sparql_from_formatted_text() -> None:
    """Queries are named .rq files with bound values; the only text built in code is what pyoxigraph
    serialised (data blocks, VALUES for a remote store, the USING clauses of graph IRIs with which a remote
    store's copy reads the caller's own update over the union). An f-string, ``%`` or ``.format`` handed to
    ``query``/``update``/``select`` anywhere else would be a way in."""
    allowed = {Path("kb/store.py"), Path("kb/remote_store.py"), Path("kb/remote_updates.py")}
    found = []
    for package in ("kb", "reasoner", "actions", "cbrs", "sim"):
        for path in sorted((ROOT / package).rglob("*.py")):
            relative = path.relative_to(ROOT)
            if relative in allowed:
                continue
            source = path.read_text(encoding="utf-8")
            if not CALLED.search(source):  # a call of .query etc. has the name in its text: half the files parse
                continue
            for node in ast.walk(ast.parse(source)):
                if not (isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute)):
                    continue
                if node.func.attr not in ("query", "update", "select") or not node.args:
                    continue
                text = node.args[0]
                formatted = isinstance(text, ast.JoinedStr) or (
                    isinstance(text, ast.BinOp) and isinstance(text.op, (ast.Mod, ast.Add))
                )
                formatted |= (
                    isinstance(text, ast.Call) and isinstance(text.func, ast.Attribute) and text.func.attr == "format"
                )
                if formatted:
                    found.append(f"{relative}:{node.lineno}")
    assert found == []


# -- read-only, the token, where the server listens -------------------------------------------------------


def test_read_only_refuses_every_write_even_with_the_token(read_only_server: Server) -> None:
    server = read_only_server
    before = server.kb.store.dump()
    base = f"http://127.0.0.1:{server.http_port}"
    auth = {"Authorization": f"Bearer {TOKEN}"}
    update = httpx.post(base + "/update", data={"update": "DROP ALL"}, headers=auth, timeout=WAIT)
    assert update.status_code == 403 and "read-only" in update.json()["message"]
    via_sparql = httpx.post(base + "/sparql", data={"update": "DROP ALL"}, headers=auth, timeout=WAIT)
    assert via_sparql.status_code == 403
    task = httpx.post(base + "/tasks.json", data={"task": "FetchMyPen"}, headers={"Origin": base}, timeout=WAIT)
    assert task.status_code == 403 and "read-only" in task.json()["message"]
    with bridge(server) as ws:
        run = call(ws, "/cbrs/run_task", {"task": "FetchMyPen"})
        planned = call(ws, "/cbrs/plan", {"task": "FetchMyPen"})
    assert run["result"] is False and "read-only" in str(run["values"])
    assert planned["result"] is True and planned["values"]["status"] == "planned"
    assert planned["values"]["recorded"] is False
    assert server.kb.store.dump() == before
    assert httpx.get(base + "/sparql", params={"query": "ASK { ?s ?p ?o }"}, timeout=WAIT).json()["boolean"]


def test_the_same_writes_work_with_the_token_when_not_read_only(server: Server) -> None:
    base = f"http://127.0.0.1:{server.http_port}"
    update = httpx.post(
        base + "/update",
        data={"update": "INSERT DATA { GRAPH <https://w3id.org/cbrs/graph/world> { <urn:a> <urn:b> <urn:c> } }"},
        headers={"Authorization": f"Bearer {TOKEN}"},
        timeout=WAIT,
    )
    assert update.status_code == 204, update.text
    with bridge(server, TOKEN) as ws:
        planned = call(ws, "/cbrs/plan", {"task": "FetchMyPen"})
    assert planned["values"]["recorded"] is True
    assert bool(server.kb.query("ASK { ?plan cbrs:planFor req:FetchMyPen }"))


def _outside_address() -> str | None:
    """An address of this machine other than loopback, if it has one (no packet is sent)."""
    probe = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    try:
        probe.connect(("10.255.255.255", 1))
        address = str(probe.getsockname()[0])
    except OSError:
        return None
    finally:
        probe.close()
    return None if address.startswith("127.") else address


def test_the_server_listens_on_loopback_only_by_default(kb: KnowledgeBase) -> None:
    assert setting("host").resolve(environ={}) == "127.0.0.1"
    assert ServeConfig().host == "127.0.0.1"
    running = Server(kb, ServeConfig(port=0, bridge_port=0))
    running.start()
    try:
        for port in (running.http_port, running.bridge_port):
            with socket.create_connection(("127.0.0.1", port), timeout=WAIT):
                pass
            outside = _outside_address()
            if outside is not None:  # the same port on another of the machine's addresses: nobody there
                with pytest.raises(OSError):
                    socket.create_connection((outside, port), timeout=WAIT).close()
    finally:
        running.stop(timeout=WAIT)


def test_the_token_comes_from_the_environment_or_a_file_never_from_the_command_line(tmp_path: Path) -> None:
    runner = CliRunner()
    help_text = runner.invoke(cli, ["serve", "--help"]).output
    assert "--update-token-file" in help_text and "--update-token " not in help_text
    refused = runner.invoke(cli, ["--store", ":memory:", "serve", "--update-token", TOKEN])
    assert refused.exit_code == 2 and "No such option" in refused.output
    empty = tmp_path / "token"
    empty.write_text("\n", encoding="utf-8")
    blank = runner.invoke(cli, ["--store", ":memory:", "serve", "--update-token-file", str(empty)])
    assert blank.exit_code == 2 and "is empty" in blank.output
    shown = runner.invoke(cli, ["settings"], env={"CBRS_UPDATE_TOKEN": TOKEN})
    assert shown.exit_code == 0 and TOKEN not in shown.output and "(set)" in shown.output


def test_no_page_shows_the_token_and_flask_debug_stays_off(kb: KnowledgeBase, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("FLASK_DEBUG", "1")
    monkeypatch.setenv("CBRS_DEBUG", "1")
    sparql = SparqlService(kb, EndpointConfig(update_token=TOKEN))
    app = create_app(sparql, tasks=TaskRunner(kb, sparql.lock, camera=None))

    def explode() -> str:
        raise RuntimeError("secret internals")

    app.add_url_rule("/explode", view_func=explode)
    app.add_url_rule("/explode.json", view_func=explode)
    assert app.debug is False and not app.config.get("PROPAGATE_EXCEPTIONS")
    client = app.test_client()
    for path in ("/", "/.json", "/sparql", "/tasks.json", "/query.json"):
        body = client.get(path).get_data(as_text=True)
        assert TOKEN not in body, path
    for path in ("/explode", "/explode.json"):
        crashed = client.get(path)
        body = crashed.get_data(as_text=True)
        assert crashed.status_code == 500
        assert "Traceback" not in body and "secret internals" not in body and 'File "' not in body


# -- path traversal ------------------------------------------------------------------------------------------

TRAVERSALS = (
    "/static/../pyproject.toml",
    "/static/..%2f..%2fpyproject.toml",
    "/static/%2e%2e/%2e%2e/pyproject.toml",
    "/static/..%5c..%5cpyproject.toml",
    "/static//etc/passwd",
    "/static/%2fetc%2fpasswd",
    "/tasks/..%2f..%2fpyproject.toml",
    "/camera.jpg/../../pyproject.toml",
)


@pytest.mark.parametrize("path", TRAVERSALS)
def test_no_path_reaches_a_file_outside_the_static_folder(client: FlaskClient, path: str) -> None:
    response = client.get(path, follow_redirects=True)  # werkzeug merges "//" by redirecting
    body = response.get_data(as_text=True)
    assert response.status_code in (400, 404), (path, response.status_code)
    assert "[project]" not in body and "root:" not in body


def test_the_import_catalogue_keeps_iris_inside_its_folders(tmp_path: Path) -> None:
    folder = tmp_path / "ontology"
    folder.mkdir()
    (folder / "books.owl").write_text("<rdf:RDF/>", encoding="utf-8")
    (tmp_path / "private.owl").write_text("secret", encoding="utf-8")
    os.symlink(tmp_path / "private.owl", folder / "link.owl")
    catalogue = Catalogue(prefixes=[("http://127.0.0.1/ontology/", folder)])
    assert catalogue.resolve("http://127.0.0.1/ontology/books.owl") == (folder / "books.owl").resolve()
    for iri in (
        "http://127.0.0.1/ontology/../private.owl",
        "http://127.0.0.1/ontology/%2e%2e/private.owl",
        f"http://127.0.0.1/ontology/{tmp_path / 'private.owl'}",  # an absolute path after the prefix
        f"http://127.0.0.1/ontology/{str(tmp_path / 'private.owl').replace('/', '%2F')}",
        "http://127.0.0.1/ontology/link.owl",  # a symlink leading out
    ):
        assert catalogue.resolve(iri) is None, iri


def test_json_errors_name_the_parameter(client: FlaskClient) -> None:
    response = client.get("/resource.json", query_string={"iri": "} ; DROP ALL ; {"})
    assert response.status_code == 400
    assert "iri" in json.dumps(response.get_json())
