"""The robot collections written blind (tests/data/robot_*, docs/matchmaking.md 9.7) load as written.

Structure only, never a ranking: they are for measuring, not tuning. A file that lost a parameter, a
condition or a relevance entry would still give a MAP, a wrong one; these checks catch that first. Each
collection's generator (bench/robot_<name>.py) holds its spec; the minimum sizes are its brief's.
"""

from __future__ import annotations

import importlib.util
from pathlib import Path
from types import ModuleType
from typing import NamedTuple

import pytest

from cbrs.reasoner.owlstc import LoadedCollection, _file_key, load_collection, read_relevance

ROOT = Path(__file__).resolve().parents[1]


class Brief(NamedTuple):
    name: str
    services: int
    queries: int
    effect_queries: int


BRIEFS = [
    Brief("heldout", 45, 12, 5),
    Brief("validation", 45, 14, 6),
    Brief("final", 45, 14, 6),
    Brief("blind5", 45, 15, 7),
    Brief("blind6", 60, 16, 7),
]


class Collection(NamedTuple):
    brief: Brief
    data: Path
    spec: ModuleType
    loaded: LoadedCollection


def _generator(name: str) -> ModuleType:
    found = importlib.util.spec_from_file_location(f"robot_{name}", ROOT / "bench" / f"robot_{name}.py")
    assert found is not None and found.loader is not None
    module = importlib.util.module_from_spec(found)
    found.loader.exec_module(module)
    return module


@pytest.fixture(scope="module", params=BRIEFS, ids=[b.name for b in BRIEFS])
def collection(request: pytest.FixtureRequest) -> Collection:
    brief: Brief = request.param
    data = ROOT / "tests" / "data" / f"robot_{brief.name}"
    return Collection(brief, data, _generator(brief.name), load_collection(data))


def _iri(spec: ModuleType, term: str) -> str:
    """How the loader names a spec term: a ?Name parameter by its type, a constant by its class."""
    return f"{spec.ONT}#{term.removeprefix('?')}"


def test_one_description_per_file_and_the_briefs_sizes(collection: Collection) -> None:
    brief, data, spec, loaded = collection
    services = sorted(p.name for p in (data / "services").glob("*.owls"))
    queries = sorted(p.name for p in (data / "queries").glob("*.owls"))
    assert services == sorted(f"{n}.owls" for n in spec.S)
    assert queries == sorted(f"{n}.owls" for n in spec.QUERY)
    assert len(services) >= brief.services and len(queries) >= brief.queries
    assert sorted(loaded.advertisements) == services
    assert sorted(loaded.requirements) == queries
    assert all(len(iris) == 1 for iris in (*loaded.advertisements.values(), *loaded.requirements.values()))
    assert len(loaded.kb.advertisements()) == len(services)
    assert len(loaded.kb.requirements()) == len(queries)
    assert sum(bool(q[3]) for q in spec.QUERY.values()) >= brief.effect_queries


def test_only_the_intended_concepts_are_undeclared(collection: Collection) -> None:
    assert 2 <= len(collection.spec.UNDECLARED) <= 4
    assert collection.loaded.unresolved_concepts == len(collection.spec.UNDECLARED)


def test_each_description_has_the_specs_parameters_and_conditions(collection: Collection) -> None:
    _, _, spec, loaded = collection
    described = {d.iri: d for d in (*loaded.kb.advertisements(), *loaded.kb.requirements())}
    for files, entries in ((loaded.advertisements, spec.S), (loaded.requirements, spec.QUERY)):
        for name, (inputs, outputs, pre, effects, *_) in entries.items():
            d = described[files[f"{name}.owls"][0]]
            assert sorted(p.type for p in d.inputs) == sorted(_iri(spec, c) for c in inputs), name
            assert sorted(p.type for p in d.outputs) == sorted(_iri(spec, c) for c in outputs), name
            for got, wanted in ((d.preconditions, pre), (d.effects, effects)):
                assert sorted((st.subject, st.predicate, st.object) for st in got) == sorted(
                    tuple(_iri(spec, t) for t in st) for st in wanted
                ), name


def test_the_relevance_file_names_loaded_services_with_the_specs_grades(collection: Collection) -> None:
    _, data, spec, loaded = collection
    judged = read_relevance(data / "relevance.xml")
    assert {_file_key(o) for o in judged.offers} == set(loaded.advertisements)
    for rated in (judged.binary, judged.graded):
        assert {_file_key(r) for r in rated} == set(loaded.requirements)
        for offers in rated.values():
            assert {_file_key(o) for o in offers} <= set(loaded.advertisements)
    for request, grades in judged.graded.items():
        wanted = spec.QUERY[_file_key(request).removesuffix(".owls")][5]
        assert {_file_key(o): g for o, g in grades.items()} == {f"{s}.owls": g for s, (g, _) in wanted.items()}
        assert set(grades.values()) <= {0, 1, 2, 3}
        assert judged.binary[request] == {o: int(g >= 1) for o, g in grades.items()}
        assert sum(g >= 1 for g in grades.values()) >= 2, request
        assert 0 in grades.values(), request


@pytest.mark.parametrize("name", ["final", "blind5", "blind6"])
def test_the_ontology_carries_the_property_tree_and_the_disjointness(name: str) -> None:
    spec = _generator(name)
    text = (ROOT / "tests" / "data" / f"robot_{name}" / "ontology" / f"robot_{name}.owl").read_text(encoding="utf-8")
    for prop, parent in spec.PROPERTIES.items():
        if parent is not None:
            assert f'rdf:ID="{prop}"><rdfs:subPropertyOf rdf:resource="#{parent}"/>' in text
    assert text.count("<owl:disjointWith") == len(spec.DISJOINT)


def test_the_committed_files_are_what_the_generator_writes(tmp_path: Path, collection: Collection) -> None:
    collection.spec.write(tmp_path)
    data = collection.data
    written = sorted(p.relative_to(tmp_path) for p in tmp_path.rglob("*") if p.is_file())
    assert written == sorted(p.relative_to(data) for p in data.rglob("*") if p.is_file())
    for path in written:
        assert (tmp_path / path).read_bytes() == (data / path).read_bytes(), path
