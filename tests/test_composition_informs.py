"""A value that only informs of a thing does not put the step given it where the thing is
(docs/composition.md#values-that-lead-to-a-thing-and-values-that-only-inform-of-it).

The lab's TellMeMyCupsWeight (docs/examples/lab_*): the kitchen scale weighs the cup, and the speaker,
effective in the living room alone, tells the person in the living room the weight. A second speaker,
effective in the bedroom only, is kept out of the compositions that do not ask for it.
"""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

import pytest
from click.testing import CliRunner

from cbrs.actions.areas import INFORMS, LEADS, Leads, UnknownAreaClassError
from cbrs.actions.composer import ComposeConfig, Composer, CompositionResult, PlanStatus
from cbrs.app import App
from cbrs.cli_actions import plan, run
from cbrs.kb import KnowledgeBase
from cbrs.kb.namespaces import PREFIXES

EXAMPLES = Path(__file__).parent.parent / "docs" / "examples"
HOME = PREFIXES["home"]
LAB = "https://example.org/lab#"
SPEAKER = LAB + "AnnounceWeight_LivingRoomSpeaker01"
BEDROOM_SPEAKER = LAB + "AnnounceWeight_BedroomSpeaker01"
TASK = "TellMeMyCupsWeight"
CYTON_PICKS = PREFIXES["svc"] + "PickUpObject_CytonDualArm01"
BEDROOM_ARM_PICKS = LAB + "PickUpObject_BedroomArm01"


def _bedroom_speaker() -> str:
    """The living-room speaker's description, as a second speaker effective in the bedroom only."""
    text = (EXAMPLES / "lab_living_room_speaker.ttl").read_text(encoding="utf-8")
    for old, new in (
        ("LivingRoomSpeaker01", "BedroomSpeaker01"),
        ("effectiveArea home:LivingRoom", "effectiveArea home:Bedroom"),
        ("cbrs:minY 0.0 ; cbrs:maxY 5.0", "cbrs:minY 5.0 ; cbrs:maxY 9.0"),
        ("/living_room_speaker_01/", "/bedroom_speaker_01/"),
    ):
        assert old in text, old  # the example changed: say so rather than test something else
        text = text.replace(old, new)
    return text


def _fill(kb: KnowledgeBase) -> None:
    kb.load([EXAMPLES / "lab_kitchen_scale.ttl"], graph="ontology")
    kb.load([EXAMPLES / "lab_kitchen_scale.ttl"], graph="map")
    kb.load([EXAMPLES / "lab_tell_me_my_cups_weight.ttl"], graph="requirements")
    kb.registry.register_all(
        [
            ((EXAMPLES / "lab_weigh_object.ttl").read_bytes(), "lab_weigh_object.ttl"),
            ((EXAMPLES / "lab_living_room_speaker.ttl").read_bytes(), "lab_living_room_speaker.ttl"),
            (_bedroom_speaker(), "bedroom_speaker.ttl"),
        ]
    )


@pytest.fixture(scope="module")
def kb() -> Iterator[KnowledgeBase]:
    found = KnowledgeBase.open(":memory:")
    _fill(found)
    yield found
    found.close()


@pytest.fixture(scope="module")
def bedroom_only_kb() -> Iterator[KnowledgeBase]:
    """The same store with the bedroom speaker alone."""
    found = KnowledgeBase.open(":memory:")
    _fill(found)
    found.registry.deregister(SPEAKER)
    yield found
    found.close()


def _compose(kb: KnowledgeBase, without: str, config: ComposeConfig | None = None) -> CompositionResult:
    kept = [ad for ad in kb.advertisements() if ad.iri != without]
    return Composer(kb, config, advertisements=kept).compose(TASK)


def test_the_living_room_speaker_tells_the_weight_the_scale_measured(kb: KnowledgeBase) -> None:
    result = _compose(kb, BEDROOM_SPEAKER)
    assert result.plan is not None, [u.text() for u in result.unsatisfied]
    [told] = [step for step in result.plan.steps if step.component == SPEAKER]
    [weight] = [b for b in told.inputs if b.name == "weight"]
    assert weight.source.step is not None  # the scale's answer, not a value the task gives


def test_by_the_former_rule_the_weight_tied_the_speaker_to_the_cup(kb: KnowledgeBase) -> None:
    result = _compose(kb, BEDROOM_SPEAKER, ComposeConfig(area_informs=()))
    assert result.status is PlanStatus.UNSOLVABLE
    [unmet] = result.unsatisfied
    assert [component for component, _ in unmet.out_of_area] == [SPEAKER]
    assert "does not cover world:Cup" in unmet.out_of_area[0][1]
    assert "cbrs plan or cbrs run --ignore-areas" in unmet.text()


def test_a_speaker_away_from_the_person_it_is_given_is_still_passed_over(bedroom_only_kb: KnowledgeBase) -> None:
    result = Composer(bedroom_only_kb).compose(TASK)
    assert result.status is PlanStatus.UNSOLVABLE
    [unmet] = result.unsatisfied
    [(component, why)] = unmet.out_of_area
    assert component == BEDROOM_SPEAKER
    assert "does not cover world:Person" in why and "home:LivingRoom" in why


BEDROOM_ARM = """
@prefix cbrs: <https://w3id.org/cbrs/core#> .
@prefix home: <https://w3id.org/cbrs/home#> .
@prefix lab:  <https://example.org/lab#> .
@prefix owl:  <http://www.w3.org/2002/07/owl#> .
lab:BedroomArm01 a owl:NamedIndividual , home:Device .
lab:PickUpObject_BedroomArm01 a cbrs:PhysicalManipulationComponent ;
    cbrs:device lab:BedroomArm01 ; cbrs:deviceName "BedroomArm01" ; cbrs:serviceName "PickUpObject" ;
    cbrs:hasOWLSModel [ a cbrs:OWLSModel ;
        cbrs:hasInput [ a cbrs:Parameter ; cbrs:parameterName "graspPose" ; cbrs:parameterType home:GraspPose ] ;
        cbrs:hasPrecondition [ a cbrs:Precondition ; cbrs:conditionSubject home:Gripper ;
            cbrs:conditionPredicate home:isNear ; cbrs:conditionObject home:PhysicalObject ] ;
        cbrs:hasEffect [ a cbrs:Effect ; cbrs:conditionSubject home:PhysicalObject ;
            cbrs:conditionPredicate home:isGraspedBy ; cbrs:conditionObject home:Gripper ] ] ;
    cbrs:hasSEAModel [ a cbrs:SEAModel ; cbrs:effectiveArea home:Bedroom ;
        cbrs:minX 0.0 ; cbrs:maxX 6.0 ; cbrs:minY 5.0 ; cbrs:maxY 9.0 ] ;
    cbrs:hasPort [ a cbrs:ServicePort ; cbrs:portName "pickUp" ; cbrs:topic "/bedroom_arm_01/pick_up" ] .
"""


def test_what_a_value_that_informs_is_about_still_leads_further() -> None:
    # the grasp planner is given the cup's manipulation properties, which only inform, so it may run
    # anywhere; the grasp pose it computes is still the cup's, so the arm that picks the cup up with it
    # must reach the kitchen: an arm over the bedroom is no alternative (without the rule, it is one)
    store = KnowledgeBase.open(":memory:")
    try:
        _fill(store)
        store.registry.register(BEDROOM_ARM)
        for config, offered in ((None, set()), (ComposeConfig(respect_area=False), {BEDROOM_ARM_PICKS})):
            result = _compose(store, BEDROOM_SPEAKER, config)
            assert result.plan is not None, [u.text() for u in result.unsatisfied]
            [pick] = [step for step in result.plan.steps if "PickUpObject" in step.component]
            assert {pick.component, *pick.alternatives} - {CYTON_PICKS} == offered
    finally:
        store.close()


@pytest.mark.parametrize(
    ("concept", "leads"),
    [
        pytest.param("ObjectWeight", False, id="a measured quantity informs"),
        pytest.param("TextMessage", False, id="a message informs"),
        pytest.param("ManipulationProperty", False, id="knowledge of a kind informs"),
        pytest.param("ColourFeature", True, id="a feature leads"),
        pytest.param("ShapeFeature", True, id="a feature without parts leads"),
        pytest.param("ObjectPosition3D", True, id="a position leads"),
        pytest.param("GraspPose", True, id="a grasp pose leads"),
        pytest.param("ObjectPlace", True, id="a place is no information"),
        pytest.param(None, True, id="an untyped value may lead"),
    ],
)
def test_what_leads_is_read_from_the_taxonomy(kb: KnowledgeBase, concept: str | None, leads: bool) -> None:
    rule = Composer(kb).area_roles()  # the store's cbrs:areaRole marks (ontologies/home.ttl)
    assert rule(HOME + concept if concept else None) is leads


def test_the_roles_are_the_stores_marks_and_the_nearer_mark_wins(kb: KnowledgeBase) -> None:
    """A lab marks its own classes in Turtle (``cbrs:areaRole``): a mark below another wins for the classes
    below it, so a position a lab reads as a figure only (marked to inform) stops tying the step given it."""
    composer = Composer(kb)
    assert composer.area_roles().roles == {
        HOME + "InformationEntity": INFORMS,
        HOME + "SpatialData": LEADS,
        HOME + "Feature": LEADS,
        HOME + "Status": INFORMS,  # a door's or a device's state: an observation's result, as a measurement is
    }
    marked = Leads(composer.index, {**composer.area_roles().roles, HOME + "ObjectPosition3D": INFORMS})
    assert not marked(HOME + "ObjectPosition3D") and marked(HOME + "GraspPose")  # a sibling keeps SpatialData's
    with pytest.raises(UnknownAreaClassError, match="no area role"):
        Leads(composer.index, {HOME + "Feature": HOME + "Feature"})


def test_a_class_the_taxonomy_does_not_hold_is_refused(kb: KnowledgeBase) -> None:
    misspelt = HOME + "SpatialDta"
    with pytest.raises(UnknownAreaClassError) as refused:
        _compose(kb, BEDROOM_SPEAKER, ComposeConfig(area_leads=(misspelt,)))
    assert refused.value.concept == misspelt
    assert misspelt in str(refused.value)


def test_plan_and_run_ignore_areas(bedroom_only_kb: KnowledgeBase) -> None:
    app = App(":memory:", bedroom_only_kb)  # this store, as opened
    refused = CliRunner().invoke(plan, [TASK, "--no-store"], obj=app)
    assert refused.exit_code == 1
    assert "BedroomSpeaker01 was passed over" in refused.output and "--ignore-areas" in refused.output
    planned = CliRunner().invoke(plan, [TASK, "--no-store", "--ignore-areas"], obj=app)
    assert planned.exit_code == 0, planned.output
    assert "planned" in planned.output and "AnnounceWeight_BedroomSpeaker01" in planned.output
    assert "--ignore-areas" in CliRunner().invoke(run, ["--help"]).output
