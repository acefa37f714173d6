"""Moved to :mod:`cbrs.kb.sparql_hints`, where the knowledge base explains its own syntax errors; kept for
``cbrs.sparql_service``, which imports it from here until it imports it from there."""

from cbrs.kb.sparql_hints import FORMS, TOKENS, explain_syntax_error, first_keyword

__all__ = ["FORMS", "TOKENS", "explain_syntax_error", "first_keyword"]
