"""Benchmark: the two scenarios of paper section 6.2 in the headless pybullet home, skills only.

Run: python bench/sim_scenarios.py [--seed N] [--steps] [--sweep N]. Prints the machine, the inputs,
and per scenario whether it succeeded, the simulated and wall-clock seconds and the real-time factor
(sim s per wall s). Each scenario runs in a fresh world; building the world is timed in its own
column. ``--sweep N`` then runs both scenarios for seeds 0 to N-1 and counts the successes.
"""

from __future__ import annotations

import argparse
import os
import platform
import time
from collections.abc import Callable
from importlib.metadata import version

from cbrs.sim import HomeWorld, build_occupancy_grid, plan_path
from cbrs.sim.world import TIME_STEP
from tests.home_layout import HANDOVER_POSE
from tests.reference_scenarios import ScenarioResult, fetch_pen, serve_cup


def run(seed: int, scenario: Callable[[HomeWorld], ScenarioResult]) -> tuple[ScenarioResult, float, float]:
    start = time.perf_counter()
    with HomeWorld.create(seed=seed) as world:
        built = time.perf_counter()
        result = scenario(world)
        done = time.perf_counter()
    return result, built - start, done - built


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--seed", type=int, default=0, help="seed of the world (moves cup, pen, person, base)")
    parser.add_argument("--steps", action="store_true", help="also print every step of each scenario")
    parser.add_argument("--sweep", type=int, default=0, help="then run seeds 0..N-1 and count successes")
    args = parser.parse_args()

    print(
        f"machine: {platform.machine()} {platform.system()} {platform.release()}, {os.cpu_count()} cores, "
        f"python {platform.python_version()}, pybullet {version('pybullet')}, numpy {version('numpy')}, "
        f"networkx {version('networkx')}"
    )
    print(f"inputs: seed {args.seed}; physics step {TIME_STEP:.6f} s; DIRECT client; TINY renderer 320x240")

    with HomeWorld.create(seed=args.seed) as world:
        start = time.perf_counter()
        grid = build_occupancy_grid(world)
        mapped = time.perf_counter()
        base = world.base_pose()
        timings = []
        for algorithm in ("astar", "dijkstra", "astar"):
            t0 = time.perf_counter()
            path = plan_path(grid, base.xy, HANDOVER_POSE.xy, algorithm)
            timings.append((algorithm, (time.perf_counter() - t0) * 1000, path.length))
        free = int(grid.free.sum())
        print(
            f"map: {grid.shape[1]}x{grid.shape[0]} cells of {grid.resolution} m, {free} free, "
            f"measured in {(mapped - start) * 1000:.0f} ms"
        )
        print(
            "plan start->hand-over: "
            + "; ".join(f"{name} {ms:.0f} ms ({length:.2f} m)" for name, ms, length in timings)
        )

    print(f"\n{'scenario':<20} {'success':>8} {'sim s':>8} {'build s':>8} {'wall s':>8} {'RTF':>7}")
    for scenario in (serve_cup, fetch_pen):
        result, build, wall = run(args.seed, scenario)
        rtf = result.sim_seconds / wall if wall > 0 else float("inf")
        print(
            f"{result.name:<20} {result.succeeded!s:>8} {result.sim_seconds:>8.2f} {build:>8.2f} {wall:>8.2f} "
            f"{rtf:>7.1f}"
        )
        if not result.succeeded and result.failure is not None:
            print(f"    failed at {result.failure.skill}: {result.failure.reason}")
        if args.steps:
            for step in result.steps:
                mark = "ok" if step.succeeded else f"FAILED: {step.reason}"
                print(f"    {step.skill:<36} {step.sim_seconds:>7.2f} sim s  {mark}")

    if args.sweep > 0:
        print(f"\nsweep over seeds 0..{args.sweep - 1}:")
        for scenario in (serve_cup, fetch_pen):
            outcomes = [run(seed, scenario) for seed in range(args.sweep)]
            failed = [r.seed for r, _, _ in outcomes if not r.succeeded]
            walls = [wall for _, _, wall in outcomes]
            sims = [r.sim_seconds for r, _, _ in outcomes]
            print(
                f"{outcomes[0][0].name:<20} {args.sweep - len(failed)}/{args.sweep} succeeded"
                f"{f' (failed: seeds {failed})' if failed else ''}; sim s {min(sims):.1f}-{max(sims):.1f}; "
                f"wall s {min(walls):.2f}-{max(walls):.2f}"
            )


if __name__ == "__main__":
    main()
