"""A lab registering its own components from docs/shapes.md alone: each mistake is refused with a
message its author can act on (no names the loader made up, no traceback, one line), the store is
unchanged, and the files a lab has (RDF/XML, JSON-LD, Protege's xsd:int) register as Turtle does."""

from __future__ import annotations

import logging
from pathlib import Path

import pyoxigraph as ox
import pytest

from cbrs.kb import InvalidDescriptionError, KnowledgeBase, NotFoundError
from cbrs.kb.errors import ForeignStatementError
from cbrs.kb.namespaces import GENID, PREFIXES, GraphName

EX = "http://example.org/mini#"
HEAD = """@prefix cbrs: <https://w3id.org/cbrs/core#> .
@prefix ex: <http://example.org/mini#> .
@prefix xsd: <http://www.w3.org/2001/XMLSchema#> .
"""
INPUT = "cbrs:hasInput [ cbrs:parameterType ex:MarkerColour ]"
OUTPUT = "cbrs:hasOutput [ cbrs:parameterType ex:Location ]"
OWLS = Path(__file__).parent / "data" / "owls" / "services" / "open_door.owls"


def _camera(
    *,
    kind: str = "cbrs:DynamicPerceptionComponent",
    device: str = '"LabCam01"',
    service: str = '"DetectDoor"',
    qos: str = "cbrs:responseTime 0.2",
    sea: str = "",
    model: str = INPUT + " ; " + OUTPUT,
) -> str:
    sea_part = f" cbrs:hasSEAModel [ {sea} ] ;" if sea else ""
    return (
        HEAD
        + f"""ex:DetectDoor_LabCam01 a {kind} ;
    cbrs:deviceName {device} ; cbrs:serviceName {service} ;{sea_part}
    cbrs:hasQoSModel [ {qos} ] ;
    cbrs:hasOWLSModel [ {model} ] .
"""
    )


def _refused(kb: KnowledgeBase, text: str | bytes, source: str = "<registration>") -> str:
    before = kb.store.dump()
    with pytest.raises(InvalidDescriptionError) as caught:
        kb.registry.register(text, source)
    assert kb.store.dump() == before
    message = str(caught.value)
    assert "\n" not in message
    return message


# -- messages that name what the author wrote ------------------------------------------------------


def test_an_untyped_parameter_is_named_by_its_name_not_by_a_made_up_iri(mini_kb: KnowledgeBase) -> None:
    message = _refused(mini_kb, _camera(model='cbrs:hasOutput [ cbrs:parameterName "doorPose" ]'))
    assert 'the output "doorPose" has no cbrs:parameterType' in message
    assert GENID not in message and "genid:" not in message


def test_an_incomplete_condition_is_named_by_its_role(mini_kb: KnowledgeBase) -> None:
    model = (
        "cbrs:hasOutput [ cbrs:parameterType ex:Location ] ;"
        " cbrs:hasEffect [ cbrs:conditionSubject ex:Door ; cbrs:conditionPredicate ex:hasStatus ]"
    )
    message = _refused(mini_kb, _camera(model=model))
    assert "an effect lacks cbrs:conditionObject" in message
    assert GENID not in message and "genid:" not in message


def test_a_partial_sea_box_does_not_show_the_model_s_made_up_iri(mini_kb: KnowledgeBase) -> None:
    message = _refused(mini_kb, _camera(sea="cbrs:effectiveArea ex:Kitchen ; cbrs:minX 0.0"))
    assert "the SEA box needs all four" in message
    assert "genid:" not in message and GENID not in message


def test_an_ill_typed_number_is_reported_without_a_traceback(
    mini_kb: KnowledgeBase, caplog: pytest.LogCaptureFixture
) -> None:
    with caplog.at_level(logging.WARNING):
        message = _refused(mini_kb, _camera(qos='cbrs:responseTime "abc"^^xsd:double'))
    assert 'got cbrs:responseTime "abc"^^xsd:double (not a valid xsd:double)' in message
    assert not [r for r in caplog.records if r.name.startswith("rdflib")]


def test_a_sea_bound_that_is_a_word_is_not_also_called_reversed(mini_kb: KnowledgeBase) -> None:
    sea = 'cbrs:effectiveArea ex:Kitchen ; cbrs:minX "0" ; cbrs:maxX 1.0 ; cbrs:minY 0.0 ; cbrs:maxY 1.0'
    message = _refused(mini_kb, _camera(sea=sea))
    assert 'a bound of the SEA box is a finite number of metres; got "0"' in message
    assert "reversed" not in message


def test_a_string_value_is_quoted_with_its_escapes(mini_kb: KnowledgeBase) -> None:
    message = _refused(mini_kb, _camera(service='"Detect \\"door\\"\\nnow"'))
    assert r'got cbrs:serviceName "Detect \"door\"\nnow"' in message


# -- what a description may say ----------------------------------------------------------------------


@pytest.mark.parametrize(
    "qos",
    [
        'cbrs:responseTime "INF"^^xsd:double',
        'cbrs:updateRate "INF"^^xsd:double',
        'cbrs:responseTime "NaN"^^xsd:double',
        'cbrs:cost "INF"^^xsd:float',
    ],
)
def test_a_qos_value_is_finite(mini_kb: KnowledgeBase, qos: str) -> None:
    metric = qos.split()[0]
    assert f"got {metric}" in _refused(mini_kb, _camera(qos=qos))


def test_a_sea_bound_is_finite(mini_kb: KnowledgeBase) -> None:
    sea = 'cbrs:effectiveArea ex:Kitchen ; cbrs:minX "-INF"^^xsd:double ; cbrs:maxX 1.0 ; cbrs:minY 0.0 ; cbrs:maxY 1.0'
    assert "a bound of the SEA box is a finite number of metres; got -inf" in _refused(mini_kb, _camera(sea=sea))


@pytest.mark.parametrize(
    ("number", "value"),
    [('"2"^^xsd:int', 2.0), ('"2"^^xsd:nonNegativeInteger', 2.0), ('"2"^^xsd:long', 2.0), ('"2.5"^^xsd:float', 2.5)],
)
def test_numbers_of_any_xsd_numeric_type_are_taken(mini_kb: KnowledgeBase, number: str, value: float) -> None:
    """Protege writes "2"^^xsd:int; the readers take any numeric literal (float of its lexical form)."""
    assert mini_kb.registry.register(_camera(qos=f"cbrs:responseTime {number}")) == [EX + "DetectDoor_LabCam01"]
    assert [q.value for q in mini_kb.description(EX + "DetectDoor_LabCam01").qos] == [value]


@pytest.mark.parametrize(
    ("field", "value"),
    [("device", '""'), ("device", '"   "'), ("service", '"Detect\\ndoor"'), ("service", '"Detect\\rdoor"')],
)
def test_names_are_one_line_and_not_empty(mini_kb: KnowledgeBase, field: str, value: str) -> None:
    label = "device name (DN)" if field == "device" else "service name (SN)"
    message = _refused(mini_kb, _camera(**{field: value}))
    assert f"the {label} is one string, on one line and not empty" in message


def test_non_ascii_names_are_fine(mini_kb: KnowledgeBase) -> None:
    mini_kb.registry.register(_camera(device='"Küchenkamera 東京"', service='"Tür finden"@de'))
    ad = mini_kb.description(EX + "DetectDoor_LabCam01")
    assert (ad.device_name, ad.service_name) == ("Küchenkamera 東京", "Tür finden")


def test_an_advertisement_has_one_component_kind(mini_kb: KnowledgeBase) -> None:
    message = _refused(mini_kb, _camera(kind="cbrs:DynamicPerceptionComponent, cbrs:StaticDataComponent"))
    assert "a description has one kind" in message


# -- what is not an advertisement ------------------------------------------------------------------------


def test_a_file_with_no_advertisement_is_named_as_a_file(mini_kb: KnowledgeBase) -> None:
    message = _refused(mini_kb, HEAD + "ex:T a ex:Camera .", "lab/cameras.ttl")
    assert message.startswith("lab/cameras.ttl is not a valid service description: it describes no advertisement")


def test_a_registration_sent_as_text_is_not_bracketed_twice(mini_kb: KnowledgeBase) -> None:
    assert _refused(mini_kb, HEAD + "ex:T a ex:Camera .").startswith("<registration> is not")


def test_a_description_without_a_kind_is_told_the_kinds(mini_kb: KnowledgeBase) -> None:
    message = _refused(mini_kb, _camera(kind="ex:Camera"), "camera.ttl")
    assert (
        "ex:DetectDoor_LabCam01 has no component kind" in message
        or f"{EX}DetectDoor_LabCam01 has no component kind" in message
    )
    assert "cbrs:DynamicPerceptionComponent" in message and "cbrs:MethodInvocationComponent" in message


def test_a_requirement_is_sent_to_the_requirements_graph(mini_kb: KnowledgeBase) -> None:
    message = _refused(mini_kb, _camera(kind="cbrs:Requirement"), "need.ttl")
    assert "is a requirement" in message and "cbrs load --graph requirements" in message


def test_an_owls_file_is_sent_to_cbrs_load(mini_kb: KnowledgeBase) -> None:
    message = _refused(mini_kb, OWLS.read_bytes(), str(OWLS))
    assert "OWL-S" in message and "cbrs load" in message


def test_a_dataset_naming_another_graph_is_refused(mini_kb: KnowledgeBase) -> None:
    trig = HEAD + "ex:g { " + _camera().split("\n", 3)[3] + " }"
    message = _refused(mini_kb, trig, "camera.trig")
    assert "names the graph <http://example.org/mini#g>" in message


# -- the formats a lab's tools write -------------------------------------------------------------------


@pytest.mark.parametrize(
    ("suffix", "rdf_format"),
    [
        (".rdf", ox.RdfFormat.RDF_XML),
        (".owl", ox.RdfFormat.RDF_XML),
        (".jsonld", ox.RdfFormat.JSON_LD),
        (".nt", ox.RdfFormat.N_TRIPLES),
    ],
)
def test_a_description_registers_from_the_format_its_name_says(
    mini_kb: KnowledgeBase, suffix: str, rdf_format: ox.RdfFormat
) -> None:
    triples = list(ox.parse(_camera().encode(), format=ox.RdfFormat.TURTLE))
    data = ox.serialize(triples, format=rdf_format)
    assert data is not None
    assert mini_kb.registry.register(data, f"camera{suffix}") == [EX + "DetectDoor_LabCam01"]
    ad = mini_kb.description(EX + "DetectDoor_LabCam01")
    assert [p.type for p in ad.outputs] == [EX + "Location"]
    assert mini_kb.registry.update(data, f"camera{suffix}") == [EX + "DetectDoor_LabCam01"]


def test_rdf_xml_sent_as_text_is_recognised(mini_kb: KnowledgeBase) -> None:
    data = ox.serialize(list(ox.parse(_camera().encode(), format=ox.RdfFormat.TURTLE)), format=ox.RdfFormat.RDF_XML)
    assert data is not None
    assert data.startswith(b"<?xml")
    assert mini_kb.registry.register(data) == [EX + "DetectDoor_LabCam01"]


def test_a_kind_the_file_declares_itself_is_a_kind(mini_kb: KnowledgeBase) -> None:
    """A lab's own subclass of a component kind, declared in the file that uses it, makes an advertisement."""
    text = _camera(kind="ex:DoorCamera") + (
        "ex:DoorCamera rdfs:subClassOf ex:LabCamera . ex:LabCamera rdfs:subClassOf cbrs:DynamicPerceptionComponent .\n"
    )
    text = "@prefix rdfs: <http://www.w3.org/2000/01/rdf-schema#> .\n" + text
    assert mini_kb.registry.register(text, "door_camera.ttl") == [EX + "DetectDoor_LabCam01"]
    assert EX + "DetectDoor_LabCam01" in [ad.iri for ad in mini_kb.advertisements()]
    mini_kb.registry.deregister(EX + "DetectDoor_LabCam01")
    assert EX + "DetectDoor_LabCam01" not in [ad.iri for ad in mini_kb.advertisements()]


def test_a_registration_cannot_restate_a_term_the_ontology_describes(mini_kb: KnowledgeBase) -> None:
    """ex:Camera is the ontology's: making it a component kind from a registration would change it for every
    reader of the union graph and outlive the component, so it is refused, and nothing is written."""
    before = mini_kb.store.dump()
    text = (
        "@prefix rdfs: <http://www.w3.org/2000/01/rdf-schema#> .\n"
        + _camera(kind="ex:DoorCamera")
        + ("ex:DoorCamera rdfs:subClassOf ex:Camera . ex:Camera rdfs:subClassOf cbrs:DynamicPerceptionComponent .\n")
    )
    with pytest.raises(ForeignStatementError) as refused:
        mini_kb.registry.register(text, "door_camera.ttl")
    assert refused.value.subject == EX + "Camera" and refused.value.graph == GraphName.ONTOLOGY.iri
    assert "rdfs:subClassOf cbrs:DynamicPerceptionComponent" in str(refused.value)
    assert mini_kb.store.dump() == before
    restated = "@prefix rdfs: <http://www.w3.org/2000/01/rdf-schema#> .\n" + _camera()
    restated += "ex:Camera rdfs:subClassOf cbrs:Device .\n"  # what the ontology says already: changes nothing
    assert mini_kb.registry.register(restated, "door_camera.ttl") == [EX + "DetectDoor_LabCam01"]


def test_an_advertisement_loaded_into_the_ontology_graph_is_said_to_be_there(
    mini_kb: KnowledgeBase, tmp_path: Path
) -> None:
    """cbrs load sends a file that declares classes to the ontology graph, its descriptions too; the
    registry (graph:services) then says where the advertisement is and what to do, not "no advertisement"."""
    path = tmp_path / "lab.ttl"
    path.write_text(
        "@prefix owl: <http://www.w3.org/2002/07/owl#> .\n" + _camera() + "ex:Location a owl:Class .\n",
        encoding="utf-8",
    )
    mini_kb.load([path])
    for attempt in (
        lambda: mini_kb.registry.deregister(EX + "DetectDoor_LabCam01"),
        lambda: mini_kb.registry.update(_camera()),
    ):
        with pytest.raises(NotFoundError) as caught:
            attempt()
        assert "is in the graph <https://w3id.org/cbrs/graph/ontology>" in str(caught.value)
        assert "--graph services" in str(caught.value)
    with pytest.raises(NotFoundError, match="no registered advertisement"):
        mini_kb.registry.deregister(EX + "Nothing")


@pytest.mark.filterwarnings("ignore:Serializing weird numerical")  # rdflib's comparison, of "abc"^^xsd:double
def test_the_shapes_see_the_terms_rdflib_s_parser_would_give() -> None:
    """The data graph is built term by term (rdflib's N-Triples parser is quadratic in a line's length:
    a registration with a 5 MB rdfs:comment took 95 s); it must be the graph the parser gave."""
    import rdflib
    from rdflib.compare import isomorphic

    from cbrs.kb.shapes import _rdflib_graph

    text = _camera(qos='cbrs:responseTime "abc"^^xsd:double', service='"Tür \\"finden\\"\\n"@de') + (
        'ex:X ex:p "plain", "x"^^xsd:string, 5, 1.5, 2e0, "2"^^xsd:int, true, "long ' + "ä" * 5000 + '" .\n'
    )
    triples = list(ox.parse(text.encode(), format=ox.RdfFormat.TURTLE))
    parsed = rdflib.Graph().parse(data=ox.serialize(triples, format=ox.RdfFormat.N_TRIPLES), format="nt")
    assert isomorphic(_rdflib_graph(triples), parsed)


def test_a_file_s_relative_iris_are_the_ones_cbrs_load_gives(mini_kb: KnowledgeBase, tmp_path: Path) -> None:
    """<#Cam> in a registered file is the file's, as cbrs load reads it, not <https://w3id.org/cbrs/#Cam>
    in cbrs's own namespace (where every lab's <#Cam> would be one thing)."""
    path = tmp_path / "cam.ttl"
    path.write_text(_camera().replace("ex:DetectDoor_LabCam01", "<#Cam>"), encoding="utf-8")
    assert mini_kb.registry.register(path.read_bytes(), str(path)) == [path.resolve().as_uri() + "#Cam"]
    before = mini_kb.store.dump()
    mini_kb.load([path])  # the same file, the same IRIs: nothing new
    assert mini_kb.store.dump() == before
    assert mini_kb.registry.register(_camera().replace("ex:DetectDoor_LabCam01", "<#Cam>")) == [
        "https://w3id.org/cbrs/#Cam"  # a text sent without a file name: cbrs's base, as before
    ]


def test_a_registered_file_s_error_names_the_line(mini_kb: KnowledgeBase, tmp_path: Path) -> None:
    """A file of many descriptions: the refusal says where the one at fault is written."""
    fine = _camera().split("\n", 3)[3]
    bad = fine.replace("DetectDoor_LabCam01", "Broken").replace("cbrs:responseTime 0.2", 'cbrs:responseTime "soon"')
    path = tmp_path / "lab.ttl"
    text = HEAD + "\n".join(fine.replace("DetectDoor_LabCam01", f"Cam{i}") for i in range(20)) + bad
    path.write_text(text, encoding="utf-8")
    line = text.splitlines().index("ex:Broken a cbrs:DynamicPerceptionComponent ;") + 1
    message = _refused(mini_kb, path.read_bytes(), str(path))
    assert message.startswith(f"{path}:{line}: <{EX}Broken> is not a valid service description: ")


def test_a_registration_may_describe_its_own_device_placed_in_the_map_first() -> None:
    """A lab places its door motor in the map, then registers the motor's component: the device is the
    component's own (named by cbrs:device), so its label and type go in; the map's door does not."""
    kb = KnowledgeBase.open(":memory:")
    kb.update(
        "INSERT DATA { GRAPH graph:map { svc:DoorMotor05 home:x 7.0 ; home:y 1.0 . world:KitchenDoor a home:Door } }"
    )
    motor = (Path(__file__).parent / "data" / "door_motor.ttl").read_text(encoding="utf-8")
    assert kb.registry.register(motor) == [PREFIXES["svc"] + "OpenDoor_DoorMotor05"]
    with pytest.raises(ForeignStatementError) as refused:
        door = "@prefix world: <https://w3id.org/cbrs/world#> .\nworld:KitchenDoor rdfs:label 'x' .\n"
        kb.registry.register(
            motor.replace("DoorMotor05", "DoorMotor06").replace("door_motor_05", "door_motor_06") + door
        )
    assert refused.value.subject == PREFIXES["world"] + "KitchenDoor" and refused.value.graph == GraphName.MAP.iri
