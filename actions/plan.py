"""Plans: ordered steps bound to components, with the data flow between them.

A plan is plain data: it serialises to JSON (``to_dict``) and to RDF for the plans graph
(``to_quads``), and the executor reads it back without knowing how it was found.
"""

from __future__ import annotations

import hashlib
from dataclasses import dataclass, field
from typing import Any

import pyoxigraph as ox

from cbrs.kb import Statement
from cbrs.kb.namespaces import BASE, PREFIXES, GraphName, shorten
from cbrs.kb.vocab import CBRS

RDF_TYPE = ox.NamedNode(PREFIXES["rdf"] + "type")
RDFS_LABEL = ox.NamedNode(PREFIXES["rdfs"] + "label")
PLAN_NS = BASE + "plan/"


@dataclass(frozen=True)
class Source:
    """Where a binding's value comes from: an earlier step's output or effect, or the requirement."""

    name: str  # output or effect of the step, or the requirement's input / precondition
    step: int | None = None  # 1-based index of the producing step; None: the requirement supplies it
    requirement: str | None = None  # the requirement that supplies it (for decomposed plans: a sub-task's)

    def to_dict(self) -> dict[str, Any]:
        if self.step is None:
            return {"requirement": self.requirement, "name": self.name}
        return {"step": self.step, "name": self.name}


@dataclass(frozen=True)
class Binding:
    """One input or precondition of a step and where it comes from."""

    role: str  # "input" or "precondition"
    name: str
    source: Source
    degree: str
    similarity: float
    concept: str | None = None
    statement: Statement | None = None

    def to_dict(self) -> dict[str, Any]:
        found: dict[str, Any] = {"role": self.role, "name": self.name}
        if self.concept is not None:
            found["type"] = self.concept
        if self.statement is not None:
            found["statement"] = _statement(self.statement)
        found["from"] = self.source.to_dict()
        found["degree"] = self.degree
        found["similarity"] = round(self.similarity, 4)
        return found

    def __repr__(self) -> str:
        """One line, where the value comes from and how well it fits: the fields in full (the concept's
        and the statement's IRIs, the source's requirement) made a plan's repr thousands of characters
        long in a notebook; :meth:`to_dict` keeps them all."""
        origin = f"step {self.source.step}" if self.source.step is not None else "the requirement"
        taken = (
            f"{self.name} <- {origin}"
            if self.source.name == self.name
            else f"{self.name} <- {self.source.name} of {origin}"
        )
        return f"<Binding {self.role} {taken}, {self.degree} {self.similarity:.2f}>"


@dataclass(frozen=True)
class PlanStep:
    index: int
    component: str
    label: str | None
    kind: str | None
    device: str | None
    action: str | None  # the action class the component realises, if it is action-type
    bindings: tuple[Binding, ...]
    outputs: tuple[tuple[str, str], ...]  # (name, type)
    effects: tuple[Statement, ...]
    cost: float
    part_of: str | None = None  # the sub-action of a decomposed task this step belongs to
    alternatives: tuple[str, ...] = ()  # components that can replace this one with the same bindings
    deletes: tuple[Statement, ...] = ()  # what stops being true when it has run (cbrs:hasDeleteEffect)
    # what decided the component over the others that could have done the step ("cbrs:cost", "similarity",
    # "responseTime", "level", "iri"); None: no other could, or it was not chosen by rank
    ranked_by: str | None = None

    @property
    def candidates(self) -> tuple[str, ...]:
        """The components that can do this step, in the order the executor tries them."""
        return (self.component, *self.alternatives)

    @property
    def inputs(self) -> tuple[Binding, ...]:
        return tuple(b for b in self.bindings if b.role == "input")

    @property
    def preconditions(self) -> tuple[Binding, ...]:
        return tuple(b for b in self.bindings if b.role == "precondition")

    def __repr__(self) -> str:
        """One line: the step's component and where its inputs and preconditions come from (see
        :meth:`Binding.__repr__`), and how many components could stand in for it."""
        taken = "; ".join(_taken(b) for b in self.bindings) or "nothing taken"
        others = f", {len(self.alternatives)} alternative(s)" if self.alternatives else ""
        return f"<PlanStep {self.index} {shorten(self.component)}: {taken}{others}>"

    def to_dict(self) -> dict[str, Any]:
        return {
            "index": self.index,
            "component": self.component,
            "label": self.label,
            "kind": self.kind,
            "device": self.device,
            "action": self.action,
            "part_of": self.part_of,
            "inputs": [b.to_dict() for b in self.inputs],
            "preconditions": [b.to_dict() for b in self.preconditions],
            "outputs": [{"name": name, "type": concept} for name, concept in self.outputs],
            "effects": [_statement(s) for s in self.effects],
            "deletes": [_statement(s) for s in self.deletes],
            "cost": self.cost,
            "ranked_by": self.ranked_by,
            "alternatives": list(self.alternatives),
        }


@dataclass(frozen=True)
class Plan:
    task: str
    requirement: str
    # "direct" (one composition), "decomposed" (one per sub-action), "matched" (one advertisement the
    # matchmaker ranked, when composition found nothing), "achieved" (holds: no step)
    method: str
    steps: tuple[PlanStep, ...]
    goals: tuple[Binding, ...]  # what meets the requirement's outputs and effects
    similarity: float  # mean Sem-Str similarity over every binding, goals included
    cost: float  # sum of the steps' advertised response times
    sub_actions: tuple[str, ...] = field(default=())

    @property
    def iri(self) -> str:
        digest = hashlib.sha256(self.task.encode()).hexdigest()[:12]
        local = self.task.rsplit("#", 1)[-1].rsplit("/", 1)[-1]
        return f"{PLAN_NS}{local}-{digest}"

    def step(self, index: int) -> PlanStep:
        return self.steps[index - 1]

    def __repr__(self) -> str:
        """One line: the task, how it was planned and its steps' components in order; each step's own repr
        says where its inputs come from, :meth:`to_dict` says everything (a plan's dataclass repr ran to
        8,000 characters for eight steps, and a composition's, holding it, to 47,000)."""
        components = ", ".join(f"{step.index} {shorten(step.component)}" for step in self.steps)
        steps = f"{len(self.steps)} step{'' if len(self.steps) == 1 else 's'}"
        goals = f"{len(self.goals)} goal{'' if len(self.goals) == 1 else 's'}"
        return (
            f"<Plan {shorten(self.task)} ({self.method}): {steps} [{components}], {goals},"
            f" similarity {self.similarity:.3f}, cost {self.cost:g}>"
        )

    def components(self) -> list[str]:
        return [s.component for s in self.steps]

    def to_dict(self) -> dict[str, Any]:
        return {
            "task": self.task,
            "requirement": self.requirement,
            "plan": self.iri,
            "method": self.method,
            "sub_actions": list(self.sub_actions),
            "similarity": round(self.similarity, 4),
            "cost": round(self.cost, 4),
            "steps": [s.to_dict() for s in self.steps],
            "goals": [g.to_dict() for g in self.goals],
        }

    def to_quads(self) -> list[ox.Quad]:
        """The plan as RDF in the plans graph: plan, steps (with index and component) and bindings."""
        graph = GraphName.PLANS.node
        plan = ox.NamedNode(self.iri)
        quads = [
            ox.Quad(plan, RDF_TYPE, ox.NamedNode(CBRS.Plan), graph),
            ox.Quad(plan, ox.NamedNode(CBRS.planFor), ox.NamedNode(self.requirement), graph),
            ox.Quad(plan, ox.NamedNode(CBRS.forTask), ox.NamedNode(self.task), graph),
            ox.Quad(plan, ox.NamedNode(CBRS.similarity), ox.Literal(repr(self.similarity), datatype=_DOUBLE), graph),
            ox.Quad(plan, ox.NamedNode(CBRS.planCost), ox.Literal(repr(self.cost), datatype=_DOUBLE), graph),
        ]
        for step in self.steps:
            node = self._step_node(step.index)
            quads += [
                ox.Quad(plan, ox.NamedNode(CBRS.hasStep), node, graph),
                ox.Quad(node, RDF_TYPE, ox.NamedNode(CBRS.PlanStep), graph),
                ox.Quad(node, ox.NamedNode(CBRS.stepIndex), ox.Literal(str(step.index), datatype=_INTEGER), graph),
                ox.Quad(node, ox.NamedNode(CBRS.usesComponent), ox.NamedNode(step.component), graph),
            ]
            if step.label:
                quads.append(ox.Quad(node, RDFS_LABEL, ox.Literal(step.label), graph))
            if step.action:
                quads.append(ox.Quad(node, ox.NamedNode(CBRS.realizesAction), ox.NamedNode(step.action), graph))
            quads += [
                ox.Quad(node, ox.NamedNode(CBRS.alternativeComponent), ox.NamedNode(a), graph)
                for a in step.alternatives
            ]
            for n, binding in enumerate(step.bindings, start=1):
                quads += self._binding_quads(node, ox.NamedNode(f"{node.value}/binding/{n}"), binding, graph)
        return quads

    def _step_node(self, index: int) -> ox.NamedNode:
        return ox.NamedNode(f"{self.iri}/step/{index}")

    def _binding_quads(
        self, step: ox.NamedNode, node: ox.NamedNode, binding: Binding, graph: ox.NamedNode
    ) -> list[ox.Quad]:
        quads = [
            ox.Quad(step, ox.NamedNode(CBRS.hasBinding), node, graph),
            ox.Quad(node, RDF_TYPE, ox.NamedNode(CBRS.Binding), graph),
            ox.Quad(node, ox.NamedNode(CBRS.bindingRole), ox.Literal(binding.role), graph),
            ox.Quad(node, ox.NamedNode(CBRS.boundName), ox.Literal(binding.name), graph),
            ox.Quad(node, ox.NamedNode(CBRS.fromName), ox.Literal(binding.source.name), graph),
            ox.Quad(node, ox.NamedNode(CBRS.degreeOfMatch), ox.Literal(binding.degree), graph),
            ox.Quad(node, ox.NamedNode(CBRS.similarity), ox.Literal(repr(binding.similarity), datatype=_DOUBLE), graph),
        ]
        if binding.source.step is None:
            quads.append(
                ox.Quad(node, ox.NamedNode(CBRS.fromRequirement), ox.Literal("true", datatype=_BOOLEAN), graph)
            )
        else:
            quads.append(ox.Quad(node, ox.NamedNode(CBRS.fromStep), self._step_node(binding.source.step), graph))
        return quads


_DOUBLE = ox.NamedNode(PREFIXES["xsd"] + "double")
_INTEGER = ox.NamedNode(PREFIXES["xsd"] + "integer")
_BOOLEAN = ox.NamedNode(PREFIXES["xsd"] + "boolean")


def _taken(binding: Binding) -> str:
    """A binding as a step's repr lists it: its name and the step it comes from (``req`` for the task)."""
    origin = f"#{binding.source.step}" if binding.source.step is not None else "req"
    return f"{binding.name} <- {origin}"


def _statement(statement: Statement) -> dict[str, str]:
    return {"subject": statement.subject, "predicate": statement.predicate, "object": statement.object}
