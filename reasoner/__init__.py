"""Semantic matchmaking of requirements against advertisements (paper sections 3.2 and 4).

The matchmaker ranks every advertisement with the paper's Sem-Str similarity, conceptual span
similarity over part trees and RDF-statement matching, or with a baseline; docs/matchmaking.md has the
formulas.
"""

from cbrs.reasoner.config import MatchConfig
from cbrs.reasoner.degrees import Degree, degree_of_match
from cbrs.reasoner.matchmaker import Candidate, EntityPair, Matchmaker, MatchResult, MatchStatus
from cbrs.reasoner.methods import METHODS
from cbrs.reasoner.similarity import Lin, SemStr, Similarity, StringMatch, WuPalmer
from cbrs.reasoner.taxonomy import TaxonomyIndex

__all__ = [
    "METHODS",
    "Candidate",
    "Degree",
    "EntityPair",
    "Lin",
    "MatchConfig",
    "MatchResult",
    "MatchStatus",
    "Matchmaker",
    "SemStr",
    "Similarity",
    "StringMatch",
    "TaxonomyIndex",
    "WuPalmer",
    "degree_of_match",
]
