"""Stores built from docs/examples the way the docs say to load them, shared by the tests of those examples."""

from __future__ import annotations

from pathlib import Path

from cbrs.kb import KnowledgeBase

EXAMPLES = Path(__file__).resolve().parents[1] / "docs" / "examples"


def updated_store(*updates: str) -> KnowledgeBase:
    """The bundled store with docs/examples' updates (``.ru`` files) applied, as `cbrs update --file` applies
    them."""
    kb = KnowledgeBase.open(":memory:")
    for name in updates:
        kb.update((EXAMPLES / name).read_text(encoding="utf-8"))
    return kb


def wine7_store(directory: Path) -> KnowledgeBase:
    """The bundled store with the wine bottle narrowed to 7 cm (docs/tasks.md, "the 7 cm variant": the
    7.5 cm one is refused by the jaws) and the low cupboard; the narrowed file written in ``directory``."""
    text = (EXAMPLES / "wine_bottle.ttl").read_text(encoding="utf-8")
    narrowed = text.replace("home:sizeX 0.075 ; home:sizeY 0.075", "home:sizeX 0.07 ; home:sizeY 0.07")
    assert narrowed != text
    wine = directory / "wine7.ttl"
    wine.write_text(narrowed, encoding="utf-8")
    kb = KnowledgeBase.open(":memory:")
    for graph in ("ontology", "map"):
        kb.load([wine, EXAMPLES / "low_cupboard.ttl"], graph=graph)
    return kb


def lab5_store(
    *, updates: tuple[str, ...] = (), things: tuple[str, ...] = (), hands: str | None = None
) -> KnowledgeBase:
    """A bundled store with the fifth round's ``updates`` applied, its ``things`` loaded into the ontology and
    the map, and, when given, the lab's ``hands`` in place of the Panda hands (docs/tasks.md "A fifth round")."""
    kb = KnowledgeBase.open(":memory:")
    for name in updates:
        kb.update((EXAMPLES / name).read_text())
    for name in things:
        kb.load([EXAMPLES / name], graph="ontology")
        kb.load([EXAMPLES / name], graph="map")
    if hands is not None:
        kb.update((EXAMPLES / "lab5_unhand.ru").read_text())
        kb.load([EXAMPLES / hands], graph="map")
    return kb
