"""Ablation of the matchmaking refinements: MAP of sem-str with each one turned off, on each collection.

For every collection (default: ../shared/owls-tc4 when present, and the robot collections in tests/data) it loads
the collection once and ranks every query with the default MatchConfig, then with one refinement
turned off at a time, then with all of them off (MatchConfig.published(), the frame before them).
Besides the MAP over all queries it prints the MAP over the odd- and even-numbered queries, two
held-out halves: a change that only helps one half is suspect. The paper testbed's correct testing
pairs are printed for the same configurations (it must stay >= 0.85).

Run: python bench/matchmaking_ablation.py [FOLDER ...]
"""

from __future__ import annotations

import os
import platform
import statistics
import sys
from dataclasses import replace
from pathlib import Path

from cbrs.reasoner.config import MatchConfig
from cbrs.reasoner.evaluation import evaluate_paper
from cbrs.reasoner.matchmaker import Matchmaker
from cbrs.reasoner.metrics import average_precision
from cbrs.reasoner.owlstc import _file_key, load_collection, read_relevance

ROOT = Path(__file__).resolve().parents[1]
DEFAULTS = [
    ROOT.parent / "shared" / "owls-tc4",
    ROOT / "tests" / "data" / "robot_services",
    ROOT / "tests" / "data" / "robot_heldout",
    ROOT / "tests" / "data" / "robot_validation",
    ROOT / "tests" / "data" / "robot_final",
    ROOT / "tests" / "data" / "robot_blind5",
    ROOT / "tests" / "data" / "robot_blind6",
]
BASE = MatchConfig()
VARIANTS: dict[str, MatchConfig] = {
    "default": BASE,
    "no delivered-as-subclass": replace(BASE, plugin_outputs=False),
    "no free no-input offers": replace(BASE, no_input_invocable=False),
    "no floor for narrower inputs (narrower_input_step 1)": replace(BASE, narrower_input_step=1.0),
    "arithmetic statement mean": replace(BASE, statement_mean="arithmetic"),
    "no complementary words (complement_weight 0)": replace(BASE, complement_weight=0.0),
    "predicates through the root as Sem-Str (factor 1)": replace(BASE, unrelated_predicate_factor=1.0),
    "no observed state (observed_state_weight 0)": replace(BASE, observed_state_weight=0.0),
    "no disjoint statements": replace(BASE, disjoint_statements=False),
    "no antonym statements": replace(BASE, antonym_statements=False),
    "any position contradicts (same_fact_contradictions off)": replace(BASE, same_fact_contradictions=False),
    "contradicting offers keep their score (contradiction_factor 1)": replace(BASE, contradiction_factor=1.0),
    "observed state by any is-a relative (observed_state_kind off)": replace(BASE, observed_state_kind=False),
    "equal scores by IRI only (tie_break_result off)": replace(BASE, tie_break_result=False),
    "no decomposition steps (decomposition_weight 0)": replace(BASE, decomposition_weight=0.0),
    "only producers are steps (consumer_steps off)": replace(BASE, consumer_steps=False),
    "no steps that bring about a precondition (precondition_steps off)": replace(BASE, precondition_steps=False),
    "no cross-branch links": replace(BASE, cross_branch_weight=0.0),
    "unknown concepts by their names alone (unknown_under_root off)": replace(BASE, unknown_under_root=False),
    "preconditions averaged (precondition_conjunction off)": replace(BASE, precondition_conjunction=False),
    "with WordNet core words": replace(BASE, lexicon=True),
    "with undone states (undone_state_factor 0)": replace(BASE, undone_state_factor=0.0),
    "input gate 0.4": replace(BASE, input_gate=0.4),
    "all off (published frame)": BASE.published(),
}


def _queries(folder: Path) -> tuple[Matchmaker, dict[str, set[str]]]:
    judgements = read_relevance(folder / "relevance.xml")
    loaded = load_collection(folder)
    queries: dict[str, set[str]] = {}
    for uri, rated in judgements.binary.items():
        iris = loaded.requirements.get(_file_key(uri), [])
        if iris:
            relevant = {a for offer, v in rated.items() if v for a in loaded.advertisements.get(_file_key(offer), [])}
            queries[iris[0]] = relevant
    return Matchmaker(loaded.kb), queries


def main() -> None:
    folders = [Path(a) for a in sys.argv[1:]] or [f for f in DEFAULTS if f.exists()]
    print(
        f"machine: {platform.machine()} {platform.system()}, {os.cpu_count()} cores, python {platform.python_version()}"
    )
    for folder in folders:
        base, queries = _queries(folder)
        print(f"\n{folder}: {len(queries)} queries, {len(base.advertisements)} services")
        print("| configuration | MAP | odd queries | even queries |\n|---|---:|---:|---:|")
        for name, config in VARIANTS.items():
            matcher = Matchmaker(base.kb, "sem-str", config, index=base.index, advertisements=base.advertisements)
            matcher.prepare()
            aps = [
                average_precision([c.advertisement for c in matcher.rank(q, explain=0).candidates], relevant)
                for q, relevant in queries.items()
            ]
            print(
                f"| {name} | {statistics.fmean(aps):.4f} | {statistics.fmean(aps[::2]):.4f} "
                f"| {statistics.fmean(aps[1::2]):.4f} |",
                flush=True,
            )
    print("\npaper testbed, sem-str: correct testing pairs")
    for name, config in VARIANTS.items():
        print(f"  {name}: {evaluate_paper(['sem-str'], config=config).pair_correct_rate('sem-str'):.3f}", flush=True)


if __name__ == "__main__":
    main()
