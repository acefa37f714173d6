"""Degrees of match between a requested and an advertised concept (OWL-S style, paper section 4)."""

from __future__ import annotations

from enum import Enum

from cbrs.reasoner.taxonomy import TaxonomyIndex


class Degree(Enum):
    EXACT = "Exact"  # the same concept (or equivalent)
    SUBCLASS_OF = "SubClassOf"  # the advertised concept is a subclass (subproperty) of the requested one
    HAS_SUBCLASS = "HasSubClass"  # the advertised concept is a superclass of the requested one
    FAIL = "Fail"

    @property
    def accepted(self) -> bool:
        """The paper's acceptance threshold: {Exact, SubClassOf, HasSubClass}."""
        return self is not Degree.FAIL


ACCEPTED = frozenset({Degree.EXACT, Degree.SUBCLASS_OF, Degree.HAS_SUBCLASS})


def degree_of_match(index: TaxonomyIndex, requested: str, advertised: str) -> Degree:
    """How ``advertised`` relates to ``requested`` by is-a links only (hasPart does not subsume)."""
    if requested == advertised:
        return Degree.EXACT
    if requested not in index or advertised not in index:
        return Degree.FAIL
    if index.canonical(requested) == index.canonical(advertised):
        return Degree.EXACT
    if index.canonical(requested) in index.is_a_ancestors(advertised):
        return Degree.SUBCLASS_OF
    if index.canonical(advertised) in index.is_a_ancestors(requested):
        return Degree.HAS_SUBCLASS
    return Degree.FAIL
