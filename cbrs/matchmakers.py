"""Matchmakers kept between requests: the taxonomy index is costly to build, so it is built once per
store version and shared by every method, for the browser and the rosbridge services alike."""

from __future__ import annotations

import threading

from cbrs.sparql_service import SparqlService
from reasoner.matchmaker import Matchmaker
from reasoner.taxonomy import TaxonomyIndex


class Matchmakers:
    """One matchmaker per method over the store as it is now; a SPARQL update makes them stale."""

    def __init__(self, sparql: SparqlService) -> None:
        self.sparql = sparql
        self._generation = -1
        self._index: TaxonomyIndex | None = None
        self._built: dict[str, Matchmaker] = {}
        self._guard = threading.Lock()

    def get(self, method: str) -> Matchmaker:
        """The matchmaker for ``method``; call with the knowledge-base lock held."""
        kb, generation = self.sparql.kb, self.sparql.generation
        with self._guard:
            if generation != self._generation or self._index is None:
                self._generation, self._index, self._built = generation, TaxonomyIndex.from_kb(kb), {}
            if method not in self._built:
                shared = next(iter(self._built.values()), None)
                ads = shared.advertisements if shared is not None else None
                self._built[method] = Matchmaker(kb, method, index=self._index, advertisements=ads)
            return self._built[method]
