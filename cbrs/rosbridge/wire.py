"""rosbridge's fragments and its PNG and CBOR compression, both ways a client may use them.

- A client with small buffers (a microcontroller) may send one message as ``fragment`` ops, ``{"op":
  "fragment", "id", "data", "num", "total"}``, ``data`` being consecutive pieces of the message's JSON
  text and ``num`` counting from 0. :class:`Reassembly` keeps the pieces per id and hands back the
  whole text once every ``num`` below ``total`` has come, in any order (rosbridge_suite's
  ``Defragment`` capability).
- A client may ask for a subscription's messages, or a call's response, in pieces of at most
  ``fragment_size`` characters (:func:`fragments`), or a subscription's messages as PNG images
  (``compression: "png"``, :func:`png_message`): the message's UTF-8 JSON as the pixels of an 8-bit RGB
  image padded with newlines, base64 in ``{"op": "png", "data": ...}``, as rosbridge_suite's
  ``pngcompression.encode`` writes it and roslibjs decodes it.
- A client may also ask for a subscription's messages as CBOR (``compression: "cbor"``,
  :func:`cbor_publish`): the ``publish`` op as one binary frame, as rosbridge_suite's ``subscribe``
  sends it. rosbridge_suite packs a message's numeric arrays as RFC 8746 typed arrays (little-endian)
  and its ``uint8[]`` as a byte string because the ROS message definition says what each array holds.
  Here no message has a definition: an array the server publishes says what it holds only by its
  Python type (``array.array``, a 1-D numpy array, ``bytes``; :func:`cbor_values`), and only those go
  as typed arrays or byte strings. A JSON array (what every client publishes) stays a CBOR array of
  its numbers as JSON read them, ints and floats alike: guessing a type from the values would change
  what a field decodes to from one message to the next (``[1.5, 2]`` against ``[1.5, 2.5]``).

Fragments are bounded: the pieces a client has pending hold at most ``max_message_bytes`` characters
together, in at most one piece per :data:`PIECE_CHARS` of that (the oldest unfinished messages make way,
then the message that still does not fit is refused), in at most :data:`MAX_PARTIAL` messages; and a
``fragment_size`` below :data:`MIN_FRAGMENT` is raised to it, and one message is never cut in more than
:data:`MAX_PIECES`. A CBOR message is never cut: ``fragment`` ops carry text.
"""

from __future__ import annotations

import array
import base64
import json
import math
import struct
import sys
import zlib
from collections import OrderedDict
from dataclasses import dataclass, field
from typing import Any

import cbor2

from cbrs.rosbridge import protocol
from cbrs.rosbridge.errors import ProtocolError
from cbrs.rosbridge.protocol import Message, MessageId, dumps

#: Messages one client may have in pieces at once; one more drops the oldest (a client that never
#: finishes one holds no more than this).
MAX_PARTIAL = 16
#: The smallest piece the server sends: a smaller ``fragment_size`` is raised to it.
MIN_FRAGMENT = 256
#: The most pieces the server cuts one message into (the piece size grows for a longer one): the pieces
#: of a reply are replies, and a client more than ``session.REPLY_BACKLOG`` (10,000) behind is dropped.
MAX_PIECES = 4096
#: A client's pending pieces number at most one per this many characters of ``max_message_bytes``
#: (16,384 for 1 MiB): a piece costs its bookkeeping whatever its size, so tiny pieces are counted too.
PIECE_CHARS = 64
_PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"


@dataclass
class _Partial:
    total: int
    pieces: dict[int, str] = field(default_factory=dict)
    size: int = 0  # characters received


class Reassembly:
    """One client's messages arriving in ``fragment`` ops."""

    def __init__(self, limit: int) -> None:
        self.limit = limit  # characters a whole message, and all pending pieces together, may have
        self.max_pieces = max(1, limit // PIECE_CHARS)
        self._partial: OrderedDict[MessageId, _Partial] = OrderedDict()
        self._size = 0  # characters pending, all messages together
        self._pieces = 0  # pieces pending

    def __len__(self) -> int:
        return len(self._partial)

    def add(self, message: Message) -> tuple[str | None, str | None]:
        """Take one checked ``fragment`` op: (the whole message's text once complete, else None; a warning
        to report, else None). Raises :class:`ProtocolError` for a piece that cannot belong."""
        message_id, num, total, data = message.get("id"), message["num"], message["total"], message["data"]
        if message_id is None:
            raise ProtocolError("a fragment needs the 'id' of the message it is part of")
        if total < 1 or not 0 <= num < total:
            raise ProtocolError(f"num must be from 0 to total - 1, not {num} of {total}", message_id=message_id)
        if total > self.max_pieces:
            raise ProtocolError(
                f"total {total} is more pieces than a message may have ({self.max_pieces})", message_id=message_id
            )
        dropped: list[MessageId] = []
        partial = self._partial.get(message_id)
        if partial is None:
            if len(self._partial) >= MAX_PARTIAL:
                dropped.append(self._drop_oldest())
            partial = self._partial[message_id] = _Partial(total)
        elif partial.total != total:
            raise ProtocolError(
                f"total {total} differs from the {partial.total} of the pieces already received", message_id=message_id
            )
        if num in partial.pieces:
            return None, f"piece {num} of message {message_id!r} came twice; the first is kept"
        while self._size + len(data) > self.limit or self._pieces + 1 > self.max_pieces:
            if next(iter(self._partial)) == message_id:  # the oldest is this one: it cannot fit
                self._drop(message_id)
                raise ProtocolError(
                    f"the pieces of message {message_id!r} exceed the limit of {self.limit} bytes (max_message_bytes)",
                    message_id=message_id,
                )
            dropped.append(self._drop_oldest())
        partial.pieces[num] = data
        partial.size += len(data)
        self._size += len(data)
        self._pieces += 1
        warning = (
            f"dropped the unfinished fragments of {', '.join(map(repr, dropped))} to make room" if dropped else None
        )
        if len(partial.pieces) < total:
            return None, warning
        self._drop(message_id)
        return "".join(partial.pieces[index] for index in range(total)), warning

    def _drop(self, message_id: MessageId) -> None:
        partial = self._partial.pop(message_id)
        self._size -= partial.size
        self._pieces -= len(partial.pieces)

    def _drop_oldest(self) -> MessageId:
        oldest = next(iter(self._partial))
        self._drop(oldest)
        return oldest

    def clear(self) -> None:
        self._partial.clear()
        self._size = self._pieces = 0


def fragments(text: str, size: int, message_id: MessageId) -> list[str]:
    """``text`` as ``fragment`` ops of at most ``size`` characters of it each (``[text]`` if it fits); the
    size is raised to :data:`MIN_FRAGMENT`, and so that no message takes more than :data:`MAX_PIECES`."""
    size = max(size, MIN_FRAGMENT, math.ceil(len(text) / MAX_PIECES))
    if len(text) <= size:
        return [text]
    total = math.ceil(len(text) / size)
    return [
        dumps({"op": "fragment", "id": message_id, "data": text[at : at + size], "num": num, "total": total})
        for num, at in enumerate(range(0, len(text), size))
    ]


def png_message(text: str) -> str:
    """``text`` as rosbridge's ``png`` op: its UTF-8 bytes the pixels of a near-square RGB image,
    padded with newlines (white space to a JSON parser), PNG-encoded and base64'd."""
    data = text.encode("utf-8")
    pixels = max(1, math.ceil(len(data) / 3))
    width = max(1, math.isqrt(pixels))
    height = math.ceil(pixels / width)
    data += b"\n" * (width * height * 3 - len(data))
    row = width * 3
    raw = b"".join(b"\x00" + data[at : at + row] for at in range(0, len(data), row))  # filter 0 (none) per row
    image = (
        _PNG_SIGNATURE
        + _chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0))  # 8-bit RGB, no interlace
        + _chunk(b"IDAT", zlib.compress(raw, 6))
        + _chunk(b"IEND", b"")
    )
    return dumps({"op": "png", "data": base64.b64encode(image).decode("ascii")})


def _chunk(kind: bytes, body: bytes) -> bytes:
    return struct.pack(">I", len(body)) + kind + body + struct.pack(">I", zlib.crc32(kind + body))


# -- CBOR ---------------------------------------------------------------------------------------------

#: RFC 8746 typed-array tags, little-endian (as rosbridge_suite writes them and roslibjs reads them), by
#: element kind (numpy's letters: i signed, u unsigned, f float) and size in bytes. uint8 is no tag:
#: rosbridge_suite sends ``uint8[]`` as a plain byte string (which roslibjs reads as a Uint8Array too).
TYPED_ARRAY_TAGS: dict[tuple[str, int], int] = {
    ("i", 1): 72,
    ("u", 2): 69,
    ("u", 4): 70,
    ("u", 8): 71,
    ("i", 2): 77,
    ("i", 4): 78,
    ("i", 8): 79,
    ("f", 4): 85,
    ("f", 8): 86,
}


def typed_json(value: Any) -> Any:
    """The JSON form of a typed array or bytes in a message the server publishes (``json``'s ``default``):
    an array's numbers as a list, bytes as base64 text (rosbridge's JSON for ``uint8[]``).
    Raises TypeError for anything else, as ``json`` does."""
    if isinstance(value, bytes | bytearray):
        return base64.b64encode(value).decode("ascii")
    if isinstance(value, array.array):
        _array_kind(value)  # refuses unicode arrays
        return value.tolist()
    if _is_ndarray(value):
        _ndarray_kind(value)
        return value.tolist()
    raise TypeError(f"Object of type {type(value).__name__} is not JSON serializable")


def cbor_values(value: Any) -> Any:
    """A copy of a message the server publishes with its typed arrays as CBOR tags and its bytes as byte
    strings, and what is JSON as JSON would read it back (tuples as lists, keys as text): what a CBOR
    subscriber decodes is what a JSON subscriber reads, bar the arrays' types. A copy, so the publisher may
    change its dict once ``publish`` returns. NaNs and infinities stay floats (CBOR has them; JSON text
    gets them as ``Bridge(non_finite=)`` says)."""
    if isinstance(value, dict):
        return {_json_key(key): cbor_values(item) for key, item in value.items()}
    if isinstance(value, list | tuple):
        return [cbor_values(item) for item in value]
    if isinstance(value, bytes | bytearray):
        return bytes(value)
    if isinstance(value, array.array):
        return _tagged(_array_kind(value), value.itemsize, value.tobytes(), sys.byteorder == "big")
    if _is_ndarray(value):
        kind = _ndarray_kind(value)
        if kind == "b":
            return [bool(item) for item in value.tolist()]
        little = value.astype(value.dtype.newbyteorder("<"), copy=False)
        return _tagged(kind, value.dtype.itemsize, little.tobytes(), swap=False)
    return value  # str, int, float (NaN too), bool, None: the JSON dump that came first let nothing else through


_TYPED_ENCODER = json.JSONEncoder(separators=(",", ":"), ensure_ascii=False, allow_nan=False, default=typed_json)
_TYPED_TOKENS = json.JSONEncoder(separators=(",", ":"), ensure_ascii=False, allow_nan=True, default=typed_json)


def typed_encode(value: Any, non_finite: str = "null") -> tuple[str, bool]:
    """Compact JSON of a message the server publishes with typed arrays or bytes in it (:func:`typed_json`),
    and whether it holds every number (:func:`cbrs.rosbridge.protocol.encode`)."""
    return protocol.encode(value, non_finite, _TYPED_ENCODER.encode, _TYPED_TOKENS.encode)


def typed_dumps(value: Any, non_finite: str = "null") -> str:
    """:func:`typed_encode`'s text."""
    return typed_encode(value, non_finite)[0]


def cbor_publish(topic: str, msg: Any) -> bytes:
    """A ``publish`` op as CBOR, the binary frame a ``compression: "cbor"`` subscriber gets."""
    return cbor2.dumps({"op": "publish", "topic": topic, "msg": msg})


def _tagged(kind: str, size: int, data: bytes, swap: bool) -> Any:
    if kind == "u" and size == 1:
        return data
    if swap and size > 1:  # the machine is big-endian: the tags here say little-endian
        swapped = array.array({2: "H", 4: "I", 8: "Q"}[size], data)
        swapped.byteswap()
        data = swapped.tobytes()
    return cbor2.CBORTag(TYPED_ARRAY_TAGS[(kind, size)], data)


def _array_kind(value: array.array[Any]) -> str:
    code = value.typecode
    if code in "fd":
        return "f"
    if code in "bhilq":
        return "i"
    if code in "BHILQ":
        return "u"
    raise TypeError(f"array.array of typecode {code!r} is no numeric array: publish text as a str")


def _is_ndarray(value: Any) -> bool:
    numpy = sys.modules.get("numpy")  # not imported: no value can be an array of it
    return numpy is not None and isinstance(value, numpy.ndarray)


def _ndarray_kind(value: Any) -> str:
    kind, size = value.dtype.kind, value.dtype.itemsize
    if value.ndim != 1:
        raise TypeError(f"a numpy array in a message must have one dimension, not shape {value.shape}")
    if kind != "b" and (kind, size) not in TYPED_ARRAY_TAGS and (kind, size) != ("u", 1):
        raise TypeError(f"numpy dtype {value.dtype} has no typed array in rosbridge's CBOR: convert it first")
    return str(kind)


def _json_key(key: Any) -> str:
    """A dict key as ``json`` writes it (only str, int, float, bool and None get past ``json``)."""
    if isinstance(key, str):
        return key
    if key is None or isinstance(key, bool):
        return dumps(key)
    return dumps(key) if isinstance(key, float) else str(int(key))
