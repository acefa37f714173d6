"""Evaluate the matching methods on an OWL-S test collection in the OWLS-TC layout.

A collection folder holds ``services/`` (OWL-S advertisements), ``ontology/`` (the ontologies they
use), ``queries/`` (OWL-S requests) and ``relevance.xml`` (SME2: a binary relevance set and a graded,
0-3, relevance set per request; a service a request does not rate is not relevant to it). The whole
collection is loaded into a fresh in-memory store, offline: imports resolve to ``ontology/``. Every
method ranks the whole service pool for every request; the figures are the means over the requests.
"""

from __future__ import annotations

import difflib
import math
import statistics
import time
import xml.etree.ElementTree as ET
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from cbrs.kb import KnowledgeBase, Store
from cbrs.kb.catalog import Catalogue
from cbrs.kb.errors import KnowledgeBaseError
from cbrs.kb.resources import ontology_dir
from cbrs.reasoner.config import MatchConfig
from cbrs.reasoner.matchmaker import Matchmaker
from cbrs.reasoner.methods import METHODS
from cbrs.reasoner.metrics import (
    RECALL_LEVELS,
    average_precision,
    interpolated_precision,
    ndcg,
    precision_at_k,
    r_precision,
)

METRICS = ("map", "ndcg", "p_at_1", "p_at_10", "r_precision", "query_ms")


class CollectionError(KnowledgeBaseError):
    """The folder is not an OWLS-TC style collection."""

    http_status = 400

    def __init__(self, root: Path, reason: str) -> None:
        self.root = root
        super().__init__(f"{root}: {reason}")


@dataclass(frozen=True)
class Judgements:
    """Per request IRI (as relevance.xml names it): binary relevance and grades, by offer IRI."""

    binary: dict[str, dict[str, int]]
    graded: dict[str, dict[str, int]]
    offers: list[str]


#: The values each relevance set allows: binary relevance, and OWLS-TC's 4-graded scale.
_SCALES = {"relevant": (0, 1), "grade/value": (0, 3)}
_SET_NAMES = {"relevant": "binary relevance set", "grade/value": "graded relevance (relevancegrades)"}


def read_relevance(path: Path) -> Judgements:
    """Read an SME2 relevance file. A value that is not a whole number of its scale (binary 0 or 1, grades
    0 to 3), a request or offer without its URI, and a request judged in one set and not the other are
    refused, each named: read as it was, a grade of 5 raised NDCG, 'yes' stopped the run with Python's
    int() message, and a request left out of the graded set scored NDCG 0 without a word. A file that
    grades nothing is read (binary relevance alone): its NDCG is not computed."""
    try:
        root = ET.parse(path).getroot()
    except (OSError, ET.ParseError) as error:
        raise CollectionError(path.parent, f"cannot read {path.name}: {error}") from error
    wrong: list[str] = []

    def ratings(section: ET.Element | None, value_path: str) -> dict[str, dict[str, int]]:
        found: dict[str, dict[str, int]] = {}
        low, high = _SCALES[value_path]
        for number, request in enumerate(section.iter("request") if section is not None else (), 1):
            uri = (request.findtext("uri") or "").strip()
            if not uri:
                wrong.append(f"request {number} of the {_SET_NAMES[value_path]} has no <uri>")
                continue
            rated = found.setdefault(uri, {})
            for offer in request.iter("offer"):
                value = offer.findtext(value_path)
                if value is None:
                    continue
                offer_uri = (offer.findtext("uri") or "").strip()
                if not offer_uri:
                    wrong.append(f"request {uri} rates an offer without its <uri>")
                    continue
                text = value.strip()
                if not text.lstrip("-").isdigit() or not low <= int(text) <= high:
                    expected = f"{low} or {high}" if high == low + 1 else f"a whole number from {low} to {high}"
                    wrong.append(
                        f"request {uri} rates {offer_uri} {text!r} in the {_SET_NAMES[value_path]}: expected {expected}"
                    )
                    continue
                rated[offer_uri] = int(text)
        return found

    offers = [(o.findtext("uri") or "").strip() for o in root.iterfind("offers/offer")]
    binary = ratings(root.find(".//binaryrelevanceset"), "relevant")
    graded = ratings(root.find(".//relevancegrades"), "grade/value")
    if not binary and not wrong:
        raise CollectionError(path.parent, f"{path.name} has no binary relevance set")
    for uri in sorted(binary.keys() - graded.keys() if graded else ()):  # none graded: NDCG is not computed
        wrong.append(f"request {uri} is in the binary relevance set and not in the graded one (NDCG reads grades)")
    for uri in sorted(graded.keys() - binary.keys()):
        wrong.append(f"request {uri} is in the graded relevance and not in the binary set (MAP reads it)")
    if wrong:
        raise CollectionError(path.parent, f"{path.name}: " + _listed(wrong))
    return Judgements(binary, graded, offers)


def _listed(problems: Sequence[str], shown: int = 5) -> str:
    """The first ``shown`` problems, and how many more."""
    more = f"; and {len(problems) - shown} more" if len(problems) > shown else ""
    return "; ".join(problems[:shown]) + more


def _file_key(uri: str) -> str:
    """relevance.xml names services by file (``.../services/1.1/x.owls#X``): the file name is the key."""
    return uri.split("#", 1)[0].rstrip("/").rsplit("/", 1)[-1]


@dataclass
class LoadedCollection:
    kb: KnowledgeBase
    advertisements: dict[str, list[str]]  # file name -> advertisement IRIs it holds
    requirements: dict[str, list[str]]  # file name -> requirement IRIs it holds
    unresolved_concepts: int
    unresolved_imports: int
    seconds: float
    #: What is unresolved, one line each, named: the counts alone said neither which nor where from.
    unresolved: tuple[str, ...] = ()


def check_layout(root: Path) -> None:
    """Raise CollectionError naming the first part an OWLS-TC folder lacks."""
    for part in ("services", "queries", "ontology", "relevance.xml"):
        if not (root / part).exists():
            raise CollectionError(
                root, f"no {part} (an OWLS-TC folder has services/, ontology/, queries/, relevance.xml)"
            )


def _check_files(root: Path, judgements: Judgements, loaded: LoadedCollection) -> None:
    """Raise CollectionError naming each request and judged offer of relevance.xml that no file of
    ``queries/`` or ``services/`` describes (a misspelt name, a file left out): the evaluation dropped
    such a request and counted such an offer as not there, and its figures were of another collection."""
    missing: list[str] = []
    for kind, folder, table, uris in (
        ("request", "queries", loaded.requirements, sorted(judgements.binary.keys() | judgements.graded.keys())),
        (
            "judged offer",
            "services",
            loaded.advertisements,
            sorted({o for sets in (judgements.binary, judgements.graded) for rated in sets.values() for o in rated}),
        ),
    ):
        for uri in uris:
            name = _file_key(uri)
            if table.get(name):
                continue
            held = (
                f"{folder}/ holds no {name}"
                if not (root / folder / name).exists()
                else f"{folder}/{name} describes no OWL-S service"
            )
            close = difflib.get_close_matches(name, sorted(table), n=2)
            hint = f" (did you mean {' or '.join(close)}?)" if close else ""
            missing.append(f"{kind} {uri}: {held}{hint}")
    if missing:
        raise CollectionError(root, "relevance.xml names what the collection does not hold: " + _listed(missing))


Progress = Callable[[str, int, int], None]
"""Told how an evaluation goes (stage, items done, of how many; 0 when not counted): for a person waiting."""


def load_collection(root: Path, progress: Progress | None = None) -> LoadedCollection:
    """Load services, requests and ontologies of a collection folder into a fresh in-memory store."""
    check_layout(root)
    start = time.perf_counter()
    kb = KnowledgeBase(Store.open(":memory:"))
    kb.load([ontology_dir() / "core.ttl"], graph="ontology")  # the service model only, not the home domain
    catalogue = Catalogue.open(root / "ontology")
    services = kb.load([root / "services"], catalogue=catalogue, progress=_stage(progress, "services: "))
    queries = kb.load(
        [root / "queries"], graph="requirements", catalogue=catalogue, progress=_stage(progress, "queries: ")
    )

    def by_file(report: Any) -> dict[str, list[str]]:
        return {
            Path(item.source).name: [service.iri for service in item.owls.services]
            for item in report.files
            if item.owls is not None
        }

    return LoadedCollection(
        kb=kb,
        advertisements=by_file(services),
        requirements=by_file(queries),
        unresolved_concepts=len({c.iri for c in (*services.unresolved_concepts, *queries.unresolved_concepts)}),
        unresolved_imports=len(services.unresolved_imports) + len(queries.unresolved_imports),
        seconds=time.perf_counter() - start,
        unresolved=_unresolved(root, (services, queries)),
    )


def _unresolved(root: Path, reports: Sequence[Any]) -> tuple[str, ...]:
    """A line for each unresolved import (the file that needs it, and the ontology/ files of a near name)
    and each concept no loaded ontology declares (what uses it): a misnamed import of the collection's own
    ontology left its services' concepts hanging from the root, and the figures said nothing of it."""
    held = sorted(path.name for path in (root / "ontology").iterdir()) if (root / "ontology").is_dir() else []
    lines: list[str] = []
    for report in reports:
        for missing in report.unresolved_imports:
            wanted = missing.iri.rstrip("/").rsplit("/", 1)[-1]
            close = difflib.get_close_matches(wanted, held, n=2)
            hint = f" (it holds {' and '.join(close)})" if close else ""
            needed_by = Path(missing.needed_by)
            lines.append(
                f"unresolved import {missing.iri}, {missing.reason} of {needed_by.parent.name}/{needed_by.name}: "
                f"ontology/ has no {wanted}{hint}"
            )
        for concept in report.unresolved_concepts:
            lines.append(
                f"unresolved concept {concept.iri}, {concept.used_as} of {concept.used_by}: "
                "no loaded ontology declares it"
            )
    return tuple(dict.fromkeys(lines))


@dataclass
class CollectionReport:
    methods: dict[str, dict[str, float]]
    queries: int
    services: int
    curves: dict[str, list[float]]  # method -> mean interpolated precision at RECALL_LEVELS
    unmatched_requests: list[str] = field(default_factory=list)
    unmatched_offers: int = 0
    unresolved_concepts: int = 0
    unresolved_imports: int = 0
    load_seconds: float = 0.0
    unresolved: tuple[str, ...] = ()
    unjudged: tuple[str, ...] = ()  # query files relevance.xml judges nothing for: not evaluated

    def to_json(self) -> dict[str, Any]:
        return {
            "methods": {
                name: {metric: None if math.isnan(values[metric]) else round(values[metric], 4) for metric in METRICS}
                for name, values in self.methods.items()
            },
            "queries": self.queries,
            "services": self.services,
            "unresolved": list(self.unresolved),
            "unjudged": list(self.unjudged),
        }

    def text(self) -> str:
        header = "| method | MAP | NDCG | P@1 | P@10 | R-precision | query ms |"
        rows = [header, "|---|---:|---:|---:|---:|---:|---:|"]
        for name, v in self.methods.items():
            rows.append(
                f"| {name} | {v['map']:.4f} | {_figure(v['ndcg'])} | {v['p_at_1']:.4f} | {v['p_at_10']:.4f} "
                f"| {v['r_precision']:.4f} | {v['query_ms']:.2f} |"
            )
        lines = [
            f"{self.queries} queries against {self.services} services, loaded in {self.load_seconds:.1f} s; "
            f"{self.unresolved_concepts} concepts and {self.unresolved_imports} imports unresolved; "
            f"{self.unmatched_offers} judged offers and {len(self.unmatched_requests)} requests not found in the "
            "loaded files",
            *self.unresolved,
            *(
                [f"not evaluated, judged by no request of relevance.xml: {', '.join(self.unjudged)}"]
                if self.unjudged
                else []
            ),
            *(
                ["relevance.xml grades nothing (no relevancegrades): NDCG is not computed"]
                if any(math.isnan(v["ndcg"]) for v in self.methods.values())
                else []
            ),
            "",
            *rows,
        ]
        return "\n".join(lines)


def _figure(value: float) -> str:
    """A figure to four decimals; "-" for one not computed (NDCG of a collection that grades nothing)."""
    return "-" if math.isnan(value) else f"{value:.4f}"


def _stage(progress: Progress | None, prefix: str) -> Progress | None:
    """``progress`` with ``prefix`` in front of each stage it is told."""
    if progress is None:
        return None
    told = progress
    return lambda stage, done, total: told(prefix + stage, done, total)


def evaluate_collection(
    root: Path,
    methods: Sequence[str] = METHODS,
    config: MatchConfig | None = None,
    progress: Progress | None = None,
    loaded: LoadedCollection | None = None,
) -> CollectionReport:
    """Load the collection and score every method on every judged request (``config``: the matching
    parameters, MatchConfig's defaults when None); ``progress`` is told each load stage, and each query
    as each method ranks for it. ``loaded``: ``root`` as :func:`load_collection` loaded it, ranked in
    without loading again (one load for several configurations; only read)."""
    check_layout(root)
    judgements = read_relevance(root / "relevance.xml")
    if loaded is None:
        loaded = load_collection(root, progress)

    def to_iris(uri: str, table: dict[str, list[str]]) -> list[str]:
        return table.get(_file_key(uri), [])

    _check_files(root, judgements, loaded)
    requests: dict[str, tuple[dict[str, int], dict[str, int]]] = {}
    for uri, rated in judgements.binary.items():
        iris = to_iris(uri, loaded.requirements)
        binary: dict[str, int] = {}
        grades: dict[str, int] = {}
        for offer, value in rated.items():
            binary.update(dict.fromkeys(to_iris(offer, loaded.advertisements), value))
        for offer, value in judgements.graded.get(uri, {}).items():
            grades.update(dict.fromkeys(to_iris(offer, loaded.advertisements), value))
        requests[iris[0]] = (binary, grades)

    first: Matchmaker | None = None
    figures: dict[str, dict[str, float]] = {}
    curves: dict[str, list[float]] = {}
    for number, method in enumerate(methods, 1):
        stage = f"{method} ({number}/{len(methods)}): ranking for query"
        if progress is not None:
            progress(f"{method} ({number}/{len(methods)}): reading the advertisements", 0, 0)
        matcher = (
            Matchmaker(loaded.kb, method, config, index=first.index, advertisements=first.advertisements)
            if first is not None
            else Matchmaker(loaded.kb, method, config)
        )
        first = first or matcher
        matcher.prepare()  # reading the pool is loading, not answering a query
        values: dict[str, list[float]] = {metric: [] for metric in METRICS}
        curve = [0.0] * len(RECALL_LEVELS)
        for done, (requirement, (binary, grades)) in enumerate(requests.items()):
            if progress is not None:
                progress(stage, done, len(requests))
            start = time.perf_counter()
            result = matcher.rank(requirement, explain=0)
            values["query_ms"].append((time.perf_counter() - start) * 1000)
            ranking = [c.advertisement for c in result.candidates]
            relevant = {iri for iri, flag in binary.items() if flag}
            values["map"].append(average_precision(ranking, relevant))
            if judgements.graded:
                values["ndcg"].append(ndcg(ranking, grades))
            values["p_at_1"].append(precision_at_k(ranking, relevant, 1))
            values["p_at_10"].append(precision_at_k(ranking, relevant, 10))
            values["r_precision"].append(r_precision(ranking, relevant))
            for i, p in enumerate(interpolated_precision(ranking, relevant)):
                curve[i] += p / len(requests)
        figures[method] = {metric: statistics.fmean(v) if v else 0.0 for metric, v in values.items()}
        if not judgements.graded:
            figures[method]["ndcg"] = math.nan  # nothing graded: shown as not computed, not as 0
        curves[method] = curve
    return CollectionReport(
        methods=figures,
        queries=len(requests),
        services=len(first.advertisements) if first is not None else 0,
        curves=curves,
        unresolved_concepts=loaded.unresolved_concepts,
        unresolved_imports=loaded.unresolved_imports,
        load_seconds=loaded.seconds,
        unresolved=loaded.unresolved,
        unjudged=tuple(
            f"queries/{name}"
            for name in sorted(set(loaded.requirements) - {_file_key(uri) for uri in judgements.binary})
        ),
    )


def plot_curves(report: CollectionReport, path: Path) -> Path:
    """Precision-recall curves (11-point interpolated, mean over requests), one line per method."""
    from cbrs.extras import require

    require("eval", "the plot (--plot)")
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7, 5), dpi=110)
    for name, curve in report.curves.items():
        ax.plot(RECALL_LEVELS, curve, marker="o", markersize=3, label=f"{name} (MAP {report.methods[name]['map']:.2f})")
    ax.set_xlabel("recall")
    ax.set_ylabel("interpolated precision (mean over requests)")
    ax.set_xlim(0, 1)
    ax.set_ylim(0, 1.02)
    ax.set_title(f"OWL-S test collection: {report.queries} requests, {report.services} services")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, format="png")
    plt.close(fig)
    return path
