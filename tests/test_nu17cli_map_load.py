"""A load into graph:map that the semantic map's reader would refuse is refused before it is written
(new-user CLI repro 12: a misspelt support loaded without a word, then every task run failed on it, and
only a SPARQL update could take it out again)."""

from __future__ import annotations

from pathlib import Path

import pytest
from click.testing import CliRunner

from cbrs.cli import cli
from cbrs.kb import KnowledgeBase
from cbrs.kb.semantic_map import MapError

MUG = """@prefix home:  <https://w3id.org/cbrs/home#> .
@prefix world: <https://w3id.org/cbrs/world#> .
world:Mug1 a home:Mug ; home:shapeKind "cylinder" ; home:sizeX 0.08 ; home:sizeY 0.08 ; home:sizeZ 0.1 ;
    home:massKg 0.3 ; home:colourName "blue" ; home:rgba "0.1 0.2 0.9 1" ;
    home:isLocatedOn world:{on} ; home:x 8.3 ; home:y 3.0 ; home:yaw 0.0 .
"""


def test_a_misspelt_support_is_refused_and_nothing_written(tmp_path: Path) -> None:
    kb = KnowledgeBase.open(":memory:")
    before = kb.store.dump()
    mug = tmp_path / "mug.ttl"
    mug.write_text(MUG.format(on="KitchenTabel"), encoding="utf-8")
    with pytest.raises(MapError, match="did you mean KitchenTable") as refused:
        kb.load([mug], graph="map")
    assert refused.value.__notes__ == [
        f"nothing was loaded from {mug} (a load into graph:map is checked as a task reads the map)"
    ]
    assert kb.store.dump() == before
    mug.write_text(MUG.format(on="KitchenTable"), encoding="utf-8")
    assert kb.load([mug], graph="map").added_quads == 12


def test_the_cli_says_it_in_one_line(tmp_path: Path) -> None:
    mug = tmp_path / "mug.ttl"
    mug.write_text(MUG.format(on="KitchenTabel").replace("sizeX", "sizX"), encoding="utf-8")
    result = CliRunner().invoke(cli, ["--store", ":memory:", "load", "--graph", "map", str(mug)])
    assert result.exit_code == 1
    assert result.output.startswith("Error: semantic map: Mug1 ")
    assert f"; nothing was loaded from {mug}" in result.output
