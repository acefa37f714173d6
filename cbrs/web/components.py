"""Live components over HTTP: register with the bearer token, keep the lease, end it; list their states.

- ``POST /components`` (``text/turtle`` or ``application/ld+json`` body, ``?ttl=`` seconds) registers the
  components the description describes, as ``/cbrs/register`` does on the bridge: 201 with the IRIs
  and a lease id;
- ``POST /components/leases/<id>`` renews the lease (the heartbeat); 404 once it has lapsed;
- ``DELETE /components/leases/<id>`` ends it: the components become unavailable at once;
- ``GET /components`` lists every live component's state (available, until when, why not).

Registering and the lease need the update token (``Authorization: Bearer``); the listing does not.
"""

from __future__ import annotations

import hmac
import secrets

from flask import Blueprint, Response, current_app, jsonify, request
from werkzeug.exceptions import BadRequest, Forbidden, NotFound, UnsupportedMediaType

from cbrs.component_protocol import READ_ONLY
from cbrs.live_components import LiveComponents
from cbrs.web import context

__all__ = ["blueprint"]

blueprint = Blueprint("components", __name__)

FORMATS = {"text/turtle": "turtle", "application/ld+json": "json-ld"}


def _live() -> LiveComponents:
    found: LiveComponents = current_app.extensions["cbrs.live"]
    return found


def _authorised() -> None:
    config = context.sparql().config
    if config.read_only or config.update_token is None:  # a registration writes the store: none, token or not
        raise Forbidden(READ_ONLY)
    header = request.headers.get("Authorization", "")
    given = header[7:].strip() if header.lower().startswith("bearer ") else ""
    if not given or not hmac.compare_digest(given.encode("utf-8"), config.update_token.encode("utf-8")):
        raise Forbidden("registering a component needs the server's update token: Authorization: Bearer <token>")


@blueprint.post("/components")
def register() -> tuple[Response, int]:
    _authorised()
    fmt = FORMATS.get(request.mimetype)
    if fmt is None:
        raise UnsupportedMediaType(
            f"send the description as {' or '.join(FORMATS)}, not {request.mimetype or '(none)'}"
        )
    try:
        text = request.get_data(as_text=False).decode("utf-8")
    except UnicodeDecodeError as error:
        raise BadRequest(f"the description is not UTF-8: {error}") from error
    try:
        ttl = float(request.args.get("ttl", _live().ttl))
    except ValueError:
        raise BadRequest(f"ttl must be a number of seconds, not {request.args.get('ttl')!r}") from None
    if not 0.1 <= ttl <= 3600:
        raise BadRequest(f"ttl must be from 0.1 to 3600 s, not {ttl:g}")
    lease = "http-" + secrets.token_urlsafe(12)
    components = _live().register(text, lease, fmt, ttl)  # a library error is answered by the app's handler
    return jsonify({"components": components, "lease": lease, "ttl": ttl}), 201


@blueprint.post("/components/leases/<lease>")
def renew(lease: str) -> Response:
    _authorised()
    renewed = _live().renew(lease)
    if not renewed:
        raise NotFound(f"no live lease {lease!r}: it lapsed or was ended; register again")
    return jsonify({"components": renewed})


@blueprint.delete("/components/leases/<lease>")
def end(lease: str) -> Response:
    _authorised()
    _live().disconnected(lease)
    return Response(status=204)


@blueprint.get("/components")
def states() -> Response:
    found = context.kb().liveness.states()
    return jsonify(
        [
            {
                "component": state.component,
                "available": state.live,
                "leaseUntil": state.lease_until.isoformat() if state.lease_until else None,
                "reason": state.reason,
                "registeredBy": state.registered_by,
            }
            for state in sorted(found.values(), key=lambda s: s.component)
        ]
    )
