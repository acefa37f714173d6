"""The example sweep's data (bench/data/example_tasks.toml) parses, names only files of docs/examples/, and
covers every example file with a task: a new example without a sweep entry, or a left-out entry, fails
here rather than going unchecked (bench/example_tasks.py runs the trials; nothing is simulated here)."""

from __future__ import annotations

import importlib.util
import re
import shutil
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
    """Every file a trial of the data names: its setup steps, the steps between its runs, its programs."""
    _, trials = bench.read_trials(DATA)
    found: set[str] = set()
    for trial in trials:
        found.update(step.file for step in trial.setup)
        found.update(step.file for run in trial.runs for step in run.before)
        found.update(serve.program for serve in trial.serve)
        if trial.library is not None:
            found.add(trial.library.program)
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


def test_the_data_parses_into_trials_with_runs_forms_or_refusals(bench: ModuleType) -> None:
    tolerance, trials = bench.read_trials(DATA)
    assert tolerance > 0
    assert trials
    for trial in trials:
        assert trial.runs or trial.forms or any(step.expect_refusal for step in trial.setup), trial.label


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


def test_the_forms_beyond_the_command_line_each_have_a_trial(bench: ModuleType) -> None:
    """A library program, several programs at once, runs over /cbrs/run_task (the service with programs
    and without, the action), files posted to the server (taken and refused), two runs at once and the
    browser's forms (the Start form, the New task page saving and refusing) are each swept: the header's
    forms are used."""
    _, trials = bench.read_trials(DATA)
    assert any(t.via == "library" and t.library is not None for t in trials)
    assert any(t.via == "bridge" and len(t.serve) > 1 for t in trials)
    assert any(t.via == "run_task" and t.serve for t in trials)
    assert any(t.via == "run_task" and not t.serve for t in trials)
    assert any(t.post and t.via == "http" for t in trials)
    assert any(t.via == "action" for t in trials)
    assert any(t.busy and t.via == "http" for t in trials) and any(t.busy and t.via == "page" for t in trials)
    assert any(t.post and any(s.expect_refusal for s in t.setup) for t in trials if t.via == "http")
    assert any(t.via == "page" and t.post and any(s.verb == "requirements" for s in t.setup) for t in trials)
    assert any(t.via == "page" and any(s.expect_refusal and s.verb == "requirements" for s in t.setup) for t in trials)
    assert any(serve.program.endswith(".mjs") for t in trials for serve in t.serve)  # a Node program
    assert any(t.stop is not None for t in trials) and any(t.forms for t in trials)
    assert any(run.says for t in trials for run in t.runs) and any(run.steps for t in trials for run in t.runs)


@pytest.mark.parametrize(
    ("row", "said"),
    [
        pytest.param('library = { program = "lab7_where_is_my_pen.py" }\nvia = "cli"', "runs via library", id="via"),
        pytest.param(
            'library = { program = "lab7_where_is_my_pen.py" }\nserve = { program = "lab6_kettle.py" }',
            "runs alone",
            id="served",
        ),
        pytest.param(
            'library = { program = "no_such_program.py" }', "no file docs/examples/no_such_program.py", id="missing"
        ),
        pytest.param(
            'serve = [{ program = "lab6_kettle.py" }, { program = "no_such_speaker.py" }]',
            "no file docs/examples/no_such_speaker.py",
            id="second-program",
        ),
        pytest.param('via = "run_tasks"', "unknown via 'run_tasks'", id="unknown-via"),
        pytest.param('post = true\nvia = "cli"', "its runs must go to one", id="posted-to-no-server"),
        pytest.param(
            'post = true\nvia = "http"\nsetup = [{ load = "map", file = "lab8_mistake_apple.ttl", replace = true }]',
            "(no replace)",
            id="posted-replace",
        ),
        pytest.param('busy = "one task runs at a time"\nvia = "http"', "two runs or more", id="busy-one-run"),
        pytest.param('stop = { after = 1, says = "a", again = "b" }\nvia = "http"', "(via page)", id="stop-by-http"),
        pytest.param(
            'stop = { after = 1, says = "a", again = "b" }\nvia = "page"', "ends cancelled", id="stop-succeeded"
        ),
        pytest.param('via = "page"\nforms = [{ form = "q" }]', "the first form's page", id="form-without-page"),
        pytest.param("steps = [1, 2]", "steps, one number a seed", id="steps-per-seed"),
        pytest.param(
            'busy = "one task runs at a time"\nvia = "run_task"\nruns = [{ task = "A", status = ["succeeded"], '
            'seconds = [0] }, { task = "B", status = ["succeeded"], seconds = [0] }]',
            "via http or page",
            id="busy-over-the-bridge",
        ),
    ],
)
def test_a_form_the_bench_cannot_run_as_written_is_refused(
    bench: ModuleType, tmp_path: Path, row: str, said: str
) -> None:
    data = tmp_path / "forms.toml"
    setup = "" if "setup =" in row else "setup = []\n"
    data.write_text(
        '[[trial]]\nlabel = "x"\ntask = "WhereIsMyPen"\nseeds = [0]\nstatus = ["succeeded"]\n'
        f"seconds = [0.7]\n{setup}{row}\n",
        encoding="utf-8",
    )
    with pytest.raises(SystemExit, match=re.escape(said)):
        bench.read_trials(data)


def test_a_run_s_json_from_the_server_or_a_library_program_is_read_as_cbrs_run_s(bench: ModuleType) -> None:
    """/tasks/<id>.json and /cbrs/task_status give the run with its result inside; the library program
    prints its outcome: both are read into the statuses the data gives."""
    trial = bench.Trial("x", "", [], [0], [bench.Run("T", ["refused"], [0.0])], via="run_task")
    ended = bench._ended({"status": "error", "error": "a precondition does not hold", "result": None})
    assert ended == {"status": "error", "error": "a precondition does not hold"}
    assert bench._outcome(trial, 0, 0, 0, ended, 1.0).status == "refused"
    served = bench._ended({"status": "no-plan", "result": {"sim_seconds": 0.0, "plan": {"reason": "none"}}})
    assert bench._outcome(trial, 0, 0, 0, served, 1.0).status == "no plan"


def test_a_node_program_runs_from_a_copy_beside_its_modules(bench: ModuleType, tmp_path: Path) -> None:
    """A Node program is started by node from a copy with node_modules and the example files beside it
    (an ES module finds its imports there, not by NODE_PATH), its bridge's URL where its args say; a
    Python program takes --bridge first. Without roslib the trial is skipped, saying where it looked."""
    modules = tmp_path / "modules"
    (modules / "roslib").mkdir(parents=True)
    node = bench.Serve("lab10_lamp_switch.mjs", ("{bridge}", "--answer", "text"))
    if shutil.which("node") is None:
        with pytest.raises(bench.Skip, match="node is not installed"):
            node.argv("ws://127.0.0.1:9", tmp_path / "copy", modules)
    else:
        argv = node.argv("ws://127.0.0.1:9", tmp_path / "copy", modules)
        assert argv[1:] == [str(tmp_path / "copy" / "lab10_lamp_switch.mjs"), "ws://127.0.0.1:9", "--answer", "text"]
        assert (tmp_path / "copy" / "node_modules").resolve() == modules.resolve()
        assert (tmp_path / "copy" / "lab10_lamp_switch.ttl").resolve() == EXAMPLES / "lab10_lamp_switch.ttl"
        assert not (tmp_path / "copy" / "lab10_lamp_switch.mjs").is_symlink()  # a copy: its imports resolve here
        other = bench.Serve("lab10_lamp_switch.mjs").argv("ws://127.0.0.1:9", tmp_path / "two", modules)
        (tmp_path / "two" / "lab10_lamp_switch.mjs").unlink()
        (tmp_path / "two" / "lab10_lamp_switch.mjs").symlink_to(EXAMPLES / "lab10_lamp_switch.mjs")
        assert bench.Serve("lab10_lamp_switch.mjs").argv("ws://127.0.0.1:9", tmp_path / "two", modules) == other
        assert not (tmp_path / "two" / "lab10_lamp_switch.mjs").is_symlink()  # a second program's link replaced
    python = bench.Serve("lab6_kettle.py", ("--seconds", "5")).argv("ws://127.0.0.1:9", tmp_path / "py", modules)
    assert python[1:] == [str(EXAMPLES / "lab6_kettle.py"), "--bridge", "ws://127.0.0.1:9", "--seconds", "5"]
    run = bench.Run("SwitchOnTheReadingLamp", ["succeeded"], [0.3])
    trial = bench.Trial("lamp", "", [], [0], [run], via="bridge", serve=(node,))
    why = bench.skip_reason(trial, tmp_path / "nowhere")
    assert ("roslib is not in" in why and "nowhere" in why) or "node is not installed" in why
    assert bench.skip_reason(trial, modules) in (
        "",
        "node is not installed (the program runs on node >= 20 with roslib)",
    )
    (skipped,) = bench.skipped(trial, 0, why)
    assert skipped.status == bench.SKIPPED and skipped.reason == why and bench.deviation(skipped, 0.2) == ""


def test_a_runs_phrase_and_steps_are_read_from_its_json_and_compared(bench: ModuleType) -> None:
    """A run the docs quote must say their phrase, and take the steps they count, else a deviation."""
    run = bench.Run("T", ["failed", "failed"], [0.0, 0.0], says="did not answer within 10 s", steps=[1, 2])
    trial = bench.Trial("x", "", [], [0, 1], [run], via="bridge")
    steps = [{"outcome": "failed", "reason": "/plug did not answer within 10 s"}]
    found = {"status": "failed", "execution": {"steps": steps}, "reason": "step 1 failed"}
    first = bench._outcome(trial, 0, 0, 0, found, 1.0)
    assert (first.said, first.steps, first.expected_steps) == (True, 1, 1) and bench.deviation(first, 0.2) == ""
    second = bench._outcome(trial, 0, 1, 1, found, 1.0)
    assert bench.deviation(second, 0.2) == "1 steps, the docs say 2"
    quiet = bench._outcome(trial, 0, 0, 0, {"status": "failed", "execution": {"steps": []}}, 1.0)
    assert bench.deviation(quiet, 0.2) == "failed without 'did not answer within 10 s', which the docs say"
