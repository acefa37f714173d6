"""Benchmark: the paper's scenarios under seeded random component failures, in the simulated home.

Run: python bench/fault_injection.py [--seeds 50] [--rate 0.3] [--spare-rate 0.5]. Two regimes per task:
``all`` breaks any component of the plan with probability --rate; ``spare`` breaks only components of
steps that have an alternative, with probability --spare-rate. Prints the machine, the inputs, one row
per run (what the policy breaks, the steps it dooms, the outcome, failovers, the unmet step) and a
summary: runs that kept a healthy provider for every step and how many of them succeeded; doomed runs
(every plan-time candidate of some step broken) and how they ended: failed naming the unmet
requirement, or succeeded, because the faults struck after the components' last use or because a new
plan, composed from what was achieved, found another way; and how many runs re-planned.
"""

from __future__ import annotations

import argparse
import importlib.metadata
import os
import platform
import time
from collections import Counter

from cbrs.actions.composer import Composer
from cbrs.actions.faults import RandomFaults, doomed_steps, planned_faults
from cbrs.actions.runner import run_task
from cbrs.kb import KnowledgeBase
from cbrs.kb.namespaces import shorten
from cbrs.kb.semantic_map import SemanticMap
from cbrs.sim.components import SimEnvironment
from cbrs.sim.world import HomeWorld

TASKS = ("FetchMyPen", "RobotArmServeACup")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, default=50, help="fault seeds 0..N-1 per task and regime")
    parser.add_argument("--rate", type=float, default=0.3, help="fault probability per component (all)")
    parser.add_argument("--spare-rate", type=float, default=0.5, help="fault probability (spare regime)")
    parser.add_argument("--quiet", action="store_true", help="print the summary only")
    args = parser.parse_args()
    print(
        f"machine: {platform.platform()}, {os.cpu_count()} cores, python {platform.python_version()}, "
        f"pybullet {importlib.metadata.version('pybullet')}"
    )
    print(
        f"inputs: tasks {', '.join(TASKS)}; fault seeds 0-{args.seeds - 1}; regimes all (rate {args.rate}) "
        f"and spare (rate {args.spare_rate}); max_after_ticks 2; world seed 0; DIRECT, headless\n"
    )
    kb = KnowledgeBase.open(":memory:")
    composer = Composer(kb)
    summary: Counter[tuple[str, str, str]] = Counter()
    replanned: Counter[str] = Counter()
    started = time.perf_counter()
    if not args.quiet:
        head = f"{'task':<18} {'regime':<6} {'seed':>4} {'broken':>6} {'doomed':<10} {'status':<10}"
        print(f"{head} {'fo':>2} {'rp':>2}  unmet")
    for task in TASKS:
        plan = composer.compose(task).plan
        assert plan is not None, task
        spare = frozenset(c for s in plan.steps if s.alternatives for c in s.candidates)
        for regime in ("all", "spare"):
            for seed in range(args.seeds):
                if regime == "all":
                    policy = RandomFaults(seed, args.rate)
                else:
                    policy = RandomFaults(seed, args.spare_rate, among=spare)
                doomed = doomed_steps(policy, plan)
                world = HomeWorld.create(seed=0, semantic_map=SemanticMap.read(kb))
                try:
                    result = run_task(kb, task, SimEnvironment(world, kb), composer=composer, fault_policy=policy)
                finally:
                    world.close()
                report = result.report
                assert report is not None
                failovers = sum(1 for s in report.steps if s.failed_over)
                kind = "doomed" if doomed else "healthy"
                outcome = report.status.value
                if report.status.value != "succeeded":
                    outcome += " (unmet named)" if report.unmet is not None else " (unmet NOT named!)"
                elif result.replans:
                    outcome += " (re-planned)"
                summary[(task, kind, outcome)] += 1
                replanned[task] += 1 if result.replans else 0
                if not args.quiet:
                    last = report.unmet.tried[-1].component if report.unmet and report.unmet.tried else ""
                    unmet = f"step {report.unmet.step}: {shorten(last)}" if report.unmet else "-"
                    print(
                        f"{task:<18} {regime:<6} {seed:>4} {len(planned_faults(policy, plan)):>6} "
                        f"{','.join(map(str, doomed)) or '-':<10} {report.status.value:<10} {failovers:>2} "
                        f"{len(result.replans):>2}  {unmet}"
                    )
    print(f"\n{'task':<18} {'faults leave':<13} {'ended':<26} {'runs':>4}")
    for (task, kind, outcome), count in sorted(summary.items()):
        print(f"{task:<18} {('a provider' if kind == 'healthy' else 'none (doomed)'):<13} {outcome:<26} {count:>4}")
    for task in TASKS:
        print(f"{task}: {replanned[task]} of {2 * args.seeds} runs re-planned")
    print(f"\n{sum(summary.values())} runs in {time.perf_counter() - started:.0f} s")


if __name__ == "__main__":
    main()
