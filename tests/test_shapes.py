"""Service descriptions checked against ontologies/shapes.ttl and the declared terms, on every way in.

Each bad description is refused with a message naming the description, what is wrong and (for a
misspelt term) the term meant; the store is unchanged afterwards.
"""

from __future__ import annotations

import re
from collections.abc import Iterator
from pathlib import Path

import pytest
from click.testing import CliRunner

from cbrs.cli import cli
from cbrs.kb import KnowledgeBase
from cbrs.kb.errors import InvalidDescriptionError
from cbrs.kb.namespaces import GraphName
from cbrs.kb.shapes import DescriptionShapeError, check_descriptions

ROOT = Path(__file__).resolve().parents[1]
OWLS = Path(__file__).parent / "data" / "owls"

GOOD = """@prefix cbrs: <https://w3id.org/cbrs/core#> . @prefix svc: <https://w3id.org/cbrs/service#> .
@prefix home: <https://w3id.org/cbrs/home#> .
svc:LocateMobileRobot_CeilingCamera03 a cbrs:DynamicPerceptionComponent ;
  cbrs:deviceName "CeilingCamera03" ; cbrs:serviceName "LocateMobileRobot" ;
  cbrs:hasOWLSModel [ cbrs:hasInput [ cbrs:parameterType home:MarkerColour ] ;
                      cbrs:hasOutput [ cbrs:parameterType home:RobotLocation ] ] ;
  cbrs:hasSEAModel [ cbrs:effectiveArea home:Kitchen ;
                     cbrs:minX 6.0 ; cbrs:maxX 10.0 ; cbrs:minY 0.0 ; cbrs:maxY 5.0 ] ;
  cbrs:hasQoSModel [ cbrs:responseTime 0.1 ; cbrs:availability 0.9 ] .
"""
CAMERA = "https://w3id.org/cbrs/service#LocateMobileRobot_CeilingCamera03"

# (what to change in GOOD, what the message must say)
BAD = [
    pytest.param(
        ("home:MarkerColour", "home:MarkerColor"),
        "home:MarkerColor is declared nowhere in the store or in this input (as cbrs:parameterType); "
        "did you mean home:MarkerColour?",
        id="misspelt-class",
    ),
    pytest.param(
        ("a cbrs:DynamicPerceptionComponent", "a cbrs:DynamicPerceptionComponnet"),
        "cbrs:DynamicPerceptionComponnet is declared nowhere in the store or in this input (as rdf:type); "
        "did you mean cbrs:DynamicPerceptionComponent?",
        id="misspelt-kind",
    ),
    pytest.param(
        ("cbrs:responseTime 0.1", "cbrs:responsTime 0.1"),
        "the property cbrs:responsTime is declared nowhere in the store or in this input; "
        "did you mean cbrs:responseTime?",
        id="misspelt-property",
    ),
    pytest.param(
        ("cbrs:minX 6.0 ; cbrs:maxX 10.0", "cbrs:minX 10.0 ; cbrs:maxX 6.0"),
        "the SEA box is reversed: cbrs:minX is greater than cbrs:maxX; got cbrs:minX 10.0",
        id="reversed-box",
    ),
    pytest.param(
        ("cbrs:responseTime 0.1", 'cbrs:responseTime "fast"'),
        'cbrs:responseTime is one number of seconds, 0 or more (0.1, not "fast"); got cbrs:responseTime "fast"',
        id="word-for-a-number",
    ),
    pytest.param(
        ("cbrs:availability 0.9", "cbrs:availability 90"),
        "cbrs:availability is one number from 0 to 1; got cbrs:availability 90",
        id="out-of-range",
    ),
    pytest.param(
        ("cbrs:minY 0.0 ; cbrs:maxY 5.0", ""),
        "the SEA box needs all four of cbrs:minX, cbrs:maxX, cbrs:minY and cbrs:maxY, or none",
        id="half-a-box",
    ),
    pytest.param(
        ("cbrs:parameterType home:RobotLocation", "cbrs:parameterType home:RobotLocation , home:RobotPose"),
        "a parameter has exactly one cbrs:parameterType",
        id="two-parameter-types",
    ),
    pytest.param(
        ('cbrs:deviceName "CeilingCamera03"', "cbrs:deviceName svc:CeilingCamera03"),
        "the device name (DN) is one string, on one line and not empty; got cbrs:deviceName svc:CeilingCamera03",
        id="device-for-its-name",
    ),
]


def bad(change: tuple[str, str]) -> str:
    old, new = change
    assert old in GOOD
    return GOOD.replace(old, new)


@pytest.fixture(scope="module")
def shared() -> Iterator[KnowledgeBase]:
    """A seeded store that every refused write must leave as it was."""
    kb = KnowledgeBase.open(":memory:")
    yield kb
    kb.close()


@pytest.mark.parametrize(("change", "message"), BAD)
def test_registration_refuses_with_the_reason(shared: KnowledgeBase, change: tuple[str, str], message: str) -> None:
    before = shared.store.dump()
    with pytest.raises(DescriptionShapeError) as caught:
        shared.registry.register(bad(change), "camera3.ttl")
    assert str(caught.value).startswith(f"<{CAMERA}> is not a valid service description: ")
    assert message in str(caught.value)
    assert caught.value.iri == CAMERA and caught.value.http_status == 400
    assert isinstance(caught.value, InvalidDescriptionError)  # what callers of the registry already catch
    assert shared.store.dump() == before


def test_a_good_description_registers(shared: KnowledgeBase) -> None:
    assert shared.registry.register(GOOD) == [CAMERA]
    shared.registry.deregister(CAMERA)


def test_every_bundled_description_conforms(shared: KnowledgeBase) -> None:
    graphs = (GraphName.SERVICES, GraphName.REQUIREMENTS, GraphName.ONTOLOGY, GraphName.MAP)
    check_descriptions(shared.store, [q for g in graphs for q in shared.store.quads(graph=g.node)])


def test_cli_register_names_the_term_meant(tmp_path: Path) -> None:
    path = tmp_path / "camera3.ttl"
    path.write_text(bad(("home:MarkerColour", "home:MarkerColor")), encoding="utf-8")
    result = CliRunner().invoke(cli, ["--store", ":memory:", "register", str(path)])
    assert result.exit_code == 1
    assert result.output.startswith(
        f"Error: {path}:3: <https://w3id.org/cbrs/service#LocateMobileRobot_CeilingCamera03>"
    )
    assert "did you mean home:MarkerColour?" in result.output and result.output.count("\n") == 1


def test_load_refuses_a_broken_description_and_loads_nothing(tmp_path: Path) -> None:
    good, broken = tmp_path / "a_good.ttl", tmp_path / "b_broken.ttl"
    good.write_text(GOOD.replace("CeilingCamera03 a", "CeilingCamera09 a"), encoding="utf-8")
    broken.write_text(bad(("cbrs:minX 6.0 ; cbrs:maxX 10.0", "cbrs:minX 10.0 ; cbrs:maxX 6.0")), encoding="utf-8")
    kb = KnowledgeBase.open(":memory:")
    before = kb.store.dump()
    with pytest.raises(DescriptionShapeError, match="the SEA box is reversed"):
        kb.load([good, broken])
    assert kb.store.dump() == before
    kb.load([good])  # alone it loads


def test_load_accepts_a_class_declared_in_the_same_load(tmp_path: Path) -> None:
    ontology = tmp_path / "lab.ttl"
    ontology.write_text(
        "@prefix owl: <http://www.w3.org/2002/07/owl#> . @prefix home: <https://w3id.org/cbrs/home#> .\n"
        "home:MarkerShade a owl:Class .\n",
        encoding="utf-8",
    )
    services = tmp_path / "camera.ttl"
    services.write_text(bad(("home:MarkerColour", "home:MarkerShade")), encoding="utf-8")
    kb = KnowledgeBase.open(":memory:")
    kb.load([ontology, services])
    assert CAMERA in kb.registry.description_quads(CAMERA)[0].subject.value


def test_a_task_written_without_its_type_is_refused_not_loaded_as_nothing(tmp_path: Path) -> None:
    """Without ``a cbrs:Requirement`` a task file loaded quietly and the task then "did not exist"."""
    task = (Path(__file__).parent / "data" / "tasks" / "fetch_my_pencil.ttl").read_text(encoding="utf-8")
    untyped = tmp_path / "untyped.ttl"
    untyped.write_text(task.replace("req:FetchMyPencil a cbrs:Requirement ;", "req:FetchMyPencil"), encoding="utf-8")
    kb = KnowledgeBase.open(":memory:")
    before = kb.store.dump()
    with pytest.raises(DescriptionShapeError, match="a description says what it is: a cbrs:Requirement") as refused:
        kb.load([untyped], graph="requirements")
    assert "untyped.ttl:11: <https://w3id.org/cbrs/requirement#FetchMyPencil>" in str(refused.value)
    assert kb.store.dump() == before


def test_an_update_inserting_a_broken_description_is_refused() -> None:
    kb = KnowledgeBase.open(":memory:")
    before = kb.store.dump()
    body = bad(("cbrs:responseTime 0.1", 'cbrs:responseTime "fast"'))
    _, _, triples = body.rpartition("home#> .\n")
    update = (
        "PREFIX cbrs: <https://w3id.org/cbrs/core#> PREFIX svc: <https://w3id.org/cbrs/service#> "
        "PREFIX home: <https://w3id.org/cbrs/home#> "
        f"INSERT DATA {{ GRAPH <{GraphName.SERVICES.iri}> {{ {triples} }} }}"
    )
    with pytest.raises(DescriptionShapeError, match='got cbrs:responseTime "fast"'):
        kb.update(update)
    assert kb.store.dump() == before


def test_an_update_that_breaks_a_stored_description_is_undone() -> None:
    kb = KnowledgeBase.open(":memory:")
    before = kb.store.dump()
    update = """DELETE { GRAPH ?g { ?qos cbrs:responseTime ?t } } INSERT { GRAPH ?g { ?qos cbrs:responseTime "fast" } }
    WHERE { GRAPH ?g { svc:LocateMobileRobot_CeilingCamera01 cbrs:hasQoSModel ?qos . ?qos cbrs:responseTime ?t } }"""
    with pytest.raises(DescriptionShapeError, match="LocateMobileRobot_CeilingCamera01>"):
        kb.update(update)
    assert kb.store.dump() == before
    kb.update(update.replace('"fast"', "0.2"))  # a good change goes through
    assert kb.store.dump() != before


def test_the_endpoints_update_answers_400_naming_the_description() -> None:
    from cbrs.sparql_service import EndpointConfig, SparqlService
    from cbrs.web import create_app

    kb = KnowledgeBase.open(":memory:")
    client = create_app(SparqlService(kb, EndpointConfig(update_token="t"))).test_client()
    before = kb.store.dump()
    update = """PREFIX cbrs: <https://w3id.org/cbrs/core#> PREFIX svc: <https://w3id.org/cbrs/service#>
    DELETE { GRAPH ?g { ?sea cbrs:minX ?x } } INSERT { GRAPH ?g { ?sea cbrs:minX 99.0 } }
    WHERE { GRAPH ?g { svc:LocateMobileRobot_CeilingCamera01 cbrs:hasSEAModel ?sea . ?sea cbrs:minX ?x } }"""
    response = client.post(
        "/update", data=update.encode(), content_type="application/sparql-update", headers={"Authorization": "Bearer t"}
    )
    assert response.status_code == 400
    assert "LocateMobileRobot_CeilingCamera01> is not a valid service description" in response.text
    assert "the SEA box is reversed" in response.text
    assert kb.store.dump() == before


def test_an_owls_import_is_checked_against_the_shapes(tmp_path: Path) -> None:
    text = (OWLS / "services" / "navigate.owls").read_text(encoding="utf-8")
    extra = (
        '<rdf:Description rdf:about="#NavigateService" xmlns:cbrs="https://w3id.org/cbrs/core#">'
        '<cbrs:hasQoSModel rdf:parseType="Resource"><cbrs:responseTime>fast</cbrs:responseTime>'
        "</cbrs:hasQoSModel></rdf:Description>\n</rdf:RDF>"
    )
    broken = tmp_path / "navigate.owls"
    broken.write_text(re.sub(r"</rdf:RDF>\s*$", extra, text), encoding="utf-8")
    kb = KnowledgeBase.open(":memory:")
    before = kb.store.dump()
    with pytest.raises(DescriptionShapeError, match=r"NavigateService> .*got cbrs:responseTime \"fast\""):
        kb.load([broken], catalogue=OWLS / "catalog-v001.xml")
    assert kb.store.dump() == before
    kb.load([OWLS / "services" / "navigate.owls"], catalogue=OWLS / "catalog-v001.xml")  # the original loads


# -- docs/shapes.md: every error it shows is the one cbrs prints ----------------------------------


def _doc_examples() -> list[tuple[str, str, str]]:
    text = (ROOT / "docs" / "shapes.md").read_text(encoding="utf-8")
    pairs = re.findall(r"```turtle\n(.*?)```\s*```\n\$ cbrs register (\S+)\n(Error: .*?)\n```", text, re.DOTALL)
    return [(turtle, name, error) for turtle, name, error in pairs]


def test_the_docs_show_one_error_of_each_kind() -> None:
    examples = _doc_examples()
    assert len(examples) >= 5
    shown = " ".join(error for _, _, error in examples)
    for kind in ("did you mean home:MarkerColour?", "the property", "SEA box is reversed", '"fast"', "from 0 to 1"):
        assert kind in shown


@pytest.mark.parametrize("index", range(6))
def test_the_docs_errors_are_what_cbrs_prints(tmp_path: Path, index: int, monkeypatch: pytest.MonkeyPatch) -> None:
    examples = _doc_examples()
    if index >= len(examples):
        pytest.skip("fewer examples")
    turtle, name, error = examples[index]
    (tmp_path / name).write_text(turtle, encoding="utf-8")
    monkeypatch.chdir(tmp_path)  # the file as the docs give it, by its name: the error names it so
    result = CliRunner().invoke(cli, ["--store", ":memory:", "register", name])
    assert result.exit_code == 1
    assert result.output.strip() == error.strip()


def test_a_shape_error_on_a_node_with_no_triples_of_its_own_names_the_file(tmp_path: Path) -> None:
    """A parameter that is only pointed at (its element was mangled) is still traced to its file."""
    broken = tmp_path / "dangling.ttl"
    broken.write_text(
        """@prefix cbrs: <https://w3id.org/cbrs/core#> . @prefix home: <https://w3id.org/cbrs/home#> .
        <urn:x:Locate> a cbrs:DynamicPerceptionComponent ; cbrs:deviceName "C" ; cbrs:serviceName "Locate" ;
          cbrs:hasOWLSModel [ a cbrs:OWLSModel ; cbrs:hasOutput _:nothing ] .""",
        encoding="utf-8",
    )
    kb = KnowledgeBase.open(":memory:")
    with pytest.raises(InvalidDescriptionError) as refused:
        kb.load([broken])
    assert str(refused.value).startswith(str(broken))
