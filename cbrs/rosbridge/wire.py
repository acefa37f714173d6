"""rosbridge's fragments and PNG compression, both ways a client may use them.

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

Both are bounded: a message in pieces is no larger than ``max_message_bytes`` once whole, a client
has at most :data:`MAX_PARTIAL` messages in pieces (the oldest is dropped), and a ``fragment_size``
below :data:`MIN_FRAGMENT` is raised to it, so one message never becomes millions of frames.
"""

from __future__ import annotations

import base64
import math
import struct
import zlib
from collections import OrderedDict
from dataclasses import dataclass, field

from cbrs.rosbridge.errors import ProtocolError
from cbrs.rosbridge.protocol import Message, MessageId, dumps

#: Messages one client may have in pieces at once; one more drops the oldest (a client that never
#: finishes one holds no more than this).
MAX_PARTIAL = 16
#: The smallest piece the server sends: a smaller ``fragment_size`` is raised to it.
MIN_FRAGMENT = 256
_PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"


@dataclass
class _Partial:
    total: int
    pieces: dict[int, str] = field(default_factory=dict)
    size: int = 0  # characters received


class Reassembly:
    """One client's messages arriving in ``fragment`` ops."""

    def __init__(self, limit: int) -> None:
        self.limit = limit  # characters a whole message may have (max_message_bytes)
        self._partial: OrderedDict[MessageId, _Partial] = OrderedDict()

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
        if total > self.limit:  # every piece carries at least a character
            raise ProtocolError(f"total {total} is more pieces than a message may have", message_id=message_id)
        warning = None
        partial = self._partial.get(message_id)
        if partial is None:
            if len(self._partial) >= MAX_PARTIAL:
                dropped, _ = self._partial.popitem(last=False)
                warning = f"dropped the unfinished fragments of message {dropped!r} ({MAX_PARTIAL} at most at once)"
            partial = self._partial[message_id] = _Partial(total)
        elif partial.total != total:
            raise ProtocolError(
                f"total {total} differs from the {partial.total} of the pieces already received", message_id=message_id
            )
        if num in partial.pieces:
            return None, f"piece {num} of message {message_id!r} came twice; the first is kept"
        if partial.size + len(data) > self.limit:
            del self._partial[message_id]
            raise ProtocolError(
                f"the pieces of message {message_id!r} exceed the limit of {self.limit} bytes (max_message_bytes)",
                message_id=message_id,
            )
        partial.pieces[num] = data
        partial.size += len(data)
        if len(partial.pieces) < total:
            return None, warning
        del self._partial[message_id]
        return "".join(partial.pieces[index] for index in range(total)), warning

    def clear(self) -> None:
        self._partial.clear()


def fragments(text: str, size: int, message_id: MessageId) -> list[str]:
    """``text`` as ``fragment`` ops of at most ``size`` characters of it each (``[text]`` if it fits)."""
    size = max(size, MIN_FRAGMENT)
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
