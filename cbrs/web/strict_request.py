"""Request parameters read strictly: a percent-escape that does not decode is a 400, not a changed text.

Werkzeug reads the query string and an urlencoded form leniently: bytes that are not UTF-8 once
percent-decoded stay percent-encoded in the value. So ``update=INSERT DATA { ... "caf%E9" }``, an
update encoded in Latin-1, stored the literal ``"caf%E9"`` and answered 204, and a query with such a
byte failed with a parser message about a column the client never wrote. Here such a request is
refused with 400 naming the parameter and the byte. A form that declares its charset
(``application/x-www-form-urlencoded; charset=iso-8859-1``) is read in it; one that declares a charset
Python does not know is refused the same way.
"""

from __future__ import annotations

from functools import cached_property
from typing import IO, Any
from urllib.parse import unquote_to_bytes

from flask import Request
from werkzeug.datastructures import MultiDict
from werkzeug.exceptions import BadRequest
from werkzeug.formparser import FormDataParser

__all__ = ["BadParameterEncoding", "StrictRequest", "parameters"]

FORM_FIELD = "the form field"
URL_PARAMETER = "the URL's parameter"


class BadParameterEncoding(BadRequest):
    """A request parameter whose percent-decoded bytes are not text in the request's charset."""

    def __init__(self, where: str, parameter: str, charset: str, error: UnicodeDecodeError) -> None:
        self.where = where
        self.parameter = parameter
        byte = error.object[error.start : error.start + 1].hex().upper()
        fix = "percent-encode the text's UTF-8 bytes (é is %C3%A9)"
        if where == FORM_FIELD:
            fix += ", or name the form's charset (application/x-www-form-urlencoded; charset=...)"
        super().__init__(
            f"{where} {parameter!r} is not {charset} once percent-decoded (byte %{byte} at position {error.start}); "
            + fix
        )


def parameters(raw: bytes, where: str, charset: str = "UTF-8") -> list[tuple[str, str]]:
    """The ``name=value`` pairs of an urlencoded ``raw`` (a query string or a form body), each decoded in
    ``charset``; :class:`BadParameterEncoding` for one that does not decode. ``where`` names the place
    in the message ("the URL's parameter", "the form field")."""
    pairs = []
    for field in raw.split(b"&"):
        if not field:
            continue
        name_bytes, _, value_bytes = field.partition(b"=")
        name = _decoded(name_bytes, where, charset, None)
        pairs.append((name, _decoded(value_bytes, where, charset, name)))
    return pairs


def _decoded(part: bytes, where: str, charset: str, name: str | None) -> str:
    data = unquote_to_bytes(part.replace(b"+", b" "))
    try:
        return data.decode(charset)
    except UnicodeDecodeError as error:
        shown = name if name is not None else data.decode(charset, "replace")
        raise BadParameterEncoding(where, shown, charset, error) from None


class _StrictFormParser(FormDataParser):
    def _parse_urlencoded(
        self, stream: IO[bytes], mimetype: str, content_length: int | None, options: dict[str, str]
    ) -> tuple[IO[bytes], MultiDict[str, Any], MultiDict[str, Any]]:
        charset = options.get("charset", "").strip().strip('"') or "UTF-8"
        try:
            "".encode(charset)  # a charset Python knows (LookupError), and one that is a text encoding
        except LookupError:
            raise BadRequest(f"the form's charset {charset!r} is not one this server knows; send UTF-8") from None
        items = parameters(stream.read(), FORM_FIELD, charset)
        return stream, self.cls(items), self.cls()


class StrictRequest(Request):
    """Flask's request with its query string and urlencoded form read strictly (see the module), and a
    JSON body nested past what Python's parser reads refused with 400 (it was a RecursionError: 500)."""

    form_data_parser_class = _StrictFormParser

    def get_json(self, force: bool = False, silent: bool = False, cache: bool = True) -> Any:
        try:
            return super().get_json(force=force, silent=silent, cache=cache)
        except RecursionError:
            raise BadRequest(
                "the JSON body nests deeper than this server reads (about 1,000 levels); send a flatter document"
            ) from None

    @cached_property
    def args(self) -> MultiDict[str, str]:
        try:
            return self.parameter_storage_class(parameters(self.query_string, URL_PARAMETER))
        except BadParameterEncoding:
            # refused once; what the error page reads of the parameters afterwards is werkzeug's lenient view
            self.__dict__["args"] = super().args
            raise
