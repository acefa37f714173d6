"""Could the judges' relevance be learned from the IO/PE scores? A learned combination, cross-validated.

Hybrid matchmakers such as iSeM learn how to weigh their signals from a collection's relevance
judgements. This bench asks whether that would beat Sem-Str's fixed, documented combination on IO/PE
alone. For every judged (query, service) pair it takes as features the scores of sem-str, Wu-Palmer,
Lin, logic and string, and sem-str's per-role parts (outputs, inputs, preconditions, effects, each with
an "absent" flag), each also relative to the query's best and as a rank within the query. A logistic
regression (class-balanced, L2 with strength --c) ranks services by its predicted relevance, measured
two ways:

- leave one query out: trained on the collection's other queries, tested on the held-out one;
- trained on the other collections only, tested on this one.

Sem-Str's own MAP, with nothing learned, is printed beside them. Needs the [eval] extra (scikit-learn).

Run: python bench/matchmaking_learned.py [FOLDER ...] [--c 0.1]
"""

from __future__ import annotations

import argparse
import os
import platform
import statistics
from pathlib import Path

import numpy as np
from matchmaking_ablation import DEFAULTS, _queries
from sklearn.linear_model import LogisticRegression

from cbrs.reasoner.config import MatchConfig
from cbrs.reasoner.matchmaker import Matchmaker
from cbrs.reasoner.metrics import average_precision

METHODS = ("sem-str", "wu-palmer", "lin", "logic", "string")
PARTS = ("outputs", "inputs", "preconditions", "effects")


class Query:
    """One judged query: its services, their feature rows, and which are relevant."""

    def __init__(self, services: list[str], features: np.ndarray, relevant: set[str], own: float) -> None:
        self.own = own  # sem-str's average precision, its ties broken as the matchmaker breaks them
        self.services = services
        self.features = features
        self.relevant = relevant
        self.labels = np.array([s in relevant for s in services], dtype=int)

    def average_precision(self, scores: np.ndarray) -> float:
        order = np.argsort(-scores, kind="stable")
        return average_precision([self.services[i] for i in order], self.relevant)


def collection_queries(folder: Path) -> list[Query]:
    """Rank every query with each method once and turn the scores into per-query feature rows."""
    base, judged = _queries(folder)
    matchers = {}
    for method in METHODS:
        matchers[method] = Matchmaker(
            base.kb, method, MatchConfig(), index=base.index, advertisements=base.advertisements
        )
        matchers[method].prepare()
    queries = []
    for requirement, relevant in judged.items():
        rows: dict[str, list[float]] = {}
        own = 0.0
        for position, method in enumerate(METHODS):
            ranked = matchers[method].rank(requirement, explain=0).candidates
            if method == "sem-str":
                own = average_precision([c.advertisement for c in ranked], relevant)
            for candidate in ranked:
                row = rows.setdefault(candidate.advertisement, [0.0] * (len(METHODS) + 2 * len(PARTS)))
                row[position] = candidate.score
                if method == "sem-str":
                    for k, part in enumerate(PARTS):
                        absent = part not in candidate.parts
                        row[len(METHODS) + 2 * k] = 0.0 if absent else candidate.parts[part]
                        row[len(METHODS) + 2 * k + 1] = float(absent)
        services = sorted(rows)
        raw = np.array([rows[s] for s in services])
        relative = raw - raw.max(axis=0, keepdims=True)
        ranks = raw.argsort(axis=0, kind="stable").argsort(axis=0) / max(len(raw) - 1, 1)
        queries.append(Query(services, np.hstack([raw, relative, ranks]), relevant, own))
    return queries


def learned_map(train: list[Query], test: list[Query], strength: float) -> float:
    model = LogisticRegression(C=strength, max_iter=3000, class_weight="balanced")
    model.fit(np.vstack([q.features for q in train]), np.concatenate([q.labels for q in train]))
    return statistics.fmean(q.average_precision(model.predict_proba(q.features)[:, 1]) for q in test)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("folders", nargs="*", type=Path)
    parser.add_argument("--c", type=float, default=0.1, help="inverse L2 strength of the regression")
    args = parser.parse_args()
    folders = args.folders or [f for f in DEFAULTS if f.exists()]
    print(
        f"machine: {platform.machine()} {platform.system()}, {os.cpu_count()} cores, "
        f"python {platform.python_version()}; logistic regression C={args.c}"
    )
    collections = {folder: collection_queries(folder) for folder in folders}
    print("| collection | queries | sem-str | learned, leave one query out | learned on the other collections |")
    print("|---|---:|---:|---:|---:|")
    for folder, queries in collections.items():
        own = statistics.fmean(q.own for q in queries)
        held_out = statistics.fmean(learned_map([o for o in queries if o is not q], [q], args.c) for q in queries)
        others = [q for f, qs in collections.items() if f != folder for q in qs]
        across = learned_map(others, queries, args.c) if others else float("nan")
        print(f"| {folder.name} | {len(queries)} | {own:.4f} | {held_out:.4f} | {across:.4f} |", flush=True)


if __name__ == "__main__":
    main()
