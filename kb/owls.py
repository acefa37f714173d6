"""Convert OWL-S 1.1 service descriptions into cbrs advertisements and requirements.

:func:`convert` takes the triples of one parsed OWL-S file and returns the cbrs triples that
describe each service in it (see ``docs/owls.md`` for the mapping):

- the description's IRI is the service's IRI (a requirement's gets ``-request`` appended, because
  request collections such as OWLS-TC reuse the IRIs of the services they ask for);
- ``profile:serviceName`` gives ``rdfs:label`` and ``cbrs:serviceName``, ``profile:textDescription``
  gives ``rdfs:comment``, each ``profile:serviceCategory``'s ``categoryName`` a ``cbrs:serviceCategory``;
- the contact's ``actor:name`` gives ``cbrs:deviceName``, else the stem of the source file's name;
- inputs and outputs come from the profile (or, when the profile lists none, the process), each a
  ``cbrs:Parameter`` whose ``cbrs:parameterType`` is the OWL-S ``process:parameterType``;
- preconditions and effects written as PDDL, KIF or SWRL become ``cbrs:Precondition`` / ``cbrs:Effect``
  statements where an atom can be read as one; every expression is also kept as ``cbrs:conditionText``.

Nothing here reads files or the store: the caller passes the triples, and a :class:`Vocabulary` of
what the loaded ontologies declare when it has one.
"""

from __future__ import annotations

import re
from collections import defaultdict
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Literal, TypeAlias
from urllib.parse import urljoin

import pyoxigraph as ox

from cbrs.kb.catalog import is_built_in, namespace_document
from cbrs.kb.conditions import CONDITION_PARTS
from cbrs.kb.errors import RdfParseError
from cbrs.kb.namespaces import OWL, RDF, RDFS
from cbrs.kb.vocab import CBRS
from cbrs.kb.xml_limits import check_entities

CONDITION_TEXT_BUDGET = 16 << 20
"""Characters of expression text one file's statements may carry between them. Every statement made
from an expression carries the expression's text, so an expression of n atoms costs n times its text;
past this budget an expression is kept as its text alone, once, and the conversion says so."""

Role = Literal["advertisement", "requirement"]
Term = Any  # an ox.NamedNode, ox.BlankNode or ox.Literal

REQUEST_SUFFIX = "-request"
SWRL = "http://www.w3.org/2003/11/swrl#"
DCTERMS_SOURCE = "http://purl.org/dc/terms/source"
DAML = "http://www.daml.org/2001/03/daml+oil#"

# OWL-S 1.0, 1.1 and 1.2 share the layout of their namespaces; terms are keyed "Module:local".
_OWLS_TERM = re.compile(
    r"^http://www\.daml\.org/services/owl-s/1\.[0-2]/(?:generic/)?"
    r"(Service|Profile|Process|Expression|ActorDefault)\.owl#(.+)$"
)
_IRI_IN_TEXT = re.compile(r"(?<![?\w])[A-Za-z][A-Za-z0-9+.-]*://[^\s()<>\"'?]+")
_RESOURCE_IN_XML = re.compile(r"""rdf:resource\s*=\s*["']([^"']+)["']""")
_PDDL_TOKEN = re.compile(r"\(|\)|[^\s()]+")
# Heads under which an atom says less than a positive statement: PDDL's and KIF's (=> and <=> are KIF's implications).
_NOT_TURNED = {"not", "or", "when", "imply", "forall", "exists", "either", "preference", "=>", "<=", "<=>"}

_CLASS_TYPES = {OWL + "Class", RDFS + "Class", DAML + "Class", OWL + "Restriction"}
_PROPERTY_TYPES = {
    RDF + "Property",
    OWL + "ObjectProperty",
    OWL + "DatatypeProperty",
    OWL + "AnnotationProperty",
    OWL + "FunctionalProperty",
    OWL + "InverseFunctionalProperty",
    OWL + "TransitiveProperty",
    OWL + "SymmetricProperty",
    DAML + "Property",
    DAML + "ObjectProperty",
    DAML + "DatatypeProperty",
}
_KINDS = {
    "dynamicperception": CBRS.DynamicPerceptionComponent,
    "staticdata": CBRS.StaticDataComponent,
    "physicalmanipulation": CBRS.PhysicalManipulationComponent,
    "methodinvocation": CBRS.MethodInvocationComponent,
}


def is_owls_ontology(iri: str) -> bool:
    """Whether ``iri`` is one of the OWL-S upper ontologies (``.../owl-s/1.1/Process.owl``...): the reader
    turns their terms into cbrs's model itself, so a file importing them needs no copy of them."""
    return _OWLS_TERM.match(iri.split("#", 1)[0] + "#x") is not None


def owls_key(iri: str) -> str | None:
    """``Process:hasInput`` for any OWL-S version's ``.../Process.owl#hasInput``; None for other IRIs."""
    match = _OWLS_TERM.match(iri)
    return f"{match.group(1)}:{match.group(2)}" if match else None


def is_owls(quads: Iterable[ox.Quad]) -> bool:
    """Whether the triples describe an OWL-S service or profile (an instance, not the OWL-S ontology)."""
    for q in quads:
        if (
            q.predicate.value == RDF + "type"
            and isinstance(q.object, ox.NamedNode)
            and owls_key(q.object.value) in ("Service:Service", "Profile:Profile")
        ):
            return True
    return False


SERVICE_LINKS = frozenset(
    f"Service:{local}"
    for local in ("presents", "presentedBy", "isPresentedBy", "describedBy", "describes", "supports", "supportedBy")
)
"""The OWL-S links between a service and its profiles, processes and groundings (``owls_key`` form),
either way round: what ties a service's own parts to it when they point at the service."""


def is_owls_service(kinds: Iterable[str]) -> bool:
    """Whether ``kinds`` (type IRIs) include an OWL-S ``Service`` of any version."""
    return any(owls_key(kind) == "Service:Service" for kind in kinds)


def requirement_iri(service_iri: str) -> str:
    """The IRI of the requirement made from the OWL-S service (request) ``service_iri``."""
    return service_iri + REQUEST_SUFFIX


def referenced_ontologies(quads: Iterable[ox.Quad]) -> list[tuple[str, str]]:
    """Ontology documents an OWL-S file needs: ``(iri, "owl:imports")`` for its imports, and
    ``(iri, "namespace")`` for the namespaces of its parameter types and of the IRIs its
    preconditions and effects name."""
    found: dict[str, str] = {}
    for q in quads:
        predicate = q.predicate.value
        if predicate == OWL + "imports" and isinstance(q.object, ox.NamedNode):
            found.setdefault(q.object.value.split("#", 1)[0], "owl:imports")
            continue
        key = owls_key(predicate)
        if key == "Process:parameterType" and isinstance(q.object, ox.Literal | ox.NamedNode):
            value = q.object.value.strip()
            if "://" in value:
                found.setdefault(namespace_document(value), "namespace")
        elif key == "Expression:expressionBody" and isinstance(q.object, ox.Literal):
            body = q.object.value
            # an XML literal (SWRL) repeats every namespace in scope: only its rdf:resource values count
            iris = _RESOURCE_IN_XML.findall(body) if body.lstrip().startswith("<") else _IRI_IN_TEXT.findall(body)
            for iri in iris:
                if "://" in iri:
                    found.setdefault(namespace_document(iri), "namespace")
    return [(iri, reason) for iri, reason in found.items() if not is_built_in(iri)]


# -- what the loaded ontologies declare ---------------------------------------------------------


@dataclass
class Vocabulary:
    """Terms of the loaded ontologies: which are classes, which properties, and which are described
    at all (the subject of some triple)."""

    classes: set[str] = field(default_factory=set)
    properties: set[str] = field(default_factory=set)
    described: set[str] = field(default_factory=set)
    _by_local: dict[str, list[str]] | None = field(default=None, repr=False)

    @classmethod
    def from_quads(cls, quads: Iterable[ox.Quad]) -> Vocabulary:
        vocabulary = cls()
        vocabulary.add(quads)
        return vocabulary

    def add(self, quads: Iterable[ox.Quad]) -> None:
        type_iri, sub_class, sub_property = RDF + "type", RDFS + "subClassOf", RDFS + "subPropertyOf"
        for q in quads:
            subject = q.subject
            if not isinstance(subject, ox.NamedNode):
                continue
            self.described.add(subject.value)
            predicate = q.predicate.value
            if predicate == type_iri and isinstance(q.object, ox.NamedNode):
                kind = q.object.value
                if kind in _CLASS_TYPES:
                    self.classes.add(subject.value)
                elif kind in _PROPERTY_TYPES:
                    self.properties.add(subject.value)
            elif predicate == sub_class:
                self.classes.add(subject.value)
            elif predicate in (sub_property, RDFS + "domain", RDFS + "range"):
                self.properties.add(subject.value)
        self._by_local = None

    def declares(self, iri: str) -> bool:
        return iri in self.described or is_built_in(iri)

    def is_class(self, iri: str) -> bool:
        return iri in self.classes

    def is_property(self, iri: str) -> bool:
        return iri in self.properties

    def by_local_name(self, name: str, documents: Iterable[str]) -> list[str]:
        """Declared terms with local name ``name`` in one of the ontology ``documents``."""
        if self._by_local is None:
            index: dict[str, list[str]] = defaultdict(list)
            for iri in self.classes | self.properties:
                index[local_name(iri)].append(iri)
            self._by_local = dict(index)
        wanted = set(documents)
        return sorted(iri for iri in self._by_local.get(name, []) if namespace_document(iri) in wanted)


# -- results ----------------------------------------------------------------------------------


@dataclass(frozen=True)
class ConvertedService:
    """One description made from an OWL-S service, with what went into it."""

    iri: str
    service: str
    role: Role
    name: str
    inputs: int
    outputs: int
    preconditions: int  # statements
    effects: int  # statements
    text_only: int  # condition nodes holding only the expression's text
    parameter_types: tuple[str, ...]
    statement_terms: tuple[str, ...]  # subjects, predicates and objects of its statements
    missing: tuple[str, ...] = ()  # which of service, profile and process the file does not give it


@dataclass
class Conversion:
    """The cbrs quads made from one OWL-S file and an account of them."""

    quads: list[ox.Quad] = field(default_factory=list)
    services: list[ConvertedService] = field(default_factory=list)
    expressions: int = 0  # precondition and effect expressions read
    expressions_turned: int = 0  # expressions that gave at least one statement
    atoms_turned: int = 0
    atoms_kept_as_text: int = 0
    notes: list[str] = field(default_factory=list)

    @property
    def expressions_text_only(self) -> int:
        return self.expressions - self.expressions_turned


# -- conversion -------------------------------------------------------------------------------


@dataclass(frozen=True)
class _Atom:
    """A PDDL or SWRL atom: a predicate and its arguments (variables start with ``?``)."""

    predicate: str
    arguments: tuple[str, ...]
    swrl_kind: str | None = None  # "class" or "property" for SWRL atoms, None for PDDL


_Sexp: TypeAlias = "str | list[_Sexp]"


class _Index:
    """The file's triples by subject and by object; OWL-S predicates keyed ``Module:local``."""

    def __init__(self, quads: Iterable[ox.Quad]) -> None:
        self.out: dict[Term, dict[str, list[Term]]] = defaultdict(lambda: defaultdict(list))
        self.into: dict[Term, dict[str, list[Term]]] = defaultdict(lambda: defaultdict(list))
        self.types: dict[Term, set[str]] = defaultdict(set)
        for q in quads:
            key = owls_key(q.predicate.value) or q.predicate.value
            self.out[q.subject][key].append(q.object)
            self.into[q.object][key].append(q.subject)
            if key == RDF + "type" and isinstance(q.object, ox.NamedNode):
                self.types[q.subject].add(owls_key(q.object.value) or q.object.value)

    def values(self, subjects: Iterable[Term], *keys: str) -> list[Term]:
        found: list[Term] = []
        for subject in subjects:
            for key in keys:
                for value in self.out.get(subject, {}).get(key, []):
                    if value not in found:
                        found.append(value)
        return found

    def subjects(self, objects: Iterable[Term], *keys: str) -> list[Term]:
        found: list[Term] = []
        for obj in objects:
            for key in keys:
                for subject in self.into.get(obj, {}).get(key, []):
                    if subject not in found:
                        found.append(subject)
        return found

    def text(self, subject: Term, *keys: str) -> str | None:
        for value in self.values([subject], *keys):
            if isinstance(value, ox.Literal) and value.value.strip():
                return " ".join(value.value.split())
        return None

    def typed(self, kind: str) -> list[Term]:
        return [s for s, kinds in self.types.items() if kind in kinds]


def convert(
    quads: Sequence[ox.Quad],
    source: str,
    role: Role = "advertisement",
    graph: ox.NamedNode | None = None,
    vocabulary: Vocabulary | None = None,
    prefixes: Mapping[str, str] | None = None,
) -> Conversion:
    """The cbrs description of every OWL-S service in ``quads`` (one file's triples).

    ``source`` names the file (its stem is the device name when no contact gives one); ``graph`` is
    the graph of the quads returned (the default graph when None); ``vocabulary`` tells classes from
    properties and resolves bare names in expressions; ``prefixes`` are the file's own namespace
    prefixes, for prefixed names in PDDL.
    """
    index = _Index(quads)
    result = Conversion()
    builder = _Builder(quads, index, result, source, role, graph, vocabulary or Vocabulary(), dict(prefixes or {}))
    profiles = index.typed("Profile:Profile")
    # a service is typed so, or named by a profile's links even when its own type is missing
    services = list(
        dict.fromkeys(
            [
                *index.typed("Service:Service"),
                *index.subjects(profiles, "Service:presents"),
                *index.values(profiles, "Service:presentedBy", "Service:isPresentedBy"),
            ]
        )
    )
    presented: set[Term] = set()
    for service in services:
        own = _profiles(index, service)
        presented.update(own)
        builder.service(service, own)
    for profile in profiles:
        if profile not in presented:
            builder.service(profile, [profile])  # a profile on its own describes its service
    return result


def _profiles(index: _Index, service: Term) -> list[Term]:
    return [
        *index.values([service], "Service:presents"),
        *(p for p in index.subjects([service], "Service:presentedBy", "Service:isPresentedBy")),
    ]


class _Builder:
    def __init__(
        self,
        quads: Sequence[ox.Quad],
        index: _Index,
        result: Conversion,
        source: str,
        role: Role,
        graph: ox.NamedNode | None,
        vocabulary: Vocabulary,
        prefixes: dict[str, str],
    ) -> None:
        self.index = index
        self.result = result
        self.text_spent = 0  # characters of expression text the statements made so far carry
        self.source = source
        self.role = role
        self.graph = graph if graph is not None else ox.DefaultGraph()
        self.vocabulary = vocabulary
        self.prefixes = prefixes
        self.documents = {iri for iri, _ in referenced_ontologies(quads)}
        # every parameter of the file (inputs, outputs, locals), for typing expression variables
        self.parameter_types: dict[str, str] = {}
        for subject, keyed in index.out.items():
            if isinstance(subject, ox.NamedNode) and keyed.get("Process:parameterType"):
                concept = _concept(subject, keyed["Process:parameterType"][0])
                if concept:
                    self.parameter_types[subject.value] = concept
        self.by_local: dict[str, list[str]] = defaultdict(list)
        for iri in self.parameter_types:
            self.by_local[local_name(iri).lower()].append(iri)

    # -- one service ---------------------------------------------------------------------------

    def service(self, service: Term, profiles: list[Term]) -> None:
        index = self.index
        if not isinstance(service, ox.NamedNode):
            self.note(f"a service without an IRI in {self.source} was skipped")
            return
        processes = [
            *index.values([service], "Service:describedBy"),
            *index.subjects([service], "Service:describes"),
            *index.values(profiles, "Profile:has_process"),
        ]
        holders = [*profiles, *processes]
        typed = set(index.typed("Service:Service"))
        missing = tuple(
            part
            for part, present in (
                ("service", service in typed),
                ("profile", bool(profiles)),
                ("process", bool(processes)),
            )
            if not present
        )
        iri = service.value if self.role == "advertisement" else requirement_iri(service.value)
        node = ox.NamedNode(iri)
        name = _first_text(index, profiles, "Profile:serviceName") or local_name(service.value)
        categories = self.categories(profiles)
        kind = CBRS.Requirement if self.role == "requirement" else _kind_for(categories)
        self.add(node, RDF + "type", ox.NamedNode(kind))
        self.add(node, RDFS + "label", ox.Literal(name))
        self.add(node, CBRS.serviceName, ox.Literal(name))
        self.add(node, CBRS.deviceName, ox.Literal(self.device_name(profiles)))
        description = _first_text(index, profiles, "Profile:textDescription")
        if description:
            self.add(node, RDFS + "comment", ox.Literal(description))
        for category in categories:
            self.add(node, CBRS.serviceCategory, ox.Literal(category))
        if self.role == "requirement":
            self.add(node, DCTERMS_SOURCE, service)
        model = ox.BlankNode()
        self.add(node, CBRS.hasOWLSModel, model)
        self.add(model, RDF + "type", ox.NamedNode(CBRS.OWLSModel))

        types: list[str] = []
        counts = {}
        for direction, profile_key, process_key, link in (
            ("input", "Profile:hasInput", "Process:hasInput", CBRS.hasInput),
            ("output", "Profile:hasOutput", "Process:hasOutput", CBRS.hasOutput),
        ):
            parameters = index.values(profiles, profile_key) or index.values(processes, process_key)
            counts[direction] = 0
            for number, parameter in enumerate(parameters, start=1):
                concept = self.parameter(parameter, model, link, f"{direction}{number}", iri)
                if concept:
                    types.append(concept)
                    counts[direction] += 1

        results = index.values(holders, "Process:hasResult", "Profile:hasResult")
        terms: list[str] = []
        statements: dict[tuple[str, str, str, str], ox.BlankNode] = {}
        text_only = 0
        for role, expressions in (
            ("precondition", index.values(holders, "Process:hasPrecondition", "Profile:hasPrecondition")),
            ("effect", index.values([*results, *holders], "Process:hasEffect", "Profile:hasEffect")),
        ):
            for expression in expressions:
                if not self.condition(expression, role, model, statements, terms):
                    text_only += 1
        self.result.services.append(
            ConvertedService(
                iri=iri,
                service=service.value,
                role=self.role,
                name=name,
                inputs=counts["input"],
                outputs=counts["output"],
                preconditions=sum(1 for key in statements if key[0] == "precondition"),
                effects=sum(1 for key in statements if key[0] == "effect"),
                text_only=text_only,
                parameter_types=tuple(dict.fromkeys(types)),
                statement_terms=tuple(dict.fromkeys(terms)),
                missing=missing,
            )
        )

    def categories(self, profiles: list[Term]) -> list[str]:
        names = []
        for category in self.index.values(profiles, "Profile:serviceCategory"):
            if isinstance(category, ox.Literal):
                text: str | None = " ".join(category.value.split())
            else:
                text = self.index.text(category, "Profile:categoryName", "Profile:value", "Profile:code")
                if text is None and isinstance(category, ox.NamedNode):
                    text = local_name(category.value)
            if text and text not in names:
                names.append(text)
        return names

    def device_name(self, profiles: list[Term]) -> str:
        for contact in self.index.values(profiles, "Profile:contactInformation", "Profile:serviceProvider"):
            if isinstance(contact, ox.Literal) and contact.value.strip():
                return " ".join(contact.value.split())
            name = self.index.text(contact, "ActorDefault:name", "ActorDefault:title", RDFS + "label")
            if name:
                return name
            if isinstance(contact, ox.NamedNode):
                return local_name(contact.value)
        return Path(self.source).stem

    def parameter(self, parameter: Term, model: ox.BlankNode, link: str, fallback: str, iri: str) -> str | None:
        types = self.index.values([parameter], "Process:parameterType")
        concept = _concept(parameter, types[0]) if types else None
        label = self.index.text(parameter, RDFS + "label")
        name = label or (local_name(parameter.value) if isinstance(parameter, ox.NamedNode) else fallback)
        if concept is None:
            what = "no" if not types else f"an unusable ({types[0].value!r})"
            self.note(f"{iri}: parameter {name} has {what} process:parameterType and was left out")
            return None
        node = ox.BlankNode()
        self.add(model, link, node)
        self.add(node, RDF + "type", ox.NamedNode(CBRS.Parameter))
        self.add(node, CBRS.parameterName, ox.Literal(name))
        self.add(node, CBRS.parameterType, ox.NamedNode(concept))
        return concept

    # -- preconditions and effects -----------------------------------------------------------

    def condition(
        self,
        expression: Term,
        role: str,
        model: ox.BlankNode,
        statements: dict[tuple[str, str, str, str], ox.BlankNode],
        terms: list[str],
    ) -> bool:
        """Turn one expression into statements; False when it was kept as text only."""
        self.result.expressions += 1
        text, atoms, kept = self.read_expression(expression)
        cost = len(text) * len(atoms)
        if cost and self.text_spent + cost > CONDITION_TEXT_BUDGET:
            self.note(
                f"{self.source}: an expression of {len(atoms)} atoms and {len(text)} characters kept as text "
                f"(its statements would carry {cost} characters; {CONDITION_TEXT_BUDGET} per file at most)"
            )
            atoms, kept = [], kept + len(atoms)
        self.text_spent += cost if atoms else 0
        kind = CBRS.Precondition if role == "precondition" else CBRS.Effect
        link = CBRS.hasPrecondition if role == "precondition" else CBRS.hasEffect
        made = 0
        for atom in atoms:
            triple = self.statement(atom)
            if triple is None:
                kept += 1
                continue
            made += 1
            key = (role, *triple)
            node = statements.get(key)
            if node is None:
                node = ox.BlankNode()
                statements[key] = node
                self.add(model, link, node)
                self.add(node, RDF + "type", ox.NamedNode(kind))
                for part, value in zip(CONDITION_PARTS, triple, strict=True):
                    self.add(node, part, ox.NamedNode(value))
                terms.extend(t for t in triple if t != RDF + "type")
            if text:
                self.add(node, CBRS.conditionText, ox.Literal(text))
        self.result.atoms_turned += made
        self.result.atoms_kept_as_text += kept
        if made:
            self.result.expressions_turned += 1
            return True
        node = ox.BlankNode()
        self.add(model, RDFS + "seeAlso", node)
        self.add(node, RDF + "type", ox.NamedNode(kind))
        self.add(node, CBRS.conditionText, ox.Literal(text or "(empty expression)"))
        return False

    def read_expression(self, expression: Term) -> tuple[str, list[_Atom], int]:
        """The expression's text, the atoms that may become statements, and how many may not."""
        index = self.index
        if isinstance(expression, ox.Literal):
            body: Term | None = expression
        else:
            bodies = index.values([expression], "Expression:expressionBody")
            body = bodies[0] if bodies else None
        lists = index.values([expression], "Expression:expressionObject")
        if not lists and not isinstance(expression, ox.Literal) and _is_atom_list(index, expression):
            lists = [expression]
        if lists:
            atoms, kept = _swrl_atoms(index, lists[0])
            text = body.value.strip() if body is not None else _render(atoms)
            return text, atoms, kept
        if body is None:
            return "", [], 1
        text = body.value.strip()
        language = self.language(expression)
        if text.startswith("<") or language == "SWRL":
            atoms, kept = self.swrl_literal(text)
            return text, atoms, kept
        if text.startswith("(") and language in ("PDDL", "KIF", None):  # KIF atoms are s-expressions as PDDL's
            name = language or "PDDL"
            try:
                tree = _parse_sexp(text)
            except ValueError as error:
                self.note(f"{self.source}: {name} expression kept as text ({error}): {_short(text)}")
                return text, [], 1
            atoms, kept = [], 0
            try:
                for formula in tree:
                    found, skipped = _pddl_atoms(formula)
                    atoms.extend(found)
                    kept += skipped
            except RecursionError:
                self.note(f"{self.source}: {name} expression nested too deeply, kept as text: {_short(text)}")
                return text, [], 1
            return text, atoms, kept
        return text, [], 1

    def language(self, expression: Term) -> str | None:
        if isinstance(expression, ox.Literal):
            return None
        names = [local_name(v.value) for v in self.index.values([expression], "Expression:expressionLanguage")]
        names += [k.rsplit(":", 1)[-1].rsplit("#", 1)[-1] for k in self.index.types.get(expression, ())]
        for name in names:
            upper = name.upper()
            for language in ("SWRL", "PDDL", "KIF", "DRS"):
                if upper.startswith(language):
                    return language
        return None

    def swrl_literal(self, text: str) -> tuple[list[_Atom], int]:
        """SWRL atoms written as RDF/XML inside the expression body (``rdf:parseType="Literal"``)."""
        namespaces = {"rdf": RDF, "swrl": SWRL, **self.prefixes}
        declarations = " ".join(f'xmlns:{p}="{ns}"' for p, ns in namespaces.items() if p and '"' not in ns)
        document = f"<rdf:RDF {declarations}>{text}</rdf:RDF>"
        try:
            check_entities(document.encode("utf-8"), self.source)
            parsed = list(ox.parse(input=document.encode("utf-8"), format=ox.RdfFormat.RDF_XML, base_iri=self.base()))
        except (SyntaxError, ValueError, RdfParseError) as error:
            self.note(f"{self.source}: SWRL expression kept as text ({error})")
            return [], 1
        inner = _Index(parsed)
        heads = [s for s in inner.out if _is_atom_list(inner, s) and not inner.into.get(s, {}).get(RDF + "rest")]
        atoms: list[_Atom] = []
        kept = 0
        for head in heads:
            found, skipped = _swrl_atoms(inner, head)
            atoms.extend(found)
            kept += skipped
        return atoms, kept if atoms or kept else 1

    def base(self) -> str:
        for subject in self.index.typed(OWL + "Ontology"):
            if isinstance(subject, ox.NamedNode):
                return subject.value
        for subject in self.index.typed("Service:Service"):
            if isinstance(subject, ox.NamedNode):
                return subject.value.split("#", 1)[0]
        return "urn:cbrs:owls"

    def statement(self, atom: _Atom) -> tuple[str, str, str] | None:
        """(subject class, predicate, object class) for an atom, or None when it is not one."""
        predicate = self.resolve_name(atom.predicate)
        if predicate is None:
            return None
        arguments = [self.resolve_argument(a) for a in atom.arguments]
        if any(a is None for a in arguments):
            return None
        vocabulary = self.vocabulary
        unary = atom.swrl_kind == "class" or (atom.swrl_kind is None and len(arguments) == 1)
        binary = atom.swrl_kind == "property" or (atom.swrl_kind is None and len(arguments) == 2)
        if unary and len(arguments) == 1:
            if vocabulary.is_property(predicate) and not vocabulary.is_class(predicate):
                return None  # (isReserved ?x): a property used as a one-place predicate says no statement
            return str(arguments[0]), RDF + "type", predicate
        if binary and len(arguments) == 2:
            if vocabulary.is_class(predicate) and not vocabulary.is_property(predicate):
                return None
            return str(arguments[0]), predicate, str(arguments[1])
        return None

    def resolve_name(self, token: str) -> str | None:
        """A predicate or constant: a full IRI, a prefixed name, or a bare name the file's ontologies declare."""
        token = token.strip("<>")
        if "://" in token or token.startswith("urn:"):
            return _valid_iri(token)
        prefix, sep, local = token.partition(":")
        if sep and prefix in self.prefixes:
            return _valid_iri(self.prefixes[prefix] + local)
        if not sep:
            matches = self.vocabulary.by_local_name(token, self.documents)
            if len(matches) == 1:
                return matches[0]
        return None

    def resolve_argument(self, token: str) -> str | None:
        """A variable stands for its parameter's type; anything else for itself."""
        if not token.startswith("?"):
            # a SWRL argument may be the parameter itself (OWL-S parameters are SWRL variables)
            return self.parameter_types.get(token) or self.resolve_name(token)
        name = token[1:]
        if name in self.parameter_types:
            return self.parameter_types[name]
        # the variable may name the parameter by a different namespace, or by its local name only
        matches = self.by_local.get(local_name(name).lower(), [])
        if len(matches) == 1:
            return self.parameter_types[matches[0]]
        return None

    # -- output --------------------------------------------------------------------------------

    def add(self, subject: Term, predicate: str, obj: Term) -> None:
        self.result.quads.append(ox.Quad(subject, ox.NamedNode(predicate), obj, self.graph))

    def note(self, text: str) -> None:
        self.result.notes.append(text)


def _first_text(index: _Index, subjects: list[Term], key: str) -> str | None:
    for subject in subjects:
        text = index.text(subject, key)
        if text:
            return text
    return None


def _kind_for(categories: Sequence[str]) -> str:
    """The component kind a category names (``Dynamic perception``, ``StaticDataComponent``...);
    method invocation otherwise."""
    for category in categories:
        squashed = re.sub(r"[^a-z]", "", category.lower().rsplit("#", 1)[-1]).removesuffix("component")
        if squashed in _KINDS:
            return _KINDS[squashed]
    return CBRS.MethodInvocationComponent


def _concept(parameter: Term, value: Term) -> str | None:
    """A parameter type given as an IRI or an ``xsd:anyURI`` literal, made absolute."""
    text = value.value.strip()
    if not text:
        return None
    if "://" not in text and not text.startswith("urn:"):
        if not isinstance(parameter, ox.NamedNode):
            return None
        text = urljoin(parameter.value, text)
    return _valid_iri(text)


def _valid_iri(text: str) -> str | None:
    try:
        return str(ox.NamedNode(text).value)
    except ValueError:
        return None


def local_name(iri: str) -> str:
    """The part after ``#``, else after the last ``/`` or ``:``."""
    for separator in ("#", "/", ":"):
        if separator in iri.rstrip(separator):
            tail = iri.rstrip(separator).rsplit(separator, 1)[1]
            if tail:
                return tail
    return iri


def _short(text: str, limit: int = 80) -> str:
    flat = " ".join(text.split())
    return flat if len(flat) <= limit else flat[: limit - 3] + "..."


# -- PDDL ---------------------------------------------------------------------------------------


def _parse_sexp(text: str) -> list[_Sexp]:
    """The s-expressions in ``text``; ValueError when the parentheses do not balance."""
    stack: list[list[_Sexp]] = [[]]
    for token in _PDDL_TOKEN.findall(text):
        if token == "(":
            stack.append([])
        elif token == ")":
            if len(stack) == 1:
                raise ValueError("a ')' closes nothing")
            done = stack.pop()
            stack[-1].append(done)
        else:
            stack[-1].append(token)
    if len(stack) != 1:
        raise ValueError(f"{len(stack) - 1} unclosed '('")
    return stack[0]


def _pddl_atoms(formula: _Sexp) -> tuple[list[_Atom], int]:
    """Positive atoms of a conjunction; anything under not/or/when/forall... counts as kept text."""
    if isinstance(formula, str) or not formula:
        return [], 1
    head = formula[0]
    if isinstance(head, list):
        return [], 1
    if head.lower() == "and":
        atoms: list[_Atom] = []
        kept = 0
        for part in formula[1:]:
            found, skipped = _pddl_atoms(part)
            atoms.extend(found)
            kept += skipped
        return atoms, kept
    if head.lower() in _NOT_TURNED or not all(isinstance(a, str) for a in formula[1:]):
        return [], 1
    return [_Atom(head, tuple(str(a) for a in formula[1:]))], 0


# -- SWRL ---------------------------------------------------------------------------------------


def _is_atom_list(index: _Index, node: Term) -> bool:
    return SWRL + "AtomList" in index.types.get(node, set()) or bool(index.out.get(node, {}).get(RDF + "first"))


def _swrl_atoms(index: _Index, head: Term) -> tuple[list[_Atom], int]:
    """The atoms of an ``swrl:AtomList`` (an RDF list); atoms other than class and
    individual-property atoms are counted as kept text."""
    atoms: list[_Atom] = []
    kept = 0
    node: Term = head
    seen: set[Term] = set()
    while isinstance(node, ox.NamedNode | ox.BlankNode) and node not in seen and node.value != RDF + "nil":
        seen.add(node)
        for atom in index.values([node], RDF + "first"):
            kinds = index.types.get(atom, set())
            if SWRL + "IndividualPropertyAtom" in kinds:
                parts = [*index.values([atom], SWRL + "propertyPredicate")]
                arguments = [*index.values([atom], SWRL + "argument1"), *index.values([atom], SWRL + "argument2")]
                kind = "property"
            elif SWRL + "ClassAtom" in kinds:
                parts = [*index.values([atom], SWRL + "classPredicate")]
                arguments = index.values([atom], SWRL + "argument1")
                kind = "class"
            else:
                kept += 1
                continue
            if len(parts) != 1 or not all(isinstance(a, ox.NamedNode) for a in [*parts, *arguments]):
                kept += 1
                continue
            variables = tuple(
                "?" + a.value if SWRL + "Variable" in index.types.get(a, set()) or _is_parameter(index, a) else a.value
                for a in arguments
            )
            atoms.append(_Atom(parts[0].value, variables, kind))
        rest = index.values([node], RDF + "rest")
        node = rest[0] if rest else None
    return atoms, kept


def _is_parameter(index: _Index, node: Term) -> bool:
    kinds = index.types.get(node, set())
    return bool(kinds & {"Process:Input", "Process:Output", "Process:Local", "Process:Parameter"}) or bool(
        index.out.get(node, {}).get("Process:parameterType")
    )


def _render(atoms: Sequence[_Atom]) -> str:
    return " ^ ".join(f"{a.predicate}({', '.join(a.arguments)})" for a in atoms) or "(empty SWRL atom list)"
