"""The validation collection (tests/data/robot_validation) loads whole: structure only, never MAP.

It is for final validation, not tuning, so nothing here looks at a ranking; but a file that lost a
parameter, a condition or a relevance entry would still yield a MAP, a wrong one, so these checks run first.
"""

from __future__ import annotations

import importlib.util
from pathlib import Path
from types import ModuleType

import pytest

from cbrs.reasoner.owlstc import LoadedCollection, _file_key, load_collection, read_relevance

ROOT = Path(__file__).resolve().parents[1]
DATA = ROOT / "tests" / "data" / "robot_validation"


@pytest.fixture(scope="module")
def gen() -> ModuleType:
    spec = importlib.util.spec_from_file_location("robot_validation", ROOT / "bench" / "robot_validation.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


@pytest.fixture(scope="module")
def loaded() -> LoadedCollection:
    return load_collection(DATA)


def _iri(term: str, gen: ModuleType) -> str:
    """A spec term as the loader reports it: a ?Name parameter by its type, a constant by its class."""
    return f"{gen.ONT}#{term.lstrip('?')}"


def test_each_file_is_one_description_and_the_sizes_are_the_briefs(loaded: LoadedCollection, gen: ModuleType) -> None:
    services = sorted(p.name for p in (DATA / "services").glob("*.owls"))
    queries = sorted(p.name for p in (DATA / "queries").glob("*.owls"))
    assert services == sorted(f"{name}.owls" for name in gen.S)
    assert queries == sorted(f"{name}.owls" for name in gen.QUERY)
    assert len(services) >= 45 and len(queries) >= 14
    assert sorted(loaded.advertisements) == services
    assert sorted(loaded.requirements) == queries
    assert all(len(iris) == 1 for iris in (*loaded.advertisements.values(), *loaded.requirements.values()))
    assert len(loaded.kb.advertisements()) == len(services)
    assert len(loaded.kb.requirements()) == len(queries)
    assert sum(bool(effects) for _, _, _, effects, *_ in gen.QUERY.values()) >= 6


def test_only_the_intended_concepts_are_undeclared(loaded: LoadedCollection, gen: ModuleType) -> None:
    assert 2 <= len(gen.UNDECLARED) <= 4
    assert loaded.unresolved_concepts == len(gen.UNDECLARED)


def test_every_description_carries_the_specs_parameters_and_conditions(
    loaded: LoadedCollection, gen: ModuleType
) -> None:
    by_iri = {d.iri: d for d in (*loaded.kb.advertisements(), *loaded.kb.requirements())}
    for files, spec in ((loaded.advertisements, gen.S), (loaded.requirements, gen.QUERY)):
        for name, (inputs, outputs, pre, effects, *_) in spec.items():
            d = by_iri[files[f"{name}.owls"][0]]
            assert sorted(p.type for p in d.inputs) == sorted(_iri(c, gen) for c in inputs), name
            assert sorted(p.type for p in d.outputs) == sorted(_iri(c, gen) for c in outputs), name
            for got, wanted in ((d.preconditions, pre), (d.effects, effects)):
                assert sorted((s.subject, s.predicate, s.object) for s in got) == sorted(
                    (_iri(s, gen), _iri(p, gen), _iri(o, gen)) for s, p, o in wanted
                ), name


def test_every_relevance_entry_names_a_loaded_service_and_matches_the_spec(
    loaded: LoadedCollection, gen: ModuleType
) -> None:
    judged = read_relevance(DATA / "relevance.xml")
    assert {_file_key(o) for o in judged.offers} == set(loaded.advertisements)
    for rated in (judged.binary, judged.graded):
        assert {_file_key(r) for r in rated} == set(loaded.requirements)
        for offers in rated.values():
            assert {_file_key(o) for o in offers} <= set(loaded.advertisements)
    for request, grades in judged.graded.items():
        spec = gen.QUERY[_file_key(request).removesuffix(".owls")][5]
        assert {_file_key(o): g for o, g in grades.items()} == {f"{s}.owls": g for s, (g, _) in spec.items()}
        assert judged.binary[request] == {offer: int(grade >= 1) for offer, grade in grades.items()}
        assert sum(grade >= 1 for grade in grades.values()) >= 2, request
        assert 0 in grades.values(), request


def test_the_committed_files_are_what_the_generator_writes(tmp_path: Path, gen: ModuleType) -> None:
    gen.write(tmp_path)
    written = sorted(p.relative_to(tmp_path) for p in tmp_path.rglob("*") if p.is_file())
    committed = sorted(p.relative_to(DATA) for p in DATA.rglob("*") if p.is_file())
    assert written == committed
    for path in written:
        assert (tmp_path / path).read_bytes() == (DATA / path).read_bytes(), path
