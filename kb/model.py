"""Typed views of service descriptions: advertisements, requirements and their six-tuple.

IRIs are plain strings here, so that the reasoner and the web layer never handle store terms.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, field
from typing import Any, Literal

Direction = Literal["input", "output"]


@dataclass(frozen=True)
class Statement:
    """An RDF statement used as a precondition or effect, e.g. (Door, hasStatus, Opened)."""

    subject: str
    predicate: str
    object: str


@dataclass(frozen=True)
class PartNode:
    """A node of a parameter tree: a concept and, below it, its hasPart children.

    ``via`` is the hasPart-family property that links the node to its parent (None at the root).
    """

    concept: str
    via: str | None = None
    children: tuple[PartNode, ...] = ()

    @property
    def is_leaf(self) -> bool:
        return not self.children

    def walk(self) -> list[PartNode]:
        """This node and every node below it, depth first."""
        nodes = [self]
        for child in self.children:
            nodes.extend(child.walk())
        return nodes


@dataclass(frozen=True)
class Parameter:
    """An input or output: a named slot carrying a concept, with the concept's part tree."""

    iri: str
    direction: Direction
    type: str
    name: str | None = None
    tree: PartNode | None = None


@dataclass(frozen=True)
class EffectiveArea:
    """Where a service is effective (SEA): place concepts and an optional bounding box in metres."""

    areas: tuple[str, ...] = ()
    bounds: tuple[float, float, float, float] | None = None  # min x, max x, min y, max y


@dataclass(frozen=True)
class QoSValue:
    """A quality-of-service figure; on a requirement it is a bound, a maximum when lower is better."""

    metric: str
    value: float
    better_when: Literal["lower", "higher"] | None = None


@dataclass(frozen=True)
class Port:
    iri: str
    kind: Literal["service", "data", "event"]
    name: str | None = None
    data_type: str | None = None
    topic: str | None = None
    message_type: str | None = None  # with a topic, on a service port: the component is invoked over the bridge


@dataclass(frozen=True)
class ServiceDescription:
    """The six-tuple <DN, SN, SC, IOPE, SEA, QoS> shared by advertisements and requirements."""

    iri: str
    types: tuple[str, ...]
    label: str | None = None
    comment: str | None = None
    device_name: str | None = None
    service_name: str | None = None
    category: str | None = None
    inputs: tuple[Parameter, ...] = ()
    outputs: tuple[Parameter, ...] = ()
    preconditions: tuple[Statement, ...] = ()
    effects: tuple[Statement, ...] = ()
    deletes: tuple[Statement, ...] = ()
    """Statements that stop being true when the service has run (delete effects)."""
    area: EffectiveArea | None = None
    qos: tuple[QoSValue, ...] = ()

    def __repr__(self) -> str:
        """The IRI, label and how much the description holds: the generated repr printed every part tree
        in full, 1-4 KB for one bundled component, so a notebook listing a few was unreadable.
        :meth:`to_dict` gives everything."""
        counts = [
            (len(self.inputs), "input"),
            (len(self.outputs), "output"),
            (len(self.preconditions), "precondition"),
            (len(self.effects), "effect"),
        ]
        held = ", ".join(f"{n} {word}{'' if n == 1 else 's'}" for n, word in counts if n)
        label = f" {self.label!r}" if self.label else ""
        return f"<{type(self).__name__} {self.iri!r}{label}: {held or 'no inputs, outputs or statements'}>"

    def to_dict(self) -> dict[str, Any]:
        data = asdict(self)
        data["class"] = type(self).__name__
        return data


@dataclass(frozen=True, repr=False)
class Advertisement(ServiceDescription):
    """A component's advertised service; ``kind`` is one of the four component kinds."""

    kind: str | None = None
    device: str | None = None
    realizes_action: str | None = None
    ports: tuple[Port, ...] = field(default=())

    @property
    def bridge_port(self) -> Port | None:
        """The service port naming the bridge service and type it is invoked by (a component in another
        process), if it has one."""
        return next((p for p in self.ports if p.kind == "service" and p.topic and p.message_type), None)


@dataclass(frozen=True, repr=False)
class Requirement(ServiceDescription):
    """What a requester needs; ``for_task`` names the action class of a task requirement."""

    requested_by: str | None = None
    for_task: str | None = None
