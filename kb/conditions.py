"""How a precondition or effect is written: a condition node with three annotation properties.

A condition is a statement about classes, such as (Door, hasStatus, Opened). Its node is typed
``cbrs:Precondition``, ``cbrs:Effect`` or ``cbrs:DeleteEffect`` and carries ``cbrs:conditionSubject``,
``cbrs:conditionPredicate`` and ``cbrs:conditionObject``. These are annotation properties, so the
ontologies stay in OWL 2 DL: the OWL API (and Protégé) keeps them through a load and save, and a
reasoner draws nothing from them. Core 0.1.0 wrote them as reified ``rdf:Statement`` s (``rdf:subject``,
``rdf:predicate``, ``rdf:object``), which OWL 2 DL reserves and the OWL API drops; :mod:`kb.upgrade`
rewrites a store of that form when it is opened (docs/ontologies.md).
"""

from __future__ import annotations

from typing import Final

from cbrs.kb.namespaces import RDF
from cbrs.kb.vocab import CBRS

__all__ = ["CONDITION_PARTS", "LEGACY_PARTS"]

# subject, predicate, object, in that order
CONDITION_PARTS: Final = (CBRS.conditionSubject, CBRS.conditionPredicate, CBRS.conditionObject)
# the reified form of core 0.1.0, and what each part became
LEGACY_PARTS: Final = {
    RDF + "subject": CBRS.conditionSubject,
    RDF + "predicate": CBRS.conditionPredicate,
    RDF + "object": CBRS.conditionObject,
}
