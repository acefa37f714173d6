"""How much an RDF/XML document's entities may expand, checked before any XML parser sees it.

A kilobyte of nested entity declarations ("billion laughs") expands to gigabytes, and Oxigraph's
RDF/XML parser expands them as it reads, whether they sit in text or in ``xmlns`` attributes. So every
path that parses RDF/XML (``cbrs load``, registration, catalogue imports, OWL-S conversion) first reads
the document's internal DTD here: each entity's expanded size is computed from its declaration
(memoised, so a nested chain costs its length, not its expansion), and the document is refused when one
entity or all references together would expand past the limits. External and parameter entities are
refused outright: a document may not make the server read a file or a URL.
"""

from __future__ import annotations

import re

from cbrs.kb.errors import RdfParseError

MAX_ENTITY_BYTES = 1 << 20
"""The most one entity may expand to."""
MAX_EXPANSION_BYTES = 16 << 20
"""The most all the entity references of one document may expand to together."""

_DECLARATION = re.compile(rb"<!ENTITY\s")
_GENERAL = re.compile(rb"""<!ENTITY\s+([\w.:-]+)\s+(["'])(.*?)\2\s*>""", re.S)
_REFERENCE = re.compile(rb"&([\w.:-]+);")
_PREDEFINED = frozenset({b"lt", b"gt", b"amp", b"apos", b"quot"})


def check_entities(data: bytes, source: str) -> None:
    """Raise :class:`RdfParseError` naming ``source`` if the entities of ``data`` would expand too far."""
    if b"<!ENTITY" not in data:
        return
    declared = _GENERAL.findall(data)
    if len(declared) != len(_DECLARATION.findall(data)):
        raise RdfParseError(
            source,
            "an external or parameter entity is declared (<!ENTITY % ...> or SYSTEM/PUBLIC): such entities "
            "would make the server read other files or URLs, and are refused",
        )
    values = {name: value for name, _, value in declared}
    sizes: dict[bytes, int] = {}

    def size(name: bytes, path: tuple[bytes, ...]) -> int:
        if name in sizes:
            return sizes[name]
        if name in path:
            raise RdfParseError(source, f"entity &{name.decode()}; refers to itself through {_chain(path)}")
        value = values.get(name)
        if value is None:
            return len(name) + 2  # undeclared (or predefined): left as written for the parser to judge
        total = len(value)
        for reference in _REFERENCE.finditer(value):
            total += size(reference.group(1), (*path, name)) - len(reference.group(0))
            if total > MAX_ENTITY_BYTES:
                raise RdfParseError(
                    source,
                    f"entity &{name.decode()}; expands to more than {MAX_ENTITY_BYTES >> 20} MiB "
                    "(nested entities, a 'billion laughs'); refused before parsing",
                )
        sizes[name] = total
        return total

    try:
        for name in values:
            size(name, ())
    except RecursionError:
        raise RdfParseError(source, "entities refer to entities too deeply to expand; refused before parsing") from None
    body = _GENERAL.sub(b"", data)
    expanded = 0
    for reference in _REFERENCE.finditer(body):
        name = reference.group(1)
        if name in values and name not in _PREDEFINED:
            expanded += sizes[name]
            if expanded > MAX_EXPANSION_BYTES:
                raise RdfParseError(
                    source,
                    f"the document's entity references expand to more than {MAX_EXPANSION_BYTES >> 20} MiB; "
                    "refused before parsing",
                )


def _chain(path: tuple[bytes, ...]) -> str:
    return " -> ".join(f"&{name.decode()};" for name in path)
