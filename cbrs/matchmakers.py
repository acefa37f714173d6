"""Matchmakers kept between requests: the taxonomy index is costly to build, so it is built once per
store version and shared by every method, for the browser and the rosbridge services alike."""

from __future__ import annotations

import threading
from typing import TYPE_CHECKING

from cbrs.kb.namespaces import GraphName
from cbrs.kb.store import is_remote
from cbrs.sparql_service import SparqlService

if TYPE_CHECKING:  # the reasoner loads with the first ranking, not at cbrs serve's start-up
    from cbrs.reasoner.config import MatchConfig
    from cbrs.reasoner.matchmaker import Matchmaker
    from cbrs.reasoner.taxonomy import TaxonomyIndex


class Matchmakers:
    """One matchmaker per method over the store as it is now; a SPARQL update makes them stale.

    ``params``: ``name=value`` matchmaking parameters (the match_params setting) every ranking uses."""

    def __init__(self, sparql: SparqlService, params: tuple[str, ...] = ()) -> None:
        self.sparql = sparql
        self.params = params
        self._config: MatchConfig | None = None
        self._generation: object = -1
        self._index: TaxonomyIndex | None = None
        self._built: dict[str, Matchmaker] = {}
        self._guard = threading.Lock()

    def get(self, method: str) -> Matchmaker:
        """The matchmaker for ``method``; call with the knowledge-base lock held.

        On a remote store other processes write too (another ``cbrs serve`` on the same server): the
        sizes of the ontology and services graphs are then part of the store's version, so a
        description registered through another process is matched here at the next ranking.
        """
        from cbrs.reasoner.config import MatchConfig
        from cbrs.reasoner.matchmaker import Matchmaker

        with self._guard:
            index = self._current()
            if self._config is None:
                self._config = MatchConfig().with_params(self.params)
            if method not in self._built:
                shared = next(iter(self._built.values()), None)
                ads = shared.advertisements if shared is not None else None
                self._built[method] = Matchmaker(self.sparql.kb, method, self._config, index=index, advertisements=ads)
            return self._built[method]

    def index(self) -> TaxonomyIndex:
        """The taxonomy index of the store as it is now, which the composers of /cbrs/plan share too;
        call with the knowledge-base lock held."""
        with self._guard:
            return self._current()

    def _current(self) -> TaxonomyIndex:
        from cbrs.reasoner.taxonomy import TaxonomyIndex

        kb = self.sparql.kb
        generation: object = self.sparql.generation
        if is_remote(kb.store.location):
            generation = (generation, kb.store.count(GraphName.ONTOLOGY), kb.store.count(GraphName.SERVICES))
        if generation != self._generation or self._index is None:
            self._generation, self._index, self._built = generation, TaxonomyIndex.from_kb(kb), {}
        return self._index
