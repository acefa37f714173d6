"""The error paths a new user of the ``cbrs`` command meets first: each is one line naming the bad input,
with a near miss offered where one is cheap to find, and a non-zero exit status. Throw-away stores."""

from __future__ import annotations

import json
from pathlib import Path

import click
import pytest
from click.testing import CliRunner

from cbrs.cli import cli

PENCIL = Path(__file__).parent / "data" / "tasks" / "pencil_on_the_table.ttl"
CAMERA3 = Path(__file__).resolve().parents[1] / "docs" / "examples" / "camera3.ttl"


def run(*args: str) -> tuple[int, str, str]:
    result = CliRunner().invoke(cli, ["--store", ":memory:", *args])
    assert not isinstance(result.exception, AssertionError | TypeError | AttributeError), result.exception
    return result.exit_code, result.stdout, result.stderr


def error_line(stderr: str) -> str:
    (line,) = [line for line in stderr.splitlines() if line.startswith("Error: ")]
    return line


def test_a_bare_name_is_offered_its_prefixed_names() -> None:
    for command in ("show", "deregister"):
        code, _, err = run(command, "LocateMobileRobot_CeilingCamera01")
        assert code == 2
        assert error_line(err).endswith(
            "'LocateMobileRobot_CeilingCamera01' has no prefix; did you mean svc:LocateMobileRobot_CeilingCamera01?"
        )
    code, _, err = run("show", "NoSuchThingAnywhere")  # nothing to offer: the prefixes it could take
    assert code == 2 and "neither an absolute IRI nor a prefixed name" in error_line(err)


@pytest.mark.parametrize(
    "args",
    [
        pytest.param(["show", "svc:Locate Mobile"], id="show"),
        pytest.param(["deregister", "svc:Locate Mobile"], id="deregister"),
        pytest.param(["match", "req:Robot Self"], id="match"),
    ],
)
def test_an_iri_with_a_space_is_named_as_typed(args: list[str]) -> None:
    code, _, err = run(*args)
    assert code == 2
    line = error_line(err)
    assert f"{args[1]!r} is not an IRI" in line and "code point ' '" in line
    assert "binding" not in line  # match said "binding description=...", a query's variable the user never typed


def test_a_named_query_without_its_parameter_says_the_bind_that_gives_it() -> None:
    code, out, err = run("query", "--name", "description")
    assert code == 1 and out == ""
    assert error_line(err).startswith("Error: query 'description' needs --bind description=IRI (")
    code, out, _ = run("query", "--name", "description", "--format", "json")
    assert code == 1 and json.loads(out)["exit_code"] == 1  # a script asked for JSON gets JSON


def test_a_misspelt_task_is_refused_with_its_near_names_and_json_stays_json() -> None:
    code, out, err = run("plan", "FetchMyPenn", "--json")
    assert code == 1
    refused = json.loads(out)  # what `cbrs plan ... --json | python -m json.tool` reads
    assert "did you mean FetchMyPen" in refused["error"] and refused["exit_code"] == 1
    assert "'FetchMyPenn'" in error_line(err)


@pytest.mark.parametrize(
    ("before", "after", "said"),
    [
        pytest.param(
            "a home:Pencil", "a hme:Pencil", "The prefix hme: has not been declared; did you mean home:?", id="use"
        ),
        pytest.param(
            "@prefix home:",
            "@prefix hom:",
            "The prefix home: has not been declared; declare it: @prefix home: <https://w3id.org/cbrs/home#> .",
            id="declaration",
        ),
    ],
)
def test_a_mistyped_prefix_in_a_file_is_named_with_the_fix(tmp_path: Path, before: str, after: str, said: str) -> None:
    text = PENCIL.read_text(encoding="utf-8")
    assert before in text
    typo = tmp_path / "pencil.ttl"
    typo.write_text(text.replace(before, after, 1), encoding="utf-8")
    code, out, err = run("load", "--graph", "map", str(typo))
    assert code == 1 and "loaded" not in out
    line = error_line(err)
    assert line.startswith(f"Error: {typo}:") and said in line


def test_a_file_that_breaks_otherwise_keeps_the_parser_s_words() -> None:
    code, _, err = run("load", str(Path(__file__).parent / "data" / "bad" / "broken.ttl"))
    assert code == 1 and error_line(err).endswith("Unexpected end of file")


def _commands() -> list[tuple[str, click.Command]]:
    """Every command and subcommand, lazy ones imported, by its name as typed."""
    context = click.Context(cli)
    found = []
    for name in cli.list_commands(context):
        command = cli.get_command(context, name)
        assert command is not None
        found.append((name, command))
        if isinstance(command, click.Group):
            found += [(f"{name} {sub}", command.commands[sub]) for sub in command.list_commands(context)]
    return found


def test_every_option_of_every_command_says_what_it_does() -> None:
    silent = [
        f"cbrs {name} {param.opts[0]}"
        for name, command in _commands()
        for param in command.params
        if isinstance(param, click.Option) and not param.hidden and not (param.help or "").strip()
    ]
    assert silent == []


def test_the_help_that_names_another_option_names_one_that_exists() -> None:
    """``cbrs eval paper --help`` said "--params lists them", an option only cbrs match has."""
    commands = dict(_commands())
    for name, command in commands.items():
        options = {opt for param in command.params for opt in param.opts}
        for param in command.params:
            if isinstance(param, click.Option) and "--params lists" in (param.help or ""):
                assert "cbrs match --params" in (param.help or "") or "--params" in options, name
    assert run("match", "--params")[0] == 0


def test_a_component_file_with_a_mistyped_prefix_is_named_with_the_fix(tmp_path: Path) -> None:
    text = CAMERA3.read_text(encoding="utf-8")
    typo = tmp_path / "camera.ttl"
    typo.write_text(text.replace("home:RobotLocation", "hme:RobotLocation", 1), encoding="utf-8")
    code, out, err = run("register", str(typo))
    assert code == 1 and "registered" not in out
    assert "The prefix hme: has not been declared; did you mean home:?" in error_line(err)


def test_a_home_drawing_is_refused_a_name_of_another_format(tmp_path: Path) -> None:
    code, _, err = run("home", "--draw", str(tmp_path / "home.png"))
    assert code == 2 and "'home.png' must end in .svg" in error_line(err)
    assert not (tmp_path / "home.png").exists()


def test_a_mistyped_fail_is_refused_with_its_near_names_before_the_world_is_built(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    pytest.importorskip("pybullet")
    import cbrs.sim.world

    def no_world(*args: object, **kwargs: object) -> None:
        raise RuntimeError("the world was built for a run refused by its options")

    monkeypatch.setattr(cbrs.sim.world, "open_world", no_world)
    code, _, err = run("run", "FetchMyPen", "--fail", "svc:LocateMobileRobot_CeilingCamera1")
    assert code == 2
    assert error_line(err).endswith(
        "no simulated component svc:LocateMobileRobot_CeilingCamera1 (did you mean"
        " svc:LocateMobileRobot_CeilingCamera01 or svc:LocateMobileRobot_CeilingCamera02?)"
    )


def test_a_namespace_one_slip_from_cbrs_s_is_noted(tmp_path: Path) -> None:
    text = PENCIL.read_text(encoding="utf-8")
    typo = tmp_path / "pencil.ttl"
    typo.write_text(text.replace("<https://w3id.org/cbrs/home#>", "<https://w3id.org/cbrs/hom#>", 1), encoding="utf-8")
    code, out, err = run("load", "--graph", "map", str(typo))
    assert code == 0 and "12 triples into graph:map" in out  # valid RDF: it loads
    assert f"note: {typo} names things in <https://w3id.org/cbrs/hom#>, which cbrs does not know: is it home:" in err
    code, _, err = run("load", "--graph", "map", str(PENCIL))
    assert code == 0 and "note:" not in err


def test_an_update_that_changed_nothing_names_what_the_store_does_not_mention() -> None:
    code, out, err = run("update", "DELETE WHERE { GRAPH graph:map { world:Pen home:yw ?yaw } }  # home:zz")
    assert code == 0 and "no graph changed in size" in out
    assert err.splitlines() == ["note: nothing in the store mentions home:yw; did you mean home:yaw?"]
    code, out, err = run("update", "DELETE WHERE { GRAPH graph:map { world:Pen home:yaw ?yaw } }")
    assert code == 0 and "graph:map: -1 triples" in out and err == ""
