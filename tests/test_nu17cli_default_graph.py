"""A file that describes no service and goes to graph:services only because no --graph was given is named
on standard error (new-user CLI repro 13: a map file loaded without --graph map went there without a
word, and its objects were in no map)."""

from __future__ import annotations

from pathlib import Path

from click.testing import CliRunner

from cbrs.cli import cli

ROOT = Path(__file__).resolve().parents[1]
MUG = """@prefix home:  <https://w3id.org/cbrs/home#> .
@prefix world: <https://w3id.org/cbrs/world#> .
world:Mug1 a home:Mug ; home:shapeKind "cylinder" ; home:sizeX 0.08 ; home:sizeY 0.08 ; home:sizeZ 0.1 ;
    home:massKg 0.3 ; home:colourName "blue" ; home:rgba "0.1 0.2 0.9 1" ;
    home:isLocatedOn world:KitchenTable ; home:x 8.3 ; home:y 3.0 ; home:yaw 0.0 .
"""


def _load(*args: str) -> tuple[str, str]:
    result = CliRunner().invoke(cli, ["--store", ":memory:", "load", *args])
    assert result.exit_code == 0, result.output
    return result.stdout, result.stderr


def test_a_map_file_without_graph_map_is_named(tmp_path: Path) -> None:
    mug = tmp_path / "mug.ttl"
    mug.write_text(MUG, encoding="utf-8")
    out, err = _load(str(mug))
    assert "12 triples into graph:services" in out
    assert err.startswith(f"note: {mug} describes no service and went to graph:services, the default; ")
    assert "--graph map" in err


def test_nothing_said_when_the_graph_is_given_or_the_file_describes_services(tmp_path: Path) -> None:
    mug = tmp_path / "mug.ttl"
    mug.write_text(MUG, encoding="utf-8")
    assert _load("--graph", "map", str(mug))[1] == ""
    assert _load(str(ROOT / "docs" / "examples" / "camera3.ttl"))[1] == ""
