"""Why composition found no plan: the unmet needs, each with the chain that led to it and what to do.

A need is met by the requirement (SRI), by a step's output or effect, or not at all; the report names
the need, its consumer and the way down to it from the goal, and suggests the remedy a user can act on
(declare a class, register a component, state a fact), the components that were passed over for their
effective area, those planned for it that cannot run here, and those that come close: they give a near
concept of the need's, and would have met it after a small change (:mod:`actions.near_misses`).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from cbrs.actions.graph import SRE, SRI, SRO
from cbrs.actions.near_misses import NearMiss
from cbrs.kb.namespaces import shorten

GOAL = "GOAL"  # the extraction's virtual consumer: SRO's and SRE's needs together


@dataclass(frozen=True)
class Unsatisfied:
    """A need no qualified vertex meets, and the chain of needs that led to it."""

    need: str
    consumer: str
    chain: tuple[str, ...] = ()  # from the requirement's goal down to this need
    cycle: bool = False  # providers exist, but each needs (through others) what this need blocks; with
    # deleted_by: each step achieving it again undid another need, up to ComposeConfig.max_reachieved times
    undeclared: tuple[str, ...] = ()  # classes (and properties) the need names that the ontology does not have
    properties: tuple[str, ...] = ()  # those of ``undeclared`` the requirement uses as a condition's predicate
    world_things: bool = False  # the need is an output the task asks for whose class is a kind of physical thing
    near: tuple[tuple[str, str], ...] = ()  # (undeclared class, the declared class its name is closest to)
    unrunnable: tuple[tuple[str, str], ...] = ()  # (component, why): planned for it, but cannot run here
    out_of_area: tuple[tuple[str, str], ...] = ()  # (component, why): provides it, but not where it is needed
    provided: tuple[tuple[str, str], ...] = ()  # (component, effect): what is provided about the need's subject
    # (the need's object, the objects of those effects by its predicate): it is none of them
    unlike: tuple[str, tuple[str, ...]] | None = None
    deleted_by: tuple[str, ...] = ()  # components whose delete effect undoes it before it is needed
    individuals: tuple[tuple[str, tuple[str, ...]], ...] = ()  # (undeclared term, its classes): a thing of the map
    superclasses: tuple[tuple[str, str], ...] = ()  # (undeclared class, the class its use suggests declaring it under)
    near_misses: tuple[NearMiss, ...] = ()  # components whose output or effect is near the need (actions.near_misses)
    # or near a need above it on the chain: ``along`` holds those needs, (consumer, need text), from the goal down
    along: tuple[tuple[str, str], ...] = ()
    # an input that designates a thing: the classes the statements its step serves name for it (one of which
    # its value must be), the first such statement, and the values of the input's class passed over, each
    # as (who gives it: "the task" or a component, "name (class)")
    things: tuple[str, ...] = ()
    things_for: str = ""
    passed_over: tuple[tuple[str, str], ...] = ()

    def text(self) -> str:
        found = self._text()
        for component, why in self.out_of_area:
            found += f"; {shorten(component)} was passed over: {why}"
        for component, why in self.unrunnable:
            found += f"; {shorten(component)} was planned for it but cannot run here: {why}"
        if self.provided:
            each = "; ".join(f"{effect} by {shorten(component)}" for component, effect in self.provided)
            done = "delete" if self.need.startswith("delete effect ") else "provide"
            found += f"; what components {done} about it: {each}"
        if self.unlike is not None:
            thing, others = self.unlike
            nots = [shorten(term) for term in others]
            listed = ", no ".join(nots[:-1]) + " and no " + nots[-1] if len(nots) > 1 else nots[0]
            found += f"; {shorten(thing)} is no {listed}"
        for miss in self.near_misses:
            found += f"; {miss.text(_taker(miss.consumer or self.consumer, miss.statement))}"
        return found

    def _text(self) -> str:
        consumer = "the requirement" if self.consumer in (SRO, SRE, GOAL) else shorten(self.consumer)
        via = f" (on the way to {' <- '.join(self.chain)})" if len(self.chain) > 1 else ""
        need = self.need
        if self.consumer == SRE and need.startswith("precondition "):  # the goal is the end's precondition
            need = "effect " + need.removeprefix("precondition ")
        if self.consumer == SRO and need.startswith("input "):  # the requirement's output is the end's input
            need = "output " + need.removeprefix("input ")
        if self.deleted_by:
            by = ", ".join(shorten(c) for c in self.deleted_by)
            again = (
                "each step that achieves it again undoes in turn another statement the plan needs"
                if self.cycle
                else "no component can achieve it again after that"
            )
            return f"{need} of {consumer}{via} is deleted by {by} before it is needed, and {again}; {self.remedy()}"
        if self.cycle:
            return f"only a cycle of components provides {need} of {consumer}{via}"
        if self.consumer == SRI:  # the task gives it: nothing to provide, but its class is unknown
            return f"the requirement gives {need}; {self.remedy()}"
        if self.out_of_area:
            return f"no component effective where it is needed provides {need} of {consumer}{via}; {self.remedy()}"
        if self.things:
            return f"{self._no_thing(need, consumer, via)}; {self.remedy()}"
        if need.startswith("delete effect "):
            gone = need.removeprefix("delete effect ")
            return f"no component deletes {gone} (a delete effect of {consumer}{via}); {self.remedy()}"
        return f"no component provides {need} of {consumer}{via}; {self.remedy()}"

    def _no_thing(self, need: str, consumer: str, via: str) -> str:
        """An input for a thing of a class of ``things``, of which the task gives none and no step gives one."""
        wanted = " or ".join(shorten(c) for c in self.things)
        about = f" the {wanted} of {self.things_for}" if self.things_for else f" a {wanted}"
        found = f"the task gives no {wanted} and no step gives one for {need} of {consumer}{via}, which is for{about}"
        if self.passed_over:
            each = ", ".join(f"{by if by == 'the task' else shorten(by)}'s {value}" for by, value in self.passed_over)
            found += f"; passed over, being no {wanted}: {each}"
        return found

    def remedy(self) -> str:
        """What to register or state so that this need is met (first, a class to declare: no component
        can be matched against a class the ontology does not have)."""
        if self.undeclared:
            things = dict(self.individuals)
            said = [_an_individual(term, things[term]) for term in self.undeclared if term in things]
            classes = [term for term in self.undeclared if term not in things and term not in self.properties]
            if classes:
                said.append(self._no_classes(classes))
            if self.properties:
                said.append(self._no_properties(list(self.properties)))
            return f"{'; '.join(said)}; or {self._remedy()}"
        return self._remedy()

    def _no_classes(self, classes: list[str]) -> str:
        """Terms that are nothing of the ontology: declare them, under the class their use suggests."""
        names = ", ".join(shorten(c) for c in classes)
        meant = "; ".join(
            f"{shorten(typed)}: did you mean {shorten(known)}?" for typed, known in self.near if typed in classes
        )
        example, above = shorten(classes[0]), dict(self.superclasses).get(classes[0])
        under = f"rdfs:subClassOf {shorten(above)}" if above else "rdfs:subClassOf the class it is a kind of"
        return (
            f"{names} {'is no class' if len(classes) == 1 else 'are no classes'} of the ontology"
            f"{f' ({meant})' if meant else ''}: "
            f"declare {'it' if len(classes) == 1 else 'them'} under a class the components know "
            f"(e.g. {example} {under}, loaded into the ontology graph)"
        )

    def _no_properties(self, properties: list[str]) -> str:
        """Predicates that are no property of the ontology (``home:isOn``): no component's condition can
        match them, so name a property the components' conditions use, or declare one under it."""
        names = ", ".join(shorten(p) for p in properties)
        meant = "; ".join(
            f"{shorten(typed)}: did you mean {shorten(known)}?" for typed, known in self.near if typed in properties
        )
        listed = " (what components provide about it, below)" if self.provided else ""
        return (
            f"{names} {'is no property' if len(properties) == 1 else 'are no properties'} of the ontology"
            f"{f' ({meant})' if meant else ''}: use a property the components' conditions use{listed}, or declare "
            f"{'it' if len(properties) == 1 else 'them'} under one (e.g. lab:isOn rdfs:subPropertyOf "
            "home:isLocatedOn, loaded into the ontology graph)"
        )

    def _remedy(self) -> str:
        if self.deleted_by and self.cycle:
            return (
                "ask for the statements that undo each other in separate tasks, or allow more of them to be "
                "achieved again (cbrs plan or cbrs run --max-reachieved N; ComposeConfig.max_reachieved from Python)"
            )
        if self.deleted_by:
            statement = self.need.split(" ", 1)[-1]
            return (
                f"register a component whose effect is {statement} and that can run after "
                f"{', '.join(shorten(c) for c in self.deleted_by)}, or compose without protecting what steps "
                "need (cbrs plan or cbrs run --no-protect; ComposeConfig(protect=False) from Python)"
            )
        if self.out_of_area:
            return (
                "register a component that provides it whose effective area (cbrs:hasSEAModel) covers the things "
                "named, or compose without the area rule (cbrs plan or cbrs run --ignore-areas; "
                "ComposeConfig(respect_area=False) from Python)"
            )
        if self.consumer == SRI:
            return "correct the input's cbrs:parameterType"
        if self.things:
            wanted = " or ".join(shorten(c) for c in self.things)
            held = f", or plan the task where {self.things_for} holds already (after a task that achieves it)"
            return (
                f"give a {wanted} as an input of the task (cbrs:hasInput with cbrs:parameterType "
                f"{shorten(self.things[0])}){held if self.things_for else ''}"
            )
        if self.consumer == GOAL:  # the task states nothing to plan towards
            return (
                "state what the task wants as an output (cbrs:hasOutput), an effect (cbrs:hasEffect) or a "
                "delete effect (cbrs:hasDeleteEffect): composition plans towards those"
            )
        if self.need.startswith("delete effect "):  # a statement the task wants to stop being true
            statement = self.need.removeprefix("delete effect ")
            return (
                f"register a component whose delete effect (cbrs:hasDeleteEffect) meets {statement}: its "
                "subject, relation and object each the same class as the task's, a subclass or a superclass"
            )
        if self.need.startswith("precondition "):
            statement = self.need.removeprefix("precondition ")
            return (
                f"register a component whose effect is {statement}, or state it as a precondition of the task "
                "or a fact of the semantic map"
            )
        concept = self.need.rsplit("(", 1)[-1].rstrip(")") if "(" in self.need else self.need
        if self.consumer == SRO and self.world_things:  # "which cups are there?": the store knows
            return (
                f"register a component whose output is a {concept}; or, to know which {concept} there are and "
                "where, ask the store, whose map and belief hold the things of the world as facts, not a "
                f"component's output (cbrs query --name things_in_room --bind class={concept} --bind room=ROOM; "
                "--name world_positions)"
            )
        if self.consumer == SRO:  # what the task asks for: giving it as an input would be no answer
            return f"register a component whose output is a {concept}"
        return f"register a component whose output is a {concept}, or give one as an input of the task"

    def to_dict(self) -> dict[str, Any]:
        return {
            "need": self.need,
            "consumer": self.consumer,
            "chain": list(self.chain),
            "cycle": self.cycle,
            "text": self.text(),
            "remedy": self.remedy(),
            "unrunnable": [{"component": component, "why": why} for component, why in self.unrunnable],
            "out_of_area": [{"component": component, "why": why} for component, why in self.out_of_area],
            "provided": [{"component": component, "effect": effect} for component, effect in self.provided],
            "unlike": None if self.unlike is None else {"object": self.unlike[0], "none_of": list(self.unlike[1])},
            "deleted_by": list(self.deleted_by),
            "near_misses": [miss.to_dict() for miss in self.near_misses],
            "things": list(self.things),
            "things_for": self.things_for,
            "passed_over": [{"by": by, "value": value} for by, value in self.passed_over],
        }


def _taker(consumer: str, statement: bool) -> str:
    """Who takes a need, as a near miss's text names it."""
    if consumer in (SRO, SRE, GOAL):
        return "the requirement wants" if statement else "the requirement asks for"
    return f"{shorten(consumer)} {'needs' if statement else 'takes'}"


def _an_individual(term: str, classes: tuple[str, ...]) -> str:
    """A term that is a thing of the map, named where a class belongs: name its class."""
    of = " or ".join(shorten(c) for c in classes)
    return (
        f"{shorten(term)} is a thing of the map (an individual of {of.replace(' or ', ' and ')}), not a class: "
        f"a task's goals and inputs name classes, and a run finds the things of the map of those classes "
        f"(did you mean {of}?)"
    )


__all__ = ["GOAL", "Unsatisfied"]
