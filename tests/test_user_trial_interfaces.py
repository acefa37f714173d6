"""What a new user tripped on over HTTP and the CLI, trying every interface from the docs.

A 405 came without the ``Allow`` header and said only "The method is not allowed for the requested
URL."; a ``PUT /store`` that created a graph answered 201 labelled ``text/html`` with a page's security
headers and no body; the matchmaking page ignored ``method=`` (the spelling of ``cbrs match --method``
and of ``/cbrs/match``) and ranked by Sem-Str alone; ``cbrs settings``, ``register`` and
``deregister`` had no ``--json``; ``cbrs eval paper`` said nothing for its seconds of ranking; the
camera program took its bridge as ``--url``, not ``--bridge`` as ``cbrs run`` does.
"""

from __future__ import annotations

import errno
import functools
import io
import json
import logging
import re
import socket
from pathlib import Path
from typing import Any

import pyoxigraph as ox
import pytest
from click.testing import CliRunner
from flask.testing import FlaskClient

from cbrs import external_camera
from cbrs.bridge_services import KnowledgeServices
from cbrs.cli import cli
from cbrs.cli_actions import scenario_runs
from cbrs.cli_reasoner import match_config
from cbrs.cli_serve import _websockets_level
from cbrs.component import Component
from cbrs.component_protocol import READ_ONLY
from cbrs.kb import KnowledgeBase
from cbrs.kb.errors import KnowledgeBaseError
from cbrs.output import ProgressLine
from cbrs.rosbridge import Bridge, ServiceError
from cbrs.server import ServeConfig, Server
from cbrs.settings import setting
from cbrs.sparql_service import EndpointConfig, SparqlService
from cbrs.tasks import TaskRunner
from cbrs.web import create_app
from cbrs.web.components import blueprint as components_blueprint

TOKEN = "trial-token"
ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="module")
def client() -> FlaskClient:
    kb = KnowledgeBase.open(":memory:")
    return create_app(SparqlService(kb, EndpointConfig(update_token=TOKEN, isolate=False))).test_client()


@pytest.mark.parametrize(
    ("method", "path", "allowed"),
    [
        pytest.param("PATCH", "/store?graph=urn:x", {"GET", "HEAD", "PUT", "POST", "DELETE"}, id="graph-store"),
        pytest.param("DELETE", "/sparql", {"GET", "HEAD", "POST"}, id="sparql"),
        pytest.param("PUT", "/update", {"POST"}, id="update"),
        pytest.param("PUT", "/index.json", {"GET", "HEAD"}, id="json-twin"),
    ],
)
def test_a_405_names_the_methods_the_path_takes_in_allow_and_in_its_message(
    client: FlaskClient, method: str, path: str, allowed: set[str]
) -> None:
    answer = client.open(path, method=method, headers={"Accept": "*/*"})
    assert answer.status_code == 405
    assert {m.strip() for m in answer.headers["Allow"].split(",")} - {"OPTIONS"} == allowed
    body = answer.get_json()
    assert body["error"] == "method-not-allowed"
    assert body["message"] == f"{method} is not allowed on {path.split('?')[0]}: use {' or '.join(sorted(allowed))}"


@pytest.mark.parametrize("path", ["/tasks/run-9/cancel", "/resource?iri=home:Cup"], ids=["page", "resource-page"])
def test_a_405_on_a_page_is_a_page_with_allow_and_what_to_use(client: FlaskClient, path: str) -> None:
    answer = client.open(path, method="PUT", headers={"Accept": "text/html"})
    assert answer.status_code == 405 and answer.mimetype == "text/html"
    assert "Allow" in answer.headers
    assert f"PUT is not allowed on {path.split('?')[0]}: use " in answer.text


def test_a_graph_created_by_put_is_a_201_without_a_content_type(client: FlaskClient) -> None:
    headers = {"Authorization": f"Bearer {TOKEN}", "Content-Type": "text/turtle"}
    created = client.put("/store?graph=urn:trial:created", data="<urn:a> <urn:b> <urn:c> .", headers=headers)
    assert created.status_code == 201 and created.data == b""
    assert "Content-Type" not in created.headers and "Content-Security-Policy" not in created.headers


def test_the_matchmaking_page_reads_method_as_the_cli_and_the_bridge_spell_it(client: FlaskClient) -> None:
    asked = {"requirement": "req:RobotSelfPosition", "top": "2"}
    one = client.get("/match.json", query_string={**asked, "method": "wu-palmer"}).get_json()
    assert one["form"]["methods"] == ["wu-palmer"] and [r["method"] for r in one["rankings"]] == ["wu-palmer"]
    both = client.get("/match.json", query_string={**asked, "methods": "lin", "method": "logic"}).get_json()
    assert [r["method"] for r in both["rankings"]] == ["lin", "logic"]
    wrong = client.get("/match.json", query_string={**asked, "method": "wu_palmer"})
    assert wrong.status_code == 400 and "no method 'wu_palmer'" in wrong.get_json()["fields"]["methods"]


def test_cbrs_settings_json_gives_typed_values_and_hides_the_token() -> None:
    env = {"CBRS_UPDATE_TOKEN": "s3cret", "CBRS_STORE": "http://robot:pw@127.0.0.1:7878", "CBRS_PORT": "8181"}
    result = CliRunner().invoke(cli, ["settings", "--json"], env=env)
    assert result.exit_code == 0, result.output
    assert "s3cret" not in result.output and ":pw@" not in result.output
    listed = {item["setting"]: item for item in json.loads(result.output)}
    assert listed["update_token"]["value"] is True and listed["port"]["value"] == 8181
    assert listed["port"]["environment"] == "CBRS_PORT" and listed["port"]["help"]
    assert listed["store"]["value"] == "http://robot:***@127.0.0.1:7878"
    assert listed["cors_origins"]["value"] == [] and listed["read_only"]["value"] is False


def test_register_and_deregister_json_name_what_they_did(tmp_path: Path) -> None:
    store = ["--store", str(tmp_path / "store")]
    camera = str(ROOT / "docs" / "examples" / "camera3.ttl")
    iri = "https://w3id.org/cbrs/service#LocateMobileRobot_CeilingCamera03"
    runner = CliRunner()
    registered = runner.invoke(cli, [*store, "register", camera, "--json"])
    assert registered.exit_code == 0, registered.output
    assert json.loads(registered.output) == {"registered": [iri], "updated": []}
    updated = runner.invoke(cli, [*store, "register", "--update", camera, "--json"])
    assert json.loads(updated.output) == {"registered": [], "updated": [iri]}
    removed = runner.invoke(cli, [*store, "deregister", "svc:LocateMobileRobot_CeilingCamera03", "--json"])
    answer = json.loads(removed.output)
    assert removed.exit_code == 0 and answer["deregistered"] == iri and answer["triples"] > 0


def test_the_camera_program_takes_its_bridge_as_cbrs_run_does(capsys: pytest.CaptureFixture[str]) -> None:
    with socket.socket() as probe:  # a port nothing listens on
        probe.bind(("127.0.0.1", 0))
        url = f"ws://127.0.0.1:{probe.getsockname()[1]}"
    assert external_camera.main(["--bridge", url, "CeilingCamera01"]) == 1
    assert f"cannot reach the bridge at {url}" in capsys.readouterr().err


class _Figures:
    """Stands in for the evaluation's report: the seconds of ranking are not what is tested."""

    def text(self) -> str:
        return "figures"

    def to_json(self) -> dict[str, str]:
        return {"figures": "json"}


def test_eval_paper_says_what_it_is_doing_before_its_seconds_of_ranking(monkeypatch: pytest.MonkeyPatch) -> None:
    from cbrs.reasoner import evaluation

    monkeypatch.setattr(evaluation, "evaluate_paper", lambda methods, config: _Figures())
    shown = CliRunner().invoke(cli, ["eval", "paper", "--method", "sem-str", "--method", "lin"])
    assert shown.exit_code == 0, shown.output
    assert shown.stderr == "ranking the testbed's components for each requirement with sem-str, lin ...\n"
    assert shown.stdout == "figures\n"
    as_json = CliRunner().invoke(cli, ["eval", "paper", "--json"])
    assert as_json.stderr == "" and json.loads(as_json.stdout) == {"figures": "json"}


DESCRIPTION = """
@prefix svc: <https://w3id.org/cbrs/service#> . @prefix home: <https://w3id.org/cbrs/home#> .
@prefix cbrs: <https://w3id.org/cbrs/core#> .
svc:ReadRoomTemperature_Thermometer31 a cbrs:DynamicPerceptionComponent ;
    cbrs:deviceName "Thermometer31" ; cbrs:serviceName "ReadRoomTemperature" ;
    cbrs:serviceCategory "EnvironmentalSensing" ;
    cbrs:hasPort [ a cbrs:ServicePort ; cbrs:portName "read" ;
        cbrs:topic "/thermometer31/read" ; cbrs:messageType "cbrs_msgs/RoomTemperature" ] .
"""


def test_a_handler_that_cannot_take_the_request_is_refused_when_decorated() -> None:
    """It failed each call instead, with "<lambda>() takes 0 positional arguments but 1 was given"
    on the caller's side and in the component's log."""
    made = Component(DESCRIPTION)
    with pytest.raises(TypeError, match=r"the handler of /thermometer31/read must take one argument"):
        made.handler(lambda: {"celsius": 21.5})
    with pytest.raises(TypeError, match="must take one argument"):
        made.handler(lambda request, unit: {"celsius": 21.5})
    for fine in (lambda request: {}, lambda request, unit="C": {}, lambda *args: {}, dict):
        assert made.handler(fine) is fine


def _server_app(config: EndpointConfig) -> FlaskClient:
    """An app as cbrs serve builds it (its own origins known, /components served), over a fresh store."""
    app = create_app(
        SparqlService(KnowledgeBase.open(":memory:"), config), own_origins=lambda: ["http://127.0.0.1:8080"]
    )
    app.register_blueprint(components_blueprint)
    return app.test_client()


@pytest.fixture(scope="module")
def read_only() -> FlaskClient:
    return _server_app(EndpointConfig(update_token=TOKEN, read_only=True, isolate=False))


@pytest.fixture(scope="module")
def tokenless() -> FlaskClient:
    return _server_app(EndpointConfig(isolate=False))


@pytest.mark.parametrize("app", ["read_only", "tokenless"])
def test_a_server_that_takes_no_writes_registers_no_component_over_http(
    app: str, request: pytest.FixtureRequest
) -> None:
    """A --read-only server with a token took a registration over HTTP (the bridge refused it), and one
    without a token asked for the token it does not have."""
    client: FlaskClient = request.getfixturevalue(app)
    sent = client.post(
        "/components", data=DESCRIPTION, content_type="text/turtle", headers={"Authorization": f"Bearer {TOKEN}"}
    )
    assert sent.status_code == 403
    assert sent.get_json()["message"] == READ_ONLY
    assert client.get("/components").get_json() == []


def test_starting_a_task_says_what_would_work_on_this_server(read_only: FlaskClient, tokenless: FlaskClient) -> None:
    headers = {"Authorization": f"Bearer {TOKEN}"}
    disabled = read_only.post("/tasks/run-1/cancel.json")  # no token: none would help
    assert disabled.status_code == 403 and "this server is read-only" in disabled.get_json()["message"]
    no_token = tokenless.post("/tasks/run-1/cancel.json", headers=headers).get_json()["message"]
    assert "this server has no update token, so a run may be stopped only from its own tasks page" in no_token


def test_serve_on_an_address_not_of_this_machine_is_a_usage_error_not_a_backtrace() -> None:
    """With --port 0 the free-port check was skipped and Granian's bind failed with a Rust backtrace,
    after a warning that the server was "listening on" the address, reachable from other machines."""
    result = CliRunner().invoke(
        cli, ["--store", ":memory:", "serve", "--host", "192.0.2.1", "--port", "0", "--bridge-port", "0"]
    )
    assert result.exit_code == 2
    assert "192.0.2.1 is no address of this machine" in result.stderr and "--host" in result.stderr
    assert "warning: listening" not in result.stderr and "Traceback" not in result.stderr


def test_list_options_read_commas_as_their_help_and_environment_variables_do() -> None:
    """`--match-param a=off,b=0` was one parameter whose value was 'off,b=0'; `--cors-origin lab.example`
    (no scheme, so never an Origin a browser sends) was taken and matched nothing."""
    config = match_config(("consumer_steps=off,undone_state_factor=0",))
    assert config.consumer_steps is False and config.undone_state_factor == 0
    origins = setting("cors_origins").from_options(("https://lab.example/,http://10.0.0.5:8081", "https://b.example"))
    assert origins == ("https://lab.example", "http://10.0.0.5:8081", "https://b.example")
    refused = CliRunner().invoke(cli, ["--store", ":memory:", "serve", "--cors-origin", "lab.example"])
    assert refused.exit_code == 2 and "'lab.example' is not a web origin" in refused.stderr
    assert setting("cors_origins").from_options(()) is None  # not given: the environment or the default


def test_the_knowledge_services_refuse_a_field_they_do_not_read() -> None:
    """A misspelt optional field was ignored: /cbrs/match with "metod": "lin" ranked by Sem-Str. rosbridge
    refuses a field that the service's message type lacks."""
    sparql = SparqlService(KnowledgeBase.open(":memory:"))
    handlers = {
        name: handler
        for name, (_, handler) in KnowledgeServices(sparql, TaskRunner(sparql.kb, sparql.lock)).handlers().items()
    }
    with pytest.raises(
        ServiceError,
        match=r"/cbrs/match has no field 'metod' \(did you mean 'method'\?\): it takes requirement, method, top",
    ):
        handlers["/cbrs/match"]({"requirement": "RobotSelfPosition", "metod": "lin"})
    with pytest.raises(ServiceError, match="/cbrs/tasks has no field 'all': it takes no field"):
        handlers["/cbrs/tasks"]({"all": True})
    with pytest.raises(ServiceError, match="/cbrs/query has no field 'format'"):
        handlers["/cbrs/query"]({"query": "ASK {}", "format": "csv"})
    assert handlers["/cbrs/match"]({"requirement": "RobotSelfPosition", "method": "lin", "top": 1})["method"] == "lin"
    assert handlers["/cbrs/query"]({"query": "ASK {}"})["result"]["boolean"] is True


@pytest.mark.parametrize(
    ("level", "expected"), [("DEBUG", logging.DEBUG), ("INFO", logging.WARNING), ("ERROR", logging.ERROR)]
)
def test_websockets_own_connection_lines_show_only_when_debugging(level: str, expected: int) -> None:
    """cbrs.rosbridge logs each client's connection with its number; websockets' INFO lines said it again."""
    assert _websockets_level(level) == expected


def test_turtle_declares_only_the_prefixes_it_uses(client: FlaskClient) -> None:
    """`cbrs query 'CONSTRUCT ...'` and GET /store printed the 25 declared prefixes before any triple."""
    shown = CliRunner().invoke(
        cli, ["--store", ":memory:", "query", "CONSTRUCT { home:Cup ?p ?o } WHERE { home:Cup ?p ?o }"]
    )
    assert shown.exit_code == 0, shown.output
    declared = set(re.findall(r"^@prefix (\w+):", shown.stdout, re.M))
    assert {"home", "owl", "rdfs"} <= declared and not declared & {"svc", "req", "world", "qudt", "sosa"}
    assert len(list(ox.parse(shown.stdout.encode(), format=ox.RdfFormat.TURTLE))) >= 3
    headers = {"Authorization": f"Bearer {TOKEN}", "Content-Type": "text/turtle"}
    client.put("/store?graph=urn:trial:plain", data="<urn:a> <urn:b> <urn:c> .", headers=headers)
    plain = client.get("/store?graph=urn:trial:plain").text
    assert "@prefix" not in plain and "<urn:a> <urn:b> <urn:c>" in plain
    typed = client.get("/store?graph=https://w3id.org/cbrs/graph/map").text
    assert "@prefix world:" in typed and "@prefix req:" not in typed


def test_a_server_on_an_address_not_of_this_machine_fails_to_start_with_an_oserror(
    caplog: pytest.LogCaptureFixture,
) -> None:
    """Library use (tests, a lab's own launcher): Granian's bind raised a RuntimeError with a Rust
    backtrace, logged as well as raised."""
    server = Server(KnowledgeBase.open(":memory:"), ServeConfig(host="192.0.2.1", port=0, bridge_port=0))
    with pytest.raises(OSError) as failed:
        server.start()
    assert failed.value.errno == errno.EADDRNOTAVAIL
    assert not [r for r in caplog.records if r.levelno >= logging.ERROR]


def test_the_demo_says_which_scenario_it_runs_before_each_run(monkeypatch: pytest.MonkeyPatch) -> None:
    """The demo's three runs took 10-15 s after "the two scenarios, planned and run ..." with nothing on
    the screen. The world is refused here: what is tested is what is said before it opens."""
    from cbrs.sim import world

    class Opened(Exception):
        pass

    def refuse(**_: Any) -> None:
        raise Opened

    monkeypatch.setattr(world, "open_world", refuse)
    screen = io.StringIO()
    screen.isatty = lambda: True  # type: ignore[method-assign]
    shown = ProgressLine(screen, interval=0)
    with pytest.raises(Opened):
        scenario_runs(KnowledgeBase.open(":memory:"), progress=shown)
    assert screen.getvalue() == "\rrunning RobotArmServeACup 0/3 ..."


def test_a_path_nothing_serves_names_the_nearest_that_do(client: FlaskClient) -> None:
    """A 404 said "... If you entered the URL manually please check your spelling and try again."."""
    twin = client.get("/taxonmy.json")
    assert twin.status_code == 404
    assert twin.get_json()["message"].startswith("nothing is served at /taxonmy.json; did you mean /taxonomy.json")
    page = client.get("/sparq", headers={"Accept": "text/html"})
    assert page.status_code == 404 and "did you mean /sparql?" in page.text
    assert "did you mean" not in client.get("/zzzz.json").get_json()["message"]
    assert client.get("/tasks/run-9.json").get_json()["message"] == "no task run 'run-9'"  # a view's own 404 stays


def test_a_run_asked_for_in_json_refuses_a_body_it_cannot_read(client: FlaskClient) -> None:
    """Broken JSON or a list read as an empty form ("task: choose a task"); a misspelt field was dropped
    and the run started with the default."""
    post = functools.partial(client.post, "/tasks.json", content_type="application/json")
    broken = post(data="{bad")
    assert broken.status_code == 400 and broken.get_json()["message"].startswith("the body is not JSON")
    assert "a JSON list" in post(data="[1]").get_json()["message"]
    misspelt = post(data=json.dumps({"task": "PersonWhereabouts", "sed": 3}))
    assert misspelt.status_code == 400
    assert misspelt.get_json()["fields"] == {
        "sed": "no such field; did you mean 'seed'? a run takes task, seed, fail, fault_rate, repeat_failures,"
        " objective, base_ties, near_misses"
    }
    assert client.get("/tasks.json").get_json()["runs"] == []  # nothing started


def test_a_misspelt_query_parameter_is_named_not_answered_with_the_service_description(client: FlaskClient) -> None:
    """GET /sparql?qeury=... answered 200 with the endpoint's service description, as if no query was sent."""
    misspelt = client.get("/sparql", query_string={"qeury": "ASK {}"})
    assert misspelt.status_code == 400
    assert misspelt.get_json()["message"].startswith("GET /sparql has no parameter 'qeury': did you mean query=?")
    posted = client.post("/sparql", data={"updat": "CLEAR ALL"})
    assert posted.status_code == 400 and "(it has 'updat': did you mean update=?)" in posted.get_json()["message"]
    described = client.get("/sparql", query_string={"format": "json"})  # no query at all: the description
    assert described.status_code == 200 and "sparql-service-description" in described.text


def test_a_misspelt_graph_parameter_on_the_graph_store_writes_nothing(client: FlaskClient) -> None:
    """POST /store?grpah=IRI named no graph: a Turtle body went where cbrs load puts it."""
    before = client.get("/store", headers={"Accept": "application/n-quads"}).data
    headers = {"Authorization": f"Bearer {TOKEN}", "Content-Type": "text/turtle"}
    sent = client.post("/store?grpah=urn:trial:typo", data="<urn:typo> <urn:b> <urn:c> .", headers=headers)
    assert sent.status_code == 400
    assert sent.get_json()["message"] == "/store has no parameter 'grpah': did you mean graph=?"
    assert client.get("/store", headers={"Accept": "application/n-quads"}).data == before


def test_a_store_url_that_is_a_rosbridge_port_says_which_port_to_give() -> None:
    """`cbrs --store http://127.0.0.1:9090 ...` (the bridge, not the endpoint) said only "request to
    .../query failed: Server disconnected without sending a response."."""
    with Bridge().start(host="127.0.0.1", port=0) as running, pytest.raises(KnowledgeBaseError) as failed:
        KnowledgeBase.open(f"http://127.0.0.1:{running.port}")
    assert "closed the connection without an HTTP answer" in str(failed.value)
    assert "not its bridge port (9090)" in str(failed.value)
