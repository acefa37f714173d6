"""The paper's matchmaking testbed (section 6.1): 20 requirements and 100 service components.

The paper says only that it "generated a testing database including 20 requirements and 100 service
components" and "selected some testing pairs of Advertisements and Requirements in which their IOPE
entities were not given with exactly the same strings", with Position and Location (both x, y, theta)
as the example. This module rebuilds such a database for the home-care domain of ``ontologies/`` from
rules fixed before any method was run on it, and from the catalogue of intents, advertisements, devices
and new concepts in ``reasoner/data/paper_testbed_catalogue.toml``. ``python -m cbrs.reasoner.testbed`` writes
``reasoner/data/paper_testbed.ttl`` and ``reasoner/data/paper_testbed_truth.json``; the same seed gives
byte-identical files.

Rules of the testbed
--------------------

T1. Twenty requirement intents of home-care robots (the ``[[intents]]`` of the catalogue), each one
    requirement in the shape of ``ontologies/requirements.ttl``: requester, DN, SN, SC and IOPE.
    Requirements state no SEA and no QoS bounds: the SEA/QoS filters act the same for every method
    and section 6.1 measures the matching of IOPE entities.
T2. Every intent has one to three relevant advertisements, 42 in all. A relevant advertisement does
    what the requester asks, can be invoked with what the requester offers (each of its inputs is one
    of the offered concepts, a superclass of one, or a variant of one by a rule below) and, where the
    requirement states an effect, has an effect that says the same thing (possibly with sub- or
    superclass terms).
T3. No relevant pair shares the exact string of its decisive entity: the requested output, or for a
    requirement without outputs the effect (or input) that varies. Each relevant pair exercises one
    naming variation on that entity, recorded in the truth file:

    - ``synonym-sibling``: another word for the same thing, declared next to the requested concept
      (neither subsumes the other, they meet at most two is-a links above each) with the same parts,
      if any. Position vs Location, RobotPosition vs RobotLocation.
    - ``subclass``: a differently named, more specific declared concept (OccupancyGridMap for GridMap).
    - ``superclass``: a differently named, more general declared concept (Temperature for
      RoomTemperature): accepted by the paper's threshold {Exact, SubClassOf, HasSubClass}.
    - ``reworded-compound``: the requested concept's words with the head word moved, joined by a
      linking word (TemperatureOfRoom for RoomTemperature, like home:ColourOfMarker for
      MarkerColour); the testbed declares it as a subclass of the concept it rewords.
    - ``undeclared``: a concept declared in no ontology (only used as a parameter type), so that no
      taxonomy information exists and only the name can help; it keeps the head word of the concept
      it stands for (ResidentLocation for PersonLocation).
    - ``parts-not-wholes``: the whole concepts are different kinds of thing (they meet more than two
      is-a links above one of them, or only at the root) but every part of the requested concept
      has an equal or is-a related part in the advertised one (a 3D bounding box for an object's 3D
      position, GoalPose for PersonLocation, a map image with resolution and origin for a grid map).

    The mix is fixed by the catalogue: 8 synonym-sibling, 8 subclass, 4 superclass, 8
    reworded-compound, 7 undeclared, 7 parts-not-wholes. The paper's own example (same parts under
    another name) and naming variation weigh most; a superclass offer is rarer because it is less
    specific than asked.
T4. The other 58 advertisements are distractors written for one intent each (and every advertisement
    of another intent is a distractor too). Their kinds: ``same-words`` (shares words with the
    request but is another thing: PersonPosition when the robot's position is wanted),
    ``same-family`` (a sibling concept of the same family: a topological map for a grid map),
    ``wrong-inputs`` (the requested output, or nearly, from inputs the requester cannot provide),
    ``other-output`` (takes what the requester offers, returns something else), ``consumes-it``
    (takes the requested concept as input) and ``wrong-effect`` (acts on the same things with another
    effect). No distractor is relevant to any intent.
T5. New concepts are declared in the testbed file under ``tb:`` as subclasses of home classes, with
    their parts restated as existential hasPart restrictions (the home.ttl convention).
T6. The seed decides only what does not change relevance: which device of a pool hosts each
    service (and so its SEA), its QoS figures, and the numbers in the advertisement IRIs
    (``tb:A017_...``), which decide ties in the matchmaker's ordering. The catalogue order, the
    IOPE of every description and the truth never depend on it.

The data was not adjusted after seeing any method's scores.
"""

from __future__ import annotations

import argparse
import difflib
import functools
import json
import random
import re
import sys
import tomllib
from collections import Counter
from collections.abc import Collection, Sequence
from dataclasses import MISSING, dataclass, fields, is_dataclass
from pathlib import Path
from typing import Any, get_args, get_type_hints

from cbrs.kb import Advertisement, KnowledgeBase, PartNode, Requirement, ServiceDescription, Store
from cbrs.kb.namespaces import GraphName
from cbrs.kb.resources import bundled_files
from cbrs.reasoner.names import local_name, words
from cbrs.reasoner.taxonomy import ROOT, TaxonomyIndex

TB = "https://w3id.org/cbrs/testbed#"
HOME = "https://w3id.org/cbrs/home#"
CBRS = "https://w3id.org/cbrs/core#"
SEED = 61
DATA_DIR = Path(__file__).resolve().parent / "data"
TESTBED_FILE = DATA_DIR / "paper_testbed.ttl"
TRUTH_FILE = DATA_DIR / "paper_testbed_truth.json"
CATALOGUE_FILE = DATA_DIR / "paper_testbed_catalogue.toml"

RULES: dict[str, str] = {
    "synonym-sibling": "another word for the same thing, declared beside the requested concept, same parts",
    "subclass": "a differently named, more specific declared concept",
    "superclass": "a differently named, more general declared concept",
    "reworded-compound": "the same words with the head word moved and a linking word (TemperatureOfRoom)",
    "undeclared": "a concept declared nowhere, keeping the head word; only its name can help",
    "parts-not-wholes": "wholes of different kinds, the requested parts all found among the advertised parts",
}

DISTRACTOR_KINDS: dict[str, str] = {
    "same-words": "shares words with the requested concept but is another thing",
    "same-family": "a sibling concept of the same family, not the one asked for",
    "wrong-inputs": "the requested output, or nearly, from inputs the requester cannot provide",
    "other-output": "takes what the requester offers and returns something else",
    "consumes-it": "takes the requested concept as an input instead of producing it",
    "wrong-effect": "acts on the same things with another effect",
}

_KINDS = {
    "DPC": "cbrs:DynamicPerceptionComponent",
    "SDC": "cbrs:StaticDataComponent",
    "PMC": "cbrs:PhysicalManipulationComponent",
    "MIC": "cbrs:MethodInvocationComponent",
}

# Floor plan shared with ontologies/services.ttl: place concept and bounding box (min x, max x, min y, max y).
_AREAS: dict[str, tuple[str, float, float, float, float]] = {
    "LivingRoom": ("home:LivingRoom", 0.0, 6.0, 0.0, 5.0),
    "Kitchen": ("home:Kitchen", 6.0, 10.0, 0.0, 5.0),
    "Bedroom": ("home:Bedroom", 0.0, 6.0, 5.0, 9.0),
    "Home": ("home:Home", 0.0, 10.0, 0.0, 9.0),
    "KitchenTable": ("home:Kitchen", 7.0, 8.5, 3.0, 4.5),
}

Triple = tuple[str, str, str]


# --------------------------------------------------------------------------------------------------
# The catalogue (data/paper_testbed_catalogue.toml): its records, read and checked
# --------------------------------------------------------------------------------------------------
# A record is a table of the file and its fields the table's keys; _Reader checks each value against the
# field's annotation.


@dataclass(frozen=True)
class NewClass:
    """A concept the testbed declares: its parent home class and its parts (property, class)."""

    name: str
    parent: str
    comment: str
    parts: tuple[tuple[str, str], ...] = ()


@dataclass(frozen=True)
class Device:
    name: str
    type: str
    area: str
    comment: str


@dataclass(frozen=True, kw_only=True)
class Ad:
    """An advertisement template: everything but its host, QoS and IRI number."""

    service: str
    component: str  # a key of _KINDS
    hosts: tuple[str, ...]
    category: str
    inputs: tuple[str, ...] = ()
    outputs: tuple[str, ...] = ()
    preconditions: tuple[Triple, ...] = ()
    effects: tuple[Triple, ...] = ()
    port: str = "data"


@dataclass(frozen=True, kw_only=True)
class Relevant(Ad):
    rule: str
    role: str  # which entity carries the variation: output, input, effect subject, effect object
    requested: str
    advertised: str
    why: str


@dataclass(frozen=True, kw_only=True)
class Distractor(Ad):
    kind: str
    why: str


@dataclass(frozen=True)
class Intent:
    key: str
    title: str
    requester: str
    category: str
    comment: str
    relevant: tuple[Relevant, ...]
    distractors: tuple[Distractor, ...] = ()
    inputs: tuple[str, ...] = ()
    outputs: tuple[str, ...] = ()
    preconditions: tuple[Triple, ...] = ()
    effects: tuple[Triple, ...] = ()


@dataclass(frozen=True)
class Catalogue:
    devices: tuple[Device, ...]
    new_classes: tuple[NewClass, ...]
    intents: tuple[Intent, ...]
    undeclared: tuple[str, ...] = ()


class CatalogueError(ValueError):
    """The catalogue file is malformed; the message names the entry and the field at fault."""


_CURIE = re.compile(r"(home|tb|cbrs):[A-Za-z][A-Za-z0-9_]*")
_CURIE_FIELDS = {"type", "parent", "requested", "advertised", "inputs", "outputs", "undeclared", "parts"}
_CURIE_FIELDS |= {"preconditions", "effects"}
# Arrays whose items may be names of constants, defined in tables at the top of the file (spliced in place).
_CONSTANTS = {"hosts": "device_groups", "parts": "part_sets", "preconditions": "statements", "effects": "statements"}


def _error(where: str, problem: str, name: object = None, known: Collection[str] = ()) -> CatalogueError:
    close = difflib.get_close_matches(str(name), known, n=1)
    return CatalogueError(f"{where}: {problem}" + (f" (did you mean {close[0]!r}?)" if close else ""))


class _Reader:
    """Builds records from the parsed file. A field's annotation says what its value must be: a string, a
    tuple of n strings (a list of n names), or an array of those or of records (tables)."""

    def __init__(self, constants: dict[str, Any], devices: Collection[str]) -> None:
        for section, table in constants.items():
            if not isinstance(table, dict):
                raise _error("top level", f"{section!r} should be a table of constants, got {table!r}")
        self.constants = constants
        roles = ("output", "input", "effect subject", "effect object")
        self.choices: dict[str, Collection[str]] = {"area": _AREAS, "component": _KINDS, "rule": RULES, "role": roles}
        self.choices |= {"kind": DISTRACTOR_KINDS, "port": ("data", "event", "service")}
        self.choices |= {"requester": devices, "hosts": devices}

    def record(self, cls: type[Any], table: object, where: str) -> Any:
        """A ``cls`` from a table keyed by its field names; ``where`` names the table in errors."""
        if not isinstance(table, dict):
            raise _error(where, f"expected a table, got {table!r}")
        hints = get_type_hints(cls)
        known = [*hints, *(self.constants if cls is Catalogue else ())]  # at the top level, tables of constants too
        for key in table:
            if key not in hints:
                raise _error(where, f"unknown field {key!r}", key, known)
        missing = [field.name for field in fields(cls) if field.name not in table and field.default is MISSING]
        if missing:
            raise _error(where, f"missing field {missing[0]!r}")
        return cls(**{key: self.value(hints[key], value, where, key) for key, value in table.items()})

    def value(self, hint: Any, value: Any, entry: str, name: str) -> Any:
        """The value of the field ``name`` of the table ``entry``, as the type ``hint``."""
        where, args = f"{entry}, field {name!r}", get_args(hint)
        if hint is str:
            if not isinstance(value, str) or not value:
                raise _error(where, f"expected a non-empty string, got {value!r}")
            if name in self.choices and value not in self.choices[name]:
                known = [*self.choices[name], *(self.constants["device_groups"] if name == "hosts" else ())]
                raise _error(where, f"unknown name {value!r}", value, known)
            if name in _CURIE_FIELDS and not _CURIE.fullmatch(value):
                raise _error(where, f"{value!r} is not a home:, tb: or cbrs: name")
            return value
        if args[-1] is not Ellipsis:  # a (property, class) part or a (subject, predicate, object) statement
            if not isinstance(value, list) or len(value) != len(args):
                known = self.constants[_CONSTANTS[name]]
                raise _error(where, f"{value!r} is neither a list of {len(args)} names nor a constant", value, known)
            return tuple(self.value(str, item, entry, name) for item in value)
        if name == "devices" and isinstance(value, dict):  # a table keyed by device name
            value = [{"name": key, **table} if isinstance(table, dict) else table for key, table in value.items()]
        if not isinstance(value, list):
            raise _error(where, f"expected an array, got {value!r}")
        items: list[Any] = []
        for item in value:
            constant = self.constants.get(_CONSTANTS.get(name, ""), {}).get(item) if isinstance(item, str) else None
            spliced = isinstance(constant, list) and _CONSTANTS[name] != "statements"  # a statement is one item
            items += [item] if constant is None else constant if spliced else [constant]
        cls: type[Any] = args[0]
        if not is_dataclass(cls):
            return tuple(self.value(cls, item, entry, name) for item in items)
        prefix, key = "" if entry == "top level" else f"{entry}, ", fields(cls)[0].name
        titles = [repr(t[key]) if isinstance(t, dict) and key in t else f"#{n}" for n, t in enumerate(items, 1)]
        return tuple(self.record(cls, t, f"{prefix}{name} {title}") for t, title in zip(items, titles, strict=True))


def load_catalogue(path: Path = CATALOGUE_FILE) -> Catalogue:
    """Read and check a catalogue file; a ``CatalogueError`` names the entry and the field at fault."""
    try:
        data = tomllib.loads(path.read_text(encoding="utf-8"))
        constants = {key: data.pop(key, {}) for key in ("device_groups", "part_sets", "statements")}
        reader = _Reader(constants, data["devices"] if isinstance(data.get("devices"), dict) else {})
        catalogue: Catalogue = reader.record(Catalogue, data, "top level")
        return catalogue
    except tomllib.TOMLDecodeError as error:
        raise CatalogueError(f"{path.name}: not valid TOML: {error}") from None
    except CatalogueError as error:
        raise CatalogueError(f"{path.name}: {error}") from None


@functools.cache
def catalogue() -> Catalogue:
    """The bundled catalogue file, read once."""
    return load_catalogue()


# --------------------------------------------------------------------------------------------------
# Generation
# --------------------------------------------------------------------------------------------------


def expand(curie: str) -> str:
    """A ``home:``, ``tb:`` or ``cbrs:`` CURIE as a full IRI."""
    prefix, _, name = curie.partition(":")
    return {"home": HOME, "tb": TB, "cbrs": CBRS}[prefix] + name


def requirement_curie(number: int, intent: Intent) -> str:
    return f"tb:R{number:02d}_{intent.key}"


@dataclass(frozen=True)
class _Placed:
    """An advertisement template of an intent with what the seed decided: its number, host and QoS."""

    number: int
    intent: Intent
    template: Relevant | Distractor
    host: Device
    qos: tuple[tuple[str, float], ...]

    @property
    def curie(self) -> str:
        return f"tb:A{self.number:03d}_{self.template.service}"


def _place(seed: int, cat: Catalogue) -> list[_Placed]:
    """The advertisement templates in catalogue order (each intent's relevant ones, then its distractors)."""
    rng = random.Random(seed)
    entries = [(intent, item) for intent in cat.intents for item in intent.relevant + intent.distractors]
    numbers = list(range(1, len(entries) + 1))
    rng.shuffle(numbers)
    devices = {device.name: device for device in cat.devices}
    placed = []
    for number, (intent, template) in zip(numbers, entries, strict=True):
        host = devices[rng.choice(template.hosts)]
        qos: list[tuple[str, float]] = [
            ("responseTime", round(rng.uniform(0.02, 0.5), 2)),
            ("availability", round(rng.uniform(0.85, 0.99), 2)),
        ]
        if template.port in ("data", "event"):
            qos.append(("updateRate", float(rng.choice((1, 2, 5, 10, 15, 30)))))
        placed.append(_Placed(number, intent, template, host, tuple(qos)))
    return placed


def _lower_camel(name: str) -> str:
    """markerColour from home:MarkerColour (or from MarkerColour)."""
    name = name.rpartition(":")[2]
    return name[0].lower() + name[1:]


def _snake(name: str) -> str:
    return "_".join(words(name))


def _label(name: str) -> str:
    """bounding box 3D from BoundingBox3D."""
    return re.sub(r"(\d) d\b", r"\1D", " ".join(words(name)))


def _literal(text: str) -> str:
    return '"' + text.replace("\\", "\\\\").replace('"', '\\"') + '"'


def _number(value: float) -> str:
    return f"{value:.2f}"


def _owls_model(described: Ad | Intent) -> str:
    lines = ["    cbrs:hasOWLSModel [ a cbrs:OWLSModel"]
    for prop, params in (("cbrs:hasInput", described.inputs), ("cbrs:hasOutput", described.outputs)):
        for concept in params:
            lines.append(
                f"        {prop} [ a cbrs:Parameter ; cbrs:parameterName {_literal(_lower_camel(concept))} ; "
                f"cbrs:parameterType {concept} ]"
            )
    for prop, cls, statements in (
        ("cbrs:hasPrecondition", "cbrs:Precondition", described.preconditions),
        ("cbrs:hasEffect", "cbrs:Effect", described.effects),
    ):
        for s, p, o in statements:
            lines.append(
                f"        {prop} [ a {cls} ; cbrs:conditionSubject {s} ; cbrs:conditionPredicate {p} ; "
                f"cbrs:conditionObject {o} ]"
            )
    return " ;\n".join(lines) + " ]"


def _class_turtle(cls: NewClass) -> str:
    head = (
        f"tb:{cls.name} a owl:Class ; rdfs:subClassOf {cls.parent} ;\n"
        f"    rdfs:label {_literal(_label(cls.name))}@en ; rdfs:comment {_literal(cls.comment)}@en"
    )
    if not cls.parts:
        return head + " .\n"
    restrictions = " ,\n        ".join(
        f"[ a owl:Restriction ; owl:onProperty {prop} ; owl:someValuesFrom {part} ]" for prop, part in cls.parts
    )
    return head + f" ;\n    rdfs:subClassOf {restrictions} .\n"


def _device_turtle(device: Device) -> str:
    return (
        f"tb:{device.name} a owl:NamedIndividual , {device.type} ;\n"
        f"    rdfs:label {_literal(device.name)}@en ; rdfs:comment {_literal(device.comment)}@en .\n"
    )


def _advertisement_turtle(ad: _Placed) -> str:
    t = ad.template
    place, min_x, max_x, min_y, max_y = _AREAS[ad.host.area]
    port_class = {"data": "cbrs:DataPort", "event": "cbrs:EventPort", "service": "cbrs:ServicePort"}[t.port]
    topic = f"/{_snake(ad.host.name)}/{_snake(t.service)}"
    port = f"[ a {port_class} ; cbrs:portName {_literal(_lower_camel(t.service))}"
    if t.outputs:
        port += f" ; cbrs:dataType {t.outputs[0]}"
    port += f" ; cbrs:topic {_literal(topic)} ]"
    qos = " ; ".join(f"cbrs:{metric} {_number(value)}" for metric, value in ad.qos)
    parts = [
        f"{ad.curie} a {_KINDS[t.component]}",
        f"    rdfs:label {_literal(f'{_label(t.service).capitalize()} ({ad.host.name})')}@en",
        f"    cbrs:device tb:{ad.host.name}",
        f"    cbrs:deviceName {_literal(ad.host.name)}",
        f"    cbrs:serviceName {_literal(t.service)}",
        f"    cbrs:serviceCategory {_literal(t.category)}",
        _owls_model(t),
        f"    cbrs:hasSEAModel [ a cbrs:SEAModel ; cbrs:effectiveArea {place} ; cbrs:minX {_number(min_x)} ; "
        f"cbrs:maxX {_number(max_x)} ; cbrs:minY {_number(min_y)} ; cbrs:maxY {_number(max_y)} ]",
        f"    cbrs:hasQoSModel [ a cbrs:QoSModel ; {qos} ]",
        f"    cbrs:hasPort {port}",
    ]
    return " ;\n".join(parts) + " .\n"


def _requirement_turtle(number: int, intent: Intent) -> str:
    parts = [
        f"{requirement_curie(number, intent)} a cbrs:Requirement",
        f"    rdfs:label {_literal(intent.title.capitalize())}@en",
        f"    rdfs:comment {_literal(intent.comment)}@en",
        f"    cbrs:requestedBy tb:{intent.requester}",
        f"    cbrs:deviceName {_literal(intent.requester)}",
        f"    cbrs:serviceName {_literal(intent.key)}",
        f"    cbrs:serviceCategory {_literal(intent.category)}",
        _owls_model(intent),
    ]
    return " ;\n".join(parts) + " .\n"


_HEADER = """\
@prefix tb:      <https://w3id.org/cbrs/testbed#> .
@prefix home:    <https://w3id.org/cbrs/home#> .
@prefix cbrs:    <https://w3id.org/cbrs/core#> .
@prefix dcterms: <http://purl.org/dc/terms/> .
@prefix owl:     <http://www.w3.org/2002/07/owl#> .
@prefix rdf:     <http://www.w3.org/1999/02/22-rdf-syntax-ns#> .
@prefix rdfs:    <http://www.w3.org/2000/01/rdf-schema#> .

# GENERATED by `python -m cbrs.reasoner.testbed` (seed {seed}); do not edit by hand.
# The matchmaking testbed of the paper's section 6.1: {requirements} requirements and {services}
# advertisements in the home-care domain. The rules it follows are in reasoner/testbed.py and
# docs/evaluation.md; which advertisements are relevant to which requirement, and why, is in
# paper_testbed_truth.json, not here.

<https://w3id.org/cbrs/testbed>
    a owl:Ontology ;
    rdfs:label "cbrs matchmaking testbed"@en ;
    dcterms:description "Twenty requirements and one hundred service components, worded differently."@en ;
    owl:imports <https://w3id.org/cbrs/core> , <https://w3id.org/cbrs/home> .
"""


def _section(title: str) -> str:
    bar = "#" * 100
    return f"\n{bar}\n#  {title}\n{bar}\n\n"


def generate(seed: int = SEED) -> tuple[str, dict[str, Any]]:
    """The testbed as Turtle text and its ground truth, from ``seed`` (deterministic)."""
    cat = catalogue()
    placed = _place(seed, cat)
    out = [_HEADER.format(seed=seed, requirements=len(cat.intents), services=len(placed))]
    out.append(_section("Concepts the testbed adds (subclasses of home classes, parts restated)"))
    out.extend(_class_turtle(cls) + "\n" for cls in cat.new_classes)
    out.append(_section("Devices hosting the components"))
    out.extend(_device_turtle(device) + "\n" for device in cat.devices)
    out.append(_section("Requirements"))
    out.extend(_requirement_turtle(n, intent) + "\n" for n, intent in enumerate(cat.intents, start=1))
    out.append(_section("Advertisements (numbered by the seed)"))
    out.extend(_advertisement_turtle(ad) + "\n" for ad in sorted(placed, key=lambda ad: ad.number))
    turtle = "".join(out).rstrip("\n") + "\n"

    requirements: dict[str, Any] = {}
    distractors: dict[str, Any] = {}
    for n, intent in enumerate(cat.intents, start=1):
        relevant = []
        for ad, item in ((ad, ad.template) for ad in placed if ad.intent is intent):
            if isinstance(item, Relevant):
                requested, advertised = expand(item.requested), expand(item.advertised)
                pair = {"rule": item.rule, "role": item.role, "requested": requested, "advertised": advertised}
                relevant.append({"advertisement": expand(ad.curie), **pair, "why": item.why})
            else:
                distractors[expand(ad.curie)] = {"intent": intent.key, "kind": item.kind, "why": item.why}
        requirements[expand(requirement_curie(n, intent))] = {"intent": intent.title, "relevant": relevant}
    rule_counts = Counter(ad.template.rule for ad in placed if isinstance(ad.template, Relevant))
    kind_counts = Counter(ad.template.kind for ad in placed if isinstance(ad.template, Distractor))
    truth: dict[str, Any] = {
        "seed": seed,
        "requirements_count": len(cat.intents),
        "services_count": len(placed),
        "rules": RULES,
        "rule_counts": {rule: rule_counts[rule] for rule in RULES},
        "distractor_kinds": DISTRACTOR_KINDS,
        "distractor_kind_counts": {kind: kind_counts[kind] for kind in DISTRACTOR_KINDS},
        "undeclared": [expand(c) for c in cat.undeclared],
        "requirements": requirements,
        "distractors": dict(sorted(distractors.items())),
    }
    return turtle, truth


def truth_json(truth: dict[str, Any]) -> str:
    return json.dumps(truth, indent=2, ensure_ascii=False) + "\n"


def load_truth(path: Path = TRUTH_FILE) -> dict[str, Any]:
    data: dict[str, Any] = json.loads(path.read_text(encoding="utf-8"))
    return data


def relevant_sets(truth: dict[str, Any]) -> dict[str, frozenset[str]]:
    """Requirement IRI -> the IRIs of its relevant advertisements."""
    return {
        requirement: frozenset(entry["advertisement"] for entry in item["relevant"])
        for requirement, item in truth["requirements"].items()
    }


def summary(truth: dict[str, Any]) -> str:
    lines = [f"{truth['requirements_count']} requirements, {truth['services_count']} advertisements"]
    relevant = sum(truth["rule_counts"].values())
    lines.append(f"relevant pairs by variation rule ({relevant}):")
    lines += [f"  {rule:<18} {count:>3}" for rule, count in truth["rule_counts"].items()]
    distractors = sum(truth["distractor_kind_counts"].values())
    lines.append(f"distractors by kind ({distractors}):")
    lines += [f"  {kind:<18} {count:>3}" for kind, count in truth["distractor_kind_counts"].items()]
    return "\n".join(lines)


# --------------------------------------------------------------------------------------------------
# Loading and checking the rules
# --------------------------------------------------------------------------------------------------


def open_testbed_kb(testbed: Path = TESTBED_FILE) -> KnowledgeBase:
    """A fresh in-memory store with the bundled ontology-graph files (core, home, actions) and the
    testbed, and none of the bundled advertisements or requirements."""
    kb = KnowledgeBase(Store.open(":memory:"))
    kb.load([item.path for item in bundled_files() if item.graph == GraphName.ONTOLOGY], graph="ontology")
    kb.load([testbed])
    return kb


def _leaves(tree: PartNode | None) -> list[str]:
    if tree is None or tree.is_leaf:
        return []
    return sorted(node.concept for node in tree.walk() if node.is_leaf)


def _below(index: TaxonomyIndex, lower: str, upper: str) -> bool:
    """Both are declared and ``upper`` is ``lower`` or one of its is-a ancestors."""
    return lower in index and upper in index and index.canonical(upper) in index.is_a_ancestors(lower)


def _isa_related(index: TaxonomyIndex, a: str, b: str) -> bool:
    return a == b or _below(index, a, b) or _below(index, b, a)


def _near_siblings(index: TaxonomyIndex, a: str, b: str) -> bool:
    """Neither subsumes the other and they meet at most two is-a links above each (not at the root)."""
    if a not in index or b not in index or _isa_related(index, a, b):
        return False
    common, n1, n2 = index.common_ancestor(a, b)
    return common != ROOT and n1 <= 2 and n2 <= 2


def _tree(kb: KnowledgeBase, concept: str) -> PartNode:
    # The description reader's cached part trees; KnowledgeBase has no public accessor for a bare concept.
    return kb._reader.part_tree(concept)


def _same_parts(kb: KnowledgeBase, a: str, b: str) -> bool:
    return _leaves(_tree(kb, a)) == _leaves(_tree(kb, b))


def _providable(kb: KnowledgeBase, index: TaxonomyIndex, wanted: str, offered: Sequence[str]) -> bool:
    """The requester can give ``wanted``: it offers it, a subclass of it, or a same-parts variant."""
    for concept in offered:
        if concept == wanted:
            return True
        if _below(index, concept, wanted):
            return True
        if _same_parts_cover(kb, index, wanted, concept):  # every part the input needs is offered
            return True
        if _near_siblings(index, concept, wanted) and _same_parts(kb, concept, wanted):
            return True
    return False


def _same_parts_cover(kb: KnowledgeBase, index: TaxonomyIndex, requested: str, advertised: str) -> bool:
    """Every leaf part of ``requested`` has an equal or is-a related leaf part in ``advertised``."""
    want, have = _leaves(_tree(kb, requested)), _leaves(_tree(kb, advertised))
    return bool(want) and all(any(_isa_related(index, w, h) for h in have) for w in want)


def _entities(description: ServiceDescription, role: str) -> list[str]:
    if role == "output":
        return [p.type for p in description.outputs]
    if role == "input":
        return [p.type for p in description.inputs]
    position = {"effect subject": 0, "effect object": 2}[role]
    return [(e.subject, e.predicate, e.object)[position] for e in description.effects]


def _check_pair(kb: KnowledgeBase, index: TaxonomyIndex, rule: str, requested: str, advertised: str) -> str:
    """Why the pair breaks its rule, or the empty string."""
    if local_name(requested) == local_name(advertised):
        return "same string"
    below, above = _below(index, advertised, requested), _below(index, requested, advertised)
    if rule == "subclass":
        return "" if below else "advertised is not below requested"
    if rule == "superclass":
        return "" if above else "advertised is not above requested"
    if rule == "reworded-compound":
        w_req, w_ad = words(local_name(requested)), words(local_name(advertised))
        if not below:
            return "not declared below the concept it rewords"
        if not set(w_req) <= set(w_ad) or w_req[-1] == w_ad[-1]:
            return "not the same words with the head moved"
        return ""
    if rule == "undeclared":
        if advertised in index:
            return "advertised concept is declared"
        return "" if words(local_name(requested))[-1] == words(local_name(advertised))[-1] else "head differs"
    if rule == "synonym-sibling":
        if not _near_siblings(index, requested, advertised):
            return "not near siblings"
        return "" if _same_parts(kb, requested, advertised) else "parts differ"
    if rule == "parts-not-wholes":
        if requested not in index or advertised not in index or _isa_related(index, requested, advertised):
            return "wholes are is-a related or undeclared"
        if _near_siblings(index, requested, advertised):
            return "wholes are near siblings (that is synonym-sibling)"
        return "" if _same_parts_cover(kb, index, requested, advertised) else "requested parts not covered"
    return f"unknown rule {rule}"


def rule_violations(kb: KnowledgeBase, truth: dict[str, Any]) -> list[str]:
    """Where the testbed breaks its own rules (T2-T4); empty when it keeps them all."""
    index = TaxonomyIndex.from_kb(kb)
    ads = {ad.iri: ad for ad in kb.advertisements()}
    reqs = {req.iri: req for req in kb.requirements()}
    problems = []
    undeclared = set(truth["undeclared"])
    for concept in undeclared:
        if concept in index:
            problems.append(f"{concept} should be undeclared")
    for description in (*ads.values(), *reqs.values()):
        used = [p.type for p in (*description.inputs, *description.outputs)] + [
            term for s in (*description.preconditions, *description.effects) for term in (s.subject, s.object)
        ]
        for concept in used:
            if concept not in index and concept not in undeclared:
                problems.append(f"{local_name(description.iri)}: {concept} is declared nowhere")
    for req_iri, item in truth["requirements"].items():
        req = reqs.get(req_iri)
        if req is None:
            problems.append(f"{req_iri} is not a requirement")
            continue
        for pair in item["relevant"]:
            ad = ads.get(pair["advertisement"])
            if ad is None:
                problems.append(f"{pair['advertisement']} is not an advertisement")
                continue
            name = f"{local_name(req_iri)} / {local_name(ad.iri)}"
            if pair["requested"] not in _entities(req, pair["role"]):
                problems.append(f"{name}: requested {local_name(pair['requested'])} is not its {pair['role']}")
            if pair["advertised"] not in _entities(ad, pair["role"]):
                problems.append(f"{name}: {local_name(pair['advertised'])} is not the ad's {pair['role']}")
            why = _check_pair(kb, index, pair["rule"], pair["requested"], pair["advertised"])
            if why:
                problems.append(f"{name}: {pair['rule']}: {why}")
            offered = [p.type for p in req.inputs]
            for parameter in ad.inputs:
                if not _providable(kb, index, parameter.type, offered):
                    problems.append(f"{name}: input {local_name(parameter.type)} cannot be provided")
            if req.outputs and {local_name(p.type) for p in req.outputs} & {local_name(p.type) for p in ad.outputs}:
                problems.append(f"{name}: an output has the requested string")
            for effect in req.effects if pair["role"].startswith("effect") else ():
                if effect in ad.effects:
                    problems.append(f"{name}: the effect is stated exactly as requested")
        relevant = {pair["advertisement"] for pair in item["relevant"]}
        for ad in ads.values():
            if ad.iri not in relevant and _logically_relevant(index, ad, req):
                problems.append(f"{local_name(req_iri)}: distractor {local_name(ad.iri)} is relevant by is-a")
    return problems


def _logically_relevant(index: TaxonomyIndex, ad: Advertisement, req: Requirement) -> bool:
    """Every requested output and effect has an is-a compatible offer, and every input of the
    advertisement is one the requester offers or a superclass of one."""
    offered = [p.type for p in req.inputs]
    if not req.outputs and not req.effects:
        return False
    for parameter in req.outputs:
        if not any(_isa_related(index, parameter.type, p.type) for p in ad.outputs):
            return False
    for effect in req.effects:
        if not any(
            all(
                _isa_related(index, a, b)
                for a, b in zip(
                    (effect.subject, effect.predicate, effect.object), (e.subject, e.predicate, e.object), strict=True
                )
            )
            for e in ad.effects
        ):
            return False
    for parameter in ad.inputs:
        if not any(parameter.type == concept or _below(index, concept, parameter.type) for concept in offered):
            return False
    return True


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m cbrs.reasoner.testbed", description=__doc__.split("\n")[0])
    parser.add_argument("--seed", type=int, default=SEED)
    parser.add_argument("--check", action="store_true", help="compare with the committed files, write nothing")
    args = parser.parse_args(argv)
    turtle, truth = generate(args.seed)
    text = truth_json(truth)
    if args.check:
        same = (
            TESTBED_FILE.exists()
            and TESTBED_FILE.read_text(encoding="utf-8") == turtle
            and TRUTH_FILE.exists()
            and TRUTH_FILE.read_text(encoding="utf-8") == text
        )
        print("testbed is current" if same else "testbed differs from generate(); run python -m cbrs.reasoner.testbed")
        return 0 if same else 1
    DATA_DIR.mkdir(parents=True, exist_ok=True)
    TESTBED_FILE.write_text(turtle, encoding="utf-8")
    TRUTH_FILE.write_text(text, encoding="utf-8")
    print(f"wrote {TESTBED_FILE} and {TRUTH_FILE}")
    print(summary(truth))
    return 0


if __name__ == "__main__":
    sys.exit(main())
