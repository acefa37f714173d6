"""The held-out home-robot collection (tests/data/robot_heldout) loads whole: structure only, no MAP.

A collection that silently lost a file, a parameter or a condition would still give a MAP, just a wrong
one; these checks catch that before anyone reads its figures.
"""

from __future__ import annotations

import importlib.util
from pathlib import Path
from types import ModuleType

import pytest

from cbrs.reasoner.owlstc import LoadedCollection, _file_key, load_collection, read_relevance

ROOT = Path(__file__).resolve().parents[1]
HELD = ROOT / "tests" / "data" / "robot_heldout"


def _generator() -> ModuleType:
    spec = importlib.util.spec_from_file_location("robot_heldout", ROOT / "bench" / "robot_heldout.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


@pytest.fixture(scope="module")
def gen() -> ModuleType:
    return _generator()


@pytest.fixture(scope="module")
def loaded() -> LoadedCollection:
    return load_collection(HELD)


def test_every_service_and_query_file_becomes_one_description(loaded: LoadedCollection) -> None:
    services = sorted(p.name for p in (HELD / "services").glob("*.owls"))
    queries = sorted(p.name for p in (HELD / "queries").glob("*.owls"))
    assert len(services) >= 45 and len(queries) >= 12
    assert sorted(loaded.advertisements) == services
    assert sorted(loaded.requirements) == queries
    assert all(len(iris) == 1 for iris in (*loaded.advertisements.values(), *loaded.requirements.values()))
    assert len(loaded.kb.advertisements()) == len(services)
    assert len(loaded.kb.requirements()) == len(queries)


def test_only_the_intended_concepts_are_undeclared(loaded: LoadedCollection, gen: ModuleType) -> None:
    assert loaded.unresolved_concepts == len(gen.UNDECLARED)


def _concept(term: str, gen: ModuleType) -> str:
    return f"{gen.ONT}#{term.lstrip('?')}"


def test_descriptions_carry_every_parameter_and_condition_of_the_spec(
    loaded: LoadedCollection, gen: ModuleType
) -> None:
    described = {d.iri: d for d in (*loaded.kb.advertisements(), *loaded.kb.requirements())}
    specs = [(loaded.advertisements, gen.S, "services"), (loaded.requirements, gen.QUERY, "queries")]
    for by_file, spec, kind in specs:
        for name, (inputs, outputs, pre, effects, *_) in spec.items():
            d = described[by_file[f"{name}.owls"][0]]
            where = f"{kind}/{name}"
            assert sorted(p.type for p in d.inputs) == sorted(_concept(c, gen) for c in inputs), where
            assert sorted(p.type for p in d.outputs) == sorted(_concept(c, gen) for c in outputs), where
            for made, wanted in ((d.preconditions, pre), (d.effects, effects)):
                got = sorted((s.subject, s.predicate, s.object) for s in made)
                want = sorted((_concept(s, gen), _concept(p, gen), _concept(o, gen)) for s, p, o in wanted)
                assert got == want, where


def test_every_relevance_entry_names_a_loaded_file(loaded: LoadedCollection) -> None:
    judgements = read_relevance(HELD / "relevance.xml")
    assert {_file_key(o) for o in judgements.offers} == set(loaded.advertisements)
    for rated in (judgements.binary, judgements.graded):
        assert {_file_key(r) for r in rated} == set(loaded.requirements)
        for offers in rated.values():
            assert {_file_key(o) for o in offers} <= set(loaded.advertisements)
    for request, grades in judgements.graded.items():
        binary = judgements.binary[request]
        assert binary == {offer: int(grade >= 1) for offer, grade in grades.items()}
        assert set(grades.values()) <= {0, 1, 2, 3}
        assert sum(binary.values()) >= 2, request


def test_the_committed_files_are_what_the_generator_writes(tmp_path: Path, gen: ModuleType) -> None:
    gen.write(tmp_path)
    written = sorted(p.relative_to(tmp_path) for p in tmp_path.rglob("*") if p.is_file())
    committed = sorted(p.relative_to(HELD) for p in HELD.rglob("*") if p.is_file())
    assert written == committed
    for path in written:
        assert (tmp_path / path).read_bytes() == (HELD / path).read_bytes(), path
