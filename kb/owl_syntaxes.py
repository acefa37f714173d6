"""The OWL 2 syntaxes that are not RDF, told apart from RDF by a file's content, so that a load refuses them
in words a Protégé user can act on.

Protégé saves an ontology in RDF/XML (its default), Turtle, OWL/XML, OWL functional syntax or Manchester
syntax, and keeps the ``.owl`` extension whichever is chosen. cbrs reads RDF only: the store holds triples,
and the OWL 2 mapping from the other three to triples is the OWL API's, which cbrs does not carry (owlready2's
OWL/XML reader drops a trailing ``/`` from every IRI and turns decimals into floats, so a file read through it
would not be the file). An OWL/XML file read as RDF/XML failed "XML namespaces are required in RDF/XML", which
says nothing of what to do; :func:`check_rdf` names the syntax and the two Protégé can save instead.
"""

from __future__ import annotations

import re

from cbrs.kb.errors import RdfParseError

__all__ = ["MEDIA_TYPES", "NotRdfSyntaxError", "check_rdf", "owl_syntax"]

MEDIA_TYPES = {
    "application/owl+xml": "OWL/XML",
    "text/owl-functional": "OWL functional syntax",
    "text/owl-manchester": "Manchester syntax",
}
"""The media types OWL 2 registers for its syntaxes that are not RDF (OWL 2 Overview, section 2.1)."""

# An OWL/XML document's root element: <Ontology xmlns="...owl#"> (or a prefixed Ontology declaring the OWL
# namespace). Asked of the root's start tag alone (:func:`_root_tag`): one expression over the prolog too, its
# comments and DOCTYPE each optional inside a repetition, backtracked for minutes on an OWL-S file's entities.
_ONTOLOGY_TAG = re.compile(rb"<(?:[\w.-]+:)?Ontology[\s/>]")
_OWL_NAMESPACE = re.compile(rb"xmlns(?::[\w.-]+)?\s*=\s*[\"']http://www\.w3\.org/2002/07/owl#[\"']")
# Functional syntax opens with Prefix(...) or Ontology(, Manchester syntax with "Prefix: p: <IRI>" or
# "Ontology:", after comments and blank lines. Turtle's "Prefix : <IRI>" (SPARQL style, the empty prefix) has
# a space before its colon and no second one, so it is neither.
_FUNCTIONAL = re.compile(rb"^(?:\s|#[^\n]*\n)*(?:Prefix|Ontology|Import)\s*\(")
_MANCHESTER = re.compile(rb"^(?:\s|#[^\n]*\n)*(?:Prefix:\s+[\w.-]*:\s*<|Ontology:)")


class NotRdfSyntaxError(RdfParseError):
    """A file in one of OWL 2's syntaxes that are not RDF (OWL/XML, functional, Manchester). Nothing was
    loaded; ``syntax`` names the one found. Its JSON error's name is a parse error's, as the endpoint documents a
    body that does not parse."""

    kind = "RdfParseError"

    def __init__(self, source: str, syntax: str) -> None:
        self.syntax = syntax
        super().__init__(
            source,
            f"this is {syntax}, which cbrs does not read (it reads RDF: Turtle, RDF/XML, N-Triples, N-Quads, "
            "TriG, JSON-LD); save the ontology from Protégé as RDF/XML or Turtle (File, Save as) and load that; "
            "nothing was loaded",
        )


def owl_syntax(data: bytes) -> str | None:
    """The name of the non-RDF OWL syntax ``data`` (UTF-8) is written in, by its content whatever the file's
    extension, or ``None`` for anything else (RDF, or text no syntax claims: the RDF parsers then say what is
    wrong with it)."""
    head = data[:65536]
    root = _root_tag(head)
    if root is not None and _ONTOLOGY_TAG.match(root) and _OWL_NAMESPACE.search(root):
        return "OWL/XML"
    if _FUNCTIONAL.match(head):
        return "OWL functional syntax"
    if _MANCHESTER.match(head):
        return "Manchester syntax"
    return None


def _root_tag(head: bytes) -> bytes | None:
    """The start tag of the XML root element in ``head``, past the prolog (a byte order mark, white space,
    processing instructions, comments, a DOCTYPE with its internal subset), in one pass; ``None`` when
    ``head`` does not open as XML does, or ends first."""
    at = 3 if head.startswith(b"\xef\xbb\xbf") else 0
    while True:
        while at < len(head) and head[at] in b" \t\r\n":
            at += 1
        if head.startswith(b"<?", at):
            end = head.find(b"?>", at + 2)
            at = -1 if end < 0 else end + 2
        elif head.startswith(b"<!--", at):
            end = head.find(b"-->", at + 4)
            at = -1 if end < 0 else end + 3
        elif head.startswith(b"<!DOCTYPE", at):
            close, subset = head.find(b">", at), head.find(b"[", at)
            if 0 <= subset < close:  # the internal subset's declarations hold '>' of their own
                close = head.find(b">", max(head.find(b"]", subset), subset))
            at = -1 if close < 0 else close + 1
        elif head.startswith(b"<", at):
            end = head.find(b">", at)
            return head[at : end + 1] if end >= 0 else None
        else:
            return None
        if at < 0:
            return None


def check_rdf(data: bytes, source: str) -> None:
    """Raise :class:`NotRdfSyntaxError` when ``data`` is in a non-RDF OWL syntax."""
    syntax = owl_syntax(data)
    if syntax is not None:
        raise NotRdfSyntaxError(source, syntax)
