"""The names a plan's pictures give its components: short, and never the same for two of them.

A picture names a component by its local name (``PlanPathAStar_HomeServer01``). On OWLS-TC that is not
enough: three map services are each ``#_MAP_SERVICE``, in ``_Francemap_service.owls``,
``_mapGerman_service.owls`` and ``_mapFrankfurtBerlin_service.owls``, and the service resource graph
drew three boxes reading ``MAP_SERVICE``. The rule (docs/web.md, "Names in the plans' pictures"):

1. a component's name is its local name, when no other component of the picture has that local name;
2. components that share a local name are each qualified by their namespace: ``qualifier:local``. The
   qualifier is what ``qualifier`` says (the browser passes the prefix its pages show, so the picture
   and the page name a component alike); by default the namespace's last path segment without its
   extension (``_Francemap_service``), which for an OWL-S service is its file, the provider's description;
3. names still shared after that (two files of one name in two folders) get ``(1)``, ``(2)``... in
   IRI order.

The names depend only on the set of components drawn, not on their order, so a picture names a
component the same way each time it is drawn.
"""

from __future__ import annotations

from collections import defaultdict
from collections.abc import Callable, Iterable

from cbrs.kb.owls import local_name

__all__ = ["file_qualifier", "shown_names", "two_lines"]


def file_qualifier(iri: str) -> str:
    """The last path segment of ``iri``'s namespace, without extension: ``_Francemap_service``."""
    namespace = iri.rsplit("#", 1)[0] if "#" in iri else iri.rsplit("/", 1)[0]
    segment = namespace.rstrip("/").rsplit("/", 1)[-1]
    stem, dot, extension = segment.rpartition(".")
    return stem if dot and stem and extension.isalpha() else segment


def shown_names(iris: Iterable[str], qualifier: Callable[[str], str] | None = None) -> dict[str, str]:
    """Each IRI's name in a picture of all of them: unique, by the rule of this module."""
    qualify = qualifier or file_qualifier
    by_local: dict[str, list[str]] = defaultdict(list)
    for iri in sorted(set(iris)):
        by_local[local_name(iri)].append(iri)
    names: dict[str, str] = {}
    for local, sharing in by_local.items():
        for iri in sharing:
            names[iri] = local if len(sharing) == 1 else f"{qualify(iri)}:{local}"
    by_name: dict[str, list[str]] = defaultdict(list)
    for iri in sorted(names):
        by_name[names[iri]].append(iri)
    for name, sharing in by_name.items():
        if len(sharing) > 1:
            for number, iri in enumerate(sharing, 1):
                names[iri] = f"{name} ({number})"
    return names


def two_lines(name: str) -> str:
    """A name as a box shows it: a qualified name's qualifier above its local name; a bundled
    component's ``Service_Device`` as service above device; any other name on one line."""
    qualifier, colon, local = name.rpartition(":")
    if colon and qualifier and local:
        return f"{qualifier}:\n{local}"
    service, underscore, device = name.partition("_")
    if underscore and service and device and "_" not in device:
        return f"{service}\n{device}"
    return name
