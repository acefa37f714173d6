"""The paper testbed (reasoner.testbed) and the evaluation of the matching methods on it."""

from __future__ import annotations

from pathlib import Path

import pytest

from cbrs.kb import KnowledgeBase
from cbrs.reasoner.evaluation import METRICS, Report, evaluate_paper, metric_values, plot_report
from cbrs.reasoner.methods import METHODS
from cbrs.reasoner.metrics import average_precision, first_relevant_rank, precision_at_k, reciprocal_rank, top1
from cbrs.reasoner.testbed import (
    CATALOGUE_FILE,
    RULES,
    SEED,
    TESTBED_FILE,
    TRUTH_FILE,
    CatalogueError,
    generate,
    load_catalogue,
    load_truth,
    open_testbed_kb,
    relevant_sets,
    rule_violations,
    truth_json,
)

# --------------------------------------------------------------------------------------------------
# Metrics on hand-made rankings
# --------------------------------------------------------------------------------------------------

RANKING = ("a", "b", "c", "d", "e", "f", "g")


@pytest.mark.parametrize(
    ("relevant", "expected"),
    [
        pytest.param({"a"}, 1.0, id="hit-at-1"),
        pytest.param({"b", "c"}, 0.0, id="miss-at-1"),
        pytest.param(set(), 0.0, id="nothing-relevant"),
    ],
)
def test_top1(relevant: set[str], expected: float) -> None:
    assert top1(RANKING, relevant) == expected


def test_top1_of_an_empty_ranking_is_zero() -> None:
    assert top1((), {"a"}) == 0.0


@pytest.mark.parametrize(
    ("relevant", "k", "expected"),
    [
        pytest.param({"a", "c"}, 5, 2 / 5, id="two-of-five"),
        pytest.param({"f", "g"}, 5, 0.0, id="relevant-below-cutoff"),
        pytest.param({"a", "b", "c", "d", "e"}, 5, 1.0, id="all-five"),
        pytest.param({"b"}, 1, 0.0, id="k-1-miss"),
        pytest.param({"a", "b", "c"}, 10, 3 / 10, id="k-beyond-ranking"),
    ],
)
def test_precision_at_k(relevant: set[str], k: int, expected: float) -> None:
    assert precision_at_k(RANKING, relevant, k) == pytest.approx(expected)


def test_precision_at_k_needs_a_positive_k() -> None:
    with pytest.raises(ValueError, match="positive"):
        precision_at_k(RANKING, {"a"}, 0)


@pytest.mark.parametrize(
    ("relevant", "rank", "rr"),
    [
        pytest.param({"a", "e"}, 1, 1.0, id="first"),
        pytest.param({"d", "b"}, 2, 0.5, id="second-counts-first-hit"),
        pytest.param({"g"}, 7, 1 / 7, id="last"),
        pytest.param({"z"}, None, 0.0, id="not-ranked"),
    ],
)
def test_first_rank_and_reciprocal_rank(relevant: set[str], rank: int | None, rr: float) -> None:
    assert first_relevant_rank(RANKING, relevant) == rank
    assert reciprocal_rank(RANKING, relevant) == pytest.approx(rr)


@pytest.mark.parametrize(
    ("relevant", "expected"),
    [
        pytest.param({"a"}, 1.0, id="single-at-top"),
        pytest.param({"a", "b"}, 1.0, id="all-at-top"),
        pytest.param({"b", "d"}, (1 / 2 + 2 / 4) / 2, id="ranks-2-and-4"),
        pytest.param({"a", "c", "f"}, (1 / 1 + 2 / 3 + 3 / 6) / 3, id="ranks-1-3-6"),
        pytest.param({"c", "z"}, (1 / 3 + 0) / 2, id="one-unranked-counts-zero"),
        pytest.param(set(), 0.0, id="empty-relevant-set"),
    ],
)
def test_average_precision(relevant: set[str], expected: float) -> None:
    assert average_precision(RANKING, relevant) == pytest.approx(expected)


def test_metric_values_names_every_metric() -> None:
    values = metric_values(RANKING, {"b", "d"})
    assert list(values) == list(METRICS)
    assert values == pytest.approx({"top1": 0.0, "p_at_5": 0.4, "mrr": 0.5, "map": 0.5})


# --------------------------------------------------------------------------------------------------
# The testbed
# --------------------------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def testbed_kb() -> KnowledgeBase:
    return open_testbed_kb()


def test_committed_testbed_is_what_the_seed_generates() -> None:
    turtle, truth = generate(SEED)
    assert TESTBED_FILE.read_text(encoding="utf-8") == turtle, "run python -m cbrs.reasoner.testbed"
    assert TRUTH_FILE.read_text(encoding="utf-8") == truth_json(truth), "run python -m cbrs.reasoner.testbed"


def test_generation_is_deterministic_and_the_seed_changes_only_placement() -> None:
    first, truth = generate(SEED)
    again, _ = generate(SEED)
    other, other_truth = generate(SEED + 1)
    assert first == again
    assert other != first
    assert other_truth["rule_counts"] == truth["rule_counts"]
    # the same intents have the same relevant services (by service name) under any seed
    names = {
        r: sorted(e["advertisement"].split("_", 1)[1] for e in v["relevant"]) for r, v in truth["requirements"].items()
    }
    other_names = {
        r: sorted(e["advertisement"].split("_", 1)[1] for e in v["relevant"])
        for r, v in other_truth["requirements"].items()
    }
    assert names == other_names


def test_testbed_has_twenty_requirements_and_a_hundred_advertisements(testbed_kb: KnowledgeBase) -> None:
    ads = testbed_kb.advertisements()
    reqs = testbed_kb.requirements()
    assert len(reqs) == 20
    assert len(ads) == 100
    assert all(ad.iri.startswith("https://w3id.org/cbrs/testbed#A") for ad in ads)
    assert all(ad.outputs or ad.effects for ad in ads)
    assert all(req.outputs or req.effects for req in reqs)


def test_every_truth_iri_exists(testbed_kb: KnowledgeBase) -> None:
    truth = load_truth()
    ads = {ad.iri for ad in testbed_kb.advertisements()}
    reqs = {req.iri for req in testbed_kb.requirements()}
    assert set(truth["requirements"]) == reqs
    relevant = relevant_sets(truth)
    assert all(1 <= len(found) <= 3 for found in relevant.values())
    assert set().union(*relevant.values()) <= ads
    assert set(truth["distractors"]) <= ads
    # every advertisement is either relevant to exactly one requirement or a distractor
    relevant_count = sum(len(found) for found in relevant.values())
    assert relevant_count + len(truth["distractors"]) == 100
    assert not set().union(*relevant.values()) & set(truth["distractors"])


def test_truth_records_a_known_rule_for_every_pair() -> None:
    truth = load_truth()
    pairs = [pair for item in truth["requirements"].values() for pair in item["relevant"]]
    assert {pair["rule"] for pair in pairs} == set(RULES)
    assert sum(truth["rule_counts"].values()) == len(pairs)
    assert all(pair["why"] for pair in pairs)


def test_testbed_keeps_its_own_rules(testbed_kb: KnowledgeBase) -> None:
    assert rule_violations(testbed_kb, load_truth()) == []


@pytest.mark.parametrize(
    ("good", "bad", "message"),
    [
        pytest.param(
            'advertised = "home:OccupancyGridMap"',
            'advertized = "home:OccupancyGridMap"',
            "intents 'GridMap', relevant 'ProvideOccupancyGrid': unknown field 'advertized' "
            "(did you mean 'advertised'?)",
            id="misspelt-field",
        ),
        pytest.param(
            'title = "grid map"\n',
            "",
            "intents 'GridMap': missing field 'title'",
            id="missing-field",
        ),
    ],
)
def test_a_broken_catalogue_names_the_intent_and_the_field(tmp_path: Path, good: str, bad: str, message: str) -> None:
    text = CATALOGUE_FILE.read_text(encoding="utf-8")
    assert text.count(good) == 1
    broken = tmp_path / "catalogue.toml"
    broken.write_text(text.replace(good, bad), encoding="utf-8")
    with pytest.raises(CatalogueError) as raised:
        load_catalogue(broken)
    assert str(raised.value) == f"catalogue.toml: {message}"


def test_testbed_leaves_the_bundled_services_out(testbed_kb: KnowledgeBase) -> None:
    assert not testbed_kb.describes("https://w3id.org/cbrs/service#LocateMobileRobot_CeilingCamera01")
    assert not testbed_kb.describes("https://w3id.org/cbrs/requirement#RobotSelfPosition")


# --------------------------------------------------------------------------------------------------
# The evaluation
# --------------------------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def report(testbed_kb: KnowledgeBase) -> Report:
    return evaluate_paper(kb=testbed_kb)  # the module's testbed, not loaded a second time


def test_a_given_testbed_is_left_open(report: Report, testbed_kb: KnowledgeBase) -> None:
    assert len(testbed_kb.advertisements()) == report.services


def test_report_json_has_the_agreed_shape(report: Report) -> None:
    data = report.to_json()
    assert set(data) == {"methods", "requirements", "services"}
    assert data["requirements"] == 20
    assert data["services"] == 100
    assert list(data["methods"]) == list(METHODS)
    for name, figures in data["methods"].items():
        # the four keys, then the correct testing pairs beside them
        assert list(figures) == ["top1", "p_at_5", "mrr", "map", "pair_correct_rate"]
        assert figures["pair_correct_rate"] == round(report.pair_correct_rate(name), 4)
        for value in figures.values():
            assert isinstance(value, float)
            assert 0.0 <= value <= 1.0
            assert round(value, 4) == value
    print(data)


def test_report_keeps_every_ranking_and_first_relevant_ranks(report: Report) -> None:
    ranks = report.first_relevant_ranks()
    assert len(ranks) == 20
    for requirement, per_method in ranks.items():
        assert set(per_method) == set(METHODS)
        for method, rank in per_method.items():
            ranking = report.rankings[method][requirement]
            assert len(ranking) == 100 and len(set(ranking)) == 100
            assert rank is None or 1 <= rank <= 100
    for method in METHODS:
        assert set(report.misses(method)) <= set(ranks)
        assert 0.0 <= report.top1_tie_aware(method) <= 1.0
        assert set(report.top_ties(method)) <= set(ranks)
    assert report.table().count("\n") == len(METHODS) + 1
    by_rule = report.rule_ranks()
    assert set(by_rule) == set(RULES)
    assert sum(len(per_method["sem-str"]) for per_method in by_rule.values()) == 42
    assert report.rule_table().count("\n") == len(RULES) + 1
    assert report.detail_table().count("\n") == 20 + 1


def test_top1_agrees_with_the_misses(report: Report) -> None:
    for method in METHODS:
        assert report.methods[method]["top1"] == pytest.approx(1 - len(report.misses(method)) / 20)


def test_plot_is_written_as_png(report: Report, tmp_path: Path) -> None:
    path = plot_report(report, tmp_path / "chart" / "evaluation.png")
    data = path.read_bytes()
    assert data.startswith(b"\x89PNG\r\n\x1a\n")
    assert len(data) > 5000
