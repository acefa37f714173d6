"""``/rosout``: the server's log records as ``rosgraph_msgs/Log`` messages, as ROS tools expect them.

A logging handler publishes each record at or above its level on the bridge's ``/rosout`` topic, with
ROS 1's level numbers (DEBUG 1, INFO 2, WARN 4, ERROR 8, FATAL 16). A record logged while publishing
one (the bridge's own log) is not published again.
"""

from __future__ import annotations

import logging
import threading
from importlib.resources import files

from cbrs.rosbridge.bridge import Bridge

__all__ = ["ROSOUT", "RosoutHandler"]

ROSOUT = "/rosout"
#: The definitions of /rosout's message type and the header it uses, for rosapi's message_details.
INTERFACES = files("cbrs.rosbridge") / "definitions"
_LEVELS = ((logging.CRITICAL, 16), (logging.ERROR, 8), (logging.WARNING, 4), (logging.INFO, 2))


class RosoutHandler(logging.Handler):
    """Publishes log records on ``/rosout`` of ``bridge`` (which it adds as a server topic)."""

    def __init__(self, bridge: Bridge, level: int = logging.INFO) -> None:
        super().__init__(level)
        self.bridge = bridge
        self._inside = threading.local()
        bridge.add_topic(ROSOUT, "rosgraph_msgs/Log")
        for package in ("std_msgs", "rosgraph_msgs"):  # Log uses std_msgs/Header
            bridge.interfaces.load(INTERFACES / package, package)

    def emit(self, record: logging.LogRecord) -> None:
        if getattr(self._inside, "busy", False):
            return
        self._inside.busy = True
        try:
            secs = int(record.created)
            self.bridge.publish(
                ROSOUT,
                {
                    "header": {"stamp": {"secs": secs, "nsecs": int((record.created - secs) * 1e9)}},
                    "level": next((ros for python, ros in _LEVELS if record.levelno >= python), 1),
                    "name": record.name,
                    "msg": record.getMessage(),
                    "file": record.pathname,
                    "function": record.funcName,
                    "line": record.lineno,
                    "topics": [],
                },
            )
        except Exception:  # a log record must never break what logged it
            self.handleError(record)
        finally:
            self._inside.busy = False
