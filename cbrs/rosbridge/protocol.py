"""The rosbridge v2 wire format: decoding and checking client messages, encoding server messages.

Every check raises :class:`ProtocolError` with a reason a person can act on; the bridge turns it into a
``status`` message and keeps the connection. Names are resolved as ROS resolves names of a node in the
root namespace: ``chatter`` and ``/chatter`` are the same topic.
"""

from __future__ import annotations

import array
import functools
import json
import re
import sys
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from cbrs.rosbridge.errors import ProtocolError

Message = dict[str, Any]
MessageId = str | int

#: What a missing field most often means, for the clients that leave it out.
MISSING_HINTS = {
    ("service_response", "result"): (
        " (roslibjs sends none when an advertise callback returns nothing: return true, or false to fail)"
    ),
}

#: Status levels, least verbose first; a client at level L receives statuses of levels up to L.
LEVELS = ("none", "error", "warning", "info")


@dataclass(frozen=True)
class Field:
    """One field of an op: its name, the JSON types it may have, whether it must be there."""

    name: str
    kinds: tuple[type, ...]
    required: bool = True


def _opt(name: str, *kinds: type) -> Field:
    return Field(name, kinds, required=False)


def _req(name: str, *kinds: type) -> Field:
    return Field(name, kinds)


#: The ops this server implements and their fields (``op`` and ``id`` are common to all; other fields
#: are ignored, as rosbridge does).
OPS: dict[str, tuple[Field, ...]] = {
    "advertise": (_req("topic", str), _req("type", str), _opt("latch", bool), _opt("queue_size", int)),
    "unadvertise": (_req("topic", str),),
    "publish": (_req("topic", str), _opt("msg", dict), _opt("latch", bool)),
    "subscribe": (
        _req("topic", str),
        _opt("type", str),
        _opt("throttle_rate", int),
        _opt("queue_length", int),
        _opt("fragment_size", int),
        _opt("compression", str),
    ),
    "unsubscribe": (_req("topic", str),),
    "call_service": (
        _req("service", str),
        _opt("args", dict, list),
        _opt("type", str),
        _opt("timeout", float),
        _opt("fragment_size", int),
        _opt("compression", str),
    ),
    "service_response": (_req("service", str), _opt("values", dict, str), _req("result", bool)),
    "advertise_service": (_req("service", str), _req("type", str)),
    "unadvertise_service": (_req("service", str),),
    "advertise_action": (_req("action", str), _req("type", str)),
    "unadvertise_action": (_req("action", str),),
    "send_action_goal": (
        _req("action", str),
        _req("action_type", str),
        _opt("args", dict, list),
        _opt("feedback", bool),
        _opt("fragment_size", int),
        _opt("compression", str),
    ),
    "cancel_action_goal": (_req("action", str),),
    "action_feedback": (_req("action", str), _opt("values", dict)),
    "action_result": (_req("action", str), _opt("values", dict), _req("status", int), _req("result", bool)),
    "set_level": (_req("level", str),),
    # one piece of a message sent in pieces (cbrs.rosbridge.wire); ``id`` names the message
    "fragment": (_req("data", str), _req("num", int), _req("total", int)),
    # rosbridge's auth op carries a rosauth MAC; cbrs reads its update token from ``mac`` (or ``token``)
    "auth": (_opt("mac", str), _opt("token", str)),
}

#: Ops of the rosbridge protocol this server knows about but does not implement, and why.
UNSUPPORTED = {
    "png": "PNG-compressed messages from a client are not supported; send JSON text (or fragments)",
}

_TYPE_NAMES = {
    str: "a string",
    int: "an integer",
    float: "a number",
    bool: "a boolean",
    dict: "an object",
    list: "an array",
}


def json_type(value: Any) -> str:
    """The JSON name of a decoded value's type, for messages."""
    if value is None:
        return "null"
    if isinstance(value, bool):
        return "boolean"
    if isinstance(value, int | float):
        return "number"
    if isinstance(value, str):
        return "string"
    if isinstance(value, list):
        return "array"
    return "object"


#: How the server writes a NaN or an infinity in JSON text, which has no such numbers (``Bridge(non_finite=)``):
#: ``null`` as rosbridge_suite writes a ROS float field (JSON.parse, so roslibjs, reads it; the value is
#: lost), ``tokens`` as Python's json writes them, ``NaN``, ``Infinity``, ``-Infinity`` (roslibpy and
#: rosbridge_suite read them back as the floats; JSON.parse, so roslibjs, refuses the whole message).
#: CBOR carries them as they are, either way.
NON_FINITE = ("null", "tokens")

# Made once: json.loads and json.dumps with options build a new decoder or encoder on every call. The
# decoder reads NaN, Infinity and -Infinity as floats, as rosbridge_suite's (Python's json) does: what
# roslibpy (Python's json.dumps) sends for them.
_DECODER = json.JSONDecoder()
_ENCODER = json.JSONEncoder(separators=(",", ":"), ensure_ascii=False, allow_nan=False)
_TOKENS = json.JSONEncoder(separators=(",", ":"), ensure_ascii=False, allow_nan=True)
_SCAN: Callable[[str, int], tuple[Any, int]] = getattr(_DECODER, "scan_once")  # noqa: B009 (not in typeshed)


def decode(text: str, limit: int) -> Message:
    """Parse one text frame into a message with a string ``op``; raises :class:`ProtocolError`."""
    if len(text) > limit or (len(text) * 4 > limit and len(text.encode("utf-8")) > limit):
        size = len(text.encode("utf-8"))
        raise ProtocolError(f"message of {size} bytes exceeds the limit of {limit} bytes (max_message_bytes)")
    try:
        message = _parse(text)
    except ValueError as error:
        raise ProtocolError(f"message is not valid JSON: {error}") from None
    except RecursionError:
        raise ProtocolError("message is nested too deeply to parse") from None
    if not isinstance(message, dict):
        raise ProtocolError(f"a rosbridge message must be a JSON object, not {json_type(message)}")
    message_id = message.get("id")
    if message_id is not None and (isinstance(message_id, bool) or not isinstance(message_id, str | int)):
        raise ProtocolError(f"field 'id' must be a string or an integer, not {json_type(message_id)}")
    if "op" not in message:
        raise ProtocolError("message has no 'op' field", message_id=message_id)
    op = message["op"]
    if not isinstance(op, str):
        raise ProtocolError(f"field 'op' must be a string, not {json_type(op)}", message_id=message_id)
    return message


LEADING_CHARS = 4096
"""How far into an unreadable message :func:`leading_fields` looks: ids and service names are short."""
_MEMBER = re.compile(
    r'\s*"((?:[^"\\]|\\.)*)"\s*:\s*("(?:[^"\\]|\\.)*"|-?\d+(?:\.\d+)?(?:[eE][+-]?\d+)?|true|false|null)\s*([,}])'
)


def leading_fields(text: str) -> Message:
    """The members of a message that could not be decoded (too large, or not JSON further on) that stand
    at its top level before its first object or array: ``op``, ``id`` and ``service`` as roslibpy and
    roslibjs write them, before ``args``. Enough to answer the call the message was, by its id; nothing
    nested is read, so a field of ``args`` named ``id`` is never taken for the message's."""
    fields: Message = {}
    start = text.find("{", 0, 64)
    if start < 0 or text[:start].strip():
        return fields
    position, end = start + 1, min(len(text), LEADING_CHARS)  # the head only: a huge message costs nothing more
    while (match := _MEMBER.match(text, position, end)) is not None:
        try:
            fields.setdefault(json.loads(f'"{match[1]}"'), json.loads(match[2]))
        except ValueError:  # an escape JSON does not have: read no further
            break
        if match[3] == "}":
            break
        position = match.end()
    return fields


def several(text: str, limit: int = 1000) -> list[str] | None:
    """The texts of the JSON objects ``text`` holds one after the other (``{...} {...}``), as rosbridge_suite
    reads a frame that carries several messages; None unless it holds two or more objects and nothing
    else but white space (at most ``limit``: the frame is within ``max_message_bytes`` anyway)."""
    found: list[str] = []
    position, end = 0, len(text)
    while position < end and len(found) < limit:
        while position < end and text[position] in " \t\r\n":
            position += 1
        if position == end:
            break
        if text[position] != "{":
            return None
        try:
            _, stop = _SCAN(text, position)
        except (StopIteration, ValueError, RecursionError):
            return None
        found.append(text[position:stop])
        position = stop
    return found if len(found) > 1 and position >= end else None


def _parse(text: str) -> Any:
    """``_DECODER.decode(text)``, through its scanner straight away for the usual frame (no white space
    around the object): ``decode`` matches a white-space pattern at both ends of every message first."""
    try:
        value, end = _SCAN(text, 0)
    except StopIteration:  # no value at the start: white space first, or not JSON (decode says which)
        return _DECODER.decode(text)
    return value if end == len(text) else _DECODER.decode(text)


def check(message: Message) -> str:
    """Check the fields of a decoded message against its op; returns the op. Normalises integral floats."""
    op: str = message["op"]
    message_id = message.get("id")
    if op not in OPS:
        if op in UNSUPPORTED:
            raise ProtocolError(UNSUPPORTED[op], op, message_id)
        raise ProtocolError(f"unknown op {op!r}; this server supports {', '.join(OPS)}", message_id=message_id)
    for field in OPS[op]:
        value = message.get(field.name)
        if type(value) in field.kinds:  # the common case, with nothing to convert (True is no integer here)
            continue
        if value is None:
            if field.required:
                hint = MISSING_HINTS.get((op, field.name), "")
                raise ProtocolError(f"missing required field {field.name!r}{hint}", op, message_id)
            continue
        converted = _convert(value, field.kinds)
        if converted is None:
            wanted = " or ".join(_TYPE_NAMES[kind] for kind in field.kinds)
            raise ProtocolError(f"field {field.name!r} must be {wanted}, not {json_type(value)}", op, message_id)
        message[field.name] = converted
    return op


def _convert(value: Any, kinds: tuple[type, ...]) -> Any:
    """``value`` if it has one of ``kinds`` (JSON numbers: 3.0 is an integer, 3 is a number), else None."""
    if isinstance(value, bool):
        return value if bool in kinds else None
    if int in kinds and isinstance(value, float) and value.is_integer():
        return int(value)
    if float in kinds and isinstance(value, int):
        return float(value)
    return value if isinstance(value, kinds) else None


def resolve(name: str, what: str = "name") -> str:
    """The global form of a topic, service or parameter name (``chatter`` -> ``/chatter``)."""
    if not name or name.isspace():
        raise ProtocolError(f"{what} must not be empty")
    return name if name.startswith("/") else "/" + name


def same_type(one: str, other: str) -> bool:
    """Whether two type names name the same type: ROS 2's ``std_msgs/msg/String`` is ROS 1's
    ``std_msgs/String`` (and ``pkg/srv/Name``, ``pkg/action/Name`` likewise), as rosbridge_suite's ROS 2
    loader reads either, so a roslibpy publisher and a ROS 2 roslibjs subscriber can share a topic."""
    return one == other or _short_type(one) == _short_type(other)


def _short_type(kind: str) -> str:
    parts = kind.split("/")
    return f"{parts[0]}/{parts[2]}" if len(parts) == 3 and parts[1] in ("msg", "srv", "action") else kind


def loads(text: str) -> Any:
    """Values back from JSON text this server wrote (a message's ``msg``, to send it again as CBOR)."""
    return _parse(text)


def check_non_finite(non_finite: str) -> str:
    """``non_finite`` if it is one of :data:`NON_FINITE`, else ValueError naming it."""
    if non_finite not in NON_FINITE:
        raise ValueError(f"non_finite must be one of {', '.join(NON_FINITE)}, not {non_finite!r}")
    return non_finite


def encode(
    value: Any,
    non_finite: str = "null",
    strict: Callable[[Any], str] = _ENCODER.encode,
    tokens: Callable[[Any], str] = _TOKENS.encode,
) -> tuple[str, bool]:
    """Compact JSON of ``value`` with its NaNs and infinities written as ``non_finite`` says, and whether
    the text holds every number of ``value`` (False: some became null; send CBOR from ``value`` itself).

    ``strict`` (NaN refused) and ``tokens`` (NaN written) are the encoders to use. A value with nothing
    but finite numbers, the usual one, is encoded once, at the strict encoder's speed."""
    if non_finite == "tokens":
        return tokens(value), True
    try:
        return strict(value), True
    except ValueError as error:  # a NaN or infinity (or a cycle, whose copy recurses without end)
        try:
            copy = finite(value)
        except RecursionError:
            raise error from None
        return strict(copy), False


def dumps(value: Any, non_finite: str = "null") -> str:
    """Compact JSON, NaNs and infinities written as ``non_finite`` says (:data:`NON_FINITE`)."""
    return encode(value, non_finite)[0]


def finite(value: Any) -> Any:
    """A copy of ``value`` with every NaN and infinity in it as None (JSON's null), and its arrays of
    floats (``array.array``, 1-D numpy arrays) as lists: what rosbridge_suite sends for a ROS float
    field JSON cannot hold. Values of other types are kept as they are (the encoder judges them)."""
    kind = type(value)
    if kind is float:
        return value if value - value == 0.0 else None  # inf - inf and NaN - NaN are NaN
    if kind is dict:
        return {key: finite(item) for key, item in value.items()}
    if kind is list or kind is tuple:
        return [finite(item) for item in value]
    if isinstance(value, float):  # a subclass: numpy.float64
        return float(value) if value - value == 0.0 else None
    if isinstance(value, dict):
        return {key: finite(item) for key, item in value.items()}
    if isinstance(value, list | tuple):
        return [finite(item) for item in value]
    if isinstance(value, array.array) and value.typecode in "fd":
        return [item if item - item == 0.0 else None for item in value.tolist()]
    numpy = sys.modules.get("numpy")  # not imported: no value can be an array of it
    if numpy is not None and isinstance(value, numpy.ndarray) and value.dtype.kind == "f":
        return [finite(item) for item in value.tolist()]
    return value


def _c_encoder(allow_nan: bool) -> Callable[[Any, int], Any]:
    """An encoder for values :func:`decode` made, which cannot hold a cycle: the C encoder made once,
    without the cycle check (``JSONEncoder.encode`` makes a new one on every call, about a microsecond of
    each message a publisher sends). Called with (value, 0), it gives the text's pieces."""
    make: Any = getattr(json.encoder, "c_make_encoder", None)
    try:
        encoder: Callable[[Any, int], Any] = make(
            None, _not_json, json.encoder.encode_basestring, None, ":", ",", False, False, allow_nan
        )
    except TypeError:  # no C accelerator, or another signature: the ordinary encoder
        ordinary = _TOKENS if allow_nan else _ENCODER
        return lambda value, _level: (ordinary.encode(value),)
    return encoder


def _not_json(value: Any) -> Any:
    raise TypeError(f"Object of type {type(value).__name__} is not JSON serializable")


_STRICT_C, _TOKENS_C = _c_encoder(False), _c_encoder(True)


def _decoded_strict(value: Any) -> str:
    return "".join(_STRICT_C(value, 0))


def _decoded_tokens(value: Any) -> str:
    return "".join(_TOKENS_C(value, 0))


def non_finite_field(value: Any) -> str | None:
    """Where the first NaN or infinity in a decoded ``value`` is, as a field path (``percent``,
    ``pose.x``, ``ranges[2]``) and the token roslibpy sends for it: ``"field 'percent' is NaN"``. None if
    it holds none, found at the C encoder's speed; the walk runs only when there is one."""
    try:
        _STRICT_C(value, 0)
        return None
    except ValueError:
        pass
    found = _non_finite_in(value, "")
    return None if found is None else f"field {found[0]!r} is {found[1]}"


def _non_finite_in(value: Any, path: str) -> tuple[str, str] | None:
    if isinstance(value, float) and value - value != 0.0:  # NaN, or an infinity (inf - inf is NaN)
        token = "NaN" if value != value else ("Infinity" if value > 0 else "-Infinity")
        return path or "(the values)", token
    items: Any = value.items() if isinstance(value, dict) else enumerate(value) if isinstance(value, list) else ()
    for key, item in items:
        found = _non_finite_in(item, f"{path}[{key}]" if isinstance(key, int) else f"{path}.{key}" if path else key)
        if found is not None:
            return found
    return None


def encode_decoded(value: Any, non_finite: str = "null") -> tuple[str, bool]:
    """:func:`encode` of a value that came out of :func:`decode` (what a client sent), faster: every
    message a publisher sends passes here (bench/rosbridge_relay.py)."""
    if non_finite == "null":
        try:
            return "".join(_STRICT_C(value, 0)), True
        except ValueError:  # a NaN or an infinity: encode writes a copy
            pass
    return encode(value, non_finite, _decoded_strict, _decoded_tokens)


def status(level: str, text: str, message_id: MessageId | None) -> str:
    """A ``status`` message."""
    message: Message = {"op": "status", "level": level, "msg": text}
    if message_id is not None:
        message["id"] = message_id
    return dumps(message)


def publish_text(topic: str, msg_json: str) -> str:
    """A ``publish`` message from an already encoded ``msg``."""
    return f"{_publish_head(topic)}{msg_json}}}"


@functools.lru_cache(maxsize=4096)
def _publish_head(topic: str) -> str:
    """The start of a ``publish`` message on ``topic``, encoded once per topic (every message needs it)."""
    return f'{{"op":"publish","topic":{dumps(topic)},"msg":'


def service_response(service: str, result: bool, values_json: str, message_id: MessageId | None) -> str:
    """A ``service_response`` from already encoded ``values`` (an object, or the error text on failure)."""
    tail = "" if message_id is None else f',"id":{dumps(message_id)}'
    flag = "true" if result else "false"
    return f'{{"op":"service_response","service":{dumps(service)},"values":{values_json},"result":{flag}{tail}}}'


def call_service(service: str, args: Any, message_id: str, non_finite: str = "null") -> str:
    """A ``call_service`` forwarded to the client that provides ``service``."""
    return dumps({"op": "call_service", "id": message_id, "service": service, "args": args}, non_finite)


def action_result(action: str, result: bool, status: int, values_json: str, message_id: MessageId | None) -> str:
    """An ``action_result`` from already encoded ``values`` (an object, or the reason on failure)."""
    tail = "" if message_id is None else f',"id":{dumps(message_id)}'
    head = f'{{"op":"action_result","action":{dumps(action)},"values":{values_json}'
    return f'{head},"status":{status},"result":{"true" if result else "false"}{tail}}}'


def action_feedback(action: str, values_json: str, message_id: MessageId | None) -> str:
    """An ``action_feedback`` from already encoded ``values``."""
    tail = "" if message_id is None else f',"id":{dumps(message_id)}'
    return f'{{"op":"action_feedback","action":{dumps(action)},"values":{values_json}{tail}}}'


def send_action_goal(action: str, action_type: str, args: Any, message_id: str, non_finite: str = "null") -> str:
    """A ``send_action_goal`` forwarded to the client that provides ``action`` (always with feedback)."""
    message = {"op": "send_action_goal", "id": message_id, "action": action, "action_type": action_type}
    return dumps({**message, "args": args, "feedback": True}, non_finite)


def cancel_action_goal(action: str, message_id: str) -> str:
    """A ``cancel_action_goal`` forwarded to the client that provides ``action``."""
    return dumps({"op": "cancel_action_goal", "id": message_id, "action": action})
