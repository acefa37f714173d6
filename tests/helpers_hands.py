"""A lab's gripper models (ontology graph) and its robot's grippers (map graph), written as Turtle over
the bundled core and home ontologies and read as the simulation reads hands (``kb.hands.read_hands``)."""

from __future__ import annotations

from pathlib import Path

from cbrs.kb import KnowledgeBase, Store
from cbrs.kb.hands import Hand, read_hands
from cbrs.kb.namespaces import PREFIXES
from cbrs.kb.resources import ontology_dir

HOME, LAB = PREFIXES["home"], "http://example.org/lab#"
PREFIX = f"@prefix home: <{HOME}> .\n@prefix lab: <{LAB}> .\n@prefix rdfs: <http://www.w3.org/2000/01/rdf-schema#> .\n"


def read_lab_hands(tmp_path: Path, models: str, robot: str) -> dict[str, Hand]:
    """The hands of a store holding only the bundled ontologies, ``models`` and ``robot`` (under PREFIX)."""
    kb = KnowledgeBase(Store.open(":memory:"))
    kb.load([ontology_dir() / "core.ttl", ontology_dir() / "home.ttl"], graph="ontology")
    for name, text, graph in (("models", models, "ontology"), ("robot", robot, "map")):
        (tmp_path / f"{name}.ttl").write_text(PREFIX + text, encoding="utf-8")
        kb.load([tmp_path / f"{name}.ttl"], graph=graph)
    return read_hands(kb)
