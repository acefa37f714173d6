"""The SPARQL 1.1 Protocol at ``/sparql`` (query and update) and ``/update`` (update only).

A thin layer: it reads the request the three ways the protocol allows (GET, POST form, POST direct;
HEAD answers as GET without a body), with the dataset parameters ``default-graph-uri`` and
``named-graph-uri``, hands the text to :class:`cbrs.sparql_service.SparqlService` and maps its errors
to statuses.
"""

from __future__ import annotations

import difflib
from collections.abc import Iterable

import pyoxigraph as ox
from flask import Blueprint, Response, g, request, url_for
from werkzeug.datastructures import MIMEAccept, MultiDict

from cbrs.sparql_service import (
    GRAPH_TYPES,
    RESULT_TYPES,
    Dataset,
    EndpointError,
    UpdateForbiddenError,
    accept_ranges,
    identity_header,
    negotiate,
)
from cbrs.web import context

blueprint = Blueprint("sparql", __name__)

QUERY_TYPE = "application/sparql-query"
UPDATE_TYPE = "application/sparql-update"
FORM_TYPE = "application/x-www-form-urlencoded"
_RDF_TYPE = "http://www.w3.org/1999/02/22-rdf-syntax-ns#type"
# The protocol's dataset parameters: of a query, and of an update (which cbrs does not take).
QUERY_DATASET = ("default-graph-uri", "named-graph-uri")
UPDATE_DATASET = ("using-graph-uri", "using-named-graph-uri")


class BadProtocolRequest(EndpointError):
    http_status = 400
    kind = "bad-request"


class UnsupportedMediaType(EndpointError):
    http_status = 415
    kind = "unsupported-media-type"

    def __init__(self, media_type: str) -> None:
        self.media_type = media_type
        super().__init__(
            f"a POST to the SPARQL endpoint must be {FORM_TYPE}, {QUERY_TYPE} or {UPDATE_TYPE}, not {media_type!r}"
        )


@blueprint.route("/sparql", methods=["GET", "POST"])
def sparql() -> Response:
    query, update = _operation()
    if update is not None:
        return _update(update)
    if query is None:
        misspelt = misspelt_parameter(request.args)
        if misspelt:  # "qeury=" would have been answered with the service description, as if no query was sent
            raise BadProtocolRequest(
                f"GET {request.path} has no parameter {misspelt}; without one it describes the endpoint"
            )
        if request.path == "/sparql" and request.method in ("GET", "HEAD") and _person_asks():
            # a person gets the editor, a client the description
            return Response(status=303, headers={"Location": url_for("editor.editor")})
        return _service_description()
    dataset = Dataset.from_parameters(
        request.values.getlist(QUERY_DATASET[0]), request.values.getlist(QUERY_DATASET[1])
    )
    answer = context.sparql().query(
        query, request.headers.get("Accept"), _short_format(), client=request.remote_addr, dataset=dataset
    )
    return Response(answer.body, content_type=_with_charset(answer.media_type))


@blueprint.after_request
def _vary(response: Response) -> Response:
    # The answer depends on the Accept header, and its CORS headers on the Origin: caches must key on both.
    response.vary.update(("Accept", "Origin"))
    response.headers.setdefault(*identity_header())  # a remote store client learns the server checks updates
    return response


@blueprint.route("/update", methods=["POST"])
def update_only() -> Response:
    query, update = _operation()
    if query is not None or update is None:
        raise BadProtocolRequest("/update takes an update (form field update= or a sparql-update body), not a query")
    return _update(update)


_HTML = ("text/html", "application/xhtml+xml")
_SPARQL_TYPES = tuple(dict.fromkeys((*RESULT_TYPES, *GRAPH_TYPES)))


def wants_protocol() -> bool:
    """Whether a request to a page that shares its path with a SPARQL endpoint (``/query``: the editor
    there, the query endpoint in Oxigraph's layout) comes from a SPARQL client rather than a browser.

    A SPARQL body or an update, a ``format``/``output`` parameter, or an ``Accept`` header that ranks a
    SPARQL result type above HTML say so; a header that accepts anything (curl's ``*/*``) does when the
    request carries a query. Browsers name ``text/html`` first, and a request without ``Accept`` keeps
    the page, as before."""
    if request.method == "POST" and request.mimetype in (QUERY_TYPE, UPDATE_TYPE):
        return True
    if "update" in (request.form if request.method == "POST" else request.args):
        return True
    if request.args.get("format") or request.args.get("output"):
        return True
    accept = request.headers.get("Accept")
    ranges = accept_ranges(accept) if accept else []
    if not ranges:
        return False
    parsed = MIMEAccept(ranges)
    html = max(parsed.quality(media) for media in _HTML)
    best = max(parsed.quality(media) for media in _SPARQL_TYPES)
    if best != html:
        return best > html
    named_html = any(media in _HTML for media, _ in ranges)
    return best > 0 and not named_html and "query" in request.values


def _person_asks() -> bool:
    """Whether a request without a query ranks HTML above every type the service description comes in:
    a browser (``text/html`` first, ``*/*`` after). A SPARQL client naming an RDF type, ``*/*`` alone, no
    ``Accept`` or a ``format`` parameter keep the description."""
    accept = request.headers.get("Accept")
    ranges = accept_ranges(accept) if accept else []
    if not ranges or _short_format():
        return False
    parsed = MIMEAccept(ranges)
    return max(parsed.quality(media) for media in _HTML) > max(parsed.quality(media) for media in GRAPH_TYPES)


def protocol_answer() -> Response:
    """The SPARQL endpoint's answer to this request, whatever its path (errors in JSON, as ``/sparql``'s)."""
    g.sparql_protocol = True
    response = sparql()
    response.vary.update(("Accept", "Origin"))
    response.headers.setdefault(*identity_header())
    return response


def misspelt_parameter(fields: Iterable[str], known: Iterable[str] = ("query", "update")) -> str:
    """``'qeury': did you mean query=?`` for the first field that reads as a misspelt one of ``known``
    (by default a SPARQL operation's), else empty. Fields far from all of them (a client's own) pass."""
    names = tuple(known)
    for name in fields:
        near = difflib.get_close_matches(name.lower(), names, n=1, cutoff=0.6)
        if near and name != near[0]:
            return f"{name!r}: did you mean {near[0]}=?"
    return ""


def _operation() -> tuple[str | None, str | None]:
    """The query or the update text of the request, whichever it carries; never both."""
    if request.method in ("GET", "HEAD"):
        if "update" in request.args:
            raise BadProtocolRequest("an update must be sent with POST")
        query, update = _one("query", request.args), None
    else:
        in_url = [name for name in ("query", "update") if name in request.args]
        if in_url:  # which of the two texts was meant? The body's was run, the URL's ignored without a word
            raise BadProtocolRequest(
                f"a POST carries its {in_url[0]} in the body, but the URL has {in_url[0]}= too; send it once"
            )
        media_type = request.mimetype
        if media_type == FORM_TYPE:
            query, update = _one("query", request.form), _one("update", request.form)
        elif media_type == QUERY_TYPE:
            query, update = _body(), None
        elif media_type == UPDATE_TYPE:
            query, update = None, _body()
        else:
            raise UnsupportedMediaType(media_type or "(none)")
        if query is not None and update is not None:
            raise BadProtocolRequest("a request carries a query or an update, not both")
        if query is None and update is None:
            misspelt = misspelt_parameter(request.form) if media_type == FORM_TYPE else ""
            raise BadProtocolRequest(
                "the POST carries neither query= nor update=" + (f" (it has {misspelt})" if misspelt else "")
            )
    _check_dataset_parameters(update is not None)
    return query, update


def _one(name: str, values: MultiDict[str, str]) -> str | None:
    """The single value of parameter ``name``; the protocol allows exactly one query or update per request."""
    given = values.getlist(name)
    if len(given) > 1:
        raise BadProtocolRequest(f"the request carries {len(given)} {name}= parameters; send exactly one")
    return given[0] if given else None


def _check_dataset_parameters(updating: bool) -> None:
    """Refuse the dataset parameters of the other operation, and an update's (cbrs has no USING rewrite)."""
    for name in UPDATE_DATASET:
        if name in request.values:
            if not updating:
                raise BadProtocolRequest(f"{name} belongs to updates; scope a query with default-graph-uri or FROM")
            raise BadProtocolRequest(
                f"{name} is not supported; name the graph in the update itself (WITH, USING or GRAPH)"
            )
    for name in QUERY_DATASET:
        if updating and name in request.values:
            raise BadProtocolRequest(f"{name} belongs to queries; an update names its graphs with WITH, USING or GRAPH")


def _body() -> str:
    """The body's text, in the charset its Content-Type declares (UTF-8 when it declares none)."""
    charset = request.mimetype_params.get("charset") or "utf-8"
    try:
        return request.get_data(as_text=False).decode(charset)
    except LookupError:
        raise BadProtocolRequest(f"the request body's charset {charset!r} is not one this server knows") from None
    except UnicodeDecodeError as error:
        raise BadProtocolRequest(f"the request body is not {charset}: {error}") from error


def _update(text: str) -> Response:
    context.sparql().update(text, bearer_token())
    return Response(status=204)


def bearer_token() -> str | None:
    header = request.headers.get("Authorization", "")
    scheme, _, token = header.partition(" ")
    return token.strip() if scheme.lower() == "bearer" and token.strip() else None


def typed_token_refusal(error: UpdateForbiddenError, typed: str) -> str:
    """A refused write said in a page's words when its token came from the page's field: a person in a
    browser cannot send the ``Authorization: Bearer`` header the endpoint's message names. A server that
    takes no token (none set, or read-only), a header's token or a program's JSON keep the message."""
    config = context.sparql().config
    if request.is_json or bearer_token() or config.read_only or config.update_token is None:
        return str(error)
    if not typed:
        return (
            "writing into the store needs the server's update token: type it in the Update token field "
            "(whoever started cbrs serve has it)"
        )
    return "the token typed is not this server's update token: check it with whoever started cbrs serve"


def _short_format() -> str | None:
    return request.values.get("format") or request.values.get("output")


def _with_charset(media_type: str) -> str:
    return media_type + "; charset=utf-8"


def _service_description() -> Response:
    """A GET without a query describes the endpoint (SPARQL 1.1 Service Description), as RDF, to a client
    (a browser is sent to the editor: :func:`_person_asks`)."""
    sd = "http://www.w3.org/ns/sparql-service-description#"
    formats = "http://www.w3.org/ns/formats/"
    endpoint = ox.NamedNode(request.base_url)
    node = ox.BlankNode("service")
    triples = [
        ox.Triple(node, ox.NamedNode(_RDF_TYPE), ox.NamedNode(sd + "Service")),
        ox.Triple(node, ox.NamedNode(sd + "endpoint"), endpoint),
        ox.Triple(node, ox.NamedNode(sd + "supportedLanguage"), ox.NamedNode(sd + "SPARQL11Query")),
        ox.Triple(node, ox.NamedNode(sd + "feature"), ox.NamedNode(sd + "UnionDefaultGraph")),
    ]
    if context.sparql().writable:
        triples.append(ox.Triple(node, ox.NamedNode(sd + "supportedLanguage"), ox.NamedNode(sd + "SPARQL11Update")))
    for name in (
        "SPARQL_Results_JSON",
        "SPARQL_Results_XML",
        "SPARQL_Results_CSV",
        "SPARQL_Results_TSV",
        "Turtle",
        "N-Triples",
        "N-Quads",
        "TriG",
        "N3",
        "RDF_XML",
        "JSON-LD",
    ):
        triples.append(ox.Triple(node, ox.NamedNode(sd + "resultFormat"), ox.NamedNode(formats + name)))
    media_type = negotiate(True, request.headers.get("Accept"), _short_format())
    body = ox.serialize(triples, format=GRAPH_TYPES[media_type])
    return Response(body, content_type=_with_charset(media_type))
