"""The browse pages: taxonomy, class, any IRI, services, one service, the SPARQL editor. Assertions are on
the ``.json`` twins; the HTML pages are checked to render with their headings and links."""

from __future__ import annotations

from collections.abc import Iterator
from typing import Any
from urllib.parse import parse_qs, urlsplit

import pytest
from flask.testing import FlaskClient

from cbrs.kb import KnowledgeBase
from cbrs.kb.namespaces import expand
from cbrs.sparql_service import SparqlService
from cbrs.web import create_app

CAMERA = "svc:LocateMobileRobot_CeilingCamera01"
POSITION = expand("home:Position")
ROBOT_POSITION = expand("home:RobotPosition")
XY_THETA = {expand("home:XCoordinate"), expand("home:YCoordinate"), expand("home:Theta")}


@pytest.fixture(scope="module")
def client(bundled_kb: KnowledgeBase) -> FlaskClient:
    return create_app(SparqlService(bundled_kb)).test_client()


def get_json(client: FlaskClient, path: str, status: int = 200, **query: str) -> Any:
    response = client.get(path, query_string=query)
    assert response.status_code == status, response.get_data(as_text=True)[:500]
    assert response.mimetype == "application/json"
    return response.get_json()


def walk(nodes: list[dict[str, Any]]) -> Iterator[dict[str, Any]]:
    for node in nodes:
        yield node
        yield from walk(node["children"])


# -- taxonomy --------------------------------------------------------------------------------------


def test_taxonomy_tree_nests_robot_position_below_position_with_parts(client: FlaskClient) -> None:
    body = get_json(client, "/taxonomy.json")
    position = next(node for node in walk(body["classes"]) if node["iri"] == POSITION)
    below = {child["iri"]: child for child in position["children"]}
    assert ROBOT_POSITION in below
    assert {part["iri"] for part in below[ROBOT_POSITION]["parts"]} == XY_THETA
    assert {part["iri"] for part in position["parts"]} == XY_THETA
    assert body["counts"]["classes"] > 300 and body["counts"]["properties"] > 100
    assert any(node["iri"] == expand("dul:hasPart") for node in walk(body["properties"]))


def test_taxonomy_search_finds_matches_with_their_ancestor_paths(client: FlaskClient) -> None:
    body = get_json(client, "/taxonomy.json", q="POSITION")
    matches = {m["iri"]: m for m in body["matches"]}
    assert POSITION in matches and ROBOT_POSITION in matches
    paths = [[t["iri"] for t in path] for path in matches[ROBOT_POSITION]["paths"]]
    assert any(path[-2:] == [expand("home:SpatialData"), POSITION] for path in paths)
    # the tree is pruned to the matches and their ancestors
    shown = {node["iri"]: node for node in walk(body["classes"])}
    assert shown[ROBOT_POSITION]["match"] is True and shown[expand("home:SpatialData")]["match"] is False
    assert expand("home:Cup") not in shown


def test_taxonomy_search_without_matches_says_so(client: FlaskClient) -> None:
    body = get_json(client, "/taxonomy.json", q="no-such-term-anywhere")
    assert body["matches"] == [] and body["classes"] == []
    page = client.get("/taxonomy", query_string={"q": "no-such-term-anywhere"}).get_data(as_text=True)
    assert "0 matches" in page


def test_class_page_lists_superclass_parts_and_users(client: FlaskClient) -> None:
    body = get_json(client, "/taxonomy/class.json", iri="home:RobotPosition")
    assert body["iri"] == ROBOT_POSITION and body["kind"] == "class" and body["label"] == "robot position"
    assert [t["iri"] for t in body["superclasses"]] == [POSITION]
    assert {p["iri"] for p in body["parts"]} == XY_THETA
    assert {p["property_name"] for p in body["parts"]} == {
        "home:hasXCoordinate",
        "home:hasYCoordinate",
        "home:hasOrientation",
    }
    usage = body["usage"]
    assert usage["uses"] == 3
    assert [(a["name"], a["roles"]) for a in usage["advertisements"]] == [
        ("svc:EstimateRobotPositionFromSonar_HomeServer01", ["output"])
    ]
    assert {r["name"] for r in usage["requirements"]} == {"req:RobotSelfPosition", "req:RouteToGoal"}


def test_class_page_of_position_shows_subclasses_and_inherited_parts(client: FlaskClient) -> None:
    body = get_json(client, "/taxonomy/class.json", iri=POSITION)
    assert ROBOT_POSITION in {t["iri"] for t in body["subclasses"]}
    body = get_json(client, "/taxonomy/class.json", iri="home:ApproachPosition")
    assert all(p["inherited_from"] is None for p in body["parts"])  # declared again on the class itself


def test_class_page_of_a_property_and_of_an_unknown_term(client: FlaskClient) -> None:
    body = get_json(client, "/taxonomy/class.json", iri="home:hasXCoordinate")
    assert body["kind"] == "property" and body["parts"] == []
    error = get_json(client, "/taxonomy/class.json", 404, iri="home:NoSuchClass")
    assert "home#NoSuchClass" in error["message"]


def test_taxonomy_html_pages_render(client: FlaskClient) -> None:
    page = client.get("/taxonomy").get_data(as_text=True)
    assert "<title>Taxonomy · cbrs</title>" in page and 'id="q"' in page
    assert 'href="/taxonomy/class?iri=home:RobotPosition"' in page
    response = client.get("/taxonomy/class", query_string={"iri": "home:RobotPosition"})
    page = response.get_data(as_text=True)
    assert response.status_code == 200
    assert "<h1>Class home:RobotPosition</h1>" in page and "Superclasses" in page
    assert 'href="/service?iri=req:RobotSelfPosition"' in page


# -- any IRI ---------------------------------------------------------------------------------------


def test_resource_lists_outgoing_triples_grouped_with_graphs(client: FlaskClient) -> None:
    body = get_json(client, "/resource.json", iri=CAMERA)
    assert body["iri"] == expand(CAMERA) and body["label"] == "Locate mobile robot (ceiling camera 1)"
    groups = {group["name"]: group["values"] for group in body["outgoing"]}
    assert body["outgoing"][0]["name"] == "rdf:type"
    assert groups["rdf:type"][0]["term"] == {
        "type": "iri",
        "value": expand("cbrs:DynamicPerceptionComponent"),
        "name": "cbrs:DynamicPerceptionComponent",
    }
    assert groups["rdf:type"][0]["graph"] == expand("graph:services")
    assert groups["rdfs:label"][0]["term"]["language"] == "en"
    assert groups["cbrs:serviceName"][0]["term"]["datatype"] == expand("xsd:string")
    # the stated triples, then what graph:entailed says of them in standard terms (a Service in OWL-S)
    assert body["counts"]["outgoing"] - body["counts"]["entailed"] == 11 and body["counts"]["incoming"] == 0
    assert body["counts"]["entailed"] >= 1
    assert any(v["graph"] == expand("graph:entailed") for v in groups["rdf:type"])
    for values in groups.values():
        entailed = [v["graph"] == expand("graph:entailed") for v in values]
        assert entailed == sorted(entailed), "an entailed triple came before a stated one"
    assert any(link["href"] == f"/service?iri={expand(CAMERA).replace('#', '%23')}" for link in body["pages"])


def test_resource_html_links_every_iri(client: FlaskClient) -> None:
    response = client.get("/resource", query_string={"iri": "home:RobotPosition"})
    page = response.get_data(as_text=True)
    assert response.status_code == 200
    assert "<h1>home:RobotPosition</h1>" in page
    assert 'href="/resource?iri=https://w3id.org/cbrs/home%23Position"' in page
    assert "In the taxonomy" in page and "cbrs:parameterType" in page


@pytest.mark.parametrize(
    ("query", "status", "kind"),
    [
        pytest.param({"iri": "svc:NoSuchService"}, 404, "NotFoundError", id="unknown"),
        pytest.param({}, 400, "bad-request", id="missing"),
        pytest.param({"iri": "nope:X"}, 400, "bad-request", id="unknown-prefix"),  # no IRI of scheme nope
        pytest.param({"iri": "urn:example:x"}, 404, "NotFoundError", id="unknown-urn"),  # an absolute IRI
        pytest.param({"iri": "  "}, 400, "bad-request", id="blank"),
        pytest.param({"iri": "http://example.org/a b"}, 400, "bad-request", id="malformed"),
    ],
)
def test_resource_errors_are_pages_and_json(client: FlaskClient, query: dict[str, str], status: int, kind: str) -> None:
    error = get_json(client, "/resource.json", status, **query)
    assert error["error"] == kind and error["message"]
    response = client.get("/resource", query_string=query)
    assert response.status_code == status and response.mimetype == "text/html"
    assert 'class="error-box"' in response.get_data(as_text=True)


# -- services --------------------------------------------------------------------------------------


def test_services_table_has_every_advertisement_and_filters_by_kind(client: FlaskClient) -> None:
    body = get_json(client, "/services.json")
    assert body["total"] == 53 and len(body["advertisements"]) == 53 and body["kind"] is None
    camera = next(row for row in body["advertisements"] if row["name"] == CAMERA)
    assert camera["inputs"] == [expand("home:MarkerColour")] and camera["device_name"] == "CeilingCamera01"
    assert sum(k["count"] for k in body["kinds"]) == 53
    static = get_json(client, "/services.json", kind="cbrs:StaticDataComponent")
    assert static["kind"] == expand("cbrs:StaticDataComponent")
    assert 0 < len(static["advertisements"]) < 53
    assert {row["kind"] for row in static["advertisements"]} == {expand("cbrs:StaticDataComponent")}
    assert len(get_json(client, "/services.json", kind="StaticDataComponent")["advertisements"]) == len(
        static["advertisements"]
    )


def test_services_unknown_kind_is_a_field_error(client: FlaskClient) -> None:
    error = get_json(client, "/services.json", 400, kind="cbrs:Toaster")
    assert error["error"] == "invalid-form" and "cbrs:Toaster" in error["fields"]["kind"]
    response = client.get("/services", query_string={"kind": "cbrs:Toaster"})
    assert response.status_code == 400 and 'id="kind-error"' in response.get_data(as_text=True)


def test_service_page_carries_the_six_tuple(client: FlaskClient) -> None:
    body = get_json(client, "/service.json", iri=CAMERA)
    assert body["role"] == "advertisement" and body["class"] == "Advertisement"
    assert (body["device_name"], body["service_name"], body["category"]) == (
        "CeilingCamera01",
        "LocateMobileRobot",
        "Localisation",
    )
    assert [p["type"] for p in body["inputs"]] == [expand("home:MarkerColour")]
    (output,) = body["outputs"]
    assert output["type"] == expand("home:RobotLocation")
    assert {child["concept"] for child in output["tree"]["children"]} == XY_THETA
    assert body["preconditions"] and body["effects"]
    assert body["area"]["areas"] == [expand("home:LivingRoom")]
    assert {q["metric"] for q in body["qos"]} >= {expand("cbrs:availability"), expand("cbrs:responseTime")}


def test_service_page_shows_the_delete_effects(client: FlaskClient) -> None:
    page = client.get("/service", query_string={"iri": "svc:PickUpObject_CytonDualArm01"}).text
    row = page[page.index("delete effects: what stops being true") :]
    assert "isLocated" in row[: row.index("</tr>")]
    camera = client.get("/service", query_string={"iri": CAMERA}).text
    assert "delete effects" not in camera  # shown only where a service states them


def test_service_page_of_a_requirement_and_of_something_else(client: FlaskClient) -> None:
    body = get_json(client, "/service.json", iri="req:RobotSelfPosition")
    assert body["role"] == "requirement" and [p["type"] for p in body["outputs"]] == [ROBOT_POSITION]
    if "matchmaking.matchmaking" in client.application.view_functions:
        assert urlsplit(body["match"]).path == "/match"
        assert parse_qs(urlsplit(body["match"]).query) == {"requirement": [expand("req:RobotSelfPosition")]}
    else:
        assert body["match"] is None
    get_json(client, "/service.json", 404, iri="home:RobotPosition")


def test_services_html_pages_render(client: FlaskClient) -> None:
    page = client.get("/services").get_data(as_text=True)
    assert "<title>Services · cbrs</title>" in page
    assert f'href="/service?iri={CAMERA}"' in page and 'href="/taxonomy/class?iri=home:MarkerColour"' in page
    page = client.get("/service", query_string={"iri": CAMERA}).get_data(as_text=True)
    assert "Six-tuple" in page and "markerColour" in page and "home:hasXCoordinate" in page
    assert "/ceiling_camera_1/robot_location" in page


# -- SPARQL editor ---------------------------------------------------------------------------------


def test_editor_runs_a_named_query(client: FlaskClient, bundled_kb: KnowledgeBase) -> None:
    text = bundled_kb.queries.get("advertisements").text
    body = get_json(client, "/query.json", query=text)
    result = body["result"]
    assert result["kind"] == "select" and result["count"] == 53 and not result["truncated"]
    assert result["vars"][:3] == ["service", "label", "kind"]
    assert result["rows"][0]["service"]["type"] == "uri"
    assert {e["name"] for e in body["examples"]} == set(bundled_kb.queries.names())


def test_editor_download_links_point_at_the_endpoint(client: FlaskClient) -> None:
    text = "SELECT ?c WHERE { ?c rdfs:subClassOf home:Position }"
    body = get_json(client, "/query.json", query=text)
    links = {d["format"]: d["href"] for d in body["downloads"]}
    for short in ("csv", "json"):
        url = urlsplit(links[short])
        assert url.path == "/sparql" and parse_qs(url.query) == {"query": [text], "format": [short]}
    csv = client.get(links["csv"])
    assert csv.mimetype == "text/csv" and expand("home:RobotPosition") in csv.get_data(as_text=True)


def test_editor_ask_and_construct(client: FlaskClient) -> None:
    assert get_json(client, "/query.json", query="ASK { home:RobotPosition rdfs:subClassOf home:Position }")[
        "result"
    ] == {"kind": "ask", "boolean": True}
    construct = "CONSTRUCT { ?c rdfs:subClassOf home:Position } WHERE { ?c rdfs:subClassOf home:Position }"
    result = get_json(client, "/query.json", query=construct)["result"]
    assert result["kind"] == "graph" and "RobotPosition" in result["turtle"]


def test_editor_syntax_error_is_a_field_error(client: FlaskClient) -> None:
    error = get_json(client, "/query.json", 400, query="SELEC ?x WHERE {}")
    assert error["error"] == "invalid-form" and "syntax error" in error["fields"]["query"]
    response = client.get("/query", query_string={"query": "SELEC ?x WHERE {}"})
    page = response.get_data(as_text=True)
    assert response.status_code == 400
    assert 'id="query-error"' in page and "syntax error" in page and "SELEC ?x WHERE {}</textarea>" in page
    assert "Traceback" not in page


def test_editor_page_shows_examples_and_runs_by_post(client: FlaskClient) -> None:
    page = client.get("/query", query_string={"example": "concept_parts"}).get_data(as_text=True)
    assert "<title>SPARQL · cbrs</title>" in page and 'data-example="concept_parts"' in page
    assert "# title: The hasPart children of a concept" in page and "editor.js" in page
    response = client.post("/query", data={"query": "SELECT ?c WHERE { ?c rdfs:subClassOf home:Position }"})
    page = response.get_data(as_text=True)
    assert response.status_code == 200
    assert 'class="result-table"' in page and ">home:RobotPosition</a>" in page and "format=csv" in page
    assert client.get("/query.json", query_string={"example": "nope"}).status_code == 400


def test_navigation_lists_the_browse_pages_but_not_the_resource_page(client: FlaskClient) -> None:
    page = client.get("/").get_data(as_text=True)
    for href, label in (("/taxonomy", "Taxonomy"), ("/services", "Services"), ("/query", "SPARQL")):
        assert f'<a href="{href}">{label}</a>' in page
    assert 'href="/resource"' not in page
