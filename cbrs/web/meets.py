"""Which stored requirements an advertisement meets: the way from a service to the tasks it serves.

A service page could rank the advertisements for a requirement picked from a list of all of them, but
did not say for which requirements this service is a match. Every stored requirement is ranked once per
store generation with Sem-Str (the matchmaking page's default method), as the matchmaking page ranks it,
and each advertisement keeps its place in the rankings that accept it.

On a store of many advertisements the first rankings after a start or a write wait for the matchmaker
(on OWLS-TC, 1,136 advertisements: 7 to 12 s under load), and a service page was 0.4 s. There the page
offers the list (:func:`shown_inline` says when), and shows it inline once the rankings are read.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass
from typing import Any

from cbrs.web import context
from cbrs.web.links import short

METHOD = "sem-str"
INLINE_ADVERTISEMENTS = 200  # CBRS_MEETS_INLINE: up to this many, a service page ranks the requirements itself
_KEY = "requirements_met"


@dataclass(frozen=True)
class Met:
    """One requirement's ranking that accepts an advertisement, and where the advertisement stands in it."""

    requirement: str
    name: str
    label: str | None
    rank: int  # 1 is first
    of: int  # the advertisements ranked
    score: float
    first: str  # the advertisement ranked first, to compare with

    def to_dict(self) -> dict[str, Any]:
        return asdict(self)


def shown_inline(advertisements: int, limit: int, asked: bool) -> bool:
    """Whether a service page lists the requirements met: on a store of at most ``limit`` advertisements,
    when the rankings are already read for the store as it is, or when the user ``asked`` for them."""
    return asked or advertisements <= limit or context.kept(_KEY)


def requirements_met(advertisement: str) -> list[Met]:
    """The stored requirements whose ranking accepts ``advertisement``, where it ranks best first."""
    found = context.per_generation(_KEY, _every_ranking).get(advertisement, [])
    return sorted(found, key=lambda m: (m.rank, -m.score, m.name.casefold()))


def _every_ranking() -> dict[str, list[Met]]:
    kb = context.kb()
    labels = {row["requirement"].value: row.get("label") for row in kb.select("requirements")}
    met: dict[str, list[Met]] = {}
    with context.lock():
        matchmaker = context.matchmakers().get(METHOD)
        for iri in sorted(labels):
            ranking = matchmaker.rank(iri, explain=0).candidates
            label = labels[iri]
            for place, candidate in enumerate(ranking, start=1):
                if candidate.acceptable:
                    met.setdefault(candidate.advertisement, []).append(
                        Met(
                            iri,
                            short(iri),
                            label.value if label is not None else None,
                            place,
                            len(ranking),
                            round(candidate.score, 3),
                            ranking[0].advertisement,
                        )
                    )
    return met
