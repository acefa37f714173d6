"""Exceptions of the rosbridge server: one base, a service failure, API misuse and protocol errors."""

from __future__ import annotations


class RosbridgeError(Exception):
    """Base of every error raised by :mod:`cbrs.rosbridge`."""


class ServiceError(RosbridgeError):
    """Raised by a service handler: the call answers ``result: false`` with this text as ``values``."""


class UnknownTopicError(RosbridgeError):
    """``Bridge.publish`` on a topic the server has not added; keeps the topic name."""

    def __init__(self, topic: str) -> None:
        super().__init__(f"topic {topic!r} was not added; call bridge.add_topic({topic!r}, <type>) first")
        self.topic = topic


class ProtocolError(RosbridgeError):
    """A client message the server cannot act on; answered with a ``status`` error, never raised to callers.

    Keeps the ``op`` (when known) and the message ``id`` so the status can echo it.
    """

    def __init__(self, reason: str, op: str | None = None, message_id: str | int | None = None) -> None:
        super().__init__(f"{op}: {reason}" if op else reason)
        self.reason = reason
        self.op = op
        self.message_id = message_id
