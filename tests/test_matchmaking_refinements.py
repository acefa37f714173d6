"""The refinements of docs/matchmaking.md section 9: each one on a small known-answer case, on and off."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import replace
from pathlib import Path

import pytest

from cbrs.kb import Advertisement, KnowledgeBase, Parameter, Requirement, Statement, Store
from cbrs.reasoner.antonyms import DATA_FILE as ANTONYMS
from cbrs.reasoner.antonyms import forms, opposite
from cbrs.reasoner.config import MatchConfig
from cbrs.reasoner.lexicon import DATA_FILE, Lexicon
from cbrs.reasoner.matchmaker import EntityPair, Matchmaker
from cbrs.reasoner.owlstc import CollectionReport, LoadedCollection, evaluate_collection, load_collection
from cbrs.reasoner.similarity import SemStr
from cbrs.reasoner.statements import statement_similarity
from cbrs.reasoner.taxonomy import Link, TaxonomyIndex
from tests.reasoner_examples import E, positions

ROBOT = Path(__file__).parent / "data" / "robot_services"
HELDOUT = Path(__file__).parent / "data" / "robot_heldout"
needs_wordnet = pytest.mark.skipif(not DATA_FILE.exists(), reason=f"no bundled WordNet data at {DATA_FILE}")


def _p(direction: str, concept: str) -> Parameter:
    return Parameter(f"{E}{direction}-{concept}", direction, E + concept)  # type: ignore[arg-type]


def _rank(config: MatchConfig, requirement: Requirement, *ads: Advertisement, method: str = "sem-str") -> list[str]:
    kb = KnowledgeBase(Store.open(":memory:"))
    result = Matchmaker(kb, method, config, index=positions(), advertisements=list(ads)).rank(requirement)
    return [c.advertisement.removeprefix(E) for c in result.candidates]


def test_an_output_delivered_as_a_subclass_beats_a_look_alike_sibling() -> None:
    # Asked for a Position: a RobotPosition is one; a Location (a sibling with the same parts) is not.
    wanted = Requirement(E + "Wants", (), outputs=(_p("output", "Position"),))
    sub = Advertisement(E + "GivesRobotPosition", (), outputs=(_p("output", "RobotPosition"),))
    sibling = Advertisement(E + "GivesLocation", (), outputs=(_p("output", "Location"),))
    on = _rank(MatchConfig(), wanted, sibling, sub)
    assert on[0] == "GivesRobotPosition"
    kb = KnowledgeBase(Store.open(":memory:"))
    best = Matchmaker(kb, index=positions(), advertisements=[sub]).score(wanted, sub)
    assert best.parts["outputs"] == pytest.approx(1 - MatchConfig().specialisation_step)
    assert any("delivered as a subclass" in p.how for p in best.pairs)
    off = Matchmaker(kb, config=MatchConfig(plugin_outputs=False), index=positions(), advertisements=[sub])
    assert off.score(wanted, sub).parts["outputs"] < best.parts["outputs"]


def test_an_input_narrower_than_the_one_offered_is_nearly_invocable() -> None:
    # The requester offers some Information. One service takes a RobotPosition, three is-a links below it:
    # the requester's information may be one (OWL-S's "subsumes" degree for inputs), though Wu-Palmer
    # gives the pair 0.4. Another service needs nothing. Both give the Colour asked for.
    wanted = Requirement(E + "Wants", (), inputs=(_p("input", "Information"),), outputs=(_p("output", "Colour"),))
    narrower = Advertisement(
        E + "TakesRobotPosition", (), inputs=(_p("input", "RobotPosition"),), outputs=(_p("output", "Colour"),)
    )
    free = Advertisement(E + "NeedsNothing", (), outputs=(_p("output", "Colour"),))
    step = MatchConfig().narrower_input_step
    kb = KnowledgeBase(Store.open(":memory:"))
    on = Matchmaker(kb, index=positions(), advertisements=[free, narrower])
    ranked = on.rank(wanted)  # scored by the batch path, the head explained by the scalar one
    assert [c.advertisement.removeprefix(E) for c in ranked.candidates] == ["TakesRobotPosition", "NeedsNothing"]
    best = ranked.candidates[0]
    assert best.score == pytest.approx(on.rank(wanted, explain=0).candidates[0].score)
    pair = next(p for p in best.pairs if p.role == "input")
    assert pair.similarity == pytest.approx(1 - 3 * step) and "below the one offered" in pair.how
    used = SemStr(positions())(E + "Information", E + "RobotPosition").value  # the other side keeps Sem-Str
    u = MatchConfig().input_use_weight
    assert best.parts["inputs"] == pytest.approx((1 - u) * (1 - 3 * step) + u * used)
    # off (step 1): the pair keeps its Wu-Palmer value and the offer that needs nothing ranks first
    config = MatchConfig(narrower_input_step=1.0)
    off = Matchmaker(kb, config=config, index=positions(), advertisements=[free, narrower])
    assert off.score(wanted, narrower).parts["inputs"] == pytest.approx(used)
    assert _rank(config, wanted, free, narrower) == ["NeedsNothing", "TakesRobotPosition"]
    # the baselines keep the published frame: no floor for a narrower input
    assert MatchConfig().published().narrower_input_step == 1.0


def test_baselines_keep_the_published_frame() -> None:
    wanted = Requirement(E + "Wants", (), outputs=(_p("output", "Position"),))
    sub = Advertisement(E + "GivesRobotPosition", (), outputs=(_p("output", "RobotPosition"),))
    kb = KnowledgeBase(Store.open(":memory:"))
    wu_palmer = Matchmaker(kb, "wu-palmer", index=positions(), advertisements=[sub])
    assert wu_palmer.config == MatchConfig().published()
    assert wu_palmer.score(wanted, sub).parts["outputs"] < 1 - MatchConfig().specialisation_step


def test_an_offer_that_needs_nothing_is_invocable() -> None:
    wanted = Requirement(E + "Wants", (), inputs=(_p("input", "Colour"),), outputs=(_p("output", "Position"),))
    free = Advertisement(E + "NeedsNothing", (), outputs=(_p("output", "Position"),))
    kb = KnowledgeBase(Store.open(":memory:"))
    on = Matchmaker(kb, index=positions(), advertisements=[free]).score(wanted, free)
    assert on.parts["inputs"] == pytest.approx(1 - MatchConfig().input_use_weight)
    off = Matchmaker(kb, config=MatchConfig(no_input_invocable=False), index=positions(), advertisements=[free])
    assert off.score(wanted, free).parts["inputs"] == 0.0


def test_input_gate_scales_the_score_by_what_the_requester_can_supply() -> None:
    wanted = Requirement(E + "Wants", (), inputs=(_p("input", "Colour"),), outputs=(_p("output", "Position"),))
    needy = Advertisement(E + "NeedsLaser", (), inputs=(_p("input", "Timestamp"),), outputs=(_p("output", "Position"),))
    kb = KnowledgeBase(Store.open(":memory:"))
    plain = Matchmaker(kb, index=positions(), advertisements=[needy]).score(wanted, needy)
    gated = Matchmaker(kb, config=MatchConfig(input_gate=0.5), index=positions(), advertisements=[needy])
    assert gated.score(wanted, needy).score < plain.score


def test_a_statement_is_about_as_good_as_its_worst_position() -> None:
    measure = SemStr(positions())
    wanted = Statement(E + "Position", E + "isNear", E + "Location")
    far = Statement(E + "Position", E + "isNear", E + "Timestamp")
    geometric = statement_similarity(wanted, far, measure, MatchConfig()).value
    arithmetic = statement_similarity(wanted, far, measure, MatchConfig(statement_mean="arithmetic")).value
    assert geometric < arithmetic
    with pytest.raises(ValueError, match="statement_mean"):
        MatchConfig(statement_mean="median")


def test_same_name_in_another_ontology_is_linked_across_branches() -> None:
    # Two ontologies, each with its own City: the taxonomy meets them only at the root.
    index = TaxonomyIndex.from_links(
        [
            Link("http://a.org/o#City", "http://a.org/o#Place", "is-a"),
            Link("http://b.org/o#City", "http://b.org/o#Area", "is-a"),
        ]
    )
    on = SemStr(index)("http://a.org/o#City", "http://b.org/o#City")
    off = SemStr(index, MatchConfig(cross_branch_weight=0.0))("http://a.org/o#City", "http://b.org/o#City")
    assert on.situation == "cross-branch" and on.value == pytest.approx(MatchConfig().cross_branch_weight)
    assert off.situation == "situation-1" and off.value < on.value


@needs_wordnet
def test_wordnet_links_core_words() -> None:
    lexicon = Lexicon.load()
    assert lexicon.similarity("image", "picture") == 1.0  # one synset
    assert lexicon.similarity("boxes", "box") == 1.0  # a plural is its lemma
    assert 0 < lexicon.similarity("city", "town") < 1
    assert lexicon.similarity("status", "temperature") == 0.0
    assert lexicon.similarity("e", "d") == 0.0  # letters are no words
    measure = SemStr(positions(), MatchConfig(lexicon=True))
    # outside the taxonomy (Situation 3): Picture against Image is a synonym, not a chance of letters
    assert measure(E + "Picture", E + "Image").value == pytest.approx(1.0)
    assert SemStr(positions())(E + "Picture", E + "Image").value < 0.5  # off by default


def test_empty_lexicon_knows_only_equal_words(tmp_path: Path) -> None:
    lexicon = Lexicon.load(tmp_path / "absent.json")
    assert not lexicon
    assert lexicon.similarity("cat", "cat") == 1.0 and lexicon.similarity("image", "picture") == 0.0


@pytest.fixture(scope="module")
def collections() -> Callable[[Path], LoadedCollection]:
    """Each collection folder loaded once for the module; the tests only rank in it."""
    loaded: dict[Path, LoadedCollection] = {}

    def load(root: Path) -> LoadedCollection:
        if root not in loaded:
            loaded[root] = load_collection(root)
        return loaded[root]

    return load


@pytest.fixture(scope="module")
def robot_report(collections: Callable[[Path], LoadedCollection]) -> CollectionReport:
    return evaluate_collection(ROBOT, ["sem-str", "wu-palmer", "logic"], loaded=collections(ROBOT))


def test_robot_collection_has_the_size_the_issue_asks(robot_report: CollectionReport) -> None:
    assert robot_report.services >= 60 and robot_report.queries >= 15
    assert robot_report.unmatched_requests == [] and robot_report.unmatched_offers == 0


def test_sem_str_ranks_the_robot_collection_above_the_baselines(robot_report: CollectionReport) -> None:
    figures = robot_report.methods
    assert figures["sem-str"]["map"] > max(figures["wu-palmer"]["map"], figures["logic"]["map"]) - 0.03
    assert figures["sem-str"]["map"] > figures["wu-palmer"]["map"]


BLIND = ["robot_heldout", "robot_validation", "robot_final", "robot_blind5", "robot_blind6"]


@pytest.mark.parametrize("folder", BLIND)
def test_sem_str_stays_first_on_the_collections_written_blind(
    folder: str, collections: Callable[[Path], LoadedCollection]
) -> None:
    """The refinements were found on the development collection; on the collections other engineers
    wrote and graded before any matchmaker ran (docs/matchmaking.md 9.7) Sem-Str must stay above every
    baseline and above its own published frame, or a rule fits one grader rather than the task."""
    root = Path(__file__).parent / "data" / folder
    loaded = collections(root)
    figures = evaluate_collection(root, ["sem-str", "wu-palmer", "lin", "logic", "string"], loaded=loaded).methods
    published = evaluate_collection(root, ["sem-str"], MatchConfig().published(), loaded=loaded).methods["sem-str"][
        "map"
    ]
    best_baseline = max(figures[m]["map"] for m in ("wu-palmer", "lin", "logic", "string"))
    assert figures["sem-str"]["map"] > best_baseline
    assert figures["sem-str"]["map"] > published


def test_the_best_match_of_every_robot_query_is_explained_without_fail(
    collections: Callable[[Path], LoadedCollection],
) -> None:
    """Issue 19: the explanation of the best match says how each pair matched; "Fail" only below the
    pair threshold with no rule, which the best match of a query never shows."""
    loaded = collections(ROBOT)
    matcher = Matchmaker(loaded.kb)
    shown = {
        iri: [pair.shown_degree() for pair in matcher.rank(iri, explain=1).candidates[0].pairs]
        for iris in loaded.requirements.values()
        for iri in iris
    }
    assert len(shown) >= 15 and all(degrees for degrees in shown.values())
    assert {iri: degrees for iri, degrees in shown.items() if "Fail" in degrees} == {}


def test_a_pair_reads_as_similar_above_the_threshold_and_fail_below() -> None:
    pair = EntityPair("output", M + "Location", M + "Position", 0.8, "situation-2", "Fail")
    assert pair.shown_degree() == "Similar" and replace(pair, similarity=0.3).shown_degree() == "Fail"
    assert replace(pair, degree="SubClassOf", similarity=0.1).shown_degree() == "SubClassOf"


DEFINED = Path(__file__).parent / "data" / "defined_classes.ttl"
M = "http://example.org/mini#"


@pytest.fixture(scope="module")
def defined_kb() -> KnowledgeBase:
    kb = KnowledgeBase(Store.open(":memory:"))
    kb.load([DEFINED], graph="ontology")
    return kb


def test_classes_defined_by_intersection_or_union_have_their_named_classes_as_relatives(defined_kb) -> None:  # type: ignore[no-untyped-def]
    index = TaxonomyIndex.from_kb(defined_kb)
    assert M + "Camera" in index.parents(M + "Digital")  # Digital = Camera and (hasLens some Lens)
    assert index.distance_down(M + "Bread", M + "BreadOrBiscuit") == 1  # BreadOrBiscuit = Bread or Biscuit


def test_disjointness_is_read_and_inherited(defined_kb) -> None:  # type: ignore[no-untyped-def]
    index = TaxonomyIndex.from_kb(defined_kb)
    assert index.disjoint(M + "Opened", M + "Closed") and index.disjoint(M + "Closed", M + "Opened")
    assert index.disjoint(M + "Locked", M + "Opened")  # Locked is a Closed
    assert index.disjoint(M + "Ajar", M + "Opened")  # owl:AllDisjointClasses
    assert not index.disjoint(M + "Locked", M + "Closed") and not index.disjoint(M + "Ajar", M + "Closed")
    assert not index.disjoint(M + "Opened", M + "Unknown")


def test_an_effect_that_contradicts_the_requested_one_scores_nothing(defined_kb) -> None:  # type: ignore[no-untyped-def]
    def effect(state: str) -> tuple[Statement, ...]:
        return (Statement(M + "Door", M + "hasState", M + state),)

    wanted = Requirement(M + "OpenTheDoor", (), effects=effect("Opened"))
    ads = [Advertisement(M + f"Make{state}", (), effects=effect(state)) for state in ("Closed", "Locked", "Opened")]
    index = TaxonomyIndex.from_kb(defined_kb)
    on = Matchmaker(defined_kb, index=index, advertisements=ads)
    ranked = on.rank(wanted, explain=0).candidates
    assert ranked[0].advertisement == M + "MakeOpened"
    for candidate in ranked[1:]:  # the batch scores agree with the explained ones
        explained = on.score(wanted, next(a for a in ads if a.iri == candidate.advertisement))
        assert candidate.score == explained.score == 0.0
        assert "contradicts" in explained.pairs[0].how
    config = MatchConfig(disjoint_statements=False, antonym_statements=False)
    off = Matchmaker(defined_kb, config=config, index=index, advertisements=ads)
    assert off.score(wanted, ads[0]).parts["effects"] > 0.5  # Closed and Opened: siblings, alike by the taxonomy
    assert Matchmaker(defined_kb, "wu-palmer", index=index, advertisements=ads).config.disjoint_statements is False


def test_only_the_same_fact_with_an_incompatible_value_is_a_contradiction(defined_kb) -> None:  # type: ignore[no-untyped-def]
    # Opened and Closed are declared disjoint. (Door, hasState, Closed) is the same fact as the requested
    # (Door, hasState, Opened) with an incompatible value: a contradiction. (Door, showsLabel, Closed) is
    # another relation and (Lens, hasState, Closed) another thing: neither says the door is not open, so
    # they keep their similarity (same_fact_contradictions; off, any position clashes as before).
    wanted = Requirement(M + "OpenTheDoor", (), effects=(Statement(M + "Door", M + "hasState", M + "Opened"),))
    ads = [
        Advertisement(M + name, (), effects=(Statement(M + thing, M + relation, M + "Closed"),))
        for name, thing, relation in (
            ("CloseDoor", "Door", "hasState"),
            ("LabelClosed", "Door", "showsLabel"),
            ("CloseLens", "Lens", "hasState"),
        )
    ]
    index = TaxonomyIndex.from_kb(defined_kb)
    config = MatchConfig(unrelated_predicate_factor=1.0)  # so that another relation keeps a similarity
    on = Matchmaker(defined_kb, config=config, index=index, advertisements=ads)
    ranked = {c.advertisement.removeprefix(M): c.score for c in on.rank(wanted, explain=0).candidates}
    for ad in ads:  # the batch agrees with the explained scores
        assert ranked[ad.iri.removeprefix(M)] == on.score(wanted, ad).score
    contradicting = {ad.iri.removeprefix(M) for ad in ads if "contradicts" in on.score(wanted, ad).pairs[0].how}
    assert contradicting == {"CloseDoor"} and ranked["CloseDoor"] == 0.0
    assert ranked["LabelClosed"] > 0 and ranked["CloseLens"] > 0
    old = Matchmaker(
        defined_kb, config=replace(config, same_fact_contradictions=False), index=index, advertisements=ads
    )
    assert {c.score for c in old.rank(wanted, explain=0).candidates} == {0.0}


def test_an_offer_that_undoes_the_state_the_requester_is_in_can_score_nothing(defined_kb) -> None:  # type: ignore[no-untyped-def]
    # The requester guarantees the door is Opened and asks for it Ajar. Closing it is no contradiction of
    # Ajar (nothing declares them disjoint), but it makes the guaranteed Opened false without giving what
    # was asked: a side effect that undoes the requester's state. Making it Ajar undoes Opened too, and is
    # the change asked for; closing a Lens is about another thing.
    def state(thing: str, value: str) -> Statement:
        return Statement(M + thing, M + "hasState", M + value)

    wanted = Requirement(M + "PushAjar", (), preconditions=(state("Door", "Opened"),), effects=(state("Door", "Ajar"),))
    ads = [
        Advertisement(M + name, (), effects=(state(thing, value),))
        for name, thing, value in (
            ("CloseDoor", "Door", "Closed"),
            ("AjarDoor", "Door", "Ajar"),
            ("CloseLens", "Lens", "Closed"),
        )
    ]
    index = TaxonomyIndex.from_kb(defined_kb)
    on = Matchmaker(defined_kb, config=MatchConfig(undone_state_factor=0.0), index=index, advertisements=ads)
    ranked = on.rank(wanted, explain=0).candidates
    assert [c.advertisement.removeprefix(M) for c in ranked] == ["AjarDoor", "CloseLens", "CloseDoor"]
    closer = on.score(wanted, ads[0])
    assert ranked[2].score == closer.score == 0.0  # batch and scalar agree
    assert any("undoes the guaranteed (Door, hasState, Opened)" in lack for lack in closer.lacks)
    assert on.score(wanted, ads[1]).score == 1.0 and on.score(wanted, ads[2]).score > 0
    off = Matchmaker(defined_kb, index=index, advertisements=ads)  # the default: off (docs/matchmaking.md 9.5)
    kept = off.rank(wanted, explain=0).candidates
    assert kept[1].advertisement == M + "CloseDoor" and kept[1].score == off.score(wanted, ads[0]).score > 0.5
    assert (
        Matchmaker(
            defined_kb, "wu-palmer", config=on.config, index=index, advertisements=ads
        ).config.undone_state_factor
        == 1
    )


def test_an_offer_that_reports_the_requested_state_is_a_step_towards_it(defined_kb) -> None:  # type: ignore[no-untyped-def]
    wanted = Requirement(M + "OpenTheDoor", (), effects=(Statement(M + "Door", M + "hasState", M + "Opened"),))
    checks = Advertisement(M + "DoorChecker", (), outputs=(Parameter(M + "out", "output", M + "DoorState"),))
    other = Advertisement(M + "LensFinder", (), outputs=(Parameter(M + "out2", "output", M + "Lens"),))
    index = TaxonomyIndex.from_kb(defined_kb)
    matcher = Matchmaker(defined_kb, index=index, advertisements=[other, checks])
    ranked = matcher.rank(wanted, explain=0).candidates
    assert ranked[0].advertisement == M + "DoorChecker"
    explained = matcher.score(wanted, checks)
    opened_state = SemStr(index)(M + "DoorState", M + "Opened").value
    assert explained.parts["effects"] == pytest.approx(MatchConfig().observed_state_weight * opened_state)
    assert ranked[0].score == explained.score and "reports Opened" in explained.pairs[0].how
    # the logic degree stays Fail (no is-a link: the composer must not act on it); a reader sees the rule
    assert explained.pairs[0].degree == "Fail" and explained.pairs[0].shown_degree() == "Reports"
    assert matcher.score(wanted, other).parts["effects"] == 0.0  # a Lens is no state of a door, however alike
    off = Matchmaker(defined_kb, config=MatchConfig(observed_state_weight=0.0), index=index, advertisements=[checks])
    assert off.score(wanted, checks).parts["effects"] == 0.0


def test_a_statement_with_another_relation_states_another_fact() -> None:
    a, b = "http://a.org/o#", "http://b.org/o#"
    index = TaxonomyIndex.from_links(
        [
            Link(a + "isNear", a + "spatialRelation", "is-a"),
            Link(a + "isOn", a + "spatialRelation", "is-a"),
            Link(a + "isHeldBy", a + "holding", "is-a"),
            Link(b + "isNear", b + "relation", "is-a"),
        ]
    )
    config = MatchConfig()
    wanted = Statement(E + "Cup", a + "isNear", E + "Table")

    def similarity(predicate: str, cfg: MatchConfig = config) -> float:
        offered = Statement(E + "Cup", predicate, E + "Table")
        return statement_similarity(wanted, offered, SemStr(index, cfg), cfg).value

    assert similarity(a + "isHeldBy") == 0.0  # related only through the root: another relation
    assert similarity(a + "isOn") > 0.5  # a sibling under spatialRelation
    assert similarity(b + "isNear") > 0.5  # the same relation in another ontology (cross-branch)
    published = MatchConfig(unrelated_predicate_factor=1.0)
    assert similarity(a + "isHeldBy", published) > 0.0
    kb = KnowledgeBase(Store.open(":memory:"))
    ads = [
        Advertisement(E + p, (), effects=(Statement(E + "Cup", x + p, E + "Table"),))
        for x, p in ((a, "isHeldBy"), (b, "isNear"))
    ]
    requirement = Requirement(E + "Wants", (), effects=(wanted,))
    matcher = Matchmaker(kb, index=index, advertisements=ads)
    for candidate in matcher.rank(requirement, explain=0).candidates:  # the batch agrees with the scalar path
        ad = next(x for x in ads if x.iri == candidate.advertisement)
        assert candidate.score == matcher.score(requirement, ad).score


@pytest.mark.skipif(not ANTONYMS.exists(), reason=f"no bundled WordNet antonyms at {ANTONYMS}")
def test_opposite_states_are_known_by_their_names() -> None:
    assert forms("Opened".lower()) >= {"open", "opened"} and "stop" in forms("stopped")
    assert opposite(E + "Opened", E + "Closed") and opposite(E + "Closed", E + "Opened")
    assert opposite(E + "LightOn", E + "LightOff") and opposite(E + "DoorLocked", E + "Unlocked")
    assert not opposite(E + "Opened", E + "Locked") and not opposite(E + "Position", E + "Location")
    assert not opposite(E + "Opened", E + "FullyOpened")


@pytest.mark.skipif(not ANTONYMS.exists(), reason=f"no bundled WordNet antonyms at {ANTONYMS}")
def test_an_offer_that_does_the_opposite_of_what_is_asked_scores_nothing() -> None:
    # No disjointness declared (the states are not even in the taxonomy): the names say Closed undoes Opened.
    def door(state: str) -> tuple[Statement, ...]:
        return (Statement(E + "Door", E + "hasState", E + state),)

    wanted = Requirement(E + "OpenTheDoor", (), inputs=(_p("input", "Position"),), effects=door("Opened"))
    closer = Advertisement(E + "CloseDoor", (), inputs=(_p("input", "Position"),), effects=door("Closed"))
    ajar = Advertisement(E + "PushDoor", (), inputs=(_p("input", "Location"),), effects=door("Ajar"))
    kb = KnowledgeBase(Store.open(":memory:"))
    on = Matchmaker(kb, index=positions(), advertisements=[closer, ajar])
    ranked = on.rank(wanted, explain=0).candidates
    assert [c.advertisement for c in ranked] == [E + "PushDoor", E + "CloseDoor"]
    explained = on.score(wanted, closer)
    assert ranked[1].score == explained.score == 0.0  # batch and scalar agree
    assert (
        explained.parts["effects"] == 0.0 and "contradicts: Closed is the opposite of Opened" in explained.pairs[-1].how
    )
    kept = Matchmaker(kb, config=MatchConfig(contradiction_factor=1.0), index=positions(), advertisements=[closer])
    assert kept.rank(wanted, explain=0).candidates[0].score == kept.score(wanted, closer).score > 0.3  # its inputs
    names_off = MatchConfig(antonym_statements=False)
    off = Matchmaker(kb, config=names_off, index=positions(), advertisements=[closer])
    assert off.score(wanted, closer).parts["effects"] > 0.3  # Jaro-Winkler: closed and opened share letters
    assert Matchmaker(kb, "wu-palmer", index=positions(), advertisements=[closer]).config.contradiction_factor == 1


def test_only_a_kind_of_the_requested_value_reports_it(defined_kb) -> None:  # type: ignore[no-untyped-def]
    # DoorState is what a door state detector outputs; an output that is the value itself (Opened) or the
    # subject (Door) is something the service produces or finds, not the state it observes.
    wanted = Requirement(M + "OpenTheDoor", (), effects=(Statement(M + "Door", M + "hasState", M + "Opened"),))
    ads = [
        Advertisement(M + f"Gives{c}", (), outputs=(Parameter(M + f"out{c}", "output", M + c),))
        for c in ("DoorState", "Opened", "Door")
    ]
    index = TaxonomyIndex.from_kb(defined_kb)
    matcher = Matchmaker(defined_kb, index=index, advertisements=ads)
    ranked = {c.advertisement: c for c in matcher.rank(wanted, explain=0).candidates}
    for ad in ads:
        assert ranked[ad.iri].score == matcher.score(wanted, ad).score  # batch and scalar agree
    assert ranked[M + "GivesDoorState"].parts["effects"] > 0
    assert ranked[M + "GivesOpened"].parts["effects"] == ranked[M + "GivesDoor"].parts["effects"] == 0.0
    old = Matchmaker(defined_kb, config=MatchConfig(observed_state_kind=False), index=index, advertisements=ads)
    old_ranked = {c.advertisement: c for c in old.rank(wanted, explain=0).candidates}
    assert old_ranked[M + "GivesOpened"].parts["effects"] == MatchConfig().observed_state_weight
    assert old.score(wanted, ads[1]).score == old_ranked[M + "GivesOpened"].score


def test_equal_scores_are_ordered_by_what_was_asked_for_before_the_iri(
    collections: Callable[[Path], LoadedCollection],
) -> None:
    loaded = collections(ROBOT)
    wanted = loaded.requirements["room_temperature.owls"][0]
    on = Matchmaker(loaded.kb).rank(wanted, explain=0).candidates
    names = [c.advertisement.rsplit("#", 1)[-1] for c in on]
    thermostat, humidity = (on[names.index(n)] for n in ("THERMOSTAT_READER_SERVICE", "HUMIDITY_SENSOR_SERVICE"))
    assert thermostat.score == humidity.score  # a Temperature from a Room it is not given; a Humidity
    assert thermostat.parts["outputs"] > humidity.parts["outputs"]
    assert names.index("THERMOSTAT_READER_SERVICE") < names.index("HUMIDITY_SENSOR_SERVICE")
    scores = [c.score for c in on]
    assert scores == sorted(scores, reverse=True)
    off = Matchmaker(loaded.kb, config=MatchConfig(tie_break_result=False)).rank(wanted, explain=0).candidates
    order = [c.advertisement for c in off]  # by IRI: the humidity sensor's sorts first
    assert order.index(humidity.advertisement) < order.index(thermostat.advertisement)


def _manipulation() -> TaxonomyIndex:
    """Objects, agents and poses for pick-up requests: a Cup is a PhysicalObject, a GraspPose a Pose."""
    pairs = [
        ("PhysicalObject", "Thing"),
        ("Cup", "PhysicalObject"),
        ("Agent", "PhysicalObject"),
        ("Robot", "Agent"),
        ("Person", "Agent"),
        ("SpatialData", "Thing"),
        ("Pose", "SpatialData"),
        ("GraspPose", "Pose"),
        ("TopGraspPose", "GraspPose"),
        ("RobotPose", "Pose"),
        ("Location", "SpatialData"),
        ("ObjectLocation", "Location"),
        ("PersonLocation", "Location"),
    ]
    return TaxonomyIndex.from_links([Link(E + child, E + parent, "is-a") for child, parent in pairs])


def _held(thing: str, by: str) -> tuple[Statement, ...]:
    return (Statement(E + thing, E + "isHeldBy", E + by),)


def test_an_offer_that_prepares_what_an_achiever_lacks_is_a_step_towards_the_effect() -> None:
    # Pick up the cup, knowing where it is. PickObject picks anything up but needs a GraspPose the requester
    # lacks: the grasp planner that outputs one is a step of the decomposition; a RobotPose is no GraspPose.
    wanted = Requirement(E + "GraspCup", (), inputs=(_p("input", "ObjectLocation"),), effects=_held("Cup", "Robot"))
    achiever = Advertisement(
        E + "PickObject", (), inputs=(_p("input", "GraspPose"),), effects=_held("PhysicalObject", "Robot")
    )
    planner = Advertisement(
        E + "GraspPlanner", (), inputs=(_p("input", "ObjectLocation"),), outputs=(_p("output", "GraspPose"),)
    )
    top = Advertisement(E + "TopGraspPlanner", (), outputs=(_p("output", "TopGraspPose"),))
    localiser = Advertisement(
        E + "Localiser", (), inputs=(_p("input", "ObjectLocation"),), outputs=(_p("output", "RobotPose"),)
    )
    # Handing over to a Person does not achieve holding by the Robot, so what it needs is no step...
    hand_over = Advertisement(
        E + "HandOver", (), inputs=(_p("input", "PersonLocation"),), effects=_held("PhysicalObject", "Person")
    )
    tracker = Advertisement(E + "PersonTracker", (), outputs=(_p("output", "PersonLocation"),))
    # ... nor is producing what the requester already has (PickCup takes the ObjectLocation it provides).
    pick_cup = Advertisement(E + "PickCup", (), inputs=(_p("input", "ObjectLocation"),), effects=_held("Cup", "Robot"))
    finder = Advertisement(E + "ObjectFinder", (), outputs=(_p("output", "ObjectLocation"),))
    ads = [achiever, planner, top, localiser, hand_over, tracker, pick_cup, finder]
    kb = KnowledgeBase(Store.open(":memory:"))
    matcher = Matchmaker(kb, index=_manipulation(), advertisements=ads)
    ranked = {c.advertisement.removeprefix(E): c for c in matcher.rank(wanted, explain=0).candidates}
    for ad in ads:  # the batch agrees with the scalar path
        assert ranked[ad.iri.removeprefix(E)].score == matcher.score(wanted, ad).score
    weight, step = MatchConfig().decomposition_weight, MatchConfig().specialisation_step
    pick = ranked["PickObject"].parts["effects"]
    assert pick >= MatchConfig().pair_threshold
    assert ranked["GraspPlanner"].parts["effects"] == pytest.approx(weight * pick)
    assert ranked["TopGraspPlanner"].parts["effects"] == pytest.approx(weight * pick * (1 - step))  # a subclass
    for other in ("Localiser", "PersonTracker", "ObjectFinder"):
        assert ranked[other].parts["effects"] == 0.0
    assert ranked["GraspPlanner"].score > ranked["Localiser"].score  # same inputs, only the planner feeds PickObject
    explained = matcher.score(wanted, planner)
    step_pairs = [pair for pair in explained.pairs if "GraspPose that PickObject needs" in pair.how]
    assert step_pairs and {(pair.degree, pair.shown_degree()) for pair in step_pairs} == {("Fail", "Step")}
    off = Matchmaker(kb, config=MatchConfig(decomposition_weight=0.0), index=_manipulation(), advertisements=ads)
    assert off.score(wanted, planner).parts["effects"] == 0.0
    assert off.rank(wanted, explain=0).candidates[0].advertisement == E + "PickCup"
    assert Matchmaker(kb, "wu-palmer", index=_manipulation(), advertisements=ads).config.decomposition_weight == 0


def test_an_offer_that_takes_what_an_achiever_lacks_works_towards_the_same_goal() -> None:
    # Hold the cup, knowing where it is. PickObject needs a GraspPose the requester lacks; a planner that
    # takes one (or any Pose: it accepts a GraspPose as it is) works on the pick before it happens, a
    # consumer of something narrower (a TopGraspPose) cannot take every GraspPose, and one that also needs
    # what the requester asks to get comes after the request.
    wanted = Requirement(
        E + "GraspCup",
        (),
        inputs=(_p("input", "ObjectLocation"),),
        outputs=(_p("output", "PersonLocation"),),
        effects=_held("Cup", "Robot"),
    )
    achiever = Advertisement(
        E + "PickObject", (), inputs=(_p("input", "GraspPose"),), effects=_held("PhysicalObject", "Robot")
    )
    trajectory = Advertisement(
        E + "TrajectoryPlanner", (), inputs=(_p("input", "GraspPose"),), outputs=(_p("output", "Location"),)
    )
    any_pose = Advertisement(E + "PoseChecker", (), inputs=(_p("input", "Pose"),), outputs=(_p("output", "Location"),))
    narrower = Advertisement(
        E + "TopOnly", (), inputs=(_p("input", "TopGraspPose"),), outputs=(_p("output", "Location"),)
    )
    afterwards = Advertisement(
        E + "PoseAfter",
        (),
        inputs=(_p("input", "GraspPose"), _p("input", "Location")),
        outputs=(_p("output", "Location"),),
    )
    ads = [achiever, trajectory, any_pose, narrower, afterwards]
    kb = KnowledgeBase(Store.open(":memory:"))
    matcher = Matchmaker(kb, index=_manipulation(), advertisements=ads)
    ranked = {c.advertisement.removeprefix(E): c for c in matcher.rank(wanted, explain=0).candidates}
    for ad in ads:  # the batch agrees with the scalar path
        assert ranked[ad.iri.removeprefix(E)].score == matcher.score(wanted, ad).score
    pick = ranked["PickObject"].parts["effects"]
    share = MatchConfig().decomposition_weight * pick
    assert pick >= MatchConfig().pair_threshold
    assert ranked["TrajectoryPlanner"].parts["effects"] == pytest.approx(share)  # a producer's share
    assert ranked["PoseChecker"].parts["effects"] == pytest.approx(share)
    assert ranked["TopOnly"].parts["effects"] == 0.0
    assert ranked["PoseAfter"].parts["effects"] == 0.0
    explained = matcher.score(wanted, trajectory)
    steps = [pair for pair in explained.pairs if "takes the GraspPose that PickObject needs" in pair.how]
    assert steps and {pair.shown_degree() for pair in steps} == {"Step"}
    off = Matchmaker(kb, config=MatchConfig(consumer_steps=False), index=_manipulation(), advertisements=ads)
    assert off.score(wanted, trajectory).parts["effects"] == 0.0
    assert off.score(wanted, trajectory).score < explained.score
    assert MatchConfig().published().consumer_steps is False


def test_the_planners_that_take_an_achievers_goal_rank_as_steps_on_the_robot_collection(
    collections: Callable[[Path], LoadedCollection],
) -> None:
    loaded = collections(ROBOT)

    def place(query: str, config: MatchConfig, name: str) -> int:
        wanted = loaded.requirements[query][0]
        ranked = Matchmaker(loaded.kb, config=config).rank(wanted, explain=0).candidates
        return [c.advertisement.rsplit("#", 1)[-1] for c in ranked].index(name)

    on, off = MatchConfig(), MatchConfig(consumer_steps=False)
    # grade 1 (a step: plans the path; plans the arm's motion) against grade 0 services below them
    for query, planner, other in (
        ("go_to_kitchen.owls", "PATH_PLANNER_SERVICE", "AIR_QUALITY_MONITOR_SERVICE"),
        ("grasp_cup.owls", "ARM_TRAJECTORY_PLANNER_SERVICE", "PLACE_OBJECT_SERVICE"),
    ):
        assert place(query, on, planner) < place(query, on, other)
        assert place(query, off, planner) > place(query, off, other)


def test_an_offer_that_brings_about_what_an_achiever_needs_to_hold_is_a_step() -> None:
    # Give the cup to a person. HandOver achieves it but needs the robot to hold what it hands over, which
    # the requester does not guarantee: picking any PhysicalObject up brings that about (a step), and so
    # does picking cups up; holding a Person is another thing; and where the requester guarantees the
    # robot holds the cup already, nothing needs bringing about.
    def held(thing: str) -> Statement:
        return Statement(E + thing, E + "isHeldBy", E + "Robot")

    give = (Statement(E + "Cup", E + "isDeliveredTo", E + "Person"),)
    wanted = Requirement(E + "GiveCup", (), inputs=(_p("input", "PersonLocation"),), effects=give)
    holding = replace(wanted, iri=E + "GiveHeldCup", preconditions=(held("Cup"),))
    achiever = Advertisement(
        E + "HandOver",
        (),
        inputs=(_p("input", "PersonLocation"),),
        preconditions=(held("PhysicalObject"),),
        effects=(Statement(E + "PhysicalObject", E + "isDeliveredTo", E + "Person"),),
    )
    pick_any = Advertisement(E + "PickAnything", (), effects=(held("PhysicalObject"),))
    pick_cup = Advertisement(E + "PickCupOnly", (), effects=(held("Cup"),))
    carry_person = Advertisement(E + "CarryPerson", (), effects=(held("Person"),))
    ads = [achiever, pick_any, pick_cup, carry_person]
    kb = KnowledgeBase(Store.open(":memory:"))
    matcher = Matchmaker(kb, index=_manipulation(), advertisements=ads)
    ranked = {c.advertisement.removeprefix(E): c for c in matcher.rank(wanted, explain=0).candidates}
    for requirement in (wanted, holding):  # the batch agrees with the scalar path
        batch = {c.advertisement: c.score for c in matcher.rank(requirement, explain=0).candidates}
        assert all(batch[ad.iri] == matcher.score(requirement, ad).score for ad in ads)

    def steps(matcher: Matchmaker, requirement: Requirement, ad: Advertisement) -> list[str]:
        return [pair.how for pair in matcher.score(requirement, ad).pairs if pair.shown_degree() == "Step"]

    share = MatchConfig().decomposition_weight * ranked["HandOver"].parts["effects"]
    assert ranked["PickAnything"].parts["effects"] == pytest.approx(share)
    explained = steps(matcher, wanted, pick_any)
    assert explained and "brings about (Cup, isHeldBy, Robot), which HandOver needs" in explained[0]
    # HandOver's PhysicalObject stands for the Cup asked about, in its precondition too: holding cups
    # brings about what it needs here, carrying a Person does not
    assert steps(matcher, wanted, pick_cup) and steps(matcher, wanted, carry_person) == []
    assert steps(matcher, holding, pick_any) == []  # the requester's robot holds the cup already
    off = Matchmaker(kb, config=MatchConfig(precondition_steps=False), index=_manipulation(), advertisements=ads)
    assert steps(off, wanted, pick_any) == [] and off.score(wanted, pick_any).score < ranked["PickAnything"].score
    assert MatchConfig().published().precondition_steps is False


def test_a_step_whose_effect_clashes_with_the_request_is_not_an_offer_that_undoes_it(defined_kb) -> None:  # type: ignore[no-untyped-def]
    # Leave the door ajar: PushAjar does it but needs the door Opened, which the requester does not
    # guarantee. Opening it first is a step, though Opened is declared disjoint with Ajar: its effect
    # clashes with the request only on the way there, so contradiction_factor does not zero it.
    def state(value: str) -> tuple[Statement, ...]:
        return (Statement(M + "Door", M + "hasState", M + value),)

    wanted = Requirement(M + "LeaveAjar", (), effects=state("Ajar"))
    ads = [
        Advertisement(M + "PushAjar", (), preconditions=state("Opened"), effects=state("Ajar")),
        Advertisement(M + "OpenDoor", (), effects=state("Opened")),
    ]
    index = TaxonomyIndex.from_kb(defined_kb)
    on = Matchmaker(defined_kb, index=index, advertisements=ads)
    ranked = {c.advertisement.removeprefix(M): c.score for c in on.rank(wanted, explain=0).candidates}
    assert all(ranked[ad.iri.removeprefix(M)] == on.score(wanted, ad).score for ad in ads)
    assert ranked["PushAjar"] == 1.0 and ranked["OpenDoor"] > 0
    off = Matchmaker(defined_kb, config=MatchConfig(precondition_steps=False), index=index, advertisements=ads)
    assert off.score(wanted, ads[1]).score == 0.0  # without the step, opening contradicts leaving it ajar


def test_docking_ranks_as_a_step_of_recharging_on_the_held_out_collection(
    collections: Callable[[Path], LoadedCollection],
) -> None:
    # The charge controller charges only a docked robot; the requester's robot is not docked, so a service
    # that docks it (grade 2) is a step and ranks above a fuel gauge (grade 0).
    loaded = collections(HELDOUT)
    wanted = loaded.requirements["recharge_battery.owls"][0]

    def place(config: MatchConfig, name: str) -> int:
        ranked = Matchmaker(loaded.kb, config=config).rank(wanted, explain=0).candidates
        return [c.advertisement.rsplit("#", 1)[-1] for c in ranked].index(name)

    on, off = MatchConfig(), MatchConfig(precondition_steps=False)
    assert place(on, "RETURN_TO_CHARGER_SERVICE") < place(on, "FUEL_GAUGE_SERVICE")
    assert place(off, "RETURN_TO_CHARGER_SERVICE") > place(off, "FUEL_GAUGE_SERVICE")


def test_the_grasp_planner_ranks_as_a_step_on_the_robot_collection(
    collections: Callable[[Path], LoadedCollection],
) -> None:
    loaded = collections(ROBOT)
    wanted = loaded.requirements["grasp_cup.owls"][0]

    def place(config: MatchConfig, name: str) -> int:
        ranked = Matchmaker(loaded.kb, config=config).rank(wanted, explain=0).candidates
        return [c.advertisement.rsplit("#", 1)[-1] for c in ranked].index(name)

    on, off = MatchConfig(), MatchConfig(decomposition_weight=0.0)
    # grade 1 (a step: plans the grasp) against grade 0 (puts the held object down: no input it lacks)
    assert place(on, "GRASP_PLANNER_SERVICE") < place(on, "PLACE_OBJECT_SERVICE")
    assert place(off, "GRASP_PLANNER_SERVICE") > place(off, "PLACE_OBJECT_SERVICE")


def test_a_concept_outside_the_taxonomy_hangs_from_the_root() -> None:
    index = positions()
    on, off = SemStr(index), SemStr(index, MatchConfig(unknown_under_root=False))
    # Picture is declared nowhere: against Position (depth 3) it is Situation 1 through the root, N = 1 + 3
    picture = on(E + "Picture", E + "Position")
    assert picture.situation == "outside" and picture.value == pytest.approx(1 / (2 + index.depth(E + "Position")))
    assert "placed under the root" in picture.explain()
    assert off(E + "Picture", E + "Position").value == 0.0  # Situation 3: no word in common
    # no further from a declared concept than two declared concepts that meet only at the root
    assert picture.value >= on(E + "MarkerColour", E + "Position").value > 0
    # where the names say more, Situation 3 stands; two undeclared concepts keep Situation 3 alone
    named = on(E + "RobotPlace", E + "RobotPosition")
    assert named.situation == "situation-3" and named == off(E + "RobotPlace", E + "RobotPosition")
    assert on(E + "Picture", E + "Image") == off(E + "Picture", E + "Image")
    # an offer that takes an undeclared input no longer ranks below one that takes a declared unrelated one
    wanted = Requirement(E + "Wants", (), inputs=(_p("input", "MarkerColour"),), outputs=(_p("output", "Position"),))
    undeclared = Advertisement(
        E + "TakesPicture", (), inputs=(_p("input", "Picture"),), outputs=(_p("output", "Position"),)
    )
    unrelated = Advertisement(
        E + "TakesXCoordinate", (), inputs=(_p("input", "XCoordinate"),), outputs=(_p("output", "Position"),)
    )
    assert _rank(MatchConfig(), wanted, unrelated, undeclared)[0] == "TakesPicture"
    assert _rank(MatchConfig(unknown_under_root=False), wanted, undeclared, unrelated)[0] == "TakesXCoordinate"
    kb = KnowledgeBase(Store.open(":memory:"))
    matcher = Matchmaker(kb, index=index, advertisements=[undeclared, unrelated])
    for candidate in matcher.rank(wanted, explain=0).candidates:  # the batch agrees with the scalar path
        ad = undeclared if candidate.advertisement == undeclared.iri else unrelated
        assert candidate.score == matcher.score(wanted, ad).score


def test_a_predicate_outside_the_taxonomy_is_another_relation() -> None:
    a = "http://a.org/o#"
    index = TaxonomyIndex.from_links([Link(a + "isNear", a + "spatialRelation", "is-a")])
    wanted = Statement(E + "Cup", a + "isNear", E + "Table")
    offered = Statement(E + "Cup", E + "touches", E + "Table")  # a predicate no ontology declares
    assert statement_similarity(wanted, offered, SemStr(index), MatchConfig()).value == 0.0
    published = MatchConfig(unrelated_predicate_factor=1.0)
    assert statement_similarity(wanted, offered, SemStr(index, published), published).value > 0.0
    kb = KnowledgeBase(Store.open(":memory:"))
    ads = [Advertisement(E + "Touches", (), effects=(offered,)), Advertisement(E + "Near", (), effects=(wanted,))]
    for config in (MatchConfig(), published):  # the batch agrees with the scalar path, either way round
        for requirement in (
            Requirement(E + "WantsNear", (), effects=(wanted,)),
            Requirement(E + "WantsTouch", (), effects=(offered,)),
        ):
            matcher = Matchmaker(kb, config=config, index=index, advertisements=ads)
            for candidate in matcher.rank(requirement, explain=0).candidates:
                ad = next(x for x in ads if x.iri == candidate.advertisement)
                assert candidate.score == matcher.score(requirement, ad).score


def test_every_precondition_of_an_offer_must_hold() -> None:
    at = E + "isAt"
    guaranteed = Statement(E + "Position", at, E + "XCoordinate")
    wanted = Requirement(E + "Wants", (), outputs=(_p("output", "Position"),), preconditions=(guaranteed,))
    # one precondition the requester guarantees and one it does not
    half = Advertisement(
        E + "HalfGuaranteed",
        (),
        outputs=(_p("output", "Position"),),
        preconditions=(guaranteed, Statement(E + "MarkerColour", at, E + "Colour")),
    )
    # one precondition, a near miss (another object, met only through the root)
    near = Advertisement(
        E + "NearMiss",
        (),
        outputs=(_p("output", "Position"),),
        preconditions=(Statement(E + "Position", at, E + "Colour"),),
    )
    kb = KnowledgeBase(Store.open(":memory:"))
    for config, first in ((MatchConfig(), "NearMiss"), (MatchConfig(precondition_conjunction=False), "HalfGuaranteed")):
        matcher = Matchmaker(kb, config=config, index=positions(), advertisements=[half, near])
        result = matcher.rank(wanted, explain=0)
        assert result.candidates[0].advertisement.removeprefix(E) == first
        for candidate in result.candidates:  # the batch agrees with the scalar path
            ad = half if candidate.advertisement == half.iri else near
            assert candidate.score == matcher.score(wanted, ad).score
    pairs = Matchmaker(kb, index=positions(), advertisements=[half]).score(wanted, half)
    values = [p.similarity for p in pairs.pairs if p.role == "precondition"]
    assert pairs.parts["preconditions"] == pytest.approx(min(values)) and max(values) == 1.0
