"""OWLS-TC evaluation: metrics with known answers, the SME2 reader, and a small subset end to end."""

from __future__ import annotations

import json
import math
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import pytest
from click.testing import CliRunner, Result

from cbrs.cli import cli
from cbrs.reasoner import owlstc
from cbrs.reasoner.methods import METHODS
from cbrs.reasoner.metrics import average_precision, interpolated_precision, ndcg, precision_at_k, r_precision
from cbrs.reasoner.owlstc import (
    CollectionError,
    CollectionReport,
    LoadedCollection,
    evaluate_collection,
    read_relevance,
)

SHARED = Path(__file__).resolve().parents[2] / "shared" / "owls-tc4"
needs_collection = pytest.mark.skipif(
    not (SHARED / "relevance.xml").exists(), reason=f"OWLS-TC 4 is not at {SHARED} (kept out of the repository)"
)
QUERIES = ["mileToKilometerConverter.owls", "fall_down_pill.owls"]
DISTRACTORS = ["unlock_door.owls", "lock_door.owls", "book_price_service.owls", "car_price_service.owls"]


@pytest.mark.parametrize(
    ("ranking", "relevant", "expected"),
    [
        pytest.param(["a", "b", "c"], {"a"}, 1.0, id="first"),
        pytest.param(["b", "a", "c"], {"a", "c"}, (1 / 2 + 2 / 3) / 2, id="second-and-third"),
        pytest.param(["b"], {"a"}, 0.0, id="unranked"),
    ],
)
def test_average_precision(ranking: list[str], relevant: set[str], expected: float) -> None:
    assert average_precision(ranking, relevant) == pytest.approx(expected)


def test_precision_r_precision_and_curve() -> None:
    ranking = ["a", "x", "b", "y"]
    assert precision_at_k(ranking, {"a", "b"}, 1) == 1.0
    assert precision_at_k(ranking, {"a", "b"}, 10) == 0.2  # k counts past the end of the list
    assert r_precision(ranking, {"a", "b"}) == 0.5
    curve = interpolated_precision(ranking, {"a", "b"})
    assert curve[0] == 1.0 and curve[5] == 1.0 and curve[10] == pytest.approx(2 / 3)


def test_ndcg_uses_grades_and_the_ideal_order() -> None:
    grades = {"a": 3, "b": 1}
    assert ndcg(["a", "b", "x"], grades) == pytest.approx(1.0)
    worse = (1 / math.log2(2) + 3 / math.log2(3)) / (3 / math.log2(2) + 1 / math.log2(3))
    assert ndcg(["b", "a"], grades) == pytest.approx(worse)
    assert ndcg(["x"], {}) == 0.0


def test_read_relevance_and_missing_parts(tmp_path: Path) -> None:
    (tmp_path / "relevance.xml").write_text(
        """<testcollection><offers><offer><uri>u:s1</uri></offer></offers><relevancegradeexport>
        <binaryrelevanceset><request><uri>u:q1</uri><ratings><offer><uri>u:s1</uri><relevant>1</relevant></offer>
        </ratings></request></binaryrelevanceset><relevancegrades><scale><services><request><uri>u:q1</uri>
        <ratings><offer><uri>u:s1</uri><grade><value>3</value></grade></offer></ratings></request></services>
        </scale></relevancegrades></relevancegradeexport></testcollection>""",
        encoding="utf-8",
    )
    judged = read_relevance(tmp_path / "relevance.xml")
    assert judged.binary == {"u:q1": {"u:s1": 1}} and judged.graded == {"u:q1": {"u:s1": 3}}
    with pytest.raises(CollectionError, match="no services"):
        evaluate_collection(tmp_path)


@pytest.fixture(scope="module")
def subset(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """Two requests, the services judged for them plus a few others, and the real ontologies."""
    root = tmp_path_factory.mktemp("owlstc")
    tree = ET.parse(SHARED / "relevance.xml")
    keep_requests = {f"http://127.0.0.1/queries/1.1/{q}" for q in QUERIES}
    services = set(DISTRACTORS)
    for section in tree.getroot().iter("relevancegradeexport"):
        for parent in section.iter():
            for request in list(parent.findall("request")):
                uri = (request.findtext("uri") or "").strip().split("#")[0]
                if uri not in keep_requests:
                    parent.remove(request)
                    continue
                for offer in request.iter("offer"):
                    services.add((offer.findtext("uri") or "").strip().split("#")[0].rsplit("/", 1)[1])
    (root / "services").mkdir()
    (root / "queries").mkdir()
    for name in sorted(services):
        (root / "services" / name).write_bytes((SHARED / "services" / name).read_bytes())
    for name in QUERIES:
        (root / "queries" / name).write_bytes((SHARED / "queries" / name).read_bytes())
    (root / "ontology").symlink_to(SHARED / "ontology")
    tree.write(root / "relevance.xml", encoding="utf-8")
    return root


@dataclass
class SubsetRun:
    """``cbrs eval owls-tc SUBSET --json --plot`` (every method): what it printed and wrote, the
    CollectionReport behind it, and the collection as it loaded it."""

    result: Result
    chart: Path
    report: CollectionReport
    loaded: LoadedCollection


@pytest.fixture(scope="module")
def subset_run(subset: Path, tmp_path_factory: pytest.TempPathFactory) -> SubsetRun:
    """The command run once: the end-to-end test reads its report rather than evaluating the subset
    again, and the --text-weight run ranks in the collection it loaded (ranking only reads it)."""
    chart = tmp_path_factory.mktemp("owlstc-plot") / "pr.png"
    printed: list[CollectionReport] = []
    loaded: list[LoadedCollection] = []
    evaluate, load = owlstc.evaluate_collection, owlstc.load_collection

    def keep(*args: Any, **kwargs: Any) -> CollectionReport:
        printed.append(evaluate(*args, **kwargs))
        return printed[-1]

    def keep_loaded(*args: Any, **kwargs: Any) -> LoadedCollection:
        loaded.append(load(*args, **kwargs))
        return loaded[-1]

    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(owlstc, "evaluate_collection", keep)
        patch.setattr(owlstc, "load_collection", keep_loaded)
        patch.delenv("CBRS_MATCH_PARAMS", raising=False)  # the figures are the defaults'
        result = CliRunner().invoke(cli, ["eval", "owls-tc", str(subset), "--json", "--plot", str(chart)])
    assert result.exit_code == 0, result.output
    assert len(printed) == len(loaded) == 1
    return SubsetRun(result, chart, printed[0], loaded[0])


@needs_collection
def test_subset_end_to_end(subset: Path, subset_run: SubsetRun) -> None:
    report = subset_run.report
    assert set(report.methods) == set(METHODS)
    assert report.queries == 2 and report.services == len(list((subset / "services").iterdir()))
    assert report.unmatched_requests == [] and report.unmatched_offers == 0
    for figures in report.methods.values():
        assert all(0.0 <= figures[m] <= 1.0 for m in ("map", "ndcg", "p_at_1", "p_at_10", "r_precision"))
    # Each request has a same-named service with identical inputs and outputs: found first.
    assert report.methods["sem-str"]["p_at_1"] == 1.0
    assert report.methods["sem-str-text"]["p_at_1"] == 1.0


@needs_collection
def test_cbrs_eval_owls_tc_json_and_plot(subset: Path, subset_run: SubsetRun, monkeypatch: pytest.MonkeyPatch) -> None:
    data = json.loads(subset_run.result.stdout)
    assert data == subset_run.report.to_json()
    assert data["queries"] == 2 and set(data["methods"]) == set(METHODS)
    # --method picks the methods; the hybrid's text weight is a setting: at 0 it ranks as Sem-Str does
    monkeypatch.setattr(owlstc, "load_collection", lambda *_, **__: subset_run.loaded)  # loaded by the run above
    plain = CliRunner().invoke(
        cli,
        [
            "eval",
            "owls-tc",
            str(subset),
            "--json",
            "--method",
            "sem-str-text",
            "--method",
            "logic",
            "--text-weight",
            "0",
        ],
    )
    assert plain.exit_code == 0, plain.output
    methods = json.loads(plain.stdout)["methods"]
    assert set(methods) == {"sem-str-text", "logic"}
    figures = methods["sem-str-text"]
    assert {k: figures[k] for k in ("map", "ndcg")} == {k: data["methods"]["sem-str"][k] for k in ("map", "ndcg")}
    assert set(data["methods"]["sem-str"]) == {"map", "ndcg", "p_at_1", "p_at_10", "r_precision", "query_ms"}
    assert subset_run.chart.read_bytes()[:4] == b"\x89PNG"


def test_cbrs_eval_owls_tc_refuses_a_folder_of_the_wrong_shape(tmp_path: Path) -> None:
    result = CliRunner().invoke(cli, ["eval", "owls-tc", str(tmp_path)])
    assert result.exit_code == 1 and "no services" in result.output
