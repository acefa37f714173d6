"""Message and service definitions in ROS 1's ``.msg``/``.srv`` text, described as rosapi describes them.

The bridge's messages are JSON and need no definition to travel; tools that build forms or decoders
from rosapi's ``message_details``, ``service_request_details`` and ``service_response_details`` (or
``topics_and_raw_types``' full text) need one. A server keeps its types as data files, one per type
(``<dir>/msg/<Name>.msg``, ``<dir>/srv/<Name>.srv``), loaded by package name with :meth:`Interfaces.load`.

A typedef is the dict rosapi answers (``type``, ``fieldnames``, ``fieldtypes``, ``fieldarraylen``,
``examples``, ``constnames``, ``constvalues``), as ROS 1's rosapi builds it from a message instance: a
service's parts are named ``<pkg>/<Name>Request`` and ``<pkg>/<Name>Response``; a field's type is its
primitive or its package-qualified message; an array's length is -1 (none), 0 (unbounded) or its fixed
size; the example is the field's default (``False``, ``0``, ``0.0``, empty text), ``[]`` for an array and
``{}`` for a nested message; constants are listed by name in alphabetical order. The details services
answer the type first, then every message type it uses, depth first, each once.
"""

from __future__ import annotations

import re
from collections.abc import Iterable
from dataclasses import dataclass
from importlib.resources.abc import Traversable
from pathlib import Path
from typing import Any

from cbrs.rosbridge.errors import RosbridgeError

#: ROS 1's primitive types -> the example (default) rosapi gives a field of that type.
PRIMITIVES = {
    "bool": "False",
    "byte": "0",
    "char": "0",
    "int8": "0",
    "uint8": "0",
    "int16": "0",
    "uint16": "0",
    "int32": "0",
    "uint32": "0",
    "int64": "0",
    "uint64": "0",
    "float32": "0.0",
    "float64": "0.0",
    "string": "",
}
#: Built-in types rosapi describes as a message of two int32 fields.
SPECIALS = ("time", "duration")

_NAME = re.compile(r"[A-Za-z][A-Za-z0-9_]*$")
_TYPE = re.compile(r"(?:([A-Za-z][A-Za-z0-9_]*)/)?([A-Za-z][A-Za-z0-9_]*)(\[(\d*)\])?$")
_RULE = "\n" + "=" * 80 + "\n"


class InterfaceError(RosbridgeError):
    """A definition that cannot be read; keeps the file and the offending line."""

    def __init__(self, source: str, line: str, reason: str) -> None:
        super().__init__(f"{source}: {reason}: {line.strip()!r}")
        self.source = source
        self.line = line
        self.reason = reason


@dataclass(frozen=True)
class Field:
    name: str
    type: str  # a primitive, a special or "pkg/Name", without the array suffix
    array: int  # -1 not an array, 0 unbounded, else the fixed length


@dataclass(frozen=True)
class Constant:
    name: str
    type: str
    value: str  # as rosapi writes it (str of the parsed value)


@dataclass(frozen=True)
class Definition:
    """One message (or one half of a service): its fields and constants, and the text it was read from."""

    type: str
    fields: tuple[Field, ...]
    constants: tuple[Constant, ...]
    text: str

    def typedef(self) -> dict[str, Any]:
        """This message as rosapi's TypeDef."""
        return {
            "type": self.type,
            "fieldnames": [f.name for f in self.fields],
            "fieldtypes": [f.type for f in self.fields],
            "fieldarraylen": [f.array for f in self.fields],
            "examples": [_example(f) for f in self.fields],
            "constnames": [c.name for c in self.constants],
            "constvalues": [c.value for c in self.constants],
        }


def _example(field: Field) -> str:
    if field.array >= 0:
        return "[]"
    return PRIMITIVES.get(field.type, "{}")


def _special(kind: str) -> dict[str, Any]:
    return {
        "type": kind,
        "fieldnames": ["secs", "nsecs"],
        "fieldtypes": ["int32", "int32"],
        "fieldarraylen": [-1, -1],
        "examples": ["0", "0"],
        "constnames": [],
        "constvalues": [],
    }


def parse(package: str, name: str, text: str, source: str = "") -> Definition:
    """One ``.msg`` text (or one side of a ``.srv``) as the definition of ``package/name``."""
    source = source or f"{package}/{name}"
    fields: list[Field] = []
    constants: list[Constant] = []
    for line in text.splitlines():
        body = line.split("#", 1)[0].strip()
        if not body:
            continue
        parts = body.split(None, 1)
        if len(parts) != 2:
            raise InterfaceError(source, line, "a line is '<type> <name>' or '<type> <NAME>=<value>'")
        kind, rest = parts
        if "=" in rest:
            constants.append(_constant(source, line, kind))
            continue
        if not _NAME.match(rest):
            raise InterfaceError(source, line, f"{rest!r} is no field name (a letter, then letters, digits or _)")
        if rest in {f.name for f in fields}:
            raise InterfaceError(source, line, f"field {rest!r} is defined twice")
        fields.append(_field(source, line, package, kind, rest))
    constants.sort(key=lambda c: c.name)
    return Definition(f"{package}/{name}", tuple(fields), tuple(constants), text.strip("\n"))


def _field(source: str, line: str, package: str, kind: str, name: str) -> Field:
    found = _TYPE.match(kind)
    if found is None:
        raise InterfaceError(source, line, f"{kind!r} is no type (a primitive, Name, pkg/Name, with [] or [N])")
    owner, base, suffix, size = found.groups()
    array = -1 if suffix is None else int(size) if size else 0
    if owner is None and (base in PRIMITIVES or base in SPECIALS):
        return Field(name, base, array)
    if owner is None and base == "Header":  # as in ROS 1: a bare Header is std_msgs's in any package
        return Field(name, "std_msgs/Header", array)
    return Field(name, f"{owner or package}/{base}", array)


def _constant(source: str, line: str, kind: str) -> Constant:
    """A constant: as in ROS 1, a string's value is the rest of the line (a # included), trimmed."""
    if kind not in PRIMITIVES:
        raise InterfaceError(source, line, f"a constant's type must be a primitive, not {kind!r}")
    declared = line.split(None, 1)[1]
    name, _, value = declared.partition("=")
    name = name.strip()
    if not _NAME.match(name):
        raise InterfaceError(source, line, f"{name!r} is no constant name")
    if kind == "string":
        return Constant(name, kind, value.strip())
    value = value.split("#", 1)[0].strip()
    try:
        if kind == "bool":
            if value.lower() not in ("true", "false", "1", "0"):
                raise ValueError(value)
            return Constant(name, kind, str(value.lower() in ("true", "1")))
        number: float = float(value) if kind.startswith("float") else int(value)
    except ValueError:
        raise InterfaceError(source, line, f"{value!r} is no {kind} value") from None
    return Constant(name, kind, str(number))


class Interfaces:
    """The message and service types a bridge can describe, by ``pkg/Name``."""

    def __init__(self) -> None:
        self.messages: dict[str, Definition] = {}
        self.services: dict[str, tuple[Definition, Definition]] = {}

    def load(self, directory: Path | Traversable, package: str) -> None:
        """Read ``directory/msg/*.msg`` and ``directory/srv/*.srv`` as ``package``'s types, all or none:
        a file that cannot be read, or a field whose message type is not defined, adds nothing."""
        messages: dict[str, Definition] = {}
        services: dict[str, tuple[Definition, Definition]] = {}
        for file in _files(directory / "msg", ".msg"):
            name = file.name.removesuffix(".msg")
            messages[f"{package}/{name}"] = parse(package, name, file.read_text(encoding="utf-8"), _source(file))
        for file in _files(directory / "srv", ".srv"):
            name = file.name.removesuffix(".srv")
            text = file.read_text(encoding="utf-8")
            halves = re.split(r"^---[ \t]*$", text, flags=re.MULTILINE)
            if len(halves) != 2:
                raise InterfaceError(_source(file), text[:60], "a .srv has one '---' line between request and response")
            request = parse(package, f"{name}Request", halves[0], _source(file))
            response = parse(package, f"{name}Response", halves[1], _source(file))
            services[f"{package}/{name}"] = (request, response)
        known = {**self.messages, **messages}
        for definition in [*messages.values(), *(half for pair in services.values() for half in pair)]:
            for field in definition.fields:
                if "/" in field.type and field.type not in known:
                    line = f"{field.type} {field.name}"
                    raise InterfaceError(definition.type, line, f"message type {field.type!r} is not defined")
        self.messages.update(messages)
        self.services.update(services)

    def message(self, kind: str) -> list[dict[str, Any]]:
        """rosapi's ``message_details``: the typedefs of ``kind`` and the types it uses; [] when unknown."""
        return self._walk(_short(kind, "msg"), set())

    def request(self, kind: str) -> list[dict[str, Any]]:
        """rosapi's ``service_request_details``; [] for a service type not defined here."""
        pair = self.services.get(_short(kind, "srv"))
        return self._nested(pair[0], set()) if pair else []

    def request_fields(self, kind: str) -> tuple[str, ...] | None:
        """The names of a service request's fields in the order its definition lists them (what a call
        whose args are a list fills, as rosbridge_suite fills them); None for a type not defined here."""
        pair = self.services.get(_short(kind, "srv"))
        return None if pair is None else tuple(field.name for field in pair[0].fields)

    def response(self, kind: str) -> list[dict[str, Any]]:
        """rosapi's ``service_response_details``; [] for a service type not defined here."""
        pair = self.services.get(_short(kind, "srv"))
        return self._nested(pair[1], set()) if pair else []

    def full_text(self, kind: str) -> str:
        """The definition with those of the types it uses appended, as ROS 1's ``gendeps --cat`` writes
        it (``topics_and_raw_types``); '' for a type not defined here."""
        root = self.messages.get(_short(kind, "msg"))
        if root is None:
            return ""
        parts = [root.text]
        for used in self._uses(root, {root.type}):
            parts.append(f"MSG: {used.type}\n{used.text}")
        return _RULE.join(parts)

    def _walk(self, kind: str, seen: set[str]) -> list[dict[str, Any]]:
        if kind in seen or kind in PRIMITIVES:
            return []
        seen.add(kind)
        if kind in SPECIALS:
            return [_special(kind)]
        definition = self.messages.get(kind)
        return self._nested(definition, seen) if definition is not None else []

    def _nested(self, definition: Definition, seen: set[str]) -> list[dict[str, Any]]:
        found = [definition.typedef()]
        for field in definition.fields:
            found += self._walk(field.type, seen)
        return found

    def _uses(self, definition: Definition, seen: set[str]) -> Iterable[Definition]:
        for field in definition.fields:
            used = self.messages.get(field.type)
            if used is not None and used.type not in seen:
                seen.add(used.type)
                yield used
                yield from self._uses(used, seen)


def _short(kind: str, folder: str) -> str:
    """``pkg/Name`` from ``pkg/Name`` or ROS 2's ``pkg/msg/Name`` (``pkg/srv/Name``)."""
    parts = kind.split("/")
    return f"{parts[0]}/{parts[2]}" if len(parts) == 3 and parts[1] == folder else kind


def _files(folder: Path | Traversable, suffix: str) -> list[Traversable]:
    if not folder.is_dir():
        return []
    return sorted((f for f in folder.iterdir() if f.name.endswith(suffix)), key=lambda f: f.name)


def _source(file: Traversable) -> str:
    return str(file) if isinstance(file, Path) else file.name
