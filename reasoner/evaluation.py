"""Evaluate the matching methods on the paper testbed (section 6.1) and chart the result.

Each method ranks all 100 advertisements of the testbed for each of its 20 requirements (the
matchmaker's own order: acceptable candidates first, then by score, ties by IRI). Against the ground
truth of ``reasoner/data/paper_testbed_truth.json`` it is scored with four rank metrics, each the mean
over the requirements of a per-requirement value in [0, 1]:

- ``top1``: 1 when the top-ranked advertisement is relevant (the paper's "correct matching rate");
- ``p_at_5``: the share of relevant advertisements among the first five (at most 3/5 here, since no
  requirement has more than three relevant advertisements);
- ``mrr``: 1 / the rank of the first relevant advertisement;
- ``map``: average precision, the mean over the relevant set of the precision at each relevant
  advertisement's rank.

``cbrs eval paper [--json] [--plot PATH]`` prints the figures, per-requirement and per-rule tables and
the machine they were computed on.
"""

from __future__ import annotations

import os
import platform
import time
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from cbrs.kb import KnowledgeBase
from cbrs.reasoner.config import MatchConfig
from cbrs.reasoner.matchmaker import Matchmaker
from cbrs.reasoner.methods import METHODS
from cbrs.reasoner.metrics import average_precision, first_relevant_rank, precision_at_k, reciprocal_rank, top1
from cbrs.reasoner.names import local_name
from cbrs.reasoner.testbed import TESTBED_FILE, TRUTH_FILE, load_truth, open_testbed_kb, relevant_sets

METRICS = ("top1", "p_at_5", "mrr", "map")
METRIC_LABELS = {"top1": "top-1 correct", "p_at_5": "precision at 5", "mrr": "MRR", "map": "MAP"}

# --------------------------------------------------------------------------------------------------
# Metrics on one ranking
# --------------------------------------------------------------------------------------------------


def metric_values(ranking: Sequence[str], relevant: frozenset[str] | set[str]) -> dict[str, float]:
    return {
        "top1": top1(ranking, relevant),
        "p_at_5": precision_at_k(ranking, relevant, 5),
        "mrr": reciprocal_rank(ranking, relevant),
        "map": average_precision(ranking, relevant),
    }


# --------------------------------------------------------------------------------------------------
# The report
# --------------------------------------------------------------------------------------------------


@dataclass
class Report:
    """Figures per method, and every ranking behind them."""

    methods: dict[str, dict[str, float]]
    requirements: int
    services: int
    relevant: dict[str, frozenset[str]]  # requirement -> relevant advertisements
    rankings: dict[str, dict[str, tuple[str, ...]]]  # method -> requirement -> ranked advertisements
    top_groups: dict[str, dict[str, frozenset[str]]] = field(default_factory=dict)  # tied at rank 1
    intents: dict[str, str] = field(default_factory=dict)  # requirement -> intent title
    pair_rules: dict[str, dict[str, str]] = field(default_factory=dict)  # requirement -> ad -> variation rule
    machine: str = ""
    seconds: float = 0.0

    def to_json(self) -> dict[str, Any]:
        """The figures per method, each method's correct testing pairs (``pair_correct_rate``) beside them."""
        return {
            "methods": {
                name: {
                    **{metric: round(values[metric], 4) for metric in METRICS},
                    "pair_correct_rate": round(self.pair_correct_rate(name), 4),
                }
                for name, values in self.methods.items()
            },
            "requirements": self.requirements,
            "services": self.services,
        }

    def first_relevant_ranks(self) -> dict[str, dict[str, int | None]]:
        """Requirement -> method -> rank of its first relevant advertisement (None: not ranked)."""
        return {
            requirement: {
                method: first_relevant_rank(rankings[requirement], relevant)
                for method, rankings in self.rankings.items()
            }
            for requirement, relevant in self.relevant.items()
        }

    def misses(self, method: str) -> list[str]:
        """Requirements whose top-ranked advertisement is not relevant under ``method``."""
        return [
            requirement
            for requirement, relevant in self.relevant.items()
            if not top1(self.rankings[method][requirement], relevant)
        ]

    def top_ties(self, method: str) -> list[str]:
        """Requirements where ``method`` ties relevant and other advertisements at rank 1, so that the
        matchmaker's last sort key (the IRI, numbered by the testbed seed) decides top1."""
        ties = []
        for requirement, group in self.top_groups.get(method, {}).items():
            hits = group & self.relevant[requirement]
            if hits and hits != group:
                ties.append(requirement)
        return ties

    def top1_tie_aware(self, method: str) -> float:
        """top1 expected when ties at rank 1 are broken at random: the relevant share of the tied group."""
        groups = self.top_groups.get(method, {})
        if not groups:
            return self.methods[method]["top1"]
        shares = [len(group & self.relevant[req]) / len(group) for req, group in groups.items()]
        return sum(shares) / len(shares)

    def pair_correct_rate(self, method: str) -> float:
        """Share of (requirement, relevant advertisement) testing pairs in which the advertisement
        outranks every irrelevant one: each pair judged alone, so an easy relevant advertisement
        cannot hide a hard one behind it."""
        good = total = 0
        for requirement, relevant in self.relevant.items():
            ranking = self.rankings[method][requirement]
            for advertisement in relevant:
                total += 1
                rivals = [a for a in ranking if a not in relevant or a == advertisement]
                good += bool(rivals) and rivals[0] == advertisement
        return good / total if total else 0.0

    def text(self) -> str:
        """Every table a person wants: figures, per requirement, per variation rule, ties, machine."""
        lines = [self.table(), "", self.detail_table(), "", self.rule_table(), ""]
        for method in self.methods:
            ties = ", ".join(local_name(r) for r in self.top_ties(method)) or "none"
            lines.append(
                f"{method}: correct testing pairs {self.pair_correct_rate(method):.4f}; top1 with random "
                f"tie-breaking {self.top1_tie_aware(method):.4f}; ties at rank 1: {ties}"
            )
        lines += ["", f"machine: {self.machine}; {self.seconds:.1f} s"]
        return "\n".join(lines)

    def rule_ranks(self) -> dict[str, dict[str, list[int]]]:
        """Variation rule -> method -> the rank of each relevant advertisement that exercises it."""
        out: dict[str, dict[str, list[int]]] = {}
        for requirement, ads in self.pair_rules.items():
            for ad, rule in ads.items():
                for method, rankings in self.rankings.items():
                    out.setdefault(rule, {}).setdefault(method, []).append(rankings[requirement].index(ad) + 1)
        return out

    def rule_table(self) -> str:
        """Per variation rule and method: mean rank of the relevant advertisements and how many of them
        are in the first five, as Markdown."""
        methods = list(self.rankings)
        head = "| variation rule | pairs | " + " | ".join(methods) + " |"
        rule = "|---|---:|" + "---:|" * len(methods)
        rows = []
        for name, per_method in self.rule_ranks().items():
            count = len(next(iter(per_method.values())))
            cells = " | ".join(
                f"{sum(ranks) / len(ranks):.1f} ({sum(r <= 5 for r in ranks)})"
                for ranks in (per_method[m] for m in methods)
            )
            rows.append(f"| {name} | {count} | {cells} |")
        return "\n".join([head, rule, *rows])

    def table(self) -> str:
        """The figures as a Markdown table, with the correct testing pairs in the last column."""
        head = "| method | " + " | ".join(METRIC_LABELS[m] for m in METRICS) + " | correct pairs |"
        rule = "|---|" + "---:|" * (len(METRICS) + 1)
        rows = [
            f"| {name} | "
            + " | ".join(f"{values[m]:.4f}" for m in METRICS)
            + f" | {self.pair_correct_rate(name):.4f} |"
            for name, values in self.methods.items()
        ]
        return "\n".join([head, rule, *rows])

    def detail_table(self) -> str:
        """Rank of the first relevant advertisement per requirement and method, as Markdown."""
        methods = list(self.rankings)
        head = "| requirement | intent | relevant | " + " | ".join(methods) + " |"
        rule = "|---|---|---:|" + "---:|" * len(methods)
        rows = []
        for requirement, ranks in self.first_relevant_ranks().items():
            cells = " | ".join("-" if ranks[m] is None else str(ranks[m]) for m in methods)
            rows.append(
                f"| {local_name(requirement)} | {self.intents.get(requirement, '')} | "
                f"{len(self.relevant[requirement])} | {cells} |"
            )
        return "\n".join([head, rule, *rows])


def machine_line() -> str:
    return (
        f"{platform.system()} {platform.release()} {platform.machine()}, "
        f"Python {platform.python_version()}, {os.cpu_count()} CPUs"
    )


def evaluate_paper(
    methods: Sequence[str] = METHODS,
    testbed: Path = TESTBED_FILE,
    truth_file: Path = TRUTH_FILE,
    config: MatchConfig | None = None,
    kb: KnowledgeBase | None = None,
) -> Report:
    """Rank every testbed advertisement for every testbed requirement with each method, and score.
    ``config``: the matching parameters (the defaults of MatchConfig when None). ``kb``: the testbed
    already loaded (by :func:`open_testbed_kb`), ranked in and left open, so that a caller holding it
    does not check and load the file again; when None, ``testbed`` is loaded into a fresh store."""
    start = time.perf_counter()
    truth = load_truth(truth_file)
    relevant = relevant_sets(truth)
    given = kb
    kb = open_testbed_kb(testbed) if given is None else given
    try:
        requirements = {req.iri: req for req in kb.requirements()}
        missing = set(relevant) - set(requirements)
        if missing:
            raise ValueError(f"truth names requirements the testbed lacks: {sorted(missing)}")
        first: Matchmaker | None = None
        rankings: dict[str, dict[str, tuple[str, ...]]] = {}
        top_groups: dict[str, dict[str, frozenset[str]]] = {}
        scores: dict[str, dict[str, float]] = {}
        for method in methods:
            if first is None:
                matcher = first = Matchmaker(kb, method, config)
            else:
                matcher = Matchmaker(kb, method, config, index=first.index, advertisements=first.advertisements)
            per_requirement: dict[str, tuple[str, ...]] = {}
            groups: dict[str, frozenset[str]] = {}
            sums = dict.fromkeys(METRICS, 0.0)
            for iri, wanted in relevant.items():
                result = matcher.rank(requirements[iri], explain=0)  # the batch scores: no pairs to read
                ranking = tuple(candidate.advertisement for candidate in result.candidates)
                per_requirement[iri] = ranking
                if result.candidates:
                    best = result.candidates[0]
                    key = (best.acceptable, bool(best.rejected_by), best.score)
                    groups[iri] = frozenset(
                        c.advertisement
                        for c in result.candidates
                        if (c.acceptable, bool(c.rejected_by), c.score) == key
                    )
                for metric, value in metric_values(ranking, wanted).items():
                    sums[metric] += value
            rankings[method] = per_requirement
            top_groups[method] = groups
            scores[method] = {metric: total / len(relevant) for metric, total in sums.items()}
        services = len(first.advertisements) if first is not None else len(kb.advertisements())
    finally:
        if given is None:
            kb.close()
    return Report(
        methods=scores,
        requirements=len(relevant),
        services=services,
        relevant=relevant,
        rankings=rankings,
        top_groups=top_groups,
        intents={iri: item["intent"] for iri, item in truth["requirements"].items()},
        pair_rules={
            iri: {pair["advertisement"]: pair["rule"] for pair in item["relevant"]}
            for iri, item in truth["requirements"].items()
        },
        machine=machine_line(),
        seconds=time.perf_counter() - start,
    )


# --------------------------------------------------------------------------------------------------
# Chart
# --------------------------------------------------------------------------------------------------


def plot_report(report: Report, path: str | Path) -> Path:
    """A grouped bar chart: one group per metric, one bar per method. Written as PNG to ``path``."""
    from cbrs.extras import require

    require("eval", "the plot (--plot)")
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    path = Path(path)
    names = list(report.methods)
    width = 0.8 / max(1, len(names))
    fig, ax = plt.subplots(figsize=(8, 4.5), dpi=110)
    for i, name in enumerate(names):
        xs = [m + (i - (len(names) - 1) / 2) * width for m in range(len(METRICS))]
        values = [report.methods[name][metric] for metric in METRICS]
        bars = ax.bar(xs, values, width, label=name)
        ax.bar_label(bars, labels=[f"{v:.2f}" for v in values], fontsize=7, padding=1)
    ax.set_xticks(range(len(METRICS)), [METRIC_LABELS[m] for m in METRICS])
    ax.set_xlabel("metric")
    ax.set_ylabel("score (mean over requirements)")
    ax.set_ylim(0, 1.22)  # headroom for the legend above the bars
    ax.set_yticks([0.0, 0.2, 0.4, 0.6, 0.8, 1.0])
    ax.set_title(f"Matchmaking on the paper testbed ({report.requirements} requirements, {report.services} services)")
    ax.legend(title="method", fontsize=8, ncols=min(5, len(names)), loc="upper center")
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, format="png")
    plt.close(fig)
    return path
