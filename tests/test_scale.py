"""Behaviour that keeps cbrs fast at start-up and at scale (issue 18); the figures are in bench/."""

from __future__ import annotations

import importlib
import subprocess
import sys

import click
import pytest
from click.testing import CliRunner

from cbrs.cli import _LAZY_COMMANDS, cli

# -- start-up ------------------------------------------------------------------------------------


def _imported_after(statement: str, modules: tuple[str, ...]) -> list[str]:
    """The ``modules`` a fresh interpreter has imported after running ``statement``."""
    code = f"import sys\n{statement}\nprint(' '.join(m for m in {modules!r} if m in sys.modules))"
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    return done.stdout.split()


def test_the_cli_imports_no_heavy_library() -> None:
    heavy = ("numpy", "networkx", "sklearn", "scipy", "werkzeug", "actions", "reasoner")
    assert _imported_after("import cbrs.cli", heavy) == []


def test_the_reasoner_loads_scikit_learn_and_numpy_only_when_ranking() -> None:
    assert _imported_after("import reasoner, actions", ("sklearn", "scipy", "numpy")) == []


@pytest.mark.parametrize("name", sorted(_LAZY_COMMANDS))
def test_a_lazy_command_is_listed_with_its_own_help(name: str) -> None:
    module, attribute, text = _LAZY_COMMANDS[name]
    command = getattr(importlib.import_module(module), attribute)
    assert command.name == name
    stand_in = click.Command(name, help=text)
    for limit in (20, 45, 70, 200):
        assert stand_in.get_short_help_str(limit) == command.get_short_help_str(limit)


def test_help_lists_every_command_and_each_lazy_one_runs() -> None:
    listed = CliRunner().invoke(cli, ["--help"]).output
    for name in _LAZY_COMMANDS:
        assert f"\n  {name} " in listed
        shown = CliRunner().invoke(cli, [name, "--help"])
        assert shown.exit_code == 0, shown.output
        assert f"Usage: cli {name}" in shown.output
