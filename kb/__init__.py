"""The cbrs knowledge base: an Oxigraph store (embedded, or a SPARQL server) of ontologies, advertisements and
requirements."""

from kb.catalog import Catalogue
from kb.errors import (
    AlreadyRegisteredError,
    BindingError,
    CatalogueError,
    InvalidDescriptionError,
    KnowledgeBaseError,
    NotFoundError,
    QuerySyntaxError,
    RdfParseError,
    RemoteStoreError,
    StoreError,
    StoreEvaluationError,
    UnknownFormatError,
    UnknownGraphError,
    UnknownQueryError,
)
from kb.knowledge_base import KnowledgeBase
from kb.loader import LoadReport
from kb.model import (
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
from kb.namespaces import PREFIXES, GraphName
from kb.store import EmbeddedStore, Store

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
