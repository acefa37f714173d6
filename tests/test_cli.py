"""The cbrs command as a person meets it: exit codes and the messages shown."""

from __future__ import annotations

import json
import logging
import socket
import sys
from collections.abc import Iterator
from pathlib import Path

import pytest
from click.testing import CliRunner

from cbrs import __version__
from cbrs.cli import cli, main
from cbrs.kb import KnowledgeBase
from cbrs.task_names import task_iri

BAD = Path(__file__).parent / "data" / "bad"
DATA = Path(__file__).parent / "data"


@pytest.fixture(scope="module")
def store(tmp_path_factory: pytest.TempPathFactory) -> str:
    """An on-disk store seeded once for the module; tests that write use their own."""
    location = str(tmp_path_factory.mktemp("cli") / "store")
    result = CliRunner().invoke(cli, ["--store", location, "init"])
    assert result.exit_code == 0, result.output
    return location


def run(*args: str, store: str | None = None, env: dict[str, str] | None = None) -> tuple[int, str]:
    argv = (["--store", store] if store else []) + list(args)
    result = CliRunner().invoke(cli, argv, env=env)
    return result.exit_code, result.output


def test_version() -> None:
    code, out = run("--version")
    assert code == 0 and __version__ in out


def test_init_reports_graphs_and_is_idempotent(tmp_path: Path) -> None:
    location = str(tmp_path / "s")
    code, first = run("init", store=location)
    assert code == 0
    assert "graph:ontology" in first and "advertisements" in first
    code, second = run("init", store=location)
    assert code == 0 and second == first


def test_named_query_lists_locate_mobile_robot_as_json(store: str) -> None:
    code, out = run("query", "--name", "advertisements", "--format", "json", store=store)
    assert code == 0
    rows = {b["service"]["value"]: b for b in json.loads(out)["results"]["bindings"]}
    locate = rows["https://w3id.org/cbrs/service#LocateMobileRobot_CeilingCamera01"]
    assert locate["inputs"]["value"] == "https://w3id.org/cbrs/home#MarkerColour"
    assert locate["outputs"]["value"] == "https://w3id.org/cbrs/home#RobotLocation"
    assert locate["kind"]["value"] == "https://w3id.org/cbrs/core#DynamicPerceptionComponent"


def test_named_query_with_binding(store: str) -> None:
    code, out = run(
        "query",
        "--name",
        "description_parameters",
        "--bind",
        "description=req:RobotSelfPosition",
        store=store,
    )
    assert code == 0
    assert "home:RobotPosition" in out and "output" in out


def test_deregister_names_what_it_looked_for_and_a_mistyped_prefix(store: str) -> None:
    code, out = run("deregister", "svc:NoSuchCamera", store=store)
    assert code == 1 and "no registered advertisement or requirement" in out and "prefix" not in out
    code, out = run("deregister", "lab:Cam", store=store)  # a prefix nobody declared: a usage error
    assert code == 2 and "lab: is declared nowhere and is no IRI scheme cbrs reads bare" in out


def test_a_parameter_bound_twice_is_refused(store: str) -> None:
    code, out = run("query", "--name", "advertisements", "--bind", "kind=cbrs:A", "--bind", "kind=cbrs:B", store=store)
    assert code == 2 and "kind is bound twice" in out
    code, _ = run("query", "--name", "advertisements", "--bind", "kind=cbrs:A", "--bind", "kind=cbrs:A", store=store)
    assert code == 0  # the same value twice says one thing


@pytest.mark.parametrize(
    ("fmt", "expected"),
    [
        ("table", "home:Cup"),
        ("csv", "https://w3id.org/cbrs/home#Cup"),
        ("tsv", "<https://w3id.org/cbrs/home#Cup>"),
    ],
)
def test_query_text_in_formats(store: str, fmt: str, expected: str) -> None:
    code, out = run("query", "SELECT ?c WHERE { BIND(home:Cup AS ?c) }", "--format", fmt, store=store)
    assert code == 0 and expected in out


def test_ask_and_construct(store: str) -> None:
    assert run("query", "ASK { home:Cup a owl:Class }", store=store) == (0, "true\n")
    code, out = run("query", "CONSTRUCT { home:Cup a owl:Class } WHERE {}", store=store)
    assert code == 0 and "home:Cup a owl:Class" in out


def test_query_from_file(store: str, tmp_path: Path) -> None:
    path = tmp_path / "q.rq"
    path.write_text("SELECT (COUNT(*) AS ?n) WHERE { ?s a cbrs:Requirement }", encoding="utf-8")
    code, out = run("query", "--file", str(path), "--format", "csv", store=store)
    assert code == 0 and out.splitlines()[0] == "n" and int(out.splitlines()[1]) >= 1


def test_query_list_names_queries_and_parameters(store: str) -> None:
    code, out = run("query", "--list", store=store)
    assert code == 0
    assert "advertisements" in out and "description*:iri" in out


def test_syntax_error_is_one_line(store: str) -> None:
    code, out = run("query", "SELECT ?x WHERE { ?x", store=store)
    assert code == 1
    assert out.startswith("Error: SPARQL syntax error")
    assert out.count("\n") == 1 and "Traceback" not in out
    assert "the text ends with 1 '{' not closed" in out  # not the parser's list of every token


@pytest.mark.parametrize(
    ("args", "code", "message"),
    [
        (["query"], 2, "give exactly one of TEXT, --file or --name"),
        (["query", "ASK {}", "--name", "advertisements"], 2, "give exactly one"),
        (["query", "--name", "advertisements", "--bind", "kind"], 2, "is not VAR=VALUE"),
        (["query", "--name", "advertisements", "--bind", "knd=x"], 1, "takes no such parameter"),
        (["query", "--name", "nosuch"], 1, "no named query 'nosuch'"),
        (["query", "ASK {}", "--bind", "a=b"], 2, "--bind works with --name"),
        (["show", "hme:Cup"], 2, "hme: is declared nowhere and is no IRI scheme cbrs reads bare; did you mean home:"),
        (["show", "not an iri"], 2, "neither an absolute IRI nor a prefixed name"),
        (["show", "svc:NoSuchThing"], 1, "nothing in the store mentions"),
        (["load", "--graph", "servces", str(DATA / "mini_services.ttl")], 1, "unknown graph 'servces'"),
        (["load", str(BAD / "unknown.format")], 1, "cannot tell the RDF format"),
    ],
)
def test_errors_name_what_was_wrong(store: str, args: list[str], code: int, message: str) -> None:
    got_code, out = run(*args, store=store)
    assert got_code == code, out
    assert message in out
    assert "Traceback" not in out


def test_broken_file_loads_nothing(tmp_path: Path) -> None:
    location = str(tmp_path / "s")
    count = "SELECT (COUNT(*) AS ?n) WHERE { GRAPH ?g { ?s ?p ?o } }"
    code, before = run("query", count, "--format", "csv", store=location)
    assert code == 0
    code, out = run("load", str(DATA / "mini_services.ttl"), str(BAD / "broken.ttl"), store=location)
    assert code == 1
    assert f"{BAD / 'broken.ttl'}:4:" in out and out.count("\n") == 1
    assert run("query", count, "--format", "csv", store=location) == (0, before)


def test_load_says_where_each_file_went(tmp_path: Path) -> None:
    code, out = run("load", str(DATA / "mini_ontology.ttl"), str(DATA / "mini_services.ttl"), store=str(tmp_path / "s"))
    assert code == 0
    assert "mini_ontology.ttl: 39 triples into graph:ontology" in out
    assert "into graph:services" in out


def test_load_counts_each_graph_a_trig_file_names(tmp_path: Path) -> None:
    trig = tmp_path / "lab.trig"
    trig.write_text(
        "@prefix ex: <http://example.org/> .\nex:a ex:p ex:b .\nex:g1 { ex:c ex:p ex:d . ex:e ex:p ex:f . }\n"
    )
    code, out = run("load", str(trig), store=str(tmp_path / "s"))
    assert code == 0
    # the store's own namespace, by the prefix the browser derives for it (docs/web.md)
    assert "lab.trig: 3 triples: 2 into example:g1, 1 into graph:services" in out


def test_services_table(store: str) -> None:
    code, out = run("services", store=store)
    assert code == 0
    line = next(ln for ln in out.splitlines() if "LocateMobileRobot_CeilingCamera01" in ln)
    assert "DynamicPerception" in line and "home:MarkerColour" in line and "home:RobotLocation" in line
    code, out = run("services", "--json", store=store)
    assert code == 0 and any(r["serviceName"] == "LocateMobileRobot" for r in json.loads(out))


def test_show_six_tuple(store: str) -> None:
    code, out = run("show", "svc:LocateMobileRobot_CeilingCamera01", store=store)
    assert code == 0
    for expected in (
        "SN           LocateMobileRobot",
        "input        home:MarkerColour",
        "output       home:RobotLocation",
    ):
        assert expected in out
    code, out = run("show", "svc:LocateMobileRobot_CeilingCamera01", "--json", store=store)
    assert json.loads(out)["service_name"] == "LocateMobileRobot"


def test_show_names_the_delete_effects(store: str) -> None:
    code, out = run("show", "svc:PickUpObject_CytonDualArm01", store=store)
    assert code == 0
    assert "effect       (home:PhysicalObject, home:isGraspedBy, home:Gripper)" in out
    assert "deletes      (home:PhysicalObject, home:isLocated, home:Place)" in out


def test_show_any_resource(store: str) -> None:
    code, out = run("show", "home:Cup", store=store)
    assert code == 0
    assert "rdf:type" in out and "owl:Class" in out and "graph:ontology" in out


def test_settings_lists_environment_variables() -> None:
    code, out = run("settings", env={"CBRS_STORE": ":memory:"})
    assert code == 0 and "CBRS_STORE" in out and ":memory:" in out


def test_bad_format_from_environment_is_reported(store: str) -> None:
    code, out = run("query", "ASK {}", store=store, env={"CBRS_FORMAT": "yaml"})
    assert code == 2 and "'yaml' is not one of" in out


def test_demo_tours_the_paper_example() -> None:
    code, out = run("demo", store=":memory:")
    assert code == 0, out
    assert "Table 1" in out and "LocateMobileRobot" in out and "RobotSelfPosition" in out
    assert "matched by sem-str; best svc:LocateMobileRobot_CeilingCamera01" in out
    runs = [line.split()[:3] for line in out.splitlines() if line.startswith(("RobotArmServeACup ", "FetchMyPen "))]
    assert runs[:2] == [["RobotArmServeACup", "10", "succeeded"], ["FetchMyPen", "15", "succeeded"]]
    assert "FetchMyPen (fail svc:LocateMobileRobot_CeilingCamera01)  15     succeeded" in out
    assert "2 x svc:LocateMobileRobot_CeilingCamera01 -> svc:LocateMobileRobot_CeilingCamera02" in out
    assert "(world:Pen, home:isWith, world:Person)" in out


def test_unexpected_errors_are_one_line(monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]) -> None:
    def explode(*_: object, **__: object) -> None:
        raise RuntimeError("disk on fire")

    monkeypatch.setattr("cbrs.app.KnowledgeBase.open", explode)
    monkeypatch.setattr(sys, "argv", ["cbrs", "--store", ":memory:", "services"])
    monkeypatch.delenv("CBRS_DEBUG", raising=False)
    with pytest.raises(SystemExit) as caught:
        main()
    assert caught.value.code == 2
    err = capsys.readouterr().err
    assert err == "internal error: RuntimeError: disk on fire (set CBRS_DEBUG=1 for the traceback)\n"


def test_register_update_deregister_round_trip(tmp_path: Path) -> None:
    location = str(tmp_path / "s")
    turtle = tmp_path / "cam.ttl"
    body = """@prefix cbrs: <https://w3id.org/cbrs/core#> . @prefix svc: <https://w3id.org/cbrs/service#> .
    @prefix home: <https://w3id.org/cbrs/home#> .
    svc:LocateMobileRobot_CeilingCamera03 a cbrs:DynamicPerceptionComponent ;
      cbrs:deviceName "CeilingCamera03" ; cbrs:serviceName "LocateMobileRobot" ;
      cbrs:hasOWLSModel [ cbrs:hasInput [ cbrs:parameterType home:MarkerColour ] ;
                          cbrs:hasOutput [ cbrs:parameterType home:OUTPUT ] ] ."""
    turtle.write_text(body.replace("OUTPUT", "RobotLocation"), encoding="utf-8")
    before = run("query", "SELECT (COUNT(*) AS ?n) WHERE { GRAPH ?g { ?s ?p ?o } }", store=location)
    assert run("register", str(turtle), store=location) == (
        0,
        "registered svc:LocateMobileRobot_CeilingCamera03\n",
    )
    code, out = run("register", str(turtle), store=location)
    assert code == 1 and "already registered; update it instead" in out
    turtle.write_text(body.replace("OUTPUT", "RobotPose"), encoding="utf-8")
    assert run("register", "--update", str(turtle), store=location)[0] == 0
    code, out = run("show", "svc:LocateMobileRobot_CeilingCamera03", store=location)
    assert "home:RobotPose" in out and "home:RobotLocation" not in out
    code, out = run("deregister", "svc:LocateMobileRobot_CeilingCamera03", store=location)
    assert code == 0 and out.startswith("deregistered svc:LocateMobileRobot_CeilingCamera03")
    assert run("query", "SELECT (COUNT(*) AS ?n) WHERE { GRAPH ?g { ?s ?p ?o } }", store=location) == before


# -- serving and running where the machine says no ------------------------------------------------


@pytest.fixture
def taken_port() -> Iterator[int]:
    """A loopback port another process (here: this one) is listening on."""
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as holder:
        holder.bind(("127.0.0.1", 0))
        holder.listen(1)
        yield holder.getsockname()[1]


@pytest.mark.parametrize(
    ("option", "hint"), [("--port", "--port or CBRS_PORT"), ("--bridge-port", "--bridge-port or CBRS_BRIDGE_PORT")]
)
def test_serve_on_a_port_in_use_names_the_port(taken_port: int, option: str, hint: str) -> None:
    other = "--bridge-port" if option == "--port" else "--port"
    code, out = run("serve", option, str(taken_port), other, "0", store=":memory:")
    assert code == 1, out
    assert f"Error: port {taken_port} on 127.0.0.1 is already in use" in out
    assert hint in out and "internal error" not in out


def test_serve_takes_its_log_level_from_the_setting(monkeypatch: pytest.MonkeyPatch) -> None:
    root = logging.getLogger()
    monkeypatch.setattr(root, "level", root.level)  # restored afterwards
    monkeypatch.setattr("cbrs.server.Server.serve_forever", lambda self, ready=None: None)
    code, out = run("serve", "--port", "0", "--bridge-port", "0", store=":memory:", env={"CBRS_LOG_LEVEL": "warning"})
    assert code == 0, out
    assert root.level == logging.WARNING
    code, out = run("serve", "--log-level", "debug", "--port", "0", "--bridge-port", "0", store=":memory:")
    assert code == 0 and root.level == logging.DEBUG
    code, out = run("serve", store=":memory:", env={"CBRS_LOG_LEVEL": "loud"})
    assert code == 1 and "CBRS_LOG_LEVEL='loud': 'loud' is not a log level (DEBUG, INFO" in out


@pytest.mark.parametrize(
    ("environ", "reason"),
    [
        pytest.param({}, "DISPLAY is not set", id="unset"),
        pytest.param({"DISPLAY": ":987"}, "no X server listens on DISPLAY=:987", id="no-server"),
        pytest.param({"DISPLAY": "wayland"}, "is not an X display name", id="malformed"),
    ],
)
def test_run_gui_without_a_display_says_why(
    monkeypatch: pytest.MonkeyPatch, environ: dict[str, str], reason: str
) -> None:
    if not sys.platform.startswith("linux"):
        pytest.skip("only X11 needs a display found first")
    monkeypatch.delenv("DISPLAY", raising=False)
    for name, value in environ.items():
        monkeypatch.setenv(name, value)
    code, out = run("run", "FetchMyPen", "--gui", store=":memory:")
    assert code != 0
    assert "--gui needs a display" in out and reason in out and "xvfb-run" in out


# -- task names ------------------------------------------------------------------------------------

LAB_TASK = """@prefix cbrs: <https://w3id.org/cbrs/core#> . @prefix home: <https://w3id.org/cbrs/home#> .
@prefix lab: <http://example.org/lab#> .
lab:WhereIsMyRobot a cbrs:Requirement ; cbrs:deviceName "P3DX01" ; cbrs:serviceName "WhereIsMyRobot" ;
  cbrs:hasOWLSModel [ cbrs:hasInput [ cbrs:parameterType home:ColourOfMarker ] ;
                      cbrs:hasOutput [ cbrs:parameterType home:RobotPosition ] ] .
"""


@pytest.fixture(scope="module")
def lab_store(tmp_path_factory: pytest.TempPathFactory) -> str:
    """A store with a requirement under a namespace of its own, and one whose name a lab namespace shares."""
    folder = tmp_path_factory.mktemp("lab")
    (folder / "lab.ttl").write_text(
        LAB_TASK + LAB_TASK.replace("lab#>", "lab2#>").replace("Robot a", "Robot2 a"), "utf-8"
    )
    location = str(folder / "store")
    code, out = run("load", "--graph", "requirements", str(folder / "lab.ttl"), store=location)
    assert code == 0, out
    return location


def test_a_listed_task_of_another_namespace_plans_by_its_bare_name(lab_store: str) -> None:
    code, out = run("plan", "WhereIsMyRobot", "--no-store", store=lab_store)
    assert code == 0, out
    assert out.startswith("lab:WhereIsMyRobot: planned")  # the prefix the browser derives for lab#
    code, out = run("plan", "<http://example.org/lab2#WhereIsMyRobot2>", "--no-store", store=lab_store)
    assert code == 0, out


@pytest.mark.parametrize(
    ("command", "name", "message"),
    [
        ("plan", "WhereIsMyRobt", "no requirement or action named 'WhereIsMyRobt'; did you mean WhereIsMyRobot"),
        ("run", "RobotSelfPositon", "did you mean RobotSelfPosition?"),
        ("plan", "fetchmypen", "did you mean FetchMyPen or act:FetchMyPen?"),
        ("plan", "MakeCoffee", "no requirement or action named 'MakeCoffee'. Known tasks: FallDownAlert"),
    ],
)
def test_an_unknown_task_gets_a_did_you_mean(lab_store: str, command: str, name: str, message: str) -> None:
    code, out = run(command, name, store=lab_store)
    assert code == 1 and message in out, out
    known = out.split("Known tasks: ", 1)[1].strip().split(", ")
    assert "WhereIsMyRobot" in known and "RobotSelfPosition" in known


def test_every_listed_task_name_resolves(lab_store: str) -> None:
    _, out = run("plan", "NoSuchTask", store=lab_store)
    listed = out.split("Known tasks: ", 1)[1].strip().split(", ")
    assert "WhereIsMyRobot2" in listed and "act:FetchMyPen" in listed
    kb = KnowledgeBase.open(lab_store)
    try:
        resolved = {name: task_iri(kb, name) for name in listed}  # TaskNameError for any that does not
    finally:
        kb.close()
    assert resolved["WhereIsMyRobot2"] == "http://example.org/lab2#WhereIsMyRobot2"
    assert len(set(resolved.values())) == len(listed)


def test_a_refused_run_with_json_prints_json(tmp_path: Path) -> None:
    """A script that asks for JSON gets a JSON document for a run refused before anything moved (two
    pens in the map: which one to fetch?), as for one that ran; it got nothing on stdout."""
    second_pen = Path(__file__).parent / "data" / "second_pen.ttl"
    location = str(tmp_path / "store")
    assert run("load", "--graph", "map", str(second_pen), store=location)[0] == 0
    result = CliRunner().invoke(cli, ["--store", location, "run", "FetchMyPen", "--json"])
    assert result.exit_code == 1
    refused = json.loads(result.stdout)
    assert refused["status"] == "error" and refused["task"].endswith("FetchMyPen")
    assert refused["error"].startswith("AmbiguousDesignatorError") and "Pen2" in refused["error"]
    assert "Pen2" in result.stderr


def test_a_plan_the_matchmaker_found_says_so_and_shows_its_pairs_as_the_explanation_does(store: str) -> None:
    """RobotSelfPosition is met by one advertisement the matchmaker ranks (the paper's Position for
    Location): the text said "decomposed into " with nothing after it, and the goal's degree "Fail"
    where `cbrs match --explain` shows the same pair as "Similar"."""
    code, out = run("plan", "RobotSelfPosition", store=store)
    assert code == 0, out
    assert "planned (matched to one component by the matchmaker), 1 step," in out.splitlines()[0]
    code, out = run("plan", "RobotSelfPosition", "--json", store=store)
    plan = json.loads(out)
    assert plan["method"] == "matched"
    explained = run("match", "req:RobotSelfPosition", "--explain", store=store)[1]
    for goal in plan["goals"]:
        assert goal["degree"] != "Fail"
        assert f"{goal['degree']} " in explained  # the explanation's word for the same pair
