"""The example sweep's data (bench/data/example_tasks.toml) parses, names only files of docs/examples/, and
covers every example file with a task: a new example without a sweep entry, or a left-out entry, fails
here rather than going unchecked (bench/example_tasks.py runs the trials; nothing is simulated here)."""

from __future__ import annotations

import importlib.util
import sys
import tomllib
from pathlib import Path
from types import ModuleType

import pytest

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = ROOT / "docs" / "examples"
DATA = ROOT / "bench" / "data" / "example_tasks.toml"
TASK_MARK = "cbrs:Requirement"
"""An example file states a task when it declares a requirement; a program under docs/examples/ serves
components or runs one."""


def _bench() -> ModuleType:
    spec = importlib.util.spec_from_file_location("example_tasks_bench", ROOT / "bench" / "example_tasks.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module  # its dataclasses look their module up by name
    spec.loader.exec_module(module)
    return module


@pytest.fixture(scope="module")
def bench() -> ModuleType:
    return _bench()


@pytest.fixture(scope="module")
def named(bench: ModuleType) -> set[str]:
    """Every file a trial of the data names: its setup steps, the steps between its runs, its program."""
    _, trials = bench.read_trials(DATA)
    found: set[str] = set()
    for trial in trials:
        found.update(step.file for step in trial.setup)
        found.update(step.file for run in trial.runs for step in run.before)
        if trial.serve is not None:
            found.add(trial.serve.program)
    return found


@pytest.fixture(scope="module")
def left_out() -> dict[str, str]:
    return dict(tomllib.loads(DATA.read_text("utf-8")).get("left_out", {}))


def _with_a_task() -> set[str]:
    found: set[str] = set()
    for path in EXAMPLES.rglob("*"):
        if path.suffix == ".py" or (path.suffix in (".ttl", ".ru") and TASK_MARK in path.read_text("utf-8")):
            found.add(path.relative_to(EXAMPLES).as_posix())
    return found


def test_the_data_parses_into_trials_with_runs_or_refusals(bench: ModuleType) -> None:
    tolerance, trials = bench.read_trials(DATA)
    assert tolerance > 0
    assert trials
    for trial in trials:
        assert trial.runs or any(step.expect_refusal for step in trial.setup), trial.label


def test_every_file_named_exists_under_docs_examples(named: set[str]) -> None:
    missing = sorted(name for name in named if not (EXAMPLES / name).is_file())
    assert missing == []


def test_every_example_with_a_task_is_swept_or_left_out_by_name(named: set[str], left_out: dict[str, str]) -> None:
    unswept = sorted(_with_a_task() - named - set(left_out))
    assert unswept == [], "add a trial to bench/data/example_tasks.toml, or the file to its [left_out] with why"


def test_a_left_out_file_exists_and_is_not_also_swept(named: set[str], left_out: dict[str, str]) -> None:
    assert all(why.strip() for why in left_out.values())
    assert sorted(n for n in left_out if not (EXAMPLES / n).is_file()) == []
    assert sorted(set(left_out) & named) == []


def test_a_stale_substitution_and_an_unknown_status_are_refused(bench: ModuleType, tmp_path: Path) -> None:
    bad_status = tmp_path / "status.toml"
    bad_status.write_text(
        '[[trial]]\nlabel = "x"\ntask = "FetchMyBottle"\nsetup = [["map", "water_bottle.ttl"]]\n'
        'seeds = [0]\nstatus = ["fine"]\nseconds = [0]\n',
        encoding="utf-8",
    )
    with pytest.raises(SystemExit, match="unknown status"):
        bench.read_trials(bad_status)
    step = bench.Step("map", "water_bottle.ttl", (("no such text in the file", "x"),))
    with pytest.raises(RuntimeError, match="not in the file"):
        bench._edited(step, tmp_path)


def test_a_range_the_docs_give_is_read_and_compared(bench: ModuleType) -> None:
    _, trials = bench.read_trials(DATA)
    ranged = [run for trial in trials for run in trial.runs if run.between is not None]
    assert ranged, "no trial of the data gives a range"
    low, high = ranged[0].between
    inside = bench.Outcome("x", "T", 0, "succeeded", 0.0, "succeeded", (low + high) / 2, 1.0, "", "", (low, high))
    outside = bench.Outcome("x", "T", 0, "succeeded", 0.0, "succeeded", high + 1.0, 1.0, "", "", (low, high))
    assert bench.deviation(inside, 0.2) == ""
    assert "the docs say" in bench.deviation(outside, 0.2)
