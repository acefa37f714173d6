"""Where the simulation gets its scene: the semantic map in the store.

``HomeWorld`` builds its objects, person, arms and base from a :class:`kb.semantic_map.SemanticMap`;
given none, it reads the bundled map once per process from a fresh in-memory knowledge base seeded
with the bundled ontologies (tests and scripts that build a world without a store).
"""

from __future__ import annotations

from functools import lru_cache

from cbrs.kb import KnowledgeBase
from cbrs.kb.semantic_map import SemanticMap

__all__ = ["bundled_map"]


@lru_cache(maxsize=1)
def bundled_map() -> SemanticMap:
    """The semantic map of the bundled ``ontologies/world.ttl``, read once."""
    kb = KnowledgeBase.open(":memory:")
    try:
        return SemanticMap.read(kb)
    finally:
        kb.store.close()
