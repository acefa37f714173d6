from __future__ import annotations

import json

import pytest
from click.testing import CliRunner

from cbrs.cli import cli
from cbrs.kb import (
    Advertisement,
    KnowledgeBase,
    NotFoundError,
    Parameter,
    PartNode,
    QoSValue,
    Requirement,
    Statement,
    Store,
)
from cbrs.reasoner.config import MatchConfig
from cbrs.reasoner.matchmaker import Matchmaker, MatchStatus
from cbrs.reasoner.methods import METHODS
from cbrs.reasoner.similarity import SemStr
from cbrs.reasoner.spans import conceptual_span_similarity
from cbrs.reasoner.statements import statement_similarity
from tests.reasoner_examples import E, positions

SVC = "https://w3id.org/cbrs/service#"
REQ = "https://w3id.org/cbrs/requirement#"
HOME = "https://w3id.org/cbrs/home#"
TABLE3 = [
    "LocateMobileRobot_CeilingCamera01",
    "LocateMobileRobot_CeilingCamera02",
    "TrackPerson_CeilingCamera01",
    "TrackPerson_CeilingCamera02",
    "RecogniseObjectByColour_Kinect01",
    "DetectColourMarker_CeilingCamera01",
    "LocaliseRobotByLaser_LaserScanner01",
    "EstimateRobotPositionFromSonar_HomeServer01",
    "DeadReckoning_P3DX01",
    "DetectPersonByLaser_LaserScanner01",
]


@pytest.fixture(scope="module")
def sem_str(bundled_kb: KnowledgeBase) -> Matchmaker:
    return Matchmaker(bundled_kb)


def test_table3_ceiling_camera_ranks_first(sem_str: Matchmaker) -> None:
    result = sem_str.rank(REQ + "RobotSelfPosition")
    assert result.status is MatchStatus.MATCHED
    order = [
        c.advertisement.rsplit("#", 1)[1] for c in result.candidates if c.advertisement.rsplit("#", 1)[1] in TABLE3
    ]
    assert order[0] == "LocateMobileRobot_CeilingCamera01"
    assert result.candidates[0].advertisement == SVC + "LocateMobileRobot_CeilingCamera01"


def test_table3_explanation_matches_position_with_location(sem_str: Matchmaker) -> None:
    best = sem_str.rank(REQ + "RobotSelfPosition").candidates[0]
    root = next(p for p in best.pairs if p.role == "output" and p.requested == HOME + "RobotPosition")
    assert root.advertised == HOME + "RobotLocation"
    assert "Wu-Palmer via SpatialData" in root.how
    parts = {p.requested for p in best.pairs if p.role == "output" and p.similarity == 1.0}
    assert {HOME + "XCoordinate", HOME + "YCoordinate"} <= parts
    marker = next(p for p in best.pairs if p.role == "input" and p.advertised == HOME + "MarkerColour")
    assert marker.requested == HOME + "ColourOfMarker" and marker.degree == "HasSubClass"


def test_sea_filter_rejects_the_kitchen_camera(sem_str: Matchmaker) -> None:
    result = sem_str.rank(REQ + "RobotSelfPosition")
    kitchen = next(c for c in result.candidates if c.advertisement == SVC + "LocateMobileRobot_CeilingCamera02")
    assert not kitchen.acceptable
    assert any(reason.startswith("SEA") for reason in kitchen.rejected_by)


def test_pure_string_matching_prefers_the_exact_name(bundled_kb: KnowledgeBase, sem_str: Matchmaker) -> None:
    baseline = Matchmaker(bundled_kb, "string", index=sem_str.index, advertisements=sem_str.advertisements)
    top = baseline.rank(REQ + "RobotSelfPosition").candidates[0]
    assert top.advertisement == SVC + "EstimateRobotPositionFromSonar_HomeServer01"


@pytest.mark.parametrize("method", METHODS)
def test_every_method_ranks_every_advertisement_deterministically(
    bundled_kb: KnowledgeBase, sem_str: Matchmaker, method: str
) -> None:
    ads = sem_str.advertisements
    forward = Matchmaker(bundled_kb, method, index=sem_str.index, advertisements=ads).rank(REQ + "RobotSelfPosition")
    backward = Matchmaker(bundled_kb, method, index=sem_str.index, advertisements=ads[::-1]).rank(
        REQ + "RobotSelfPosition"
    )
    assert [c.advertisement for c in forward.candidates] == [c.advertisement for c in backward.candidates]
    assert len(forward.candidates) == len(ads)
    assert all(0.0 <= c.score <= 1.0 for c in forward.candidates)


def test_no_acceptable_match_is_a_status_with_the_table(mini_kb: KnowledgeBase) -> None:
    mini_kb.registry.register(
        """@prefix cbrs: <https://w3id.org/cbrs/core#> . @prefix ex: <http://example.org/mini#> .
        ex:Nothing a cbrs:MethodInvocationComponent ; cbrs:deviceName "d" ; cbrs:serviceName "s" ;
          cbrs:hasOWLSModel [ cbrs:hasOutput [ cbrs:parameterType ex:Door ] ] ."""
    )
    requirement = mini_kb.description("http://example.org/mini#SelfPosition")
    strict = Matchmaker(mini_kb, config=MatchConfig(accept_score=0.99), advertisements=mini_kb.advertisements())
    result = strict.rank(requirement.iri)
    assert result.status is MatchStatus.NO_ACCEPTABLE_MATCH
    assert len(result.candidates) == 3
    assert all(not c.acceptable for c in result.candidates)
    assert any(c.lacks for c in result.candidates)


def test_qos_bound_filters(mini_kb: KnowledgeBase) -> None:
    # The requirement needs responseTime <= 0.5: the camera (0.1) passes, the door opener states none.
    result = Matchmaker(mini_kb).rank("http://example.org/mini#SelfPosition")
    by_iri = {c.advertisement.rsplit("#", 1)[1]: c for c in result.candidates}
    assert not any(r.startswith("QoS") for r in by_iri["Locate"].rejected_by)
    # the door opener states no QoS at all (as no OWL-S service does): unknown is not failing
    assert not by_iri["OpenDoor"].rejected_by
    matcher = Matchmaker(mini_kb)
    requirement = matcher.kb.description("http://example.org/mini#SelfPosition")
    assert isinstance(requirement, Requirement)
    other = QoSValue("http://example.org/mini#accuracy", 0.9)
    assert matcher.filters(requirement, None, (other,)) == ["QoS: states no responseTime (needs 0.5)"]
    lenient = Matchmaker(mini_kb, config=MatchConfig(qos_missing_fails=False))
    assert lenient.filters(requirement, None, (other,)) == []


def test_rank_refuses_an_advertisement(sem_str: Matchmaker) -> None:
    with pytest.raises(NotFoundError, match="requirement"):
        sem_str.rank(SVC + "LocateMobileRobot_CeilingCamera01")


def test_requirements_are_read_again_after_the_store_changes(mini_kb: KnowledgeBase) -> None:
    iri = "http://example.org/mini#SelfPosition"
    matcher = Matchmaker(mini_kb).prepare()  # reads the store's requirements once
    before = {c.advertisement: c.parts for c in matcher.rank(iri).candidates}
    mini_kb.update(
        """PREFIX cbrs: <https://w3id.org/cbrs/core#> PREFIX ex: <http://example.org/mini#>
        DELETE { GRAPH ?g { ?p cbrs:parameterType ex:RobotPosition } }
        INSERT { GRAPH ?g { ?p cbrs:parameterType ex:Door } }
        WHERE { GRAPH ?g { ex:SelfPosition cbrs:hasOWLSModel/cbrs:hasOutput ?p . ?p cbrs:parameterType ?t } }"""
    )
    after = {c.advertisement: c.parts for c in matcher.rank(iri).candidates}
    assert after != before  # the output asked for is now a Door, not the cached RobotPosition
    assert matcher.rank(iri).requirement == iri


# -- conceptual span similarity and statements ----------------------------------------------

X, Y = PartNode(E + "XCoordinate", E + "hasX"), PartNode(E + "YCoordinate", E + "hasY")


def tree(concept: str, *children: PartNode) -> PartNode:
    return PartNode(E + concept, None, children)


def test_css_root_match_is_the_root_similarity() -> None:
    measure = SemStr(positions())
    match = conceptual_span_similarity(tree("RobotPosition", X, Y), tree("RobotPosition", X, Y), measure, 0.5)
    assert match.value == 1.0 and match.uncovered == ()
    only_root = conceptual_span_similarity(tree("RobotPosition"), tree("Position"), measure, 0.5)
    assert only_root.value == pytest.approx(2 * 3 / (1 + 2 * 3))  # Wu-Palmer, Position at depth 3


def test_css_parts_lift_position_against_location() -> None:
    measure = SemStr(positions())
    flat = measure(E + "RobotPosition", E + "RobotLocation").value
    match = conceptual_span_similarity(tree("RobotPosition", X, Y), tree("RobotLocation", X, Y), measure, 0.5)
    assert match.value == pytest.approx((flat + 2) / 3)
    assert match.value > flat


def test_css_ignores_parts_implied_by_the_common_superclass() -> None:
    # RobotPosition and PersonPosition both inherit x and y from Position: no evidence beyond it.
    measure = SemStr(positions())
    flat = measure(E + "RobotPosition", E + "PersonPosition").value
    implied = positions().parts_of(E + "Position")
    assert implied == {E + "XCoordinate", E + "YCoordinate"}
    match = conceptual_span_similarity(
        tree("RobotPosition", X, Y), tree("PersonPosition", X, Y), measure, 0.5, implied=implied
    )
    assert match.value == pytest.approx(flat)


def test_css_a_subclass_inherits_every_requested_part() -> None:
    # RobotPosition is a Position: it has x and y by inheritance, so they are covered, not left out.
    # Left out, a subclass (0.86) ranked below a sibling lifted by the same parts (Location, 0.89).
    index = positions()
    measure = SemStr(index)
    implied = index.parts_of(E + "Position")
    flat = measure(E + "Position", E + "RobotPosition").value
    wanted = tree("Position", X, Y)
    subclass = conceptual_span_similarity(wanted, tree("RobotPosition"), measure, 0.5, implied=implied, inherited=True)
    assert subclass.value == pytest.approx((flat + 2) / 3)
    inherited = {p.requested for p in subclass.pairs if p.similarity.situation == "inherited"}
    assert inherited == {E + "XCoordinate", E + "YCoordinate"} and subclass.uncovered == ()
    left_out = conceptual_span_similarity(wanted, tree("RobotPosition"), measure, 0.5, implied=implied)
    assert left_out.value == pytest.approx(flat)
    sibling = conceptual_span_similarity(wanted, tree("Location", X, Y), measure, 0.5)
    assert subclass.value > sibling.value > measure(E + "Position", E + "Location").value


def _parameter(direction: str, concept: str) -> Parameter:
    return Parameter(f"{E}{direction}-{concept}", direction, E + concept)  # type: ignore[arg-type]


def test_an_input_offered_as_a_subclass_makes_the_advertisement_invocable() -> None:
    # The advertisement takes any Position; the requester offers a RobotPosition, which it can pass as
    # it is: "can it be invoked?" scores 1, though the taxonomy gives the pair 0.86.
    index = positions()
    kb = KnowledgeBase(Store.open(":memory:"))
    wants = Advertisement(E + "WantsPosition", (), inputs=(_parameter("input", "Position"),))
    sibling = Advertisement(E + "WantsLocation", (), inputs=(_parameter("input", "Location"),))
    requirement = Requirement(E + "Needs", (), inputs=(_parameter("input", "RobotPosition"),))
    ranked = Matchmaker(kb, index=index, advertisements=[sibling, wants]).rank(requirement)
    best = ranked.candidates[0]
    assert best.advertisement == E + "WantsPosition"
    needed = next(p for p in best.pairs if p.role == "input")
    assert needed.similarity == 1.0 and "invocable" in needed.how
    used = SemStr(index)(E + "RobotPosition", E + "Position").value
    # "does it use what the requester offers?": a Position input takes the RobotPosition one link below
    delivered = 1 - MatchConfig().specialisation_step
    assert best.parts["inputs"] == pytest.approx((1 + delivered) / 2)
    off = Matchmaker(
        kb, config=MatchConfig(plugin_inputs=False, plugin_outputs=False), index=index, advertisements=[wants]
    )
    assert off.score(requirement, wants).parts["inputs"] == pytest.approx(used)
    # pure string matching knows no subclasses
    string = Matchmaker(kb, "string", index=index, advertisements=[wants]).score(requirement, wants)
    assert string.parts["inputs"] == 0.0


def test_css_reports_uncovered_parts() -> None:
    measure = SemStr(positions())
    match = conceptual_span_similarity(tree("Position", X, Y), tree("Colour", X), measure, 0.9)
    assert E + "YCoordinate" in match.uncovered
    assert 0 < match.value < 1


def test_statement_similarity_weighs_subject_predicate_object() -> None:
    measure = SemStr(positions())
    config = MatchConfig()
    same = Statement(E + "Position", E + "isNear", E + "Location")
    assert statement_similarity(same, same, measure, config).value == pytest.approx(1.0)
    other = Statement(E + "RobotPosition", E + "isNear", E + "Location")
    value = statement_similarity(same, other, measure, config).value
    subject = 2 * 3 / (1 + 2 * 3)
    assert value == pytest.approx(subject ** (1 / 3))  # geometric: a statement is as good as its worst position
    arithmetic = MatchConfig(statement_mean="arithmetic")
    assert statement_similarity(same, other, measure, arithmetic).value == pytest.approx((subject + 1 + 1) / 3)


# -- the command ---------------------------------------------------------------------------------


def test_cbrs_match_ranks_and_explains() -> None:
    result = CliRunner().invoke(
        cli, ["--store", ":memory:", "match", "req:RobotSelfPosition", "--top", "3", "--explain"]
    )
    assert result.exit_code == 0, result.output
    lines = result.output.splitlines()
    assert lines[0] == "req:RobotSelfPosition: matched by sem-str; best svc:LocateMobileRobot_CeilingCamera01"
    assert "Wu-Palmer via SpatialData" in result.output
    assert "(3 of 53 advertisements)" in result.output


def test_cbrs_match_json() -> None:
    result = CliRunner().invoke(
        cli,
        ["--store", ":memory:", "match", "req:RobotSelfPosition", "--top", "2", "--json", "--method", "lin"],
    )
    assert result.exit_code == 0
    data = json.loads(result.output)
    assert data["method"] == "lin" and data["status"] == "matched" and len(data["candidates"]) == 2
    assert {"advertisement", "score", "parts", "pairs", "lacks", "rejected_by", "acceptable"} <= set(
        data["candidates"][0]
    )


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["match", "req:Nope"], "no service description"),
        (["match", "svc:LocateMobileRobot_CeilingCamera01"], "it is an advertisement"),
        (["match", "req:RobotSelfPosition", "--method", "magic"], "'magic' is not one of"),
    ],
)
def test_cbrs_match_errors(args: list[str], message: str) -> None:
    result = CliRunner().invoke(cli, ["--store", ":memory:", *args])
    assert result.exit_code != 0 and message in result.output
