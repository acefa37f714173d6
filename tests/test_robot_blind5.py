"""The fifth (blind) collection, tests/data/robot_blind5, loads as its spec says: structure only.

It is measured once for the release note and never tuned on, so nothing here ranks or computes a MAP. A
file that lost a parameter, a condition or a relevance entry would still yield a figure, a wrong one;
these checks catch that before the figure is taken.
"""

from __future__ import annotations

import importlib.util
from pathlib import Path
from types import ModuleType

import pytest

from cbrs.reasoner.owlstc import LoadedCollection, _file_key, load_collection, read_relevance

ROOT = Path(__file__).resolve().parents[1]
DATA = ROOT / "tests" / "data" / "robot_blind5"


@pytest.fixture(scope="module")
def spec() -> ModuleType:
    found = importlib.util.spec_from_file_location("robot_blind5", ROOT / "bench" / "robot_blind5.py")
    assert found is not None and found.loader is not None
    module = importlib.util.module_from_spec(found)
    found.loader.exec_module(module)
    return module


@pytest.fixture(scope="module")
def loaded() -> LoadedCollection:
    return load_collection(DATA)


def _type(spec: ModuleType, term: str) -> str:
    """The IRI the loader gives a spec term: a ?Name parameter by its type, a constant by its class."""
    return f"{spec.ONT}#{term.removeprefix('?')}"


def test_every_file_is_one_description_and_the_sizes_are_the_briefs(loaded: LoadedCollection, spec: ModuleType) -> None:
    services = sorted(p.name for p in (DATA / "services").glob("*.owls"))
    queries = sorted(p.name for p in (DATA / "queries").glob("*.owls"))
    assert services == sorted(f"{n}.owls" for n in spec.S)
    assert queries == sorted(f"{n}.owls" for n in spec.QUERY)
    assert len(services) >= 45 and len(queries) >= 15
    assert sorted(loaded.advertisements) == services
    assert sorted(loaded.requirements) == queries
    assert all(len(iris) == 1 for iris in (*loaded.advertisements.values(), *loaded.requirements.values()))
    assert len(loaded.kb.advertisements()) == len(services)
    assert len(loaded.kb.requirements()) == len(queries)
    assert sum(bool(q[3]) for q in spec.QUERY.values()) >= 7


def test_only_the_intended_concepts_are_undeclared(loaded: LoadedCollection, spec: ModuleType) -> None:
    assert 2 <= len(spec.UNDECLARED) <= 4
    assert loaded.unresolved_concepts == len(spec.UNDECLARED)


def test_every_description_carries_the_specs_parameters_and_conditions(
    loaded: LoadedCollection, spec: ModuleType
) -> None:
    by_iri = {d.iri: d for d in (*loaded.kb.advertisements(), *loaded.kb.requirements())}
    for files, entries in ((loaded.advertisements, spec.S), (loaded.requirements, spec.QUERY)):
        for name, (inputs, outputs, pre, effects, *_) in entries.items():
            d = by_iri[files[f"{name}.owls"][0]]
            assert sorted(p.type for p in d.inputs) == sorted(_type(spec, c) for c in inputs), name
            assert sorted(p.type for p in d.outputs) == sorted(_type(spec, c) for c in outputs), name
            for got, wanted in ((d.preconditions, pre), (d.effects, effects)):
                assert sorted((s.subject, s.predicate, s.object) for s in got) == sorted(
                    tuple(_type(spec, t) for t in st) for st in wanted
                ), name


def test_every_relevance_entry_names_a_loaded_service_with_the_specs_grade(
    loaded: LoadedCollection, spec: ModuleType
) -> None:
    judged = read_relevance(DATA / "relevance.xml")
    assert {_file_key(o) for o in judged.offers} == set(loaded.advertisements)
    for rated in (judged.binary, judged.graded):
        assert {_file_key(r) for r in rated} == set(loaded.requirements)
        for offers in rated.values():
            assert {_file_key(o) for o in offers} <= set(loaded.advertisements)
    for request, grades in judged.graded.items():
        wanted = spec.QUERY[_file_key(request).removesuffix(".owls")][5]
        assert {_file_key(o): g for o, g in grades.items()} == {f"{s}.owls": g for s, (g, _) in wanted.items()}
        assert judged.binary[request] == {o: int(g >= 1) for o, g in grades.items()}
        assert sum(g >= 1 for g in grades.values()) >= 2, request
        assert 0 in grades.values(), request


def test_the_ontology_has_its_property_tree_and_disjointness(spec: ModuleType) -> None:
    text = (DATA / "ontology" / "robot_blind5.owl").read_text(encoding="utf-8")
    for prop, parent in spec.PROPERTIES.items():
        if parent is not None:
            assert f'rdf:ID="{prop}"><rdfs:subPropertyOf rdf:resource="#{parent}"/>' in text
    assert text.count("<owl:disjointWith") == len(spec.DISJOINT)


def test_the_committed_files_are_what_the_generator_writes(tmp_path: Path, spec: ModuleType) -> None:
    spec.write(tmp_path)
    written = sorted(p.relative_to(tmp_path) for p in tmp_path.rglob("*") if p.is_file())
    assert written == sorted(p.relative_to(DATA) for p in DATA.rglob("*") if p.is_file())
    for path in written:
        assert (tmp_path / path).read_bytes() == (DATA / path).read_bytes(), path
