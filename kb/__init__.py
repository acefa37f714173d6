"""The cbrs knowledge base: an Oxigraph store (embedded, or a SPARQL server) of ontologies, advertisements and
requirements.

The names below load their modules on first use, as :mod:`cbrs.actions`'s do: a program that needs
only a light module of the package (a component program's ``cbrs.kb.errors``) does not pay for the
store, the loader and backup.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from cbrs.kb.catalog import Catalogue
    from cbrs.kb.errors import (
        AlreadyRegisteredError,
        BindingError,
        CatalogueError,
        InvalidDescriptionError,
        KnowledgeBaseError,
        NotFoundError,
        QuerySyntaxError,
        RdfParseError,
        RemoteStoreError,
        ReplaceError,
        StoreError,
        StoreEvaluationError,
        UnknownFormatError,
        UnknownGraphError,
        UnknownQueryError,
    )
    from cbrs.kb.knowledge_base import KnowledgeBase
    from cbrs.kb.loader import LoadReport
    from cbrs.kb.model import (
        Advertisement,
        EffectiveArea,
        Parameter,
        PartNode,
        Port,
        QoSValue,
        Requirement,
        ServiceDescription,
        Statement,
    )
    from cbrs.kb.namespaces import PREFIXES, GraphName
    from cbrs.kb.semantic_map import MapError
    from cbrs.kb.shapes import DescriptionShapeError
    from cbrs.kb.store import EmbeddedStore, Store, StoreInUseError

_HOMES = {
    "cbrs.kb.catalog": ("Catalogue",),
    "cbrs.kb.errors": (
        "AlreadyRegisteredError",
        "BindingError",
        "CatalogueError",
        "InvalidDescriptionError",
        "KnowledgeBaseError",
        "NotFoundError",
        "QuerySyntaxError",
        "RdfParseError",
        "RemoteStoreError",
        "ReplaceError",
        "StoreError",
        "StoreEvaluationError",
        "UnknownFormatError",
        "UnknownGraphError",
        "UnknownQueryError",
    ),
    "cbrs.kb.knowledge_base": ("KnowledgeBase",),
    "cbrs.kb.loader": ("LoadReport",),
    "cbrs.kb.model": (
        "Advertisement",
        "EffectiveArea",
        "Parameter",
        "PartNode",
        "Port",
        "QoSValue",
        "Requirement",
        "ServiceDescription",
        "Statement",
    ),
    "cbrs.kb.namespaces": ("PREFIXES", "GraphName"),
    # raised by KnowledgeBase's own methods (a load or update the map or the shapes refuse, an on-disk store
    # open elsewhere): a caller catches them by these names without knowing the module that raises them
    "cbrs.kb.semantic_map": ("MapError",),
    "cbrs.kb.shapes": ("DescriptionShapeError",),
    "cbrs.kb.store": ("EmbeddedStore", "Store", "StoreInUseError"),
}
_WHERE = {name: module for module, names in _HOMES.items() for name in names}

__all__ = [
    "PREFIXES",
    "Advertisement",
    "AlreadyRegisteredError",
    "BindingError",
    "Catalogue",
    "CatalogueError",
    "DescriptionShapeError",
    "EffectiveArea",
    "EmbeddedStore",
    "GraphName",
    "InvalidDescriptionError",
    "KnowledgeBase",
    "KnowledgeBaseError",
    "LoadReport",
    "MapError",
    "NotFoundError",
    "Parameter",
    "PartNode",
    "Port",
    "QoSValue",
    "QuerySyntaxError",
    "RdfParseError",
    "RemoteStoreError",
    "ReplaceError",
    "Requirement",
    "ServiceDescription",
    "Statement",
    "Store",
    "StoreError",
    "StoreEvaluationError",
    "StoreInUseError",
    "UnknownFormatError",
    "UnknownGraphError",
    "UnknownQueryError",
]


def __getattr__(name: str) -> Any:
    module = _WHERE.get(name)
    if module is None:
        raise AttributeError(f"module 'cbrs.kb' has no attribute {name!r}")
    value = getattr(importlib.import_module(module), name)
    globals()[name] = value
    return value
