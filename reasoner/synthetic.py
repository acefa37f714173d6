"""Seeded synthetic taxonomies, advertisement pools and requirements, for benchmarks and tests."""

from __future__ import annotations

import random

from cbrs.kb import Advertisement, Parameter, PartNode, Requirement, Statement
from cbrs.reasoner.taxonomy import ROOT, Link, TaxonomyIndex

NS = "http://example.org/bench#"


def build(
    classes: int, ads: int, queries: int, seed: int
) -> tuple[TaxonomyIndex, list[Advertisement], list[Requirement]]:
    """A random is-a tree with has-part restrictions (parts shared across wholes, as coordinates
    are), advertisements with 1-3 inputs, 1-2 outputs and sometimes an effect, and requirements
    drawn the same way. Same seed, same pool."""
    rng = random.Random(seed)
    names = [f"{NS}C{i}" for i in range(classes)]
    links = [Link(names[0], ROOT, "is-a")]
    for i in range(1, classes):
        links.append(Link(names[i], names[rng.randrange(max(1, i // 3), i) if i > 3 else 0], "is-a"))
    parts = names[classes - classes // 10 :]  # the last tenth are part concepts (coordinates, ...)
    trees: dict[str, PartNode] = {}
    wholes = names[: classes - len(parts)]
    for whole in wholes:
        chosen = rng.sample(parts, rng.choice((0, 0, 2, 3)))
        for part in chosen:
            links.append(Link(part, whole, "has-part"))
        trees[whole] = PartNode(whole, None, tuple(PartNode(p, NS + "hasPart") for p in sorted(chosen)))
    predicates = [f"{NS}p{i}" for i in range(30)]
    links += [Link(p, predicates[0], "is-a") for p in predicates[1:]]
    index = TaxonomyIndex.from_links(links)

    def parameter(direction: str, n: int) -> Parameter:
        concept = rng.choice(wholes)
        return Parameter(f"{NS}param{n}", direction, concept, None, trees[concept])  # type: ignore[arg-type]

    def statement() -> Statement:
        return Statement(rng.choice(wholes), rng.choice(predicates), rng.choice(wholes))

    pool = [
        Advertisement(
            iri=f"{NS}ad{i}",
            types=(),
            inputs=tuple(parameter("input", j) for j in range(rng.randint(1, 3))),
            outputs=tuple(parameter("output", j) for j in range(rng.randint(1, 2))),
            effects=(statement(),) if rng.random() < 0.5 else (),
        )
        for i in range(ads)
    ]
    requirements = [
        Requirement(
            iri=f"{NS}req{i}",
            types=(),
            inputs=tuple(parameter("input", j) for j in range(rng.randint(1, 2))),
            outputs=tuple(parameter("output", j) for j in range(rng.randint(1, 2))),
            effects=(statement(),),
        )
        for i in range(queries)
    ]
    return index, pool, requirements
