"""A thread-safe parameter store shaped like the ROS 1 parameter server: a tree of JSON values.

``/robot/speed`` is the ``speed`` child of the ``/robot`` namespace, so after ``set("/robot/speed", 1)``,
``get("/robot")`` is ``{"speed": 1}``; setting a dictionary sets a whole namespace. Values are copied in
and out (as JSON), so callers never share mutable state with the store. A float may be NaN or an
infinity, as a ROS 2 double parameter may (``range_max: .inf``); the rosapi services write those as the
bridge's ``non_finite`` says (cbrs.rosbridge.rosapi).
"""

from __future__ import annotations

import json
import threading
from collections.abc import Iterator, Mapping
from typing import Any

_MISSING: Any = object()

#: Characters of JSON the store holds at most (about: each value's text and its names): parameters are
#: small settings, and any client may set them, so a flood of them must not take the server's memory.
MAX_BYTES = 16 << 20


class ParamLimitError(ValueError):
    """A parameter that would take the store past its size; keeps the name and the sizes."""

    def __init__(self, name: str, size: int, limit: int) -> None:
        super().__init__(
            f"parameter {name!r} would bring the parameters to {size} characters of JSON, past the limit of"
            f" {limit}: delete some first"
        )
        self.name, self.size, self.limit = name, size, limit


def _parts(name: str) -> list[str]:
    return [part for part in name.split("/") if part]


def _copy(value: Any) -> Any:
    """A deep copy through JSON, which also refuses values JSON cannot hold (but for NaN and infinities,
    which Python's json writes and reads back as the floats)."""
    return _copy_sized(value)[0]


def _copy_sized(value: Any) -> tuple[Any, int]:
    """:func:`_copy`, and the length of the value's JSON text."""
    try:
        text = json.dumps(value)
        return json.loads(text), len(text)
    except (TypeError, ValueError, RecursionError) as error:
        raise ValueError(f"a parameter must be JSON (numbers, strings, booleans, lists, dicts): {error}") from None


def _size(value: Any) -> int:
    return len(json.dumps(value))


class ParamStore:
    """Parameters by global name; every method may be called from any thread."""

    def __init__(self, initial: Mapping[str, Any] | None = None, max_bytes: int = MAX_BYTES) -> None:
        self._tree: dict[str, Any] = {}
        self._lock = threading.Lock()
        self.max_bytes = max_bytes
        self._bytes = 2  # about len(json.dumps(tree)): kept up to date by set and delete
        for name, value in (initial or {}).items():
            self.set(name, value)

    def get(self, name: str, default: Any = _MISSING) -> Any:
        """The value (a dict for a namespace); ``default`` if unset, else :class:`KeyError`."""
        with self._lock:
            node: Any = self._tree
            for part in _parts(name):
                if not isinstance(node, dict) or part not in node:
                    if default is _MISSING:
                        raise KeyError(name)
                    return default
                node = node[part]
            return _copy(node)

    def set(self, name: str, value: Any) -> None:
        """Set a value; a dict value replaces the whole namespace, intermediate namespaces are created."""
        parts = _parts(name)
        value, size = _copy_sized(value)
        if not parts and not isinstance(value, dict):
            raise ValueError("only a dict can be set at the root '/'")
        with self._lock:
            if not parts:
                if size > self.max_bytes:
                    raise ParamLimitError(name, size, self.max_bytes)
                self._tree, self._bytes = value, size
                return
            node: Any = self._tree
            replaced = 0  # the text the new value takes the place of: a value, or a value in its way
            for part in parts:
                if not isinstance(node, dict) or part not in node:
                    break
                node = node[part]
            else:
                replaced = _size(node)
            names = sum(len(part) + 4 for part in parts)  # a name's quotes, colon and comma: about
            grown = self._bytes + size + names - replaced
            if grown > self.max_bytes and size + names > replaced:
                raise ParamLimitError("/" + "/".join(parts), grown, self.max_bytes)
            node = self._tree
            for part in parts[:-1]:
                if not isinstance(node.get(part), dict):
                    node[part] = {}
                node = node[part]
            node[parts[-1]] = value
            self._bytes = grown

    def delete(self, name: str) -> bool:
        """Delete a value or namespace; False if it was not set."""
        parts = _parts(name)
        with self._lock:
            if not parts:
                had = bool(self._tree)
                self._tree, self._bytes = {}, 2
                return had
            node = self._find(parts[:-1])
            if not isinstance(node, dict) or parts[-1] not in node:
                return False
            self._bytes = max(2, self._bytes - _size(node.pop(parts[-1])) - len(parts[-1]) - 4)
            return True

    def has(self, name: str) -> bool:
        """Whether a value or namespace is set under ``name``."""
        with self._lock:
            return self._find(_parts(name)) is not _MISSING

    def names(self) -> list[str]:
        """The global names of every value (not of namespaces), sorted."""
        with self._lock:
            return sorted(self._leaves(self._tree, ""))

    def search(self, name: str) -> str | None:
        """The global name ``name`` resolves to from the root namespace, if set (rosapi ``search_param``)."""
        full = "/" + "/".join(_parts(name))
        return full if _parts(name) and self.has(full) else None

    def _find(self, parts: list[str]) -> Any:
        node: Any = self._tree
        for part in parts:
            if not isinstance(node, dict) or part not in node:
                return _MISSING
            node = node[part]
        return node

    def _leaves(self, node: dict[str, Any], prefix: str) -> Iterator[str]:
        for key, value in node.items():
            if isinstance(value, dict) and value:
                yield from self._leaves(value, f"{prefix}/{key}")
            else:
                yield f"{prefix}/{key}"
