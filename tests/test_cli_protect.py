"""``cbrs plan`` and ``cbrs run`` --protect/--no-protect and --max-reachieved (ComposeConfig.protect and
max_reachieved), on the decomposed task of tests/test_progression_joined.py: stowing the object takes the
robot from the shelf, where switching the lamp on, the next sub-action, needs it."""

from __future__ import annotations

import json
from collections.abc import Iterator
from contextlib import contextmanager
from typing import Any

import pytest
from click.testing import CliRunner, Result

from cbrs.actions.composer import ComposeConfig
from cbrs.app import App
from cbrs.cli_actions import plan, run
from cbrs.kb import KnowledgeBase
from tests.test_composition import EX
from tests.test_progression_joined import DECOMPOSED, _store


@pytest.fixture(scope="module")
def apps(tmp_path_factory: pytest.TempPathFactory) -> Iterator[dict[bool, App]]:
    """The store with and without a component that takes the robot back to the shelf."""
    stores = {reachieve: _store(tmp_path_factory.mktemp("cli"), DECOMPOSED, reachieve) for reachieve in (True, False)}
    yield {reachieve: App(":memory:", kb) for reachieve, kb in stores.items()}
    for kb in stores.values():
        kb.close()


def _plan(app: App, *options: str) -> Result:
    return CliRunner().invoke(plan, [EX + "Req", "--no-store", "--json", *options], obj=app)


def _steps(result: Result) -> list[str]:
    return [step["component"].removeprefix(EX) for step in json.loads(result.output)["steps"]]


def test_plan_protects_by_default_and_no_protect_gives_the_plan_as_extracted(apps: dict[bool, App]) -> None:
    protected = _plan(apps[True])
    assert protected.exit_code == 0, protected.output
    assert _steps(protected) == ["PutAway", "GoToShelf", "SwitchOn"]
    unprotected = _plan(apps[True], "--no-protect")
    assert unprotected.exit_code == 0, unprotected.output
    assert _steps(unprotected) == ["PutAway", "SwitchOn"]


def test_a_refused_plan_names_the_flag_that_would_let_it_through(apps: dict[bool, App]) -> None:
    refused = CliRunner().invoke(plan, [EX + "Req", "--no-store"], obj=apps[False])
    assert refused.exit_code == 1
    assert f"is deleted by {EX}PutAway before it is needed" in refused.output
    assert "cbrs plan or cbrs run --no-protect" in refused.output
    assert _plan(apps[False], "--no-protect").exit_code == 0


def test_max_reachieved_bounds_the_statements_achieved_again(apps: dict[bool, App]) -> None:
    refused = CliRunner().invoke(plan, [EX + "Req", "--no-store", "--max-reachieved", "0"], obj=apps[True])
    assert refused.exit_code == 1
    assert "--max-reachieved N" in refused.output
    assert _plan(apps[True], "--max-reachieved", "1").exit_code == 0


@pytest.mark.parametrize("command", [plan, run], ids=["plan", "run"])
def test_a_negative_max_reachieved_is_refused_before_anything_is_read(command: Any) -> None:
    result = CliRunner().invoke(command, ["FetchMyPen", "--max-reachieved", "-1"])
    assert result.exit_code == 2
    assert "Invalid value for '--max-reachieved': -1 is not in the range x>=0" in result.output


def test_run_composes_with_the_options_given(apps: dict[bool, App], monkeypatch: pytest.MonkeyPatch) -> None:
    """``cbrs run`` hands them to the composer of the run (the world and the run itself are stand-ins)."""
    import cbrs.cli_actions
    import cbrs.kb.semantic_map
    import cbrs.sim.components
    import cbrs.sim.world
    import cbrs.tasks

    class Composed(Exception):
        pass

    class World:
        time = 0.0

    @contextmanager
    def open_world(**_: Any) -> Iterator[World]:
        yield World()

    seen: list[ComposeConfig] = []

    def run_task(kb: KnowledgeBase, iri: str, *_: Any, composer: Any, **__: Any) -> None:
        seen.append(composer.config)
        raise Composed

    monkeypatch.setattr(cbrs.sim.world, "open_world", open_world)
    monkeypatch.setattr(cbrs.kb.semantic_map.SemanticMap, "read", staticmethod(lambda kb: None))
    monkeypatch.setattr(cbrs.sim.components, "SimEnvironment", lambda *_: type("Env", (), {"registry": {}})())
    monkeypatch.setattr(cbrs.cli_actions, "run_task", run_task)
    # the lab's components have no simulated skill, so the check before the world is built would refuse
    # the task: it composes with the run's composer, and goes on here
    monkeypatch.setattr(cbrs.tasks, "refusal_in_home", lambda *_: None)
    for options, expected in (
        ([], (True, ComposeConfig().max_reachieved)),
        (["--no-protect", "--max-reachieved", "3"], (False, 3)),
    ):
        result = CliRunner().invoke(run, [EX + "Req", *options], obj=apps[True])
        assert isinstance(result.exception, Composed), result.output
        assert (seen[-1].protect, seen[-1].max_reachieved) == expected
