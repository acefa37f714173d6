"""Matchmaking: taxonomy index, Sem-Str similarity, conceptual span similarity and PE matching.

Empty until the matchmaking work lands; see docs/architecture.md for where it fits.
"""
