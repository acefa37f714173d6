"""What a component's program and the server that registers it must agree on: the lease's default
length, the description formats, the words a heartbeat's refusal starts with, and where a description
names its rosbridge service.

Apart from :mod:`cbrs.live_components` (the server's side, with the store, the SPARQL service and the
bridge) so that the SDK (:mod:`cbrs.component`), which runs in the component's own program, imports
only these.
"""

from __future__ import annotations

import pyoxigraph as ox

from cbrs.kb.namespaces import RDF
from cbrs.kb.vocab import CBRS

__all__ = ["DEFAULT_TTL", "DEREGISTERED", "FORMATS", "NO_LIVE_COMPONENT", "READ_ONLY", "UNPROVIDED", "grounding"]

DEFAULT_TTL = 3.0
"""Seconds a lease lasts unless renewed: three missed one-second heartbeats."""
FORMATS = {"turtle": ox.RdfFormat.TURTLE, "json-ld": ox.RdfFormat.JSON_LD}
NO_LIVE_COMPONENT = "this session has no live component"
"""How a heartbeat says the session's registration is gone (its lease lapsed): register again."""
DEREGISTERED = "was deregistered"
"""How a heartbeat says a component was deregistered (``cbrs deregister``): do not register it again."""
UNPROVIDED = "no bridge client provides its service"
"""How a lease ended because nobody answers the component's service: a bridge registration whose program
never advertised the service its description names (a misspelt name), or an HTTP one whose provider left."""
READ_ONLY = (
    "this server is read-only, so it registers no component: start cbrs serve with an update token "
    "(CBRS_UPDATE_TOKEN or --update-token-file, without --read-only) and give the component that token"
)
"""Why a server without an update token, or started ``--read-only``, refuses a registration, over the
bridge and over HTTP alike: no token the component could send would help."""


def grounding(quads: list[ox.Quad], component: str) -> tuple[str, str] | None:
    """The rosbridge service and its type a description's service port names, if one does."""
    ports = [q.object for q in quads if q.subject == ox.NamedNode(component) and q.predicate.value == CBRS.hasPort]
    for port in ports:
        facts: dict[str, str] = {}
        for q in quads:
            if q.subject == port and isinstance(q.object, ox.NamedNode | ox.Literal):
                facts.setdefault(q.predicate.value, q.object.value)
        if facts.get(RDF + "type") == CBRS.ServicePort and CBRS.topic in facts and CBRS.messageType in facts:
            return facts[CBRS.topic], facts[CBRS.messageType]
    return None
