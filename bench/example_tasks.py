"""Benchmark: the tasks of docs/examples/ against what the docs say they do, so that a regression of one shows.

Run: python bench/example_tasks.py [--data bench/data/example_tasks.toml] [--only LABEL ...] [--jobs N]
                                   [--json FILE] [--keep DIR]

Each trial of the data file (written from the examples' headers and docs/tasks.md's round tables) is run
at each of its seeds in a store of its own, as a user would: ``cbrs --store DIR init``, the trial's setup
steps in order (``cbrs load --graph``, ``cbrs update --file``, ``cbrs register``; a step may load a copy
of its file with literal substitutions, as the docs' ``sed`` variants, or be expected refused: then its
error class and phrase are checked and the store's graph sizes are compared before and after), then its
runs in order in that store (``cbrs run TASK --seed N --json``; a trial of several runs is a sequence in
one store). A trial whose components are served by a program of the example's own starts, for each seed,
``cbrs serve`` on free loopback ports with an update token and the program against its bridge, then
runs ``cbrs --store URL run TASK --bridge WS``, as the docs do (several programs at once: each started
once the one before says it is ready; a Node program by node from a copy with the modules beside it,
skipped, saying why, where node or roslib is missing); a trial run over HTTP posts the task to the server's
``/tasks.json`` and polls the run's JSON; one run over the bridge calls its ``/cbrs/run_task`` service with
the token and polls ``/cbrs/task_status``. A trial may send its files to the server (``POST /store``,
``POST /update``) instead of loading them before it starts. A library program of the examples runs its
task itself in the trial's store (``python PROGRAM --store DIR --seed N``) and prints the outcome as JSON.
A posted file the docs say is refused must be answered 4xx saying their phrase, the store's digest
(``GET /store`` as N-Quads) the same before and after. A trial run from the pages (``page``) uses the
knowledge browser's forms as a browser submits them (form-encoded, with the page's ``Origin``; no
script): the tasks page's Start form, the run read from its page; a requirement's file written on the New
task page (checked, saved with the token, or refused there). Two runs at once (``busy``): while a run
goes, the next one's start must be refused with 409 saying so, and taken once the run has ended. The
Stop button (``stop``): pressed on the run's page after some steps, taken (303 to the run's page), the
run cancelled with the steps not taken pending, pressed again refused (409). The pages' GET forms (``forms``: search,
taxonomy, services, plans, matchmaking, the SPARQL page's), each answer's status and words checked.
The processes are stopped by PID; every wait is bounded. The stores are made once a trial and copied for
each seed, before anything runs in them. Runs go in parallel processes, up to ``--jobs`` (default: the
cores). The outcome is read from the run's JSON:
succeeded, refused (before anything moved: the run's error), no plan, or failed; a run whose JSON cannot
be read is "broken". Prints the machine, the commit, the load checks, one row a run (expected and found
status and simulated seconds) and the deviations: a status other than the docs', a successful run's
simulated seconds off by more than the data's tolerance, a refused step accepted or refused otherwise,
a store changed by a refusal, a second start taken or refused otherwise, a page not as it should be,
a run without the docs' phrase or steps.
Exits 1 when there is a deviation. ``--json FILE`` writes the same as a record.
"""

from __future__ import annotations

import argparse
import concurrent.futures
import hashlib
import html
import html.parser
import importlib.metadata
import itertools
import json
import os
import platform
import re
import secrets
import shutil
import signal
import socket
import subprocess
import sys
import tempfile
import threading
import time
import tomllib
import urllib.error
import urllib.parse
import urllib.request
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = ROOT / "docs" / "examples"
DATA = ROOT / "bench" / "data" / "example_tasks.toml"
GRAPHS = ("ontology", "map", "requirements")
VERBS = (*GRAPHS, "update", "register")
STATUSES = ("succeeded", "refused", "no plan", "failed", "cancelled")
RUN_STATUS = {"succeeded": "succeeded", "failed": "failed", "cancelled": "cancelled", "unsolvable": "no plan"}
SERVER_STATUS = {"succeeded": "succeeded", "failed": "failed", "cancelled": "cancelled", "no-plan": "no plan"}
SKIPPED = "skipped"
"""A run the machine cannot make (a program's interpreter or its modules missing): said why, no deviation."""
VIAS = ("cli", "bridge", "http", "run_task", "action", "library", "page")
SERVED = ("http", "bridge", "run_task", "action", "page")
"""The ways of running that go to a server of the trial's store (``cbrs serve``)."""
STARTS = ("http", "page")
"""The ways of running whose starts the server may answer 409 while a run goes (two runs at once)."""
REQUIREMENTS_GRAPH = "https://w3id.org/cbrs/graph/requirements"
REQUIREMENT = "https://w3id.org/cbrs/core#Requirement"
GRAPH_SIZES = "SELECT ?g (COUNT(*) AS ?n) WHERE { GRAPH ?g { ?s ?p ?o } } GROUP BY ?g"
STARTUP = 90.0
"""Seconds a server or a component program may take to answer or register (bounded waits)."""
RUN_TIMEOUT = 600.0
"""Seconds one run may take, wall time, before it is stopped and counted broken."""
NODE_MODULES = ROOT / "tests" / "js" / "node_modules"
"""Where a Node program's modules are (``npm ci --prefix tests/js``: roslib); ``--node-modules`` sets another.
Node resolves an ES module's imports beside the program, not by NODE_PATH: the program runs from a copy
in the trial's directory with this linked beside it, as its header says (roslib beside it)."""
INTERPRETERS = {".py": "python", ".mjs": "node", ".js": "node"}
"""How a served program is started, by its suffix."""
BRIDGE = "{bridge}"
"""In a served program's args, where its bridge's URL goes (else ``--bridge URL`` first, as the Python ones take it)."""


@dataclass(frozen=True)
class Step:
    """One setup step: a file loaded by ``verb``, maybe a copy with literal substitutions (the docs' sed
    variants), maybe expected to be refused (its error class and a phrase of the docs' refusal)."""

    verb: str
    file: str
    sed: tuple[tuple[str, str], ...] = ()
    refused: str = ""
    says: str = ""
    replace: bool = False

    @property
    def expect_refusal(self) -> bool:
        return bool(self.refused or self.says)


@dataclass(frozen=True)
class Run:
    """One run of a trial: its task, and the status and simulated seconds the docs give at each seed;
    where the docs say more, a phrase of the run's words (``says``: its JSON, or its page's verdict) and
    the number of steps it took at each seed (``steps``)."""

    task: str
    status: list[str]
    seconds: list[float]
    before: tuple[Step, ...] = ()
    between: tuple[float, float] | None = None
    says: str = ""
    steps: list[int] | None = None


@dataclass(frozen=True)
class Serve:
    """The example's own program, served to the trial's runs: started against ``cbrs serve``'s bridge,
    ready once ``ready`` has appeared ``count`` times in its output."""

    program: str
    args: tuple[str, ...] = ()
    ready: str = "registered"
    count: int = 1

    def argv(self, ws: str, where: Path, node_modules: Path) -> list[str]:
        """The command that serves this program against the bridge ``ws``: Python's, or Node's on a copy of
        the program in ``where`` beside the other example files (linked) and ``node_modules``;
        :class:`Skip` when Node or the modules are missing."""
        args = [a.replace(BRIDGE, ws) for a in self.args]
        args = args if any(BRIDGE in a for a in self.args) else ["--bridge", ws, *args]
        if INTERPRETERS.get(Path(self.program).suffix) != "node":
            return [sys.executable, str(EXAMPLES / self.program), *args]
        node = node_command(node_modules)
        where.mkdir(parents=True, exist_ok=True)
        for path in EXAMPLES.iterdir():  # the files it reads beside itself (its description), linked
            if path.is_file() and path.name != self.program and not (where / path.name).exists():
                (where / path.name).symlink_to(path)
        if not (where / "node_modules").exists():
            (where / "node_modules").symlink_to(node_modules.resolve())
        copy = where / self.program
        if copy.is_symlink():  # linked for a Node program before it in the same trial
            copy.unlink()
        shutil.copy(EXAMPLES / self.program, copy)
        return [node, str(copy), *args]


class Skip(Exception):
    """A trial this machine cannot run (a program's interpreter or modules missing): why."""


def node_command(node_modules: Path) -> str:
    """Node's path; :class:`Skip` saying what is missing: node itself, or roslib in ``node_modules``."""
    node = shutil.which("node")
    if node is None:
        raise Skip("node is not installed (the program runs on node >= 20 with roslib)")
    if not (node_modules / "roslib").is_dir():
        raise Skip(f"roslib is not in {node_modules} (npm ci --prefix tests/js, or --node-modules DIR)")
    return node


def skip_reason(trial: Trial, node_modules: Path) -> str:
    """Why this machine cannot run ``trial`` (empty when it can): a Node program, node or its modules missing."""
    if any(INTERPRETERS.get(Path(s.program).suffix) == "node" for s in trial.serve):
        try:
            node_command(node_modules)
        except Skip as missing:
            return str(missing)
    return ""


@dataclass(frozen=True)
class Library:
    """An example's Python program that runs its task through the library in a store it opens: started as
    ``python PROGRAM --store DIR --seed N [args]``, it prints the run as JSON (``succeeded``, ``sim_seconds``)."""

    program: str
    args: tuple[str, ...] = ()


@dataclass(frozen=True)
class Trial:
    """One entry of the data file: a store made by ``setup``, the runs made in it, what the docs say.
    ``serve``: the programs served to its runs, started in order (none: cbrs serve alone)."""

    label: str
    source: str
    setup: list[Step]
    seeds: list[int]
    runs: list[Run]
    via: str = "cli"
    serve: tuple[Serve, ...] = ()
    known_failure: bool = False
    library: Library | None = None
    post: bool = False
    """Whether the setup's files are sent to the server (``POST /store``, ``POST /update``) once it answers,
    for each seed, instead of loaded on the command line before it starts (via page: a requirement's file
    written on the New task page); an expected refusal is checked there (status, words, the store as it was)."""
    busy: str = ""
    """Two runs at once: while each run but the last goes, the next run's start is sent and must be refused
    (409) saying this phrase and naming the run going; the next is started once the run has ended."""
    stop: StopAt | None = None
    """The tasks page's Stop button pressed on each run's page (via page)."""
    forms: tuple[PageForm, ...] = ()
    """The pages' GET forms (via page), submitted in order once the server answers (at the first seed)."""

    @property
    def task(self) -> str:
        return " then ".join(r.task for r in self.runs) or "(loads only)"


@dataclass(frozen=True)
class StopAt:
    """The tasks page's Stop this run, pressed on the run's page once it shows ``after`` steps ended: the
    stop must be taken (303 to the run's page, saying ``says``), the run end cancelled with the steps not taken
    pending in its result, and the same button pressed again refused (409, saying ``again``), the run
    left as it was."""

    after: int
    says: str
    again: str


@dataclass(frozen=True)
class PageForm:
    """A GET form of the pages, submitted as a browser does: on ``page`` (else on the page the form before
    answered), the form whose id is ``form`` or that holds the element of that id, with its fields typed
    (``fill``) and its lists' options chosen (``choose``); the answer must have ``status``, and its text
    (tags dropped) must say each of ``says`` and none of ``lacks`` (what a filter leaves out)."""

    form: str
    page: str = ""
    fill: tuple[tuple[str, str], ...] = ()
    choose: tuple[tuple[str, str], ...] = ()
    status: int = 200
    says: tuple[str, ...] = ()
    lacks: tuple[str, ...] = ()


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
    expected_between: tuple[float, float] | None = None
    expected_says: str = ""
    said: bool = True
    expected_steps: int | None = None
    steps: int | None = None


@dataclass
class Made:
    """A trial's store, and what its expected refusals did."""

    checks: list[str] = field(default_factory=list)
    deviations: list[str] = field(default_factory=list)


def _step(label: str, raw: Any) -> Step:
    if isinstance(raw, list):
        verb, name = raw
        return Step(verb, name)
    sed = tuple((str(a), str(b)) for a, b in raw.get("sed", []))
    refused, says = str(raw.get("refused", "")), str(raw.get("says", ""))
    return Step(raw["load"], raw["file"], sed, refused, says, bool(raw.get("replace", False)))


def _trial(path: Path, row: dict[str, Any]) -> Trial:
    label = row["label"]
    seeds = list(row.get("seeds", [0, 1, 2]))
    raw_runs = list(row.get("runs", []))
    if "task" in row:
        keys = ("task", "status", "seconds", "between", "says", "steps")
        raw_runs.insert(0, {key: row[key] for key in keys if key in row})
    runs = [
        Run(
            r["task"],
            list(r["status"]),
            [float(s) for s in r["seconds"]],
            tuple(_step(label, b) for b in r.get("before", [])),
            (float(r["between"][0]), float(r["between"][1])) if "between" in r else None,
            str(r.get("says", "")),
            [int(n) for n in r["steps"]] if "steps" in r else None,
        )
        for r in raw_runs
    ]
    forms = tuple(
        PageForm(
            str(f["form"]),
            str(f.get("page", "")),
            tuple((str(k), str(v)) for k, v in f.get("fill", {}).items()),
            tuple((str(k), str(v)) for k, v in f.get("choose", {}).items()),
            int(f.get("status", 200)),
            tuple(str(w) for w in f.get("says", [])),
            tuple(str(w) for w in f.get("lacks", [])),
        )
        for f in row.get("forms", [])
    )
    served = row.get("serve", [])
    serve = tuple(
        Serve(s["program"], tuple(s.get("args", [])), s.get("ready", "registered"), int(s.get("count", 1)))
        for s in (served if isinstance(served, list) else [served])  # one program, or several at once
    )
    library = None
    if "library" in row:
        library = Library(row["library"]["program"], tuple(row["library"].get("args", [])))
    via = row.get("via", "library" if library else "bridge" if serve else "cli")
    trial = Trial(
        label,
        row.get("source", ""),
        [_step(label, s) for s in row["setup"]],
        seeds,
        runs,
        via,
        serve,
        bool(row.get("known_failure", False)),
        library,
        bool(row.get("post", False)),
        str(row.get("busy", "")),
        StopAt(int(row["stop"]["after"]), str(row["stop"]["says"]), str(row["stop"]["again"]))
        if "stop" in row
        else None,
        forms,
    )
    _check(path, trial)
    return trial


def _check(path: Path, trial: Trial) -> None:
    """SystemExit naming what of ``trial`` the bench cannot run as written."""
    where = f"{path}: {trial.label}"
    for run in trial.runs:
        if not len(run.status) == len(run.seconds) == len(trial.seeds):
            raise SystemExit(f"{where}: {run.task}: one status and one seconds a seed ({trial.seeds})")
        if bad := [s for s in run.status if s not in STATUSES]:
            raise SystemExit(f"{where}: unknown status {bad} (one of {', '.join(STATUSES)})")
        if run.steps is not None and len(run.steps) != len(trial.seeds):
            raise SystemExit(f"{where}: {run.task}: steps, one number a seed ({trial.seeds})")
    if not trial.runs and not trial.forms and not any(s.expect_refusal for s in trial.setup):
        raise SystemExit(f"{where}: neither a run, a form nor a refusal to check")
    if (trial.stop or trial.forms) and trial.via != "page":
        raise SystemExit(f"{where}: the Stop button (stop) and the pages' forms (forms) are the pages' (via page)")
    if trial.stop and (trial.busy or any(s != "cancelled" for r in trial.runs for s in r.status)):
        raise SystemExit(f"{where}: a run stopped (stop) ends cancelled at each seed, one run at a time")
    if any(not f.page for f in trial.forms[:1]):
        raise SystemExit(f"{where}: the first form's page (page) is where the browser starts")
    if trial.via not in VIAS:
        raise SystemExit(f"{where}: unknown via {trial.via!r} (one of {', '.join(VIAS)})")
    if trial.via != "cli" and any(r.before for r in trial.runs):
        raise SystemExit(f"{where}: steps between runs are made on the command line only (via cli)")
    if trial.via == "bridge" and not trial.serve:
        raise SystemExit(f"{where}: a run over the bridge needs the program that serves its components (serve)")
    if (trial.via == "library") != (trial.library is not None) or (trial.library and trial.serve):
        raise SystemExit(f"{where}: a library program (library) runs alone, and only it runs via library")
    if trial.library is not None and len(trial.runs) != 1:
        raise SystemExit(f"{where}: a library program runs its one task: one run")
    if trial.post and trial.via not in SERVED:
        raise SystemExit(f"{where}: files are posted to a server: its runs must go to one (via {', '.join(SERVED)})")
    if trial.post and any(s.replace for s in trial.setup):
        raise SystemExit(f"{where}: a posted setup's files are added (POST), none replaces its graph (no replace)")
    if trial.busy and (trial.via not in STARTS or len(trial.runs) < 2):
        raise SystemExit(
            f"{where}: two runs at once (busy) start the next run while one goes: two runs or more, "
            f"via {' or '.join(STARTS)}"
        )
    steps = [*trial.setup, *(b for r in trial.runs for b in r.before)]
    names = [s.file for s in steps] + [s.program for s in trial.serve]
    names += [trial.library.program] if trial.library else []
    for step in steps:
        if step.verb not in VERBS:
            raise SystemExit(f"{where}: unknown load {step.verb!r} of {step.file}")
    for name in names:
        if not (EXAMPLES / name).is_file():
            raise SystemExit(f"{where}: no file docs/examples/{name}")


def read_trials(path: Path) -> tuple[float, list[Trial]]:
    """The data file's tolerance and trials, checked: each run has a status and seconds a seed, each status,
    load and way of running is one the bench knows, each file exists."""
    data = tomllib.loads(path.read_text(encoding="utf-8"))
    trials = [_trial(path, row) for row in data["trial"]]
    labels = [t.label for t in trials]
    if len(set(labels)) != len(labels):
        raise SystemExit(f"{path}: labels repeat: {sorted({x for x in labels if labels.count(x) > 1})}")
    return float(data.get("tolerance", 0.2)), trials


def _cbrs(
    store: Path | str, *args: str, env: dict[str, str] | None = None, timeout: float | None = None
) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, "-m", "cbrs", "--store", str(store), *args],
        cwd=ROOT,
        capture_output=True,
        text=True,
        check=False,
        env=env,
        timeout=timeout,
    )


def _edited(step: Step, where: Path) -> Path:
    """The step's file, or a copy of it under ``where`` with its substitutions made (each must match)."""
    source = EXAMPLES / step.file
    if not step.sed:
        return source
    text = source.read_text(encoding="utf-8")
    for old, new in step.sed:
        if old not in text:
            raise RuntimeError(f"{step.file}: the substitution's {old!r} is not in the file (the docs' sed is stale)")
        text = text.replace(old, new)
    copy = where / step.file
    copy.parent.mkdir(parents=True, exist_ok=True)
    copy.write_text(text, encoding="utf-8")
    return copy


def graph_sizes(store: Path) -> dict[str, int]:
    """Each named graph's number of triples (what a refusal must leave as it was)."""
    done = _cbrs(store, "query", GRAPH_SIZES, "--format", "json")
    if done.returncode != 0:
        raise RuntimeError(f"cbrs query of the graph sizes exited {done.returncode}: {done.stderr[-300:]}")
    rows = json.loads(done.stdout)
    rows = rows.get("results", {}).get("bindings", rows) if isinstance(rows, dict) else rows
    return {str(_value(r["g"])): int(_value(r["n"])) for r in rows}


def _value(cell: Any) -> Any:
    return cell.get("value") if isinstance(cell, dict) else cell


def make_store(trial: Trial, store: Path) -> Made:
    """A fresh store with the trial's setup steps, in order; RuntimeError naming a step that failed
    unexpectedly. An expected refusal is checked (exit, class, phrase, graph sizes) and a miss recorded."""
    made = Made()
    done = _cbrs(store, "init")
    if done.returncode != 0:
        raise RuntimeError(f"{trial.label}: cbrs init exited {done.returncode}: {done.stderr[-400:]}")
    for step in trial.setup if not trial.post else ():  # posted to the server once it runs: _post_step
        apply_step(trial.label, step, store, made)
    return made


def apply_step(label: str, step: Step, store: Path, made: Made) -> None:
    """Load ``step`` into ``store``; RuntimeError when an expected load fails, an expected refusal's miss
    recorded in ``made``."""
    path = str(_edited(step, store.parent / f"{store.name}.edited"))
    load = ("load", "--graph", step.verb, *(("--replace",) if step.replace else ()), path)
    args = {"update": ("update", "--file", path), "register": ("register", path)}.get(step.verb, load)
    before = graph_sizes(store) if step.expect_refusal else {}
    done = _cbrs(store, *args)
    said = f"cbrs {' '.join(args[:-1])} {step.file}"
    if not step.expect_refusal:
        if done.returncode != 0:
            raise RuntimeError(f"{label}: {said} exited {done.returncode}: {done.stderr[-400:]}")
        return
    made.checks.append(f"{label}: {said}: exit {done.returncode}: {_last_line(done)}")
    if miss := refusal_deviation(step, done, before, graph_sizes(store)):
        made.deviations.append(f"{label}: {said}: {miss}")


def _last_line(done: subprocess.CompletedProcess[str]) -> str:
    lines = [line for line in (done.stderr or done.stdout).splitlines() if line.strip()]
    return lines[-1][:300] if lines else "(nothing said)"


def refusal_deviation(
    step: Step, done: subprocess.CompletedProcess[str], before: dict[str, int], after: dict[str, int]
) -> str:
    """Why an expected refusal is not as the docs say (empty when it is)."""
    said = done.stderr + done.stdout
    if done.returncode == 0:
        return "accepted, the docs say refused"
    misses = [f"without {word!r}" for word in (step.refused, step.says) if word and word not in said]
    if before != after:
        changed = sorted(g for g in set(before) | set(after) if before.get(g) != after.get(g))
        misses.append(
            f"the graphs' sizes changed: {', '.join(f'{g} {before.get(g, 0)} -> {after.get(g, 0)}' for g in changed)}"
        )
    return ("refused " + "; ".join(misses) + f": {_last_line(done)}") if misses else ""


def _outcome(trial: Trial, k: int, index: int, seed: int, found: dict[str, Any], wall: float) -> Outcome:
    run = trial.runs[k]
    raw = str(found.get("status", "broken"))
    if raw == "error":
        status, reason = "refused", str(found.get("error", ""))
    else:
        status = RUN_STATUS.get(raw, SERVER_STATUS.get(raw, "broken"))
        reason = _reason(found) if status != "succeeded" else ""
    label = trial.label if len(trial.runs) == 1 else f"{trial.label} [{k + 1}: {run.task}]"
    seconds = float(found.get("sim_seconds", 0.0))
    expected = run.status[index]
    outcome = Outcome(
        label, run.task, seed, expected, run.seconds[index], status, seconds, wall, reason, "", run.between
    )
    outcome.expected_says, outcome.said = run.says, run.says in json.dumps(found, ensure_ascii=False)
    outcome.expected_steps = run.steps[index] if run.steps is not None else None
    execution = found.get("execution")
    if isinstance(execution, dict) and isinstance(execution.get("steps"), list):
        outcome.steps = len(execution["steps"])
    elif isinstance(found.get("steps"), int):  # a run's page: its steps table's rows
        outcome.steps = int(found["steps"])
    return outcome


def _parsed(done: subprocess.CompletedProcess[str]) -> dict[str, Any]:
    try:
        found = json.loads(done.stdout)
    except json.JSONDecodeError:
        return {"status": "broken", "error": (done.stderr or done.stdout)[-300:]}
    return found if isinstance(found, dict) else {"status": "broken", "error": done.stdout[-300:]}


def run_one(
    trial: Trial, index: int, store: Path, made: Made | None = None, node_modules: Path = NODE_MODULES
) -> list[Outcome]:
    """Run the trial's runs in order at its ``index``-th seed in ``store``: on the command line, or
    against a server of the store with the trial's program, and read each outcome from its JSON (or the
    run's page); what the server refused on the way (posted files, a second start) checked in ``made``."""
    seed = trial.seeds[index]
    if trial.via == "cli":
        outcomes = []
        for k, run in enumerate(trial.runs):
            started = time.perf_counter()
            try:
                for step in run.before:
                    apply_step(trial.label, step, store, Made())
                done = _cbrs(store, "run", run.task, "--seed", str(seed), "--json", timeout=RUN_TIMEOUT)
                found = _parsed(done)
            except subprocess.TimeoutExpired:
                found = {"status": "broken", "error": f"no answer in {RUN_TIMEOUT:.0f} s"}
            except RuntimeError as failed:
                found = {"status": "broken", "error": str(failed)}
            outcomes.append(_outcome(trial, k, index, seed, found, time.perf_counter() - started))
        return outcomes
    if trial.via == "library":
        return _library_runs(trial, index, store)
    return _served_runs(trial, index, store, made if made is not None else Made(), node_modules)


def _library_runs(trial: Trial, index: int, store: Path) -> list[Outcome]:
    """The trial's library program on ``store`` at its ``index``-th seed, its printed JSON the outcome:
    ``succeeded`` true or false, ``sim_seconds``; a program that prints no JSON object is broken."""
    assert trial.library is not None
    seed = trial.seeds[index]
    argv = [sys.executable, str(EXAMPLES / trial.library.program), "--store", str(store), "--seed", str(seed)]
    started = time.perf_counter()
    try:
        done = subprocess.run(
            [*argv, *trial.library.args], cwd=ROOT, capture_output=True, text=True, check=False, timeout=RUN_TIMEOUT
        )
        found = _parsed(done)
        if "succeeded" in found and "status" not in found:
            found["status"] = "succeeded" if found["succeeded"] is True else "failed"
    except subprocess.TimeoutExpired:
        found = {"status": "broken", "error": f"no answer in {RUN_TIMEOUT:.0f} s"}
    return [_outcome(trial, 0, index, seed, found, time.perf_counter() - started)]


def _free_port() -> int:
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as probe:
        probe.bind(("127.0.0.1", 0))
        return int(probe.getsockname()[1])


class _Child:
    """A child process whose output is read by a thread of its own (so it never blocks on a full pipe)."""

    def __init__(self, argv: list[str], env: dict[str, str], log: Path) -> None:
        self.log = log
        self.lines: list[str] = []
        self.process = subprocess.Popen(
            argv, cwd=ROOT, env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, start_new_session=True
        )
        self._reader = threading.Thread(target=self._read, daemon=True)
        self._reader.start()

    def _read(self) -> None:
        assert self.process.stdout is not None
        with self.log.open("w", encoding="utf-8") as out:
            for line in self.process.stdout:
                self.lines.append(line)
                out.write(line)
                out.flush()

    def wait_for(self, phrase: str, count: int, timeout: float) -> bool:
        """Whether ``phrase`` appeared ``count`` times in the output within ``timeout`` s (bounded)."""
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            if sum(phrase in line for line in list(self.lines)) >= count:
                return True
            if self.process.poll() is not None:
                return False
            time.sleep(0.2)
        return False

    def stop(self) -> None:
        """SIGTERM to this child by its PID, then SIGKILL after 15 s."""
        if self.process.poll() is None:
            os.kill(self.process.pid, signal.SIGTERM)
            try:
                self.process.wait(timeout=15)
            except subprocess.TimeoutExpired:
                os.kill(self.process.pid, signal.SIGKILL)
                self.process.wait(timeout=15)
        self._reader.join(timeout=5)


@contextmanager
def _server(
    trial: Trial,
    store: Path,
    env: dict[str, str],
    prepare: Callable[[str], None] | None = None,
    node_modules: Path = NODE_MODULES,
) -> Iterator[tuple[str, str]]:
    """``cbrs serve`` of ``store`` on free loopback ports, ``prepare(url)`` once it answers (the files
    posted), and the trial's programs against its bridge (Python's or Node's: :meth:`Serve.argv`); yields
    the HTTP and the bridge URLs; every process stopped by PID at the end."""
    http, bridge = _free_port(), _free_port()
    url, ws = f"http://127.0.0.1:{http}", f"ws://127.0.0.1:{bridge}"
    argv = [
        sys.executable,
        "-m",
        "cbrs",
        "--store",
        str(store),
        "serve",
        "--host",
        "127.0.0.1",
        "--port",
        str(http),
        "--bridge-port",
        str(bridge),
    ]
    children = [_Child(argv, env, store.parent / f"{store.name}.serve.log")]
    try:
        if not _answers(url + "/sparql?query=ASK%7B%7D", STARTUP):
            raise RuntimeError(
                f"cbrs serve did not answer at {url} within {STARTUP:.0f} s: {''.join(children[0].lines)[-300:]}"
            )
        if prepare is not None:  # before the programs, as the files come first
            prepare(url)
        for n, serve in enumerate(trial.serve):  # each ready before the next starts
            program = serve.argv(ws, store.parent / f"{store.name}.programs", node_modules)
            children.append(_Child(program, env, store.parent / f"{store.name}.program{n}.log"))
            if not children[-1].wait_for(serve.ready, serve.count, STARTUP):
                said = "".join(children[-1].lines)[-300:]
                raise RuntimeError(f"{serve.program} did not say {serve.ready!r} within {STARTUP:.0f} s: {said}")
        yield url, ws
    finally:
        for child in reversed(children):
            child.stop()


MEDIA = {
    ".ttl": "text/turtle",
    ".rdf": "application/rdf+xml",
    ".owl": "application/rdf+xml",
    ".nt": "application/n-triples",
}
MEDIA |= {".jsonld": "application/ld+json", ".trig": "application/trig", ".nq": "application/n-quads"}


def _post_request(url: str, step: Step, token: str, where: Path) -> tuple[str, urllib.request.Request]:
    """A setup step's file as a client of the server's protocols sends it: a graph's file by the Graph
    Store Protocol (``POST /store?graph=.../graph/NAME``; a component's description into graph/services,
    as ``cbrs register`` puts it), an update to ``/update``; with what it is sent to."""
    path = _edited(step, where)
    if step.verb == "update":
        target, media = "/update", "application/sparql-update"
    else:
        graph = "services" if step.verb == "register" else step.verb
        target = "/store?" + urllib.parse.urlencode({"graph": f"https://w3id.org/cbrs/graph/{graph}"})
        media = MEDIA.get(path.suffix, "text/turtle")
    headers = {"Authorization": f"Bearer {token}", "Content-Type": media}
    return f"POST {target.split('?')[0]} {step.file}", urllib.request.Request(
        url + target, path.read_bytes(), headers, method="POST"
    )


def _post_step(url: str, step: Step, token: str, where: Path) -> None:
    """Send a setup step's file to the server (:func:`_post_request`); RuntimeError unless accepted."""
    said, request = _post_request(url, step, token, where)
    try:
        with urllib.request.urlopen(request, timeout=60):
            return
    except urllib.error.HTTPError as error:
        raise RuntimeError(f"{said}: {error.code} {error.read()[:300]!r}") from None


def _post_setup(trial: Trial, url: str, token: str, where: Path, made: Made) -> None:
    """The trial's setup sent to the server in order: each file posted (an expected refusal checked, its
    miss recorded in ``made``); via page, a requirement's file written on the New task page instead."""
    browser = _Browser(url)
    for step in trial.setup:
        if step.expect_refusal and trial.via == "page" and step.verb == "requirements":
            said, miss = editor_refusal(browser, step, token, where)
            made.checks.append(f"{trial.label}: {said}")
            if miss:
                made.deviations.append(f"{trial.label}: {miss}")
        elif step.expect_refusal:
            said, miss = post_refusal(url, step, token, where)
            made.checks.append(f"{trial.label}: {said}")
            if miss:
                made.deviations.append(f"{trial.label}: {miss}")
        elif trial.via == "page" and step.verb == "requirements":
            made.checks.append(f"{trial.label}: {_editor_save(browser, step, token, where)}")
        else:
            _post_step(url, step, token, where)


def dataset(url: str) -> tuple[str, dict[str, int]]:
    """The server's whole store (``GET /store`` as N-Quads): a digest of its sorted quads, and each
    graph's number of quads (what a refused file must leave as it was)."""
    import pyoxigraph as ox  # the bench's own process: the library cbrs reads its files with

    request = urllib.request.Request(url + "/store", headers={"Accept": "application/n-quads"})
    with urllib.request.urlopen(request, timeout=60) as answer:
        data = answer.read()
    lines = sorted(line for line in data.decode("utf-8").splitlines() if line.strip())
    sizes: dict[str, int] = {}
    for quad in ox.parse(data, ox.RdfFormat.N_QUADS):
        graph = quad.graph_name.value if isinstance(quad.graph_name, ox.NamedNode) else "(default)"
        sizes[graph] = sizes.get(graph, 0) + 1
    return hashlib.sha256("\n".join(lines).encode("utf-8")).hexdigest(), sizes


def post_refusal(url: str, step: Step, token: str, where: Path) -> tuple[str, str]:
    """Post a file the server must refuse: what it answered, and why that is not as the docs say (empty
    when it is): a 4xx (a 5xx is the server's fault, not the file's) whose message (with its notes) says
    the step's phrase and error class, and the store's digest the same before and after."""
    before = dataset(url)
    said, request = _post_request(url, step, token, where)
    try:
        with urllib.request.urlopen(request, timeout=60) as answer:
            status, body = answer.status, answer.read()
    except urllib.error.HTTPError as error:
        status, body = error.code, error.read()
    after = dataset(url)
    try:
        answered = json.loads(body)
    except json.JSONDecodeError:
        answered = {"message": body.decode("utf-8", "replace")}
    answered = answered if isinstance(answered, dict) else {"message": str(answered)}
    words = " ".join([str(answered.get("error", "")), str(answered.get("message", "")), *answered.get("notes", [])])
    line = f"{said}: {status}: {words.strip()[:300] or '(nothing said)'}"
    return line, refused_post_deviation(step, status, words, before, after, said)


def refused_post_deviation(
    step: Step,
    status: int,
    words: str,
    before: tuple[str, dict[str, int]],
    after: tuple[str, dict[str, int]],
    said: str = "",
) -> str:
    """Why a posted file's refusal is not as the docs say (empty when it is)."""
    if status < 400:
        return f"{said}: accepted ({status}), the docs say refused"
    misses = [f"answered {status}, a server error"] if status >= 500 else []
    misses += [f"without {word!r}" for word in (step.refused, step.says) if word and word not in words]
    if before[0] != after[0]:
        changed = sorted(g for g in set(before[1]) | set(after[1]) if before[1].get(g) != after[1].get(g))
        sizes = ", ".join(f"{g} {before[1].get(g, 0)} -> {after[1].get(g, 0)}" for g in changed)
        misses.append(f"the store changed: {sizes or 'the same sizes, other quads'}")
    return f"{said}: refused " + "; ".join(misses) + f": {words.strip()[:300]}" if misses else ""


def _answers(url: str, timeout: float) -> bool:
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        try:
            with urllib.request.urlopen(url, timeout=5):
                return True
        except (urllib.error.URLError, OSError):
            time.sleep(0.5)
    return False


def _served_runs(trial: Trial, index: int, store: Path, made: Made, node_modules: Path = NODE_MODULES) -> list[Outcome]:
    seed = trial.seeds[index]
    token = secrets.token_hex(16)
    env = {**os.environ, "CBRS_UPDATE_TOKEN": token}
    where = store.parent / f"{store.name}.edited"
    outcomes = []

    def prepare(url: str) -> None:
        if trial.post:
            _post_setup(trial, url, token, where, made)

    try:
        with _server(trial, store, env, prepare, node_modules) as (url, ws):
            if trial.forms and index == 0:  # the pages' GET forms read the store: once, at the first seed
                for said, miss in form_checks(_Browser(url), trial.forms):
                    made.checks.append(f"{trial.label}: {said}")
                    if miss:
                        made.deviations.append(f"{trial.label}: {miss}")
            for k, run in enumerate(trial.runs):
                started = time.perf_counter()
                if trial.via in STARTS:
                    found = _started_run(trial, k, seed, url, token, made)
                elif trial.via == "run_task":
                    found = _bridge_run(ws, run.task, seed, token)
                elif trial.via == "action":
                    found = _action_run(ws, run.task, seed, token)
                else:
                    args = ("run", run.task, "--bridge", ws, "--seed", str(seed), "--json")
                    try:
                        found = _parsed(_cbrs(url, *args, env=env, timeout=RUN_TIMEOUT))
                    except subprocess.TimeoutExpired:
                        found = {"status": "broken", "error": f"no answer in {RUN_TIMEOUT:.0f} s"}
                outcomes.append(_outcome(trial, k, index, seed, found, time.perf_counter() - started))
    except Skip as missing:  # a program this machine cannot start: no run made, none a deviation
        return skipped(trial, index, str(missing))
    except (RuntimeError, OSError) as failed:
        done = len(outcomes)
        for k in range(done, len(trial.runs)):
            outcomes.append(_outcome(trial, k, index, seed, {"status": "broken", "error": str(failed)}, 0.0))
        if not trial.runs:
            made.deviations.append(f"{trial.label}: broken: {failed}")
    return outcomes


def skipped(trial: Trial, index: int, why: str) -> list[Outcome]:
    """The trial's runs at its ``index``-th seed, skipped saying ``why``."""
    found = {"status": SKIPPED, "reason": why}
    outcomes = [_outcome(trial, k, index, trial.seeds[index], found, 0.0) for k in range(len(trial.runs))]
    for outcome in outcomes:
        outcome.status, outcome.reason = SKIPPED, why
    return outcomes


@dataclass(frozen=True)
class Started:
    """A run the server took: its id, where it is followed (its JSON, or its page), and the page the
    start answered (the tasks page again, with its form, for the form's runs)."""

    run: str
    where: str
    page: str = ""


def _started_run(trial: Trial, k: int, seed: int, url: str, token: str, made: Made) -> dict[str, Any]:
    """Start the trial's ``k``-th run (POST /tasks.json, or the tasks page's form), then, for two runs at
    once, the next run while it goes (checked in ``made``: refused, 409, saying the trial's phrase and
    naming the run going); follow the run until it ends (bounded): its result as ``cbrs run --json``."""
    task, browser = trial.runs[k].task, _Browser(url)
    try:
        begun = _page_start(browser, task, seed) if trial.via == "page" else _http_start(url, task, seed, token)
    except _NotStarted as refused:
        return {"status": "broken", "error": str(refused)[:300]}
    if trial.busy and k + 1 < len(trial.runs):
        said, miss = busy_check(trial, begun, trial.runs[k + 1].task, seed, browser, token)
        made.checks.append(f"{trial.label}, seed {seed}: {said}")
        if miss:
            made.deviations.append(f"{trial.label}, seed {seed}: {miss}")
    if trial.via == "page" and trial.stop is not None:
        said, miss, found = stop_run(browser, begun, trial.stop, token)
        made.checks.append(f"{trial.label}, seed {seed}: {said}")
        if miss:
            made.deviations.append(f"{trial.label}, seed {seed}: {miss}")
        return found
    if trial.via == "page":
        return _page_follow(browser, begun)
    return _http_follow(url, begun, token)


STEP_ROW = re.compile(r'<tr data-plan="\d+" data-step="\d+" class="step-(\w+)')


def stop_run(browser: _Browser, begun: Started, stop: StopAt, token: str) -> tuple[str, str, dict[str, Any]]:
    """Press the run's page's Stop this run once the page shows ``stop.after`` steps ended, follow the run
    to its end, then press the same button again: what the pages said, why that is not as the docs say
    (empty when it is: the button shown while the run goes, 303 to the run's page saying ``stop.says``, the run's result
    its steps taken then the rest pending, 409 saying ``stop.again`` and the run as it was), and the run
    as its page shows it."""
    deadline = time.monotonic() + RUN_TIMEOUT
    while True:
        page = browser.get(begun.where)
        badge = PAGE_STATUS.search(page.body)
        ended = sum(row in ("succeeded", "failed") for row in STEP_ROW.findall(page.body))
        if badge is None or badge.group(1) != "running" or ended >= stop.after or time.monotonic() > deadline:
            break
        time.sleep(0.25)
    said = f"Stop this run on {begun.where} after {ended} steps ended"
    if badge is None or badge.group(1) != "running":
        status = badge.group(1) if badge else "no status"
        return said, f"{said}: the run was {status} before {stop.after} steps ended", _page_follow(browser, begun)
    form = read_form(page.body, "cancel", page.url)
    misses = ["the Stop button is hidden while the run goes"] if form.hidden else []
    stopped = browser.submit(form)  # followed, as a browser follows it, to the run's page (303 since 2026-11-28)
    words = _element_text(stopped.body, "content")
    sent_on = stopped.status == 200 and urllib.parse.urlparse(stopped.url).path == begun.where
    if not (stopped.status == 202 or sent_on) or stop.says not in words:
        misses.append(
            f"Stop answered {stopped.status}, the docs say 303 to the run's page saying {stop.says!r}: "
            + _form_messages(stopped.body)
        )
    found = _page_follow(browser, begun)
    steps = _run_json(browser.url, begun.run, token).get("result", {}) or {}
    outcomes = [str(step.get("outcome")) for step in (steps.get("execution") or {}).get("steps", [])]
    taken = len(list(itertools.takewhile(lambda outcome: outcome != "pending", outcomes)))
    if found.get("status") == "cancelled" and (taken == len(outcomes) or set(outcomes[taken:]) != {"pending"}):
        misses.append(f"the cancelled run's steps are {outcomes}: the docs say the steps not taken are left pending")
    found["steps"] = taken
    again = browser.submit(form)
    after = PAGE_STATUS.search(browser.get(begun.where).body)
    if again.status != 409 or stop.again not in _element_text(again.body, "content"):
        misses.append(
            f"Stop again answered {again.status}, the docs say 409 saying {stop.again!r}: {_form_messages(again.body)}"
        )
    if after is None or after.group(1) != found.get("status"):
        misses.append(
            f"Stop again changed the run: {found.get('status')} -> {after.group(1) if after else 'no status'}"
        )
    line = (
        f"{said}: {303 if sent_on else stopped.status}, {found.get('status')} after {taken} of {len(outcomes)} steps; "
    )
    line += f"again {again.status}: {_form_messages(again.body)[:200]}"
    return line, f"{said}: " + "; ".join(misses) if misses else "", found


def _form_messages(page: str) -> str:
    """A page's message boxes (what a start, a stop or a save answered)."""
    found = re.findall(r'<p class="[^"]*(?:error-box|ok-box)[^"]*"[^>]*>(.*?)</p>', page, re.S)
    return " ".join(" ".join(html.unescape(re.sub(r"<[^>]+>", "", f)).split()) for f in found) or "(nothing said)"


def form_checks(browser: _Browser, forms: tuple[PageForm, ...]) -> list[tuple[str, str]]:
    """Submit the pages' GET forms in order as a browser does, each on its page (else on the page the one
    before answered): for each, what the page answered and why that is not as the docs say (empty when
    it is: its status, each phrase in its text and none it lacks)."""
    checks: list[tuple[str, str]] = []
    answer = Answer(0, browser.url, "")
    for check in forms:
        if check.page:
            answer = browser.get(check.page)
        where = urllib.parse.urlsplit(answer.url)
        said = f"{where.path}{'?' + where.query if where.query else ''}: the form {check.form!r}"
        try:
            form = find_form(answer.body, check.form, answer.url)
            for name, value in check.fill:
                form.set(name, value)
            for name, value in check.choose:
                form.choose(name, value)
        except (RuntimeError, _NotStarted) as failed:
            checks.append((f"{said}: {failed}", f"{said}: {failed}"))
            continue
        if form.method != "get":
            checks.append(
                (f"{said}: a {form.method.upper()} form", f"{said}: a {form.method.upper()} form, not a GET form")
            )
            continue
        answer = browser.submit(form)
        text = page_text(answer.body)
        title = re.search(r"<title>([^<]*)</title>", answer.body)
        sent = ", ".join(
            f"{name}={value[:60]}{'...' if len(value) > 60 else ''}" for name, value in form.fields if value
        )
        line = f"{said} ({sent}): {answer.status}, {html.unescape(title.group(1)) if title else 'no title'}"
        misses = [f"answered {answer.status}, the docs say {check.status}"] if answer.status != check.status else []
        misses += [f"without {phrase!r}" for phrase in check.says if phrase not in text]
        misses += [f"with {phrase!r}" for phrase in check.lacks if phrase in text]
        checks.append((line, f"{line}: " + "; ".join(misses) if misses else ""))
    return checks


class _NotStarted(RuntimeError):
    """The server did not take a start (its status and words)."""

    def __init__(self, said: str, status: int, words: str) -> None:
        self.status, self.words = status, words
        super().__init__(f"{said}: {status} {words[:300]}")


def _json_headers(token: str) -> dict[str, str]:
    return {"Authorization": f"Bearer {token}", "Content-Type": "application/json", "Accept": "application/json"}


def _http_start(url: str, task: str, seed: int, token: str) -> Started:
    """POST the task to ``/tasks.json`` as a program does (JSON, the update token): the run it started;
    :class:`_NotStarted` with the answer's status and words otherwise."""
    body = json.dumps({"task": task, "seed": seed}).encode()
    request = urllib.request.Request(url + "/tasks.json", body, _json_headers(token), method="POST")
    try:
        with urllib.request.urlopen(request, timeout=30) as answer:
            location = answer.headers["Location"]
    except urllib.error.HTTPError as error:
        raise _NotStarted(f"POST /tasks.json {task}", error.code, _words(error.read())) from None
    return Started(location.rsplit("/", 1)[-1].removesuffix(".json"), location)


def _http_follow(url: str, begun: Started, token: str) -> dict[str, Any]:
    """Poll the run's JSON until it ends (bounded): the run's result with its status."""
    deadline = time.monotonic() + RUN_TIMEOUT
    while time.monotonic() < deadline:
        request = urllib.request.Request(url + begun.where, headers=_json_headers(token))
        with urllib.request.urlopen(request, timeout=30) as answer:
            page = json.loads(answer.read())
        found = page.get("run", page)
        if found.get("status") != "running":
            return _ended(found)
        time.sleep(1.0)
    return {"status": "broken", "error": f"{begun.where} still running after {RUN_TIMEOUT:.0f} s"}


def _http_run(url: str, task: str, seed: int, token: str) -> dict[str, Any]:
    """POST the task to ``/tasks.json``, poll the run's JSON until it ends (bounded): the run's result
    with its status, as ``cbrs run --json`` gives them."""
    try:
        return _http_follow(url, _http_start(url, task, seed, token), token)
    except _NotStarted as refused:
        return {"status": "broken", "error": str(refused)[:300]}


def busy_check(trial: Trial, begun: Started, task: str, seed: int, browser: _Browser, token: str) -> tuple[str, str]:
    """Start ``task`` while the run ``begun`` goes, as the trial's runs are started: what the server
    answered, and why that is not as the docs say (empty when it is): refused with 409, saying the trial's
    phrase and the run going. A start taken after the run had ended is said so (the race was lost: the
    first run was too short to start another beside it)."""
    sent = time.time()
    if trial.via == "page":
        said = f"the tasks page's Start with {task} while {begun.run} goes"
        try:
            taken = _page_start(browser, task, seed, begun.page)
            status, words = 202, f"started {taken.run}"
        except _NotStarted as refused:
            status, words = refused.status, refused.words
    else:
        said = f"POST /tasks.json {task} while {begun.run} goes"
        try:
            taken = _http_start(browser.url, task, seed, token)
            status, words = 202, f"started {taken.run}"
        except _NotStarted as refused:
            status, words = refused.status, refused.words
    line = f"{said}: {status}: {words[:300] or '(nothing said)'}"
    ended = _run_json(browser.url, begun.run, token).get("finished") if status != 409 else None
    return line, busy_deviation(said, status, words, trial.busy, begun.run, bool(ended and ended < sent))


def busy_deviation(said: str, status: int, words: str, phrase: str, running: str, ended_before: bool) -> str:
    """Why the answer to a start sent while ``running`` goes is not as the docs say (empty when it is):
    409, saying ``phrase`` and naming the run going. ``ended_before``: that run had ended before the start
    was sent (the race lost: the bench's first run too short, no two at once)."""
    if status != 409:
        race = " (the first run had ended before it: no two at once)" if ended_before else ""
        return f"{said}: {status}, the docs say 409{race}: {words[:300]}"
    misses = [f"without {word!r}" for word in (phrase, running) if word not in words]
    return (f"{said}: 409 " + "; ".join(misses) + f": {words[:300]}") if misses else ""


def _run_json(url: str, run: str, token: str) -> dict[str, Any]:
    request = urllib.request.Request(f"{url}/tasks/{run}.json", headers=_json_headers(token))
    with urllib.request.urlopen(request, timeout=30) as answer:
        page = json.loads(answer.read())
    return dict(page.get("run", page))


def _words(body: bytes) -> str:
    """What an answer says: a JSON error's message (and notes), else its text."""
    try:
        answered = json.loads(body)
    except json.JSONDecodeError:
        return body.decode("utf-8", "replace")
    if not isinstance(answered, dict):
        return str(answered)
    notes = [str(n) for n in answered.get("notes", [])]
    return " ".join([str(answered.get("error", "")), str(answered.get("message", "")), *notes]).strip()


@dataclass
class Form:
    """A page's form as a browser submits it: its named fields in order (a text input's value, a checked
    box, a select's chosen options or else its first, a textarea's text), each select's options, and its
    submit buttons (name and value); the ids of the elements inside it, and whether the page hides it."""

    id: str
    method: str
    action: str
    fields: list[list[str]] = field(default_factory=list)
    options: dict[str, list[str]] = field(default_factory=dict)
    buttons: list[tuple[str, str]] = field(default_factory=list)
    page: str = ""
    ids: set[str] = field(default_factory=set)
    hidden: bool = False

    def set(self, name: str, value: str) -> None:
        """Type ``value`` into the field ``name``; RuntimeError when the form has no such field."""
        for pair in self.fields:
            if pair[0] == name:
                pair[1] = value
                return
        raise RuntimeError(f"the form {self.id!r} of {self.page} has no field {name!r}")

    def choose(self, name: str, value: str) -> None:
        """Choose ``value`` in the select ``name``, as a person can: only an option the page offers."""
        offered = self.options.get(name)
        if offered is None:
            raise RuntimeError(f"the form {self.id!r} of {self.page} has no list {name!r}")
        if value not in offered:
            raise _NotStarted(f"the form {self.id!r} of {self.page}", 200, f"offers no {value!r} in {name!r}")
        self.fields = [pair for pair in self.fields if pair[0] != name] + [[name, value]]

    def chosen(self, name: str) -> list[str]:
        return [value for key, value in self.fields if key == name]


class _FormReader(html.parser.HTMLParser):
    """The forms of a page, read as a browser reads them to submit one (no script)."""

    def __init__(self, page: str) -> None:
        super().__init__(convert_charrefs=True)
        self.page = page
        self.forms: dict[str, Form] = {}
        self.all: list[Form] = []
        self._form: Form | None = None
        self._select: tuple[str, bool, list[str], list[str]] | None = None
        self._textarea: list[str] | None = None

    def handle_starttag(self, tag: str, attrs: list[tuple[str, str | None]]) -> None:
        a = {key: value or "" for key, value in attrs}
        if tag == "form":
            self._form = Form(a.get("id", ""), a.get("method", "get").lower(), a.get("action", ""), page=self.page)
            self._form.hidden = "hidden" in a
            self.forms.setdefault(self._form.id, self._form)  # the first of a page's forms without an id
            self.all.append(self._form)
            return
        if self._form is not None and a.get("id"):
            self._form.ids.add(a["id"])
        if self._form is None or "disabled" in a:
            return
        name, kind = a.get("name", ""), a.get("type", "text" if tag == "input" else "submit").lower()
        if tag in ("input", "button") and kind == "submit":
            if name:
                self._form.buttons.append((name, a.get("value", "")))
        elif tag == "input" and name and kind not in ("button", "reset", "image", "file"):
            if kind not in ("checkbox", "radio") or "checked" in a:
                self._form.fields.append([name, a.get("value", "on" if kind in ("checkbox", "radio") else "")])
        elif tag == "select" and name:
            self._select = (name, "multiple" in a, [], [])
        elif tag == "option" and self._select is not None:
            self._select[2].append(a.get("value", ""))
            if "selected" in a:
                self._select[3].append(a.get("value", ""))
        elif tag == "textarea" and name:
            self._textarea = [name, ""]

    def handle_data(self, data: str) -> None:
        if self._textarea is not None:
            self._textarea[1] += data

    def handle_endtag(self, tag: str) -> None:
        if tag == "textarea" and self._textarea is not None and self._form is not None:
            name, text = self._textarea
            self._form.fields.append([name, text.removeprefix("\n")])  # HTML drops the newline after the tag
            self._textarea = None
        elif tag == "select" and self._select is not None and self._form is not None:
            name, multiple, options, chosen = self._select
            chosen = chosen if multiple else (chosen[-1:] or options[:1])
            self._form.fields += [[name, value] for value in chosen]
            self._form.options[name] = options
            self._select = None
        elif tag == "form":
            self._form = None


def read_form(page: str, form_id: str, where: str = "the page") -> Form:
    """The form ``form_id`` of the HTML ``page``; RuntimeError when the page has none."""
    reader = _FormReader(where)
    reader.feed(page)
    if form_id not in reader.forms:
        raise RuntimeError(f"{where} has no form {form_id!r} (it has {sorted(reader.forms)})")
    return reader.forms[form_id]


def find_form(page: str, key: str, where: str = "the page") -> Form:
    """The form of the HTML ``page`` whose id is ``key``, else the one holding the element of id ``key`` (a
    form without an id of its own is found by its field, as a person finds it by its label); RuntimeError
    when the page has neither."""
    reader = _FormReader(where)
    reader.feed(page)
    if key in reader.forms:
        return reader.forms[key]
    for form in reader.all:
        if key in form.ids:
            return form
    held = sorted(i for form in reader.all for i in form.ids | {form.id} if i)
    raise RuntimeError(f"{where} has no form {key!r} nor one holding an element {key!r} (it has {held})")


def page_text(page: str) -> str:
    """What a person reads of a page's content (its main part, tags dropped, spaces collapsed)."""
    main = re.search(r'<main[^>]*id="content"[^>]*>(.*)</main>', page, re.S)
    text = re.sub(r"<(script|style)[^>]*>.*?</\1>", " ", main.group(1) if main else page, flags=re.S)
    return " ".join(html.unescape(re.sub(r"<[^>]+>", " ", text)).split())


def _element_text(page: str, element_id: str) -> str:
    """The text of the element ``element_id`` of ``page`` (tags dropped), empty when there is none."""
    found = re.search(rf'<(\w+)[^>]*\bid="{re.escape(element_id)}"[^>]*>(.*?)</\1>', page, re.S)
    return " ".join(html.unescape(re.sub(r"<[^>]+>", "", found.group(2))).split()) if found else ""


@dataclass
class Answer:
    status: int
    url: str
    body: str


class _Browser:
    """What the bench does of a browser on the server's pages: GET a page, submit a form form-encoded with
    the page's ``Origin`` and ``Referer`` (as a browser sends a form's POST: the pages' guard against
    another site's forms; they use no CSRF token), following redirects; no script runs."""

    def __init__(self, url: str) -> None:
        self.url = url

    def get(self, path: str) -> Answer:
        return self._open(urllib.request.Request(urllib.parse.urljoin(self.url, path), headers={"Accept": "text/html"}))

    def submit(self, form: Form, button: tuple[str, str] | None = None) -> Answer:
        if button is not None and button not in form.buttons:
            raise RuntimeError(f"the form {form.id!r} of {form.page} has no button {button!r}")
        fields = [(name, value) for name, value in form.fields] + ([button] if button else [])
        target = urllib.parse.urljoin(form.page, form.action or form.page)
        body = urllib.parse.urlencode(fields)
        if form.method != "post":
            return self._open(urllib.request.Request(f"{target}?{body}", headers={"Accept": "text/html"}))
        headers = {"Content-Type": "application/x-www-form-urlencoded", "Accept": "text/html"}
        headers |= {"Origin": self.url, "Referer": form.page}
        return self._open(urllib.request.Request(target, body.encode("ascii"), headers, method="POST"))

    def form(self, path: str, form_id: str) -> tuple[Answer, Form]:
        """GET the page ``path`` and read its form ``form_id``."""
        page = self.get(path)
        if page.status != 200:
            raise RuntimeError(f"GET {path}: {page.status}: {_element_text(page.body, 'content')[:300]}")
        return page, read_form(page.body, form_id, page.url)

    @staticmethod
    def _open(request: urllib.request.Request) -> Answer:
        try:
            with urllib.request.urlopen(request, timeout=60) as answer:
                return Answer(answer.status, answer.url, answer.read().decode("utf-8", "replace"))
        except urllib.error.HTTPError as error:
            return Answer(error.code, error.url or request.full_url, error.read().decode("utf-8", "replace"))


PAGE_STATUS = re.compile(r'id="run-status" class="badge status-([\w-]+)"')
PAGE_SECONDS = re.compile(r"; ([0-9.]+) s simulated")


def _page_start(browser: _Browser, task: str, seed: int, page: str = "") -> Started:
    """Start ``task`` from the tasks page's Start form (``page``: the one the browser shows, else GET
    /tasks): the task chosen from the list, the seed typed; the run the answer's message links to, or
    :class:`_NotStarted` with its status and the page's message."""
    form = read_form(page, "start", browser.url + "/tasks") if page else browser.form("/tasks", "start")[1]
    form.choose("task", task)
    form.set("seed", str(seed))
    answer = browser.submit(form)  # followed, as a browser follows it, to the run's page (303 since 2026-11-28)
    said = f"the tasks page's Start with {task}"
    sent_on = re.fullmatch(r"/tasks/(run-\d+)", urllib.parse.urlparse(answer.url).path)
    if answer.status == 200 and sent_on is not None:  # the start form is the tasks page's: the page to start again
        return Started(sent_on.group(1), sent_on.group(0), browser.get("/tasks").body)
    if answer.status != 202:
        words = _element_text(answer.body, "busy") or _form_errors(answer.body)
        raise _NotStarted(said, answer.status, words)
    link = re.search(r'started: .*?<a href="([^"]+)">its own page</a>', answer.body, re.S)
    if link is None:
        raise _NotStarted(said, answer.status, "no link to the run on the page")
    where = html.unescape(link.group(1))
    return Started(where.rsplit("/", 1)[-1], where, answer.body)


def _form_errors(page: str) -> str:
    """A page's messages: its alert boxes and the errors beside its fields."""
    found = re.findall(
        r'<(?:p|span)[^>]*class="[^"]*(?:error-box|field-error)[^"]*"[^>]*>(.*?)</(?:p|span)>', page, re.S
    )
    return " ".join(" ".join(html.unescape(re.sub(r"<[^>]+>", "", f)).split()) for f in found)


def _page_follow(browser: _Browser, begun: Started) -> dict[str, Any]:
    """Read the run's page each second until its status badge leaves running (bounded): the status and
    the simulated seconds as the page shows them (its verdict line), and the verdict as the reason."""
    deadline = time.monotonic() + RUN_TIMEOUT
    while time.monotonic() < deadline:
        page = browser.get(begun.where)
        badge = PAGE_STATUS.search(page.body)
        if page.status != 200 or badge is None:
            return {"status": "broken", "error": f"GET {begun.where}: {page.status}, no status badge"}
        if badge.group(1) != "running":
            verdict = _element_text(page.body, "verdict")
            seconds = PAGE_SECONDS.search(verdict)
            found: dict[str, Any] = {"status": badge.group(1), "reason": verdict, "error": verdict}
            return found | ({"sim_seconds": float(seconds.group(1))} if seconds else {})
        time.sleep(1.0)
    return {"status": "broken", "error": f"{begun.where} still running after {RUN_TIMEOUT:.0f} s"}


def _editor_save(browser: _Browser, step: Step, token: str, where: Path) -> str:
    """Write a requirement's file on the New task page as a person does: its text into the form, Check and
    plan (the page must show the task checked), then Save as task with the update token typed in its
    field (201, the page saying it saved), and the saved page's link to the tasks page followed (the task
    chosen in its Start form). What the pages said; RuntimeError when one is not as it should be."""
    text = _edited(step, where).read_text(encoding="utf-8")
    form = browser.form("/tasks/new", "task-form")[1]
    form.set("turtle", text)
    checked = browser.submit(form, ("action", "check"))
    said = f"New task page, {step.file}"
    if checked.status != 200 or 'id="task-name"' not in checked.body:
        raise RuntimeError(f"{said}: Check and plan: {checked.status}: {_form_errors(checked.body)[:300]}")
    planned = re.search(r"<title>New task: .*, ([\w -]+) · [^<]*</title>", checked.body)
    form = read_form(checked.body, "task-form", checked.url)
    if form.chosen("turtle") != [text]:
        raise RuntimeError(f"{said}: the checked page's editor does not hold the text sent")
    form.set("token", token)
    saved = browser.submit(form, ("action", "save"))
    link = re.search(r'<a id="run-link" href="([^"]+)"', saved.body)
    if saved.status != 201 or link is None:
        raise RuntimeError(f"{said}: Save as task: {saved.status}: {_form_errors(saved.body)[:300]}")
    name = re.search(r"(?:Saved|Replaced) <code>([^<]+)</code>", saved.body)
    chosen = browser.form(html.unescape(link.group(1)), "start")[1].chosen("task")
    saved_name = html.unescape(name.group(1)) if name else "?"
    if not chosen or not (saved_name.endswith(chosen[0].rpartition(":")[2]) or chosen[0] == saved_name):
        raise RuntimeError(f"{said}: the saved page's link chose {chosen} in the Start form, not {saved_name}")
    asked = _editor_asks(browser, saved_name)
    plan = html.unescape(planned.group(1)) if planned else "no plan status shown"
    return f"{said}: checked ({plan}), saved as {saved_name} (201), chosen on the tasks page; the SPARQL page: {asked}"


def _editor_asks(browser: _Browser, task: str) -> str:
    """Ask the SPARQL page's form (a GET form, read-only) whether graph:requirements now holds ``task``, as
    a person checks a save: the answer the page shows; RuntimeError unless it shows true."""
    if re.fullmatch(r"[A-Za-z][\w.-]*:[\w.-]+", task) and "://" not in task:
        term = task  # a prefixed name of cbrs's own, which the SPARQL page declares (req:FetchMyKeys)
    elif re.fullmatch(r"[^\s<>\"{}|^`\\]+", task):
        term = f"<{task}>"
    else:
        raise RuntimeError(f"the saved task {task!r} is neither an IRI nor a prefixed name to ask about")
    form = browser.form("/query", "sparql-form")[1]
    form.set("query", f"ASK {{ GRAPH <{REQUIREMENTS_GRAPH}> {{ {term} a <{REQUIREMENT}> }} }}")
    answer = browser.submit(form)
    shown = re.search(r'<p class="answer"><span class="badge \w+">(\w+)</span>', answer.body)
    if answer.status != 200 or shown is None or shown.group(1) != "true":
        raise RuntimeError(f"the SPARQL page asked for the saved {task}: {answer.status}, {shown and shown.group(1)}")
    return "ASK shows true"


def editor_refusal(browser: _Browser, step: Step, token: str, where: Path) -> tuple[str, str]:
    """Write a requirement's file the docs say is refused on the New task page: Check and plan, then Save
    as task with the token. What the pages said, and why that is not as the docs say (empty when it is):
    each a 4xx page whose messages beside the text say the step's phrase, the store's digest the same."""
    text = _edited(step, where).read_text(encoding="utf-8")
    before = dataset(browser.url)
    form = browser.form("/tasks/new", "task-form")[1]
    form.set("turtle", text)
    checked = browser.submit(form, ("action", "check"))
    form = read_form(checked.body, "task-form", checked.url)
    form.set("token", token)
    saved = browser.submit(form, ("action", "save"))
    after = dataset(browser.url)
    said = f"New task page, {step.file}"
    check_words, save_words = _form_errors(checked.body), _form_errors(saved.body)
    line = f"{said}: Check {checked.status}, Save {saved.status}: {save_words[:300] or '(nothing said)'}"
    misses = [
        miss
        for name, answer, words in (("Check", checked, check_words), ("Save", saved, save_words))
        if (miss := refused_post_deviation(step, answer.status, words, before, after, f"{said}, {name}"))
    ]
    misses += [f"{said}, Check: {miss}" for miss in misplaced_lines(checked.body, text)]
    return line, "; ".join(misses)


PROBLEM_LINE = re.compile(r'data-line="(\d+)">line \d+</a>: (?:<code>([^<]+)</code>)?')


def misplaced_lines(page: str, text: str) -> list[str]:
    """The editor's problems whose "line N" link does not point at a line of ``text`` that writes the term
    they name (outside a comment): where the page sends a person to mend it."""
    lines = text.splitlines()
    misses = []
    for number, term in PROBLEM_LINE.findall(page):
        term = html.unescape(term)
        line = lines[int(number) - 1] if 0 < int(number) <= len(lines) else ""
        code = "" if line.lstrip().startswith("#") else line.split(" #")[0]  # an IRI's # has no space before it
        if not term or term in code:
            continue
        misses.append(f"line {number} is not where {term} is written: {line.strip()[:120]!r}")
    return misses


def _ended(run: dict[str, Any]) -> dict[str, Any]:
    """A server's run that ended (its JSON, as /tasks/<id>.json and /cbrs/task_status give it): its result
    with its status and error, as ``cbrs run --json`` gives them."""
    result = dict(run.get("result") or {})
    result["status"] = run["status"]
    if run.get("error"):
        result["error"] = run["error"]
    return result


def _bridge_run(ws: str, task: str, seed: int, token: str) -> dict[str, Any]:
    """Call the bridge's ``/cbrs/run_task`` service (``wait``: it answers when the run ends or, for a long
    run, with the run going), then ``/cbrs/task_status`` each second until it ends (bounded), as a
    rosbridge client does after sending the update token (op ``auth``)."""
    from cbrs.bridge_client import BridgeClient  # the bench's own process: the client a lab's program uses

    deadline = time.monotonic() + RUN_TIMEOUT
    try:
        with BridgeClient(ws, token, timeout=60.0) as client:
            run = client.call_sync("/cbrs/run_task", {"task": task, "seed": seed})
            while run.get("status") == "running" and time.monotonic() < deadline:
                time.sleep(1.0)
                run = client.call_sync("/cbrs/task_status", {"run": run["id"]})
    except Exception as error:  # refused, or the bridge gone: the run's JSON cannot be read
        return {"status": "broken", "error": f"/cbrs/run_task: {type(error).__name__}: {error}"[:300]}
    if run.get("status") == "running":
        return {"status": "broken", "error": f"{run.get('id')} still running after {RUN_TIMEOUT:.0f} s"}
    return _ended(run)


def _action_run(ws: str, task: str, seed: int, token: str) -> dict[str, Any]:
    """Send the bridge's ``/cbrs/run_task`` action a goal, as a ROS 2 client through rosbridge does (the op
    ``auth`` with the token, then ``send_action_goal`` with feedback), and read messages until its result
    (bounded): the run as the result's values give it, its feedback counted (one a plan step that ended)."""
    from websockets.sync.client import connect

    goal: dict[str, Any] = {"op": "send_action_goal", "id": "sweep-goal", "action": "/cbrs/run_task"}
    goal |= {"action_type": "cbrs/action/RunTask", "args": {"task": task, "seed": seed}, "feedback": True}
    deadline = time.monotonic() + RUN_TIMEOUT
    feedback = 0
    try:
        with connect(ws, open_timeout=30, max_size=None) as socket_:
            socket_.send(json.dumps({"op": "auth", "mac": token}))
            socket_.send(json.dumps(goal))
            while time.monotonic() < deadline:
                message = json.loads(socket_.recv(timeout=max(1.0, deadline - time.monotonic())))
                if message.get("op") == "action_feedback" and message.get("id") == goal["id"]:
                    feedback += 1
                elif message.get("op") == "action_result" and message.get("id") == goal["id"]:
                    break
                elif message.get("op") == "status" and message.get("level") == "error":
                    return {"status": "broken", "error": f"/cbrs/run_task action: {message.get('msg')}"[:300]}
            else:
                return {"status": "broken", "error": f"no action result in {RUN_TIMEOUT:.0f} s"}
    except Exception as error:  # the bridge gone or the socket's wait over: the run cannot be read
        return {"status": "broken", "error": f"/cbrs/run_task action: {type(error).__name__}: {error}"[:300]}
    run = message.get("values")
    if not message.get("result") or not isinstance(run, dict) or "status" not in run:
        return {"status": "broken", "error": f"/cbrs/run_task action refused: {str(run)[:300]}"}
    return {**_ended(run), "feedback": feedback}


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
    """Why the outcome is not what the docs say (empty when it is); a skipped run is none."""
    if outcome.status == SKIPPED:
        return ""
    if outcome.status != outcome.expected:
        return f"{outcome.status}, the docs say {outcome.expected}"
    if not outcome.said:
        return f"{outcome.status} without {outcome.expected_says!r}, which the docs say"
    if outcome.expected_steps is not None and outcome.steps != outcome.expected_steps:
        return f"{outcome.steps} steps, the docs say {outcome.expected_steps}"
    off = abs(outcome.seconds - outcome.expected_seconds)
    if outcome.status == "succeeded" and outcome.expected_seconds and off > tolerance:
        return f"{outcome.seconds:.1f} s simulated, the docs say {outcome.expected_seconds:.1f} s"
    if outcome.status == "succeeded" and outcome.expected_between:
        low, high = outcome.expected_between
        if not low - tolerance <= outcome.seconds <= high + tolerance:
            return f"{outcome.seconds:.1f} s simulated, the docs say {low:.1f}-{high:.1f} s"
    return ""


def commit() -> str:
    """The checkout's commit, marked when tracked files differ from it."""
    head = subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=ROOT, capture_output=True, text=True)
    if head.returncode != 0:
        return "unknown (not a git checkout)"
    status = ["git", "status", "--porcelain", "--untracked-files=no"]
    dirty = subprocess.run(status, cwd=ROOT, capture_output=True, text=True)
    return head.stdout.strip() + (" (with uncommitted changes)" if dirty.stdout.strip() else "")


def _run_all(
    trials: list[Trial], scratch: Path, jobs: int, node_modules: Path = NODE_MODULES
) -> tuple[list[Outcome], list[str], Made]:
    """Every trial's store made, then its seeds run, up to ``jobs`` processes at once; a trial this
    machine cannot run (:func:`skip_reason`) skipped, saying why."""
    outcomes: list[Outcome] = []
    broken: list[str] = []
    loads = Made()
    total = sum(len(t.seeds) * len(t.runs) for t in trials)
    for trial in trials:
        if why := skip_reason(trial, node_modules):
            outcomes += [o for k in range(len(trial.seeds)) for o in skipped(trial, k, why)]
            print(f"[{len(outcomes)}/{total}] {trial.label}: skipped: {why}", file=sys.stderr, flush=True)
    trials = [t for t in trials if not skip_reason(t, node_modules)]
    with concurrent.futures.ThreadPoolExecutor(max_workers=max(1, jobs)) as pool:
        made = {pool.submit(make_store, t, scratch / f"t{i}" / "made"): (i, t) for i, t in enumerate(trials)}
        runs: dict[concurrent.futures.Future[list[Outcome]], Made] = {}
        for future in concurrent.futures.as_completed(made):
            i, trial = made[future]
            try:
                found = future.result()
            except RuntimeError as failed:
                broken.append(str(failed))
                continue
            loads.checks += found.checks
            loads.deviations += found.deviations
            # a posted refusal or the pages' forms alone are checked at the server once, at the first seed
            for k in range(len(trial.seeds) if trial.runs else int(trial.post or bool(trial.forms))):
                store = scratch / f"t{i}" / f"seed{trial.seeds[k]}"
                shutil.copytree(scratch / f"t{i}" / "made", store)
                served = Made()
                runs[pool.submit(run_one, trial, k, store, served, node_modules)] = served
        for ran in concurrent.futures.as_completed(runs):
            loads.checks += runs[ran].checks
            loads.deviations += runs[ran].deviations
            for got in ran.result():
                outcomes.append(got)
                said = f"{got.label}, seed {got.seed}: {got.status}, {got.seconds:.1f} s ({got.wall:.0f} s wall)"
                print(f"[{len(outcomes)}/{total}] {said}", file=sys.stderr, flush=True)
    return outcomes, broken, loads


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--data", type=Path, default=DATA, help="the expectations (TOML)")
    parser.add_argument("--only", nargs="+", metavar="NAME", help="only the trials of these labels or tasks")
    parser.add_argument("--jobs", type=int, default=os.cpu_count() or 1, help="runs at once (default: the cores)")
    parser.add_argument("--json", type=Path, help="write the record here")
    parser.add_argument("--keep", type=Path, help="make the stores under DIR and keep them (default: a temporary one)")
    parser.add_argument(
        "--node-modules",
        type=Path,
        default=NODE_MODULES,
        help="the modules a Node program imports, roslib among them (default: tests/js/node_modules)",
    )
    args = parser.parse_args()
    tolerance, trials = read_trials(args.data)
    if args.only:
        trials = [t for t in trials if t.label in args.only or any(r.task in args.only for r in t.runs)]
        if not trials:
            raise SystemExit(f"no trial is labelled or runs {', '.join(args.only)}")
    load = os.getloadavg()[0]
    print(
        f"machine: {platform.platform()}, {os.cpu_count()} cores, python {platform.python_version()}, "
        f"pybullet {importlib.metadata.version('pybullet')}, pyoxigraph {importlib.metadata.version('pyoxigraph')}; "
        f"load average at start {load:.2f}"
    )
    print(f"commit: {commit()}")
    runs_in_all = sum(len(t.seeds) * len(t.runs) for t in trials)
    refusals = sum(s.expect_refusal for t in trials for s in t.setup)
    posted = sum(s.expect_refusal for t in trials if t.post for s in t.setup)
    busy = sum(len(t.seeds) * (len(t.runs) - 1) for t in trials if t.busy)
    print(
        f"inputs: {len(trials)} trials, {runs_in_all} runs, {refusals} refusals at the load ({posted} sent to a "
        f"server), {busy} second starts while a run goes; {args.jobs} at once; tolerance {tolerance} s\n"
    )
    scratch = Path(tempfile.mkdtemp(prefix="example_tasks_")) if args.keep is None else args.keep
    scratch.mkdir(parents=True, exist_ok=True)
    started = time.perf_counter()
    try:
        outcomes, broken, loads = _run_all(trials, scratch, args.jobs, args.node_modules)
    finally:
        if args.keep is None:
            shutil.rmtree(scratch, ignore_errors=True)
    order = {t.label: i for i, t in enumerate(trials)}
    outcomes.sort(key=lambda o: (order.get(o.label.split(" [")[0], 0), o.seed, o.label))
    for outcome in outcomes:
        outcome.deviation = deviation(outcome, tolerance)
    if loads.checks:
        print("checks (refusals at the load and by the server, second starts, the New task page's saves):")
        for check in loads.checks:
            print(f"  {check}")
        print()
    width = max((len(o.label) for o in outcomes), default=10)
    head = f"{'trial':<{width}} {'seed':>4} {'expected':<10} {'found':<10} {'docs s':>6} {'sim s':>6} {'wall s':>6}"
    print(f"{head}  deviation")
    for o in outcomes:
        print(
            f"{o.label:<{width}} {o.seed:>4} {o.expected:<10} {o.status:<10} {o.expected_seconds:>6.1f} "
            f"{o.seconds:>6.1f} {o.wall:>6.1f}  {o.deviation}"
        )
    deviations = [o for o in outcomes if o.deviation]
    count = len(deviations) + len(loads.deviations)
    skips = sum(o.status == SKIPPED for o in outcomes)
    print(
        f"\n{len(outcomes) - skips} runs and {len(loads.checks)} checks in {time.perf_counter() - started:.0f} s"
        f"{f' ({skips} runs skipped)' if skips else ''}; {count} deviations"
    )
    known = {t.label for t in trials if t.known_failure}
    for o in deviations:
        mark = " (a known failure in the docs)" if o.label.split(" [")[0] in known else ""
        reason = f": {o.reason[:300]}" if o.reason else ""
        print(f"- {o.label}, seed {o.seed}: {o.deviation}{mark}{reason}")
    for message in loads.deviations:
        print(f"- {message}")
    for skip in sorted({f"{o.label.split(' [')[0]}: {o.reason}" for o in outcomes if o.status == SKIPPED}):
        print(f"- skipped, not a deviation: {skip}")
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
            "refusals": loads.checks,
            "refusal_deviations": loads.deviations,
            "broken": broken,
        }
        args.json.write_text(json.dumps(record, indent=2), encoding="utf-8")
    if deviations or broken or loads.deviations:
        sys.exit(1)


if __name__ == "__main__":
    main()
