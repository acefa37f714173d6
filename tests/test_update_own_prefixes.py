"""``cbrs update``'s note of names the store mentions nowhere reads the update's own PREFIX declarations: a
lab's misspelt thing under its own prefix (the eleventh round's ``lab11:Flsk1``, docs/tasks.md) matched
nothing, and only "no graph changed in size" was said, as the note skipped every prefix the update declared."""

from __future__ import annotations

from click.testing import CliRunner

from cbrs.cli import cli


def _update(text: str) -> tuple[int, str, str]:
    result = CliRunner().invoke(cli, ["--store", ":memory:", "update", text])
    return result.exit_code, result.stdout, result.stderr


def test_a_name_under_the_update_s_own_prefix_is_noted() -> None:
    code, out, err = _update(
        "PREFIX lab11: <https://example.org/lab11#>\n"
        "DELETE { GRAPH graph:map { lab11:Flsk1 home:x ?x } } INSERT { GRAPH graph:map { lab11:Flsk1 home:x 7.55 } }\n"
        "WHERE { GRAPH graph:map { lab11:Flsk1 home:x ?x } }"
    )
    assert code == 0 and "no graph changed in size" in out
    assert "note: nothing in the store mentions lab11:Flsk1" in err


def test_an_own_prefix_for_a_known_namespace_gets_the_nearest_names() -> None:
    code, _, err = _update(
        "PREFIX w: <https://w3id.org/cbrs/world#>  # PREFIX zz: <https://example.org/zz#> is a comment\n"
        "DELETE WHERE { GRAPH graph:map { w:Pn home:yaw ?yaw } }"
    )
    assert code == 0
    assert err.splitlines()[0].startswith("note: nothing in the store mentions w:Pn; did you mean")
    assert "zz:" not in err and "home:yaw" not in err  # a comment declares nothing; home:yaw is known


def test_a_name_the_store_has_under_an_own_prefix_is_not_noted() -> None:
    code, out, err = _update(
        "PREFIX w: <https://w3id.org/cbrs/world#>\nDELETE WHERE { GRAPH graph:map { w:Pen home:colourName 'x' } }"
    )
    assert code == 0 and "no graph changed in size" in out and err == ""
