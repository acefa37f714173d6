"""Ranking metrics over one ranked list of item IRIs, each a pure function with a value in [0, 1]."""

from __future__ import annotations

import math
from collections.abc import Collection, Mapping, Sequence

RECALL_LEVELS = tuple(i / 10 for i in range(11))


def first_relevant_rank(ranking: Sequence[str], relevant: Collection[str]) -> int | None:
    """1-based rank of the first relevant item, or None when none is ranked."""
    for position, item in enumerate(ranking, start=1):
        if item in relevant:
            return position
    return None


def top1(ranking: Sequence[str], relevant: Collection[str]) -> float:
    """1 when the first ranked item is relevant."""
    return 1.0 if ranking and ranking[0] in relevant else 0.0


def reciprocal_rank(ranking: Sequence[str], relevant: Collection[str]) -> float:
    rank = first_relevant_rank(ranking, relevant)
    return 0.0 if rank is None else 1.0 / rank


def precision_at_k(ranking: Sequence[str], relevant: Collection[str], k: int) -> float:
    """Share of the first ``k`` ranked items that are relevant (k counts even past the list's end)."""
    if k <= 0:
        raise ValueError("k must be positive")
    return sum(1 for item in ranking[:k] if item in relevant) / k


def average_precision(ranking: Sequence[str], relevant: Collection[str]) -> float:
    """Mean over the relevant items of the precision at each one's rank; an unranked one adds 0."""
    if not relevant:
        return 0.0
    hits = 0
    total = 0.0
    for rank, item in enumerate(ranking, start=1):
        if item in relevant:
            hits += 1
            total += hits / rank
    return total / len(relevant)


def r_precision(ranking: Sequence[str], relevant: Collection[str]) -> float:
    """Precision at R, R being the number of relevant items."""
    return precision_at_k(ranking, relevant, len(relevant)) if relevant else 0.0


def ndcg(ranking: Sequence[str], grades: Mapping[str, int]) -> float:
    """Normalised discounted cumulative gain over the whole ranking, with gain = the graded relevance
    and the discount log2(rank + 1); items without a grade gain nothing."""
    ideal = sorted((g for g in grades.values() if g > 0), reverse=True)
    best = sum(g / math.log2(rank + 1) for rank, g in enumerate(ideal, start=1))
    if best == 0:
        return 0.0
    gained = sum(grades.get(item, 0) / math.log2(rank + 1) for rank, item in enumerate(ranking, start=1))
    return gained / best


def interpolated_precision(ranking: Sequence[str], relevant: Collection[str]) -> list[float]:
    """Precision at the 11 standard recall levels, each the best precision at that recall or beyond."""
    if not relevant:
        return [0.0] * len(RECALL_LEVELS)
    points: list[tuple[float, float]] = []
    hits = 0
    for rank, item in enumerate(ranking, start=1):
        if item in relevant:
            hits += 1
            points.append((hits / len(relevant), hits / rank))
    return [max((p for r, p in points if r >= level - 1e-12), default=0.0) for level in RECALL_LEVELS]
