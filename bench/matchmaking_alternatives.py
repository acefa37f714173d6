"""Alternatives to the default Sem-Str ordering that were tried and not adopted (docs/matchmaking.md 9.5).

For every collection (default: ../shared/owls-tc4 when present, and tests/data/robot_services) it scores
every query once with the default sem-str configuration and once with the strict logic baseline (the
committed batch scorers), then ranks by each alternative built from those scores, and prints MAP over
all queries and over the odd- and even-numbered ones (held-out halves):

- OWLS-MX style hybrids: candidates the strict logic baseline rejects after the rest, then by Sem-Str;
  the logic degree score first, then Sem-Str; Sem-Str plus a share of the logic score;
- outputs weighing more than inputs: the score recomputed from its parts with output_weight 0.5, or
  multiplied by (1 - g + g * outputs) (an output gate);
- OWLS-MX's role-free signature similarity: each requested input or output against the best of all the
  advertised inputs and outputs, mixed into the score with a small weight;
- co-consumers as steps of a decomposition: an offer without effects that takes an input an achiever of
  the requested effect needs and the requester lacks (the path planner takes the NavigationGoal the
  navigation service needs) gets a share of the achiever's effects part, as the committed
  decomposition_weight gives the producers of that input (reasoner/steps.py).

Ties are broken as the matchmaker breaks them (the result part, then the IRI). Two more rows bound how
much the order of equal scores can matter: relevant services first, or last, among equal scores.

Run: python bench/matchmaking_alternatives.py [FOLDER ...]
"""

from __future__ import annotations

import os
import platform
import statistics
import sys
from collections.abc import Callable
from pathlib import Path

import numpy as np

from cbrs.kb import PartNode
from cbrs.reasoner.batch import BatchScorer, BatchScores
from cbrs.reasoner.config import MatchConfig
from cbrs.reasoner.matchmaker import Matchmaker
from cbrs.reasoner.metrics import average_precision

sys.path.insert(0, str(Path(__file__).parent))
from matchmaking_ablation import DEFAULTS, _queries

WEIGHTS = {"outputs": 0.4, "inputs": 0.2, "effects": 0.3, "preconditions": 0.1}
# (sem-str, logic, extras: "signature" similarity, "co-consumer" effects share at weight 1) -> score, or
# (score, result part for ties) when the alternative changes the result part
Score = Callable[[BatchScores, BatchScores, dict[str, np.ndarray]], np.ndarray | tuple[np.ndarray, np.ndarray]]


def _mean(parts: dict[str, np.ndarray], weights: dict[str, float]) -> np.ndarray:
    numerator = sum(np.where(np.isnan(parts[k]), 0.0, w * np.nan_to_num(parts[k])) for k, w in weights.items())
    denominator = sum(np.where(np.isnan(parts[k]), 0.0, w) for k, w in weights.items())
    return np.asarray(np.where(denominator > 0, numerator / np.maximum(denominator, 1e-300), 0.0))


def _with_effects(s: BatchScores, share: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The score and its result part (outputs and effects) with the effects part raised to ``share`` where
    that is higher (only offers without effects get a share, so no contradiction factor is undone)."""
    raised = ~np.isnan(s.parts["effects"]) & (share > s.parts["effects"])
    parts = {**s.parts, "effects": np.where(raised, share, s.parts["effects"])}
    result = _mean(parts, {"outputs": WEIGHTS["outputs"], "effects": WEIGHTS["effects"]})
    tie = result if s.tie is None else np.where(raised, result, s.tie)
    return np.where(raised, _mean(parts, WEIGHTS), s.score), tie


ALTERNATIVES: dict[str, Score] = {
    "default": lambda s, lg, x: s.score,
    "strict logic rejects last, then Sem-Str": lambda s, lg, x: s.score - 2.0 * lg.rejected,
    "logic degree score first, then Sem-Str": lambda s, lg, x: s.score + 2.0 * np.where(lg.rejected, 0, lg.score),
    "Sem-Str + 0.2 logic score": lambda s, lg, x: s.score + 0.2 * np.where(lg.rejected, 0, lg.score),
    "output_weight 0.5": lambda s, lg, x: _mean(s.parts, {**WEIGHTS, "outputs": 0.5}),
    "output gate 0.2": lambda s, lg, x: s.score * (0.8 + 0.2 * np.nan_to_num(s.parts["outputs"], nan=1.0)),
    "signature similarity 0.1": lambda s, lg, x: 0.9 * s.score + 0.1 * x["signature"],
    "co-consumers of an achiever's missing input, 0.5": lambda s, lg, x: _with_effects(s, 0.5 * x["co-consumer"]),
    "co-consumers of an achiever's missing input, 0.3": lambda s, lg, x: _with_effects(s, 0.3 * x["co-consumer"]),
}


def _signature(scorer: BatchScorer, requirement: object) -> np.ndarray:
    pool = scorer.pool
    wanted = (*requirement.inputs, *requirement.outputs)  # type: ignore[attr-defined]
    if not wanted:
        return np.zeros(len(pool.ads))
    per = []
    for parameter in wanted:
        css = scorer.css_wanted(parameter.tree or PartNode(parameter.type))
        per.append(np.maximum(pool.outputs.max(css), pool.inputs.max(css)))
    return np.asarray(np.mean(per, axis=0))


def _co_consumers(scorer: BatchScorer, requirement: object) -> np.ndarray:
    """Per offer without effects: the best effects part of an achiever (steps.py's rule) that needs an
    input this offer takes too and the requester does not provide; 0 elsewhere."""
    pool, cfg = scorer.pool, scorer.config
    found = np.zeros(len(pool.ads))
    effects = requirement.effects  # type: ignore[attr-defined]
    if not effects:
        return found
    own = np.mean([pool.effects.max(scorer.statements(e)) for e in effects], axis=0)
    achieving = pool.effects.present & (own >= cfg.pair_threshold)
    for wanted in effects:
        above = (
            scorer._at_or_above(wanted.subject)[pool.s_ids]
            & scorer._at_or_above(wanted.predicate)[pool.p_ids]
            & scorer._at_or_above(wanted.object)[pool.o_ids]
        )
        achieving &= pool.effects.max(above.astype(np.float64)) > 0
    given = np.zeros(len(pool.root_ids), dtype=bool)
    for provided in requirement.inputs:  # type: ignore[attr-defined]
        given |= scorer.plugin(provided.type) > 0
    free = pool.outputs.present & ~pool.effects.present
    for a in np.flatnonzero(achieving):
        start, count = pool.inputs.starts[a], pool.inputs.counts[a]
        for tree in set(pool.inputs.flat[start : start + count].tolist()):
            if not given[tree]:
                takes = np.zeros(len(pool.root_ids))
                takes[tree] = 1.0
                found = np.maximum(found, np.where(free, own[a] * pool.inputs.max(takes), 0.0))
    return found


def main() -> None:
    folders = [Path(a) for a in sys.argv[1:]] or [f for f in DEFAULTS if f.exists()]
    print(
        f"machine: {platform.machine()} {platform.system()}, {os.cpu_count()} cores, python {platform.python_version()}"
    )
    for folder in folders:
        base, queries = _queries(folder)
        semstr = Matchmaker(base.kb, "sem-str", MatchConfig(), index=base.index, advertisements=base.advertisements)
        logic = Matchmaker(base.kb, "logic", MatchConfig(), index=base.index, advertisements=base.advertisements)
        pool = semstr.prepare()._compiled(semstr.advertisements)
        logic_pool = logic.prepare()._compiled(logic.advertisements)
        scorer = BatchScorer(pool, semstr.method.measure, semstr.config, semstr.filters, True, True)
        bounds = ("bound: relevant first among equal scores", "bound: relevant last among equal scores")
        rows: dict[str, list[float]] = {name: [] for name in (*ALTERNATIVES, *bounds)}
        for iri, relevant in queries.items():
            requirement = semstr._requirement(iri)
            s = scorer.score(requirement)
            lg = logic._strict(logic_pool).score(requirement)
            extras = {"signature": _signature(scorer, requirement), "co-consumer": _co_consumers(scorer, requirement)}
            for name, alternative in ALTERNATIVES.items():
                found = alternative(s, lg, extras)
                score, tie = found if isinstance(found, tuple) else (found, s.tie)
                score = np.round(score, 6)
                tie = np.zeros(len(score)) if tie is None else np.round(tie, 3)
                order = np.lexsort((pool.iri_rank, -tie, -score, s.rejected))  # as batch.ranking_keys sorts
                rows[name].append(average_precision([pool.ads[i].iri for i in order], relevant))
            hit = np.array([ad.iri in relevant for ad in pool.ads], dtype=np.int64)
            for name, sign in zip(bounds, (-1, 1), strict=True):  # how much the order of ties can matter
                order = np.lexsort((pool.iri_rank, sign * hit, -s.score, s.rejected))
                rows[name].append(average_precision([pool.ads[i].iri for i in order], relevant))
        print(f"\n{folder}: {len(queries)} queries, {len(pool.ads)} services")
        print("| ordering | MAP | odd queries | even queries |\n|---|---:|---:|---:|")
        for name, aps in rows.items():
            print(
                f"| {name} | {statistics.fmean(aps):.4f} | {statistics.fmean(aps[::2]):.4f} "
                f"| {statistics.fmean(aps[1::2]):.4f} |",
                flush=True,
            )


if __name__ == "__main__":
    main()
