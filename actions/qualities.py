"""Which relation to a quality class makes the class its value: the one rule a step's effect and a late
answer's are both believed by (``sim.components.SimEnvironment``, :mod:`actions.late_answers`).

An effect whose object is a status or another quality (``home:Opened`` in (Door, hasStatus, Opened)) is
about no thing of the world; the class stands for itself, and the relation is believed and kept in the
world graph, only as the subject's own quality: by ``home:hasQualityPart`` or a relation below it
(``home:hasStatus``, ``home:hasColour``). By another relation ((Person, lab6:isAlertedOf, DoorStatus): an
alert sent) it is no lasting state of the subject, and is neither believed nor kept, as an inform is not
(docs/components.md; docs/execution.md, the belief's sources). Here, in ``actions``, so that the simulated
environment and the late answers share it (``sim`` imports ``actions``, not the other way).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

from cbrs.kb import KnowledgeBase
from cbrs.kb.namespaces import HOME

__all__ = ["OwnQualities"]


@dataclass
class OwnQualities:
    """The rule for one store: ``is_a`` its class test; the relations of ``home:hasQualityPart``'s family
    are read (named query ``taxonomy_links``) once, at the first question."""

    kb: KnowledgeBase
    is_a: Callable[[str, str], bool]
    _relations: frozenset[str] | None = field(default=None, repr=False)

    def __call__(self, predicate: str, value: str) -> bool:
        """Whether ``value``, a class, stands for itself as the value of ``predicate``: a quality, by a
        relation of ``home:hasQualityPart``'s family."""
        return self.is_a(value, HOME + "Quality") and predicate in self.relations()

    def passing(self, predicate: str, value: str) -> bool:
        """Whether ``value`` is a quality class that ``predicate`` does not make the subject's own (an
        alert about a status): such a relation is neither believed nor kept."""
        return self.is_a(value, HOME + "Quality") and predicate not in self.relations()

    def relations(self) -> frozenset[str]:
        """``home:hasQualityPart`` and the relations below it."""
        if self._relations is None:
            parents: dict[str, set[str]] = {}
            for row in self.kb.select("taxonomy_links"):
                if row["link"].value == "is-a":
                    parents.setdefault(row["child"].value, set()).add(row["parent"].value)
            found, frontier = {HOME + "hasQualityPart"}, [HOME + "hasQualityPart"]
            while frontier:
                above = frontier.pop()
                below = [child for child, ups in parents.items() if above in ups and child not in found]
                found.update(below)
                frontier += below
            self._relations = frozenset(found)
        return self._relations
