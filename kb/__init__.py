"""The cbrs knowledge base: an Oxigraph store (embedded, or a SPARQL server) of ontologies, advertisements and
requirements."""

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
from cbrs.kb.store import EmbeddedStore, Store

__all__ = [
    "PREFIXES",
    "Advertisement",
    "AlreadyRegisteredError",
    "BindingError",
    "Catalogue",
    "CatalogueError",
    "EffectiveArea",
    "EmbeddedStore",
    "GraphName",
    "InvalidDescriptionError",
    "KnowledgeBase",
    "KnowledgeBaseError",
    "LoadReport",
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
    "UnknownFormatError",
    "UnknownGraphError",
    "UnknownQueryError",
]
