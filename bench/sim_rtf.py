"""Benchmark: the simulation's real-time factor as cbrs runs a task headless, against pybullet stepping
the same scene alone.

Run: python bench/sim_rtf.py [--tasks RobotArmServeACup,FetchMyPen] [--seeds 0,1,2] [--repeat N] [--profile N]
                             [--physics] [--json FILE] [--digests FILE] [--check FILE]

For each task and seed, a world is built from the store's semantic map (as ``cbrs run`` builds it;
not timed), then:

* anchor: pybullet alone steps that freshly built world (``p.stepSimulation`` in a loop, the world's
  time step, the same bodies, nothing else) for as many steps as the task took; its real-time factor
  is simulated seconds per wall second;
* task: a second world of the same seed runs the task as ``cbrs run`` does (``actions.runner.run_task``
  with ``SimEnvironment``: perception with the cameras, path planning, the skills' control loops, the
  belief written to the store after every step, verification), timed from building the environment
  to the end of the run, less the time spent composing plans (``Composer.compose``); its real-time
  factor is the world's simulated seconds over that wall time.

The row's ratio is the median of the task's factors over the median of the anchor's (goal >= 0.8x).
``--repeat N`` runs each task and seed N times (each run followed by its anchor), so that the medians
are taken over N times as many samples: on a shared machine one sample of either moves by a third.
The same ratio on this thread's CPU time is printed too: on a machine shared with other jobs it
moves less than the wall-clock one (pybullet's DIRECT client steps and renders on this thread).
``--profile N`` also runs the tasks once under cProfile (CPU time) and prints the N functions with
the most time of their own. ``--physics`` runs each task and seed once more, timing its own physics
steps (``p.stepSimulation``) against the fresh world's steps alone: the ratio the run would reach if
nothing but its physics cost anything (cProfile is not on then: it cools the caches between steps).
``--split`` runs each task once more (seed 0) and divides its CPU time by where it goes, each part
less the parts it calls (no profiler, whose overhead on small calls distorts them): physics, the
inverse-kinematics solver, rendering, the rest of the kinematics (collision checks, forward kinematics,
lines), of perception, of stepping (the taps' check, the recorders), of driving the base, store
queries, composing, and the rest (skills, executor, checks). ``--json FILE`` writes the rows as a list
of records.

Every run also gets a digest of what it did, so that a change made for speed can be shown to leave
the runs as they were: SHA-256 over every observation written to the world graph (the belief after
each step: types, relations, positions, time), what each plan executed (per step the components
tried, their outcomes, ticks and simulated times, the effects verified: not the report's words nor the
plan's JSON, so that a reworded message or a new key leaves the digests as they are), the poses of
everything that moves, every moving joint's angle, the water in each container and spilled, and who
holds what. The frames taken are counted beside it but not in it (a cost, not an outcome).
``--digests FILE`` writes them (task, seed -> digest); ``--check FILE`` compares them with such a file
and exits with status 1 if any differs.
"""

from __future__ import annotations

import argparse
import cProfile
import hashlib
import io
import json
import os
import platform
import pstats
import statistics
import sys
import time
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from importlib.metadata import version
from pathlib import Path
from typing import Any

import pybullet as p

from cbrs.actions.belief import BeliefState, Observation
from cbrs.actions.composer import Composer
from cbrs.actions.runner import RunResult, run_task
from cbrs.kb import KnowledgeBase
from cbrs.kb.semantic_map import SemanticMap
from cbrs.kb.store import EmbeddedStore
from cbrs.sim.arms import Kinematics
from cbrs.sim.base import MobileBase
from cbrs.sim.components import SimEnvironment
from cbrs.sim.perceived import PerceivedWorld
from cbrs.sim.world import TIME_STEP, HomeWorld

TASKS = ("RobotArmServeACup", "FetchMyPen")
GOAL = 0.8
"""The task's real-time factor must be at least this fraction of pybullet's alone."""


@dataclass(frozen=True)
class Sample:
    task: str
    seed: int
    status: str
    steps: int
    simulated: float
    wall: float
    composing: float
    alone: float  # wall seconds pybullet took for the same number of steps alone
    cpu: float  # this thread's CPU seconds for the task, composing left out
    cpu_alone: float
    digest: str = ""
    frames: int = 0  # images rendered (a camera asked again with nothing changed renders none)

    @property
    def cpu_ratio(self) -> float:
        return self.cpu_alone / self.cpu

    @property
    def off_cpu(self) -> float:
        """Wall seconds of the run (composing left out) when this thread was not on a CPU: waiting, or
        made to wait by other processes (the run has no other thread and sleeps nowhere)."""
        return max(0.0, self.wall - self.composing - self.cpu)

    @property
    def factor(self) -> float:
        return self.simulated / (self.wall - self.composing)

    @property
    def anchor(self) -> float:
        return self.simulated / self.alone


@contextmanager
def composing_time() -> Iterator[list[float]]:
    """Add the wall and CPU time of every ``Composer.compose`` call (replans' composers too) to the
    yielded list."""
    spent = [0.0, 0.0]
    original = Composer.compose

    def timed(self: Composer, *args: Any, **kwargs: Any) -> Any:
        start, cpu = time.perf_counter(), time.thread_time()
        try:
            return original(self, *args, **kwargs)
        finally:
            spent[0] += time.perf_counter() - start
            spent[1] += time.thread_time() - cpu

    Composer.compose = timed  # type: ignore[method-assign]
    try:
        yield spent
    finally:
        Composer.compose = original  # type: ignore[method-assign]


@contextmanager
def observations() -> Iterator[list[Observation]]:
    """Keep every observation written to the world graph (the belief after each step) in the yielded list."""
    written: list[Observation] = []
    original = BeliefState.write

    def keep(self: BeliefState, observation: Observation, whole: bool = False) -> None:
        written.append(observation)
        original(self, observation, whole=whole)

    BeliefState.write = keep  # type: ignore[method-assign]
    try:
        yield written
    finally:
        BeliefState.write = original  # type: ignore[method-assign]


def what_ran(result: RunResult) -> list[Any]:
    """Each plan's execution as facts: its status and ticks, and per step the components tried, their
    outcomes, ticks and simulated times (exact) and the effects verified. Not the reports' words nor the
    plans' presentation: a reworded message or a key added to the JSON changes no run."""
    reports = [replan.report for replan in result.replans] + ([result.report] if result.report else [])
    return [
        [
            report.status.value,
            report.ticks,
            report.seconds,
            [
                [
                    step.index,
                    step.outcome,
                    [[a.component, a.outcome, a.ticks, a.seconds] for a in step.attempts],
                    [[repr(statement), verified] for statement, verified in step.effects],
                ]
                for step in report.steps
            ],
        ]
        for report in reports
    ]


def digest(world: HomeWorld, result: RunResult, written: list[Observation]) -> str:
    """SHA-256 of what a run did: its beliefs, what each plan executed (:func:`what_ran`) and the world's
    end state (floats exact)."""
    beliefs = [
        [sorted(o.types.items()), sorted(o.facts), sorted((k, list(v)) for k, v in o.positions.items()), o.time]
        for o in written
    ]
    client = world.client
    joints = {
        name: [
            s[0]
            for s in p.getJointStates(body, range(p.getNumJoints(body, physicsClientId=client)), physicsClientId=client)
        ]
        for name, body in sorted(world.bodies.items())
        if p.getNumJoints(body, physicsClientId=client)
    }
    state = {
        "beliefs": beliefs,
        "ran": what_ran(result),
        "poses": {name: [list(pose.position), list(pose.orientation)] for name, pose in world.snapshot().items()},
        "joints": joints,
        "water": sorted(world.water.items()),
        "spilled": world.water_spilled,
        "holders": sorted(world.holders.items()),
    }
    text = json.dumps(state, sort_keys=True, default=repr)
    return hashlib.sha256(text.encode()).hexdigest()[:16]


def step_alone(world: HomeWorld, steps: int) -> tuple[float, float]:
    """Wall and CPU seconds pybullet takes for ``steps`` steps of the world with nothing else running."""
    client = world.client
    start, cpu = time.perf_counter(), time.thread_time()
    for _ in range(steps):
        p.stepSimulation(physicsClientId=client)
    return time.perf_counter() - start, time.thread_time() - cpu


def run_one(kb: KnowledgeBase, smap: SemanticMap, composer: Composer, task: str, seed: int) -> Sample:
    world = HomeWorld.create(seed=seed, semantic_map=smap)
    try:
        steps0 = world.steps
        with composing_time() as spent, observations() as written:
            start, cpu = time.perf_counter(), time.thread_time()
            environment = SimEnvironment(world, kb)
            result = run_task(kb, task, environment, composer=composer)
            wall, cpu = time.perf_counter() - start, time.thread_time() - cpu
        steps = world.steps - steps0
        outcome = digest(world, result, written)
        frames = sum(getattr(camera, "renders", 0) for camera in world.cameras.values())
    finally:
        world.close()
    with HomeWorld.create(seed=seed, semantic_map=smap) as fresh:
        alone, cpu_alone = step_alone(fresh, steps)
    status = result.report.status.value if result.report else "no plan"
    simulated = steps * world.time_step
    return Sample(
        task, seed, status, steps, simulated, wall, spent[0], alone, cpu - spent[1], cpu_alone, outcome, frames
    )


def profile(kb: KnowledgeBase, smap: SemanticMap, composer: Composer, tasks: list[str], top: int) -> str:
    """The N costliest functions (own CPU time) of one run of each task, seed 0."""
    lines = []
    for task in tasks:
        profiler = cProfile.Profile(time.thread_time)
        world = HomeWorld.create(seed=0, semantic_map=smap)
        try:
            profiler.enable()
            run_task(kb, task, SimEnvironment(world, kb), composer=composer)
            profiler.disable()
        finally:
            world.close()
        out = io.StringIO()
        pstats.Stats(profiler, stream=out).sort_stats("tottime").print_stats(top)
        lines.append(f"{task}:{out.getvalue()}")
    return "\n".join(lines)


def physics_bound(
    kb: KnowledgeBase, smap: SemanticMap, composer: Composer, task: str, seed: int
) -> tuple[float, float]:
    """CPU seconds a step of ``task``'s own physics takes in a run (the arms' motors and contacts make
    it dearer, and the work between steps cools the caches), and a step of the fresh world alone."""
    spent = [0.0]
    original = p.stepSimulation

    def timed(**kwargs: Any) -> Any:
        start = time.thread_time()
        try:
            return original(**kwargs)
        finally:
            spent[0] += time.thread_time() - start

    world = HomeWorld.create(seed=seed, semantic_map=smap)
    try:
        steps0 = world.steps
        p.stepSimulation = timed
        try:
            run_task(kb, task, SimEnvironment(world, kb), composer=composer)
        finally:
            p.stepSimulation = original
        steps = world.steps - steps0
    finally:
        world.close()
    with HomeWorld.create(seed=seed, semantic_map=smap) as fresh:
        _, alone = step_alone(fresh, steps)
    return spent[0] / steps, alone / steps


def _split_targets() -> list[tuple[Any, str, str]]:
    """What :func:`split` times: (owner, attribute, part)."""
    kinematics = ("solve", "collides", "strikes", "brushes", "wrist_strikes", "forward", "path_clear", "line")
    return [
        (p, "stepSimulation", "physics"),
        (p, "calculateInverseKinematics", "inverse kinematics (pybullet)"),
        (p, "getCameraImage", "rendering (pybullet)"),
        *((Kinematics, name, "kinematics, the rest") for name in (*kinematics, "joint_path")),
        (PerceivedWorld, "look", "perception, the rest"),
        (PerceivedWorld, "feel", "perception, the rest"),
        (HomeWorld, "step", "stepping, the rest"),
        (MobileBase, "follow", "driving, the rest"),
        (EmbeddedStore, "query", "store queries"),
        (Composer, "compose", "composing"),
    ]


def split(kb: KnowledgeBase, smap: SemanticMap, composer: Composer, task: str, seed: int) -> dict[str, float]:
    """CPU seconds of one run of ``task`` by part (:func:`_split_targets`), each less the parts it calls,
    and the rest (``total`` is the run's)."""
    spent: dict[str, float] = {}
    stack: list[list[Any]] = []  # part, start, CPU of the parts called

    def timed(part: str, original: Any) -> Any:
        def call(*args: Any, **kwargs: Any) -> Any:
            stack.append([part, time.thread_time(), 0.0])
            try:
                return original(*args, **kwargs)
            finally:
                _, start, inner = stack.pop()
                took = time.thread_time() - start
                spent[part] = spent.get(part, 0.0) + took - inner
                if stack:
                    stack[-1][2] += took

        return call

    originals = [(owner, name, getattr(owner, name)) for owner, name, _ in _split_targets()]
    try:
        for (owner, name, part), (_, _, original) in zip(_split_targets(), originals, strict=True):
            setattr(owner, name, timed(part, original))
        # built with the parts timed: the arms and the base keep the world's step as they find it
        with HomeWorld.create(seed=seed, semantic_map=smap) as world:
            spent.clear()
            start = time.thread_time()
            run_task(kb, task, SimEnvironment(world, kb), composer=composer)
            total = time.thread_time() - start
    finally:
        for owner, name, original in originals:
            setattr(owner, name, original)
    spent["the rest"] = total - sum(spent.values())
    spent["total"] = total
    return spent


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--tasks", default=",".join(TASKS))
    parser.add_argument("--seeds", default="0,1,2")
    parser.add_argument("--repeat", type=int, default=1, metavar="N", help="run each task and seed N times")
    parser.add_argument("--profile", type=int, default=0, metavar="N", help="print the N costliest functions")
    parser.add_argument(
        "--physics", action="store_true", help="also time the tasks' own physics steps against stepping alone"
    )
    parser.add_argument("--split", action="store_true", help="also divide a run's CPU time by where it goes")
    parser.add_argument("--json", type=Path, help="also write the rows to FILE as a list of records")
    parser.add_argument("--digests", type=Path, help="write each run's outcome digest to FILE (JSON)")
    parser.add_argument("--check", type=Path, help="compare the runs' digests with FILE; exit 1 if any differs")
    args = parser.parse_args()
    tasks = args.tasks.split(",")
    seeds = [int(s) for s in args.seeds.split(",")]
    print(
        f"machine: {platform.platform()}, {os.cpu_count()} cores, python {platform.python_version()}, "
        f"pybullet {version('pybullet')}, pyoxigraph {version('pyoxigraph')}; "
        f"load average at start {os.getloadavg()[0]:.2f}"
    )
    kb = KnowledgeBase.open(":memory:")
    smap = SemanticMap.read(kb)
    composer = Composer(kb)
    print(f"inputs: tasks {', '.join(tasks)}; seeds {seeds}; physics step {TIME_STEP:.6f} s; DIRECT, headless\n")

    print(
        f"{'task':<18} {'seed':>4} {'status':>10} {'steps':>6} {'sim s':>6} {'run s':>6} {'plan s':>6} "
        f"{'alone s':>7} {'RTF':>6} {'alone':>6} {'ratio':>6} {'CPU ratio':>9} {'off CPU':>7} {'CPU s':>6} "
        f"{'frames':>6}  digest"
    )
    samples: list[Sample] = []
    for task in tasks:
        for seed in seeds:
            for _ in range(max(1, args.repeat)):
                s = run_one(kb, smap, composer, task, seed)
                samples.append(s)
                print(
                    f"{task:<18} {seed:>4} {s.status:>10} {s.steps:>6} {s.simulated:>6.1f} {s.wall:>6.2f} "
                    f"{s.composing:>6.2f} {s.alone:>7.2f} {s.factor:>6.1f} {s.anchor:>6.1f} "
                    f"{s.factor / s.anchor:>6.2f} {s.cpu_ratio:>9.2f} {s.off_cpu:>7.2f} {s.cpu:>6.2f} "
                    f"{s.frames:>6}  {s.digest}"
                )

    records = [row(f"{task}, headless", [s for s in samples if s.task == task]) for task in tasks]
    records.append(row("both tasks, headless", samples))
    print()
    for record, group in zip(records, [*([s for s in samples if s.task == t] for t in tasks), samples], strict=True):
        verdict = "met" if record["met"] else "not met"
        cpu = statistics.median(s.cpu_ratio for s in group)
        print(
            f"{record['row']}: real-time factor {record['value']:.1f} vs pybullet alone {record['anchor']:.1f}: "
            f"{record['ratio']:.2f}x (goal >= {GOAL:g}x: {verdict}); on CPU time {cpu:.2f}x"
        )
    for task in tasks:  # what a user waits for on an idle machine: less moved by other jobs than wall time
        cpu_s = statistics.median(s.cpu for s in samples if s.task == task)
        print(f"{task}: median CPU seconds a run (composing left out) {cpu_s:.2f}")
    print(f"load average at end {os.getloadavg()[0]:.2f}")
    if args.physics:
        print("\nphysics alone: a task's own steps (CPU, in a run) against the fresh world's steps alone")
        for task in tasks:
            for seed in seeds:
                in_run, alone = physics_bound(kb, smap, composer, task, seed)
                print(
                    f"{task:<18} {seed:>4}: {in_run * 1e6:.0f} us a step in the run, {alone * 1e6:.0f} alone: "
                    f"with nothing but its physics the run would reach {alone / in_run:.2f}x"
                )
    if args.split:
        print("\nCPU seconds of one run (seed 0) by part, each less the parts it calls:")
        for task in tasks:
            parts = split(kb, smap, composer, task, 0)
            total = parts.pop("total")
            listed = ", ".join(f"{part} {cpu:.3f}" for part, cpu in sorted(parts.items(), key=lambda kv: -kv[1]))
            print(f"{task}: {total:.3f} s: {listed}")
    if args.profile:
        listing = profile(kb, smap, composer, tasks, args.profile)
        print(f"\nprofile of one run of each task (seed 0), by own CPU time:\n{listing}")
    if args.json is not None:
        args.json.write_text(json.dumps(records, indent=2) + "\n", encoding="utf-8")
        print(f"written to {args.json}")
    digests = {f"{s.task} {s.seed}": s.digest for s in samples}
    unsteady = sorted({f"{s.task} {s.seed}" for s in samples if s.digest != digests[f"{s.task} {s.seed}"]})
    if unsteady:  # the same seed must give the same run every time
        print(f"digests differ between repeats of: {unsteady}")
        sys.exit(1)
    if args.digests is not None:
        args.digests.write_text(json.dumps(digests, indent=2) + "\n", encoding="utf-8")
        print(f"digests written to {args.digests}")
    if args.check is not None:
        expected = json.loads(args.check.read_text(encoding="utf-8"))
        differ = sorted(key for key, value in digests.items() if key in expected and expected[key] != value)
        compared = sum(key in expected for key in digests)
        print(
            f"digests: {compared - len(differ)} of {compared} runs as in {args.check}"
            + (f"; differ: {differ}" if differ else "")
        )
        if differ:
            sys.exit(1)


def row(name: str, samples: list[Sample]) -> dict[str, Any]:
    """One record: the medians of the task's and the anchor's real-time factors, and their ratio."""
    value = statistics.median(s.factor for s in samples)
    anchor = statistics.median(s.anchor for s in samples)
    ratio = value / anchor
    return {
        "row": f"simulation real-time factor, {name}, vs pybullet stepping the same scene alone",
        "value": round(value, 2),
        "anchor": round(anchor, 2),
        "ratio": round(ratio, 3),
        "unit": "simulated s per wall s",
        "goal": f">= {GOAL:g}x",
        "met": ratio >= GOAL,
    }


if __name__ == "__main__":
    main()
