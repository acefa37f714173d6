"""Benchmark: the tasks of docs/examples/ against what the docs say they do, so that a regression of one shows.

Run: python bench/example_tasks.py [--data bench/data/example_tasks.toml] [--only LABEL ...] [--jobs N]
                                   [--json FILE] [--keep DIR]

Each trial of the data file (written from the examples' headers and docs/tasks.md's round tables) is run
at each of its seeds in a store of its own, as a user would: ``cbrs --store DIR init``, the trial's loads
in order (``cbrs load --graph``, ``cbrs update --file``, ``cbrs register``), then ``cbrs run TASK --seed N
--json``. The stores are made once a trial and copied for each seed, before anything runs in them. Runs go
in parallel processes, up to ``--jobs`` (default: the cores). The outcome is read from the run's JSON:
succeeded, refused (before anything moved: the run's error), no plan, or failed; a run whose JSON cannot
be read is "broken". Prints the machine, the commit, one row a run (expected and found status and
simulated seconds) and the deviations: a status other than the docs', or a successful run's simulated
seconds off by more than the data's tolerance. Exits 1 when there is a deviation. ``--json FILE`` writes
the same as a record.
"""

from __future__ import annotations

import argparse
import concurrent.futures
import importlib.metadata
import json
import os
import platform
import shutil
import subprocess
import sys
import tempfile
import time
import tomllib
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = ROOT / "docs" / "examples"
DATA = ROOT / "bench" / "data" / "example_tasks.toml"
GRAPHS = ("ontology", "map", "requirements")
STATUSES = ("succeeded", "refused", "no plan", "failed")
RUN_STATUS = {"succeeded": "succeeded", "failed": "failed", "cancelled": "failed", "unsolvable": "no plan"}


@dataclass(frozen=True)
class Trial:
    """One row of the data file: a task run in a store made by ``setup``, and what the docs say of it."""

    label: str
    task: str
    source: str
    setup: list[tuple[str, str]]
    seeds: list[int]
    status: list[str]
    seconds: list[float]
    known_failure: bool = False


@dataclass
class Outcome:
    label: str
    task: str
    seed: int
    expected: str
    expected_seconds: float
    status: str
    seconds: float
    wall: float
    reason: str
    deviation: str = ""


def read_trials(path: Path) -> tuple[float, list[Trial]]:
    """The data file's tolerance and trials, checked: each seed has a status and seconds, each status and
    load is one the bench knows, each file exists."""
    data = tomllib.loads(path.read_text(encoding="utf-8"))
    trials = []
    for row in data["trial"]:
        seeds = list(row.get("seeds", [0, 1, 2]))
        trial = Trial(
            label=row["label"],
            task=row["task"],
            source=row.get("source", ""),
            setup=[(verb, name) for verb, name in row["setup"]],
            seeds=seeds,
            status=list(row["status"]),
            seconds=[float(s) for s in row["seconds"]],
            known_failure=bool(row.get("known_failure", False)),
        )
        if not len(trial.status) == len(trial.seconds) == len(seeds):
            raise SystemExit(f"{path}: {trial.label}: one status and one seconds a seed ({seeds})")
        if bad := [s for s in trial.status if s not in STATUSES]:
            raise SystemExit(f"{path}: {trial.label}: unknown status {bad} (one of {', '.join(STATUSES)})")
        for verb, name in trial.setup:
            if verb not in (*GRAPHS, "update", "register"):
                raise SystemExit(f"{path}: {trial.label}: unknown load {verb!r} of {name}")
            if not (EXAMPLES / name).is_file():
                raise SystemExit(f"{path}: {trial.label}: no file docs/examples/{name}")
        trials.append(trial)
    labels = [t.label for t in trials]
    if len(set(labels)) != len(labels):
        raise SystemExit(f"{path}: labels repeat: {sorted({x for x in labels if labels.count(x) > 1})}")
    return float(data.get("tolerance", 0.2)), trials


def _cbrs(store: Path, *args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, "-m", "cbrs", "--store", str(store), *args],
        cwd=ROOT,
        capture_output=True,
        text=True,
        check=False,
    )


def make_store(trial: Trial, store: Path) -> None:
    """A fresh store with the trial's loads, in order; SystemExit naming the load that failed."""
    steps: list[tuple[str, ...]] = [("init",)]
    for verb, name in trial.setup:
        path = str(EXAMPLES / name)
        if verb in GRAPHS:
            steps.append(("load", "--graph", verb, path))
        elif verb == "update":
            steps.append(("update", "--file", path))
        else:
            steps.append(("register", path))
    for step in steps:
        done = _cbrs(store, *step)
        if done.returncode != 0:
            raise RuntimeError(f"{trial.label}: cbrs {' '.join(step)} exited {done.returncode}: {done.stderr[-400:]}")


def run_one(trial: Trial, index: int, store: Path) -> Outcome:
    """Run the trial's task at its ``index``-th seed in ``store`` and read the outcome from its JSON."""
    seed = trial.seeds[index]
    started = time.perf_counter()
    done = _cbrs(store, "run", trial.task, "--seed", str(seed), "--json")
    wall = time.perf_counter() - started
    try:
        found: dict[str, Any] = json.loads(done.stdout)
    except json.JSONDecodeError:
        found = {"status": "broken", "error": (done.stderr or done.stdout)[-300:]}
    raw = str(found.get("status", "broken"))
    if raw == "error":
        status, reason = "refused", str(found.get("error", ""))
    else:
        status = RUN_STATUS.get(raw, "broken")
        reason = _reason(found) if status != "succeeded" else ""
    return Outcome(
        trial.label,
        trial.task,
        seed,
        trial.status[index],
        trial.seconds[index],
        status,
        float(found.get("sim_seconds", 0.0)),
        wall,
        reason,
    )


def _reason(found: dict[str, Any]) -> str:
    """A failed or unplanned run's reason, as its JSON gives it."""
    for key in ("reason", "error", "message"):
        if found.get(key):
            return str(found[key])
    report = found.get("report")
    if isinstance(report, dict) and report.get("reason"):
        return str(report["reason"])
    plan = found.get("plan")
    if isinstance(plan, dict):
        unsatisfied = plan.get("unsatisfied")
        if isinstance(unsatisfied, list) and unsatisfied and isinstance(unsatisfied[0], dict):
            return "no component provides " + "; ".join(str(u.get("need", u)) for u in unsatisfied)
        for key in ("reason", "explanation"):
            if plan.get(key):
                return str(plan[key])
    return json.dumps(found)[:300]


def deviation(outcome: Outcome, tolerance: float) -> str:
    """Why the outcome is not what the docs say (empty when it is)."""
    if outcome.status != outcome.expected:
        return f"{outcome.status}, the docs say {outcome.expected}"
    off = abs(outcome.seconds - outcome.expected_seconds)
    if outcome.status == "succeeded" and outcome.expected_seconds and off > tolerance:
        return f"{outcome.seconds:.1f} s simulated, the docs say {outcome.expected_seconds:.1f} s"
    return ""


def commit() -> str:
    """The checkout's commit, marked when tracked files differ from it."""
    head = subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=ROOT, capture_output=True, text=True)
    if head.returncode != 0:
        return "unknown (not a git checkout)"
    status = ["git", "status", "--porcelain", "--untracked-files=no"]
    dirty = subprocess.run(status, cwd=ROOT, capture_output=True, text=True)
    return head.stdout.strip() + (" (with uncommitted changes)" if dirty.stdout.strip() else "")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--data", type=Path, default=DATA, help="the expectations (TOML)")
    parser.add_argument("--only", nargs="+", metavar="NAME", help="only the trials of these labels or tasks")
    parser.add_argument("--jobs", type=int, default=os.cpu_count() or 1, help="runs at once (default: the cores)")
    parser.add_argument("--json", type=Path, help="write the record here")
    parser.add_argument("--keep", type=Path, help="make the stores under DIR and keep them (default: a temporary one)")
    args = parser.parse_args()
    tolerance, trials = read_trials(args.data)
    if args.only:
        trials = [t for t in trials if t.label in args.only or t.task in args.only]
        if not trials:
            raise SystemExit(f"no trial is labelled or runs {', '.join(args.only)}")
    load = os.getloadavg()[0]
    print(
        f"machine: {platform.platform()}, {os.cpu_count()} cores, python {platform.python_version()}, "
        f"pybullet {importlib.metadata.version('pybullet')}, pyoxigraph {importlib.metadata.version('pyoxigraph')}; "
        f"load average at start {load:.2f}"
    )
    print(f"commit: {commit()}")
    runs_in_all = sum(len(t.seeds) for t in trials)
    print(f"inputs: {len(trials)} trials, {runs_in_all} runs, {args.jobs} at once; tolerance {tolerance} s\n")
    scratch = Path(tempfile.mkdtemp(prefix="example_tasks_")) if args.keep is None else args.keep
    scratch.mkdir(parents=True, exist_ok=True)
    started = time.perf_counter()
    outcomes: list[Outcome] = []
    broken: list[str] = []
    try:
        with concurrent.futures.ThreadPoolExecutor(max_workers=max(1, args.jobs)) as pool:
            made: dict[concurrent.futures.Future[None], tuple[int, Trial]]
            made = {pool.submit(make_store, t, scratch / f"t{i}" / "made"): (i, t) for i, t in enumerate(trials)}
            runs: list[concurrent.futures.Future[Outcome]] = []
            for future in concurrent.futures.as_completed(made):
                i, trial = made[future]
                try:
                    future.result()
                except RuntimeError as failed:
                    broken.append(str(failed))
                    continue
                for k in range(len(trial.seeds)):
                    store = scratch / f"t{i}" / f"seed{trial.seeds[k]}"
                    shutil.copytree(scratch / f"t{i}" / "made", store)
                    runs.append(pool.submit(run_one, trial, k, store))
            for ran in concurrent.futures.as_completed(runs):
                got = ran.result()
                outcomes.append(got)
                said = f"{got.label}, seed {got.seed}: {got.status}, {got.seconds:.1f} s ({got.wall:.0f} s wall)"
                print(f"[{len(outcomes)}/{len(runs)}] {said}", file=sys.stderr, flush=True)
    finally:
        if args.keep is None:
            shutil.rmtree(scratch, ignore_errors=True)
    order = {t.label: i for i, t in enumerate(trials)}
    outcomes.sort(key=lambda o: (order[o.label], o.seed))
    for outcome in outcomes:
        outcome.deviation = deviation(outcome, tolerance)
    width = max((len(o.label) for o in outcomes), default=10)
    head = f"{'trial':<{width}} {'seed':>4} {'expected':<10} {'found':<10} {'docs s':>6} {'sim s':>6} {'wall s':>6}"
    print(f"{head}  deviation")
    for o in outcomes:
        mark = o.deviation or ""
        print(
            f"{o.label:<{width}} {o.seed:>4} {o.expected:<10} {o.status:<10} {o.expected_seconds:>6.1f} "
            f"{o.seconds:>6.1f} {o.wall:>6.1f}  {mark}"
        )
    deviations = [o for o in outcomes if o.deviation]
    print(f"\n{len(outcomes)} runs in {time.perf_counter() - started:.0f} s; {len(deviations)} deviations")
    for o in deviations:
        known = " (a known failure in the docs)" if next(t for t in trials if t.label == o.label).known_failure else ""
        reason = f": {o.reason[:300]}" if o.reason else ""
        print(f"- {o.label}, seed {o.seed}: {o.deviation}{known}{reason}")
    for message in broken:
        print(f"- the store could not be made: {message}")
    if args.json:
        record = {
            "machine": platform.platform(),
            "cores": os.cpu_count(),
            "load_at_start": load,
            "commit": commit(),
            "tolerance": tolerance,
            "runs": [asdict(o) for o in outcomes],
            "broken": broken,
        }
        args.json.write_text(json.dumps(record, indent=2), encoding="utf-8")
    if deviations or broken:
        sys.exit(1)


if __name__ == "__main__":
    main()
