"""An actuator's answer that comes after its call was given up: what it does to the belief.

A door motor that needs 15 s and is given 10 s opens the door after the run stopped waiting, and the
belief (the world graph) still said closed, so the next run believed a closed door. When the answer
comes, it is read as an in-time answer is (every output there and of its type, the designators of
the map's things right, no effect contradicted: ``RemoteComponent._read``), and then:

- **a success** believes the component's effects as an in-time success does (``SimEnvironment.succeeded``):
  of the relations no test of the store decides, its delete effects stop being believed and its effects
  are believed, each replacing the values it excludes (disjoint classes, a functional relation). A
  relation a test decides is left to the next run's perception. If the world graph's belief of a
  relation it sets has changed since the call was given up (a newer call, a run), which came last
  cannot be told: that relation becomes unknown (no value believed), unless the answer agrees with
  the newer belief.
- **a failure** (``result: false``: the handler raised, or the bridge ended the call, at its deadline
  or because the provider went) leaves the command's end in doubt after it ran past its timeout: it
  may have done part of it (a door stopped half-way), so every relation the call would set or delete
  becomes unknown. The protocol does not tell the handler's error from the bridge's, and neither
  says what the device did.
- **an answer the checks refuse** (malformed, a wrong thing, a contradicted effect) is no ground for any
  belief, as in time: nothing is written. Nor is anything when this process stops hearing the call (its
  own connection closed, the call was cancelled): that is no word of the device's, and it happens as
  the process ends, when its store may be closing.

Each case is one warning of ``cbrs.actions.remote`` naming the component. An effect is grounded in the
step's inputs (the one designated thing of its class; a quality, ``home:Opened``, stands for itself) when
the call is given up, and the belief of what it would change is read then, to tell later changes. A quality
class stands for itself only as the subject's own quality, by a relation of ``home:hasQualityPart``'s family,
the rule the simulated environment believes a step's effect by (:class:`actions.qualities.OwnQualities`): an
alert about a status, (Person, lab6:isAlertedOf, DoorStatus), is no lasting state and is neither believed
nor kept, late as in time (docs/components.md).
The write is :func:`actions.belief.correct`: one transaction, kept by a run still going, and heard by a
simulation environment running (:class:`actions.belief.Heard`; docs/reliability.md, "Late answers").

An answer in time that fails its step is the same case as a late failure (:func:`unsettle`): the call was
sent, so the device may have acted, in full or in part, and the answer does not say how far. Every relation
the call would set or delete about the things it was given becomes unknown, by the same grounding, so the
next plan senses or acts instead of trusting the belief from before the call. A call refused before it was
sent (its breaker open, an actuator still busy) did nothing, and the belief stays (docs/execution.md,
"The belief after a failed step").
"""

from __future__ import annotations

import logging
from collections.abc import Callable, Iterable, Mapping
from concurrent.futures import Future
from dataclasses import dataclass
from typing import Any

import pyoxigraph as ox

from cbrs.actions.answers import Classes, class_named
from cbrs.actions.belief import Fact, Pair, believed, correct
from cbrs.actions.breaker import Late
from cbrs.actions.errors import ActionsError
from cbrs.actions.qualities import OwnQualities
from cbrs.actions.remote_errors import RemoteCallError
from cbrs.kb import KnowledgeBase, KnowledgeBaseError, Statement
from cbrs.kb.errors import NotFoundError
from cbrs.kb.namespaces import shorten

__all__ = ["GivenUp", "SentAndFailed", "unsettle", "watch"]

log = logging.getLogger("cbrs.actions.remote")

Read = Callable[[Any], Mapping[str, Any]]
"""An answer's values -> its checked outputs; raises an :class:`ActionsError` for one the checks refuse."""


@dataclass(frozen=True)
class GivenUp:
    """A call given up: the component, its service, the timeout it missed and the step's inputs."""

    component: str
    service: str
    timeout: float
    inputs: Mapping[str, Any]
    effects: tuple[Statement, ...] = ()  # the advertisement's the call was made from: what it would set,
    deletes: tuple[Statement, ...] = ()  # should the store no longer describe the component (deregistered)

    def said(self, what: str) -> str:
        return (
            f"{shorten(self.component)} ({self.service}) {what} after its call was given up "
            f"(no answer within {self.timeout:g} s)"
        )


@dataclass(frozen=True)
class _Expected:
    """What a success would change, grounded when the call was given up, and what was believed of it then."""

    deletes: tuple[Fact, ...]
    adds: tuple[Fact, ...]
    before: frozenset[Fact]
    ungrounded: tuple[Statement, ...]
    functional: frozenset[str]
    passing: tuple[Statement, ...] = ()  # relations to a quality class that is no quality of the subject

    @property
    def pairs(self) -> frozenset[Pair]:
        return frozenset((s, p) for s, p, _ in (*self.deletes, *self.adds))


@dataclass(frozen=True)
class SentAndFailed:
    """A call that was sent and whose step failed without a checked success, for a reason other than a
    timeout whose answer is still awaited: the component, its service, why and the step's inputs."""

    component: str
    service: str
    reason: str
    inputs: Mapping[str, Any]
    effects: tuple[Statement, ...] = ()  # as GivenUp's
    deletes: tuple[Statement, ...] = ()

    def said(self, what: str) -> str:
        return f"{shorten(self.component)} ({self.service}) {what}"


def unsettle(kb: KnowledgeBase, classes: Classes, call: SentAndFailed) -> None:
    """Make every relation ``call`` would set or delete about the things it was given unknown (no value
    believed), as a late failure does (:func:`_believe`), with one warning naming the component, the reason
    and the relations. A relation a test of the store decides is left to perception. Never raises: a store
    that cannot be read or written now is only named in the warning (the step has failed either way)."""
    try:
        expected = _expect(kb, classes, call)
        outcome = _believe(kb, classes, expected, failed=True)
    except Exception as broken:  # the step's own failure is what the run reports: say this, do not hide it
        log.warning(
            "%s; what it may have done could not be marked unknown (%s): the belief may be stale, check the device",
            call.said(f"failed after its call was sent ({call.reason})"),
            broken,
        )
        return
    if not outcome.unknown and not expected.ungrounded:
        return  # it sets nothing only a step sets: perception decides the rest
    parts = [call.said(f"failed after its call was sent ({call.reason})")]
    if outcome.unknown:
        pairs = ", ".join(_pair(p) for p in sorted(outcome.unknown))
        parts.append(f"it may have acted, in full or in part, so no value of {pairs} is believed now")
    if expected.ungrounded:
        statements = ", ".join(_statement(s) for s in expected.ungrounded)
        parts.append(f"not changed: {statements} (no one thing of the step's inputs is meant)")
    log.warning("%s", "; ".join(parts))


def watch(kb: KnowledgeBase, classes: Classes, call: GivenUp, read: Read) -> Late | None:
    """What settles ``call``'s answer once it comes (:data:`actions.breaker.Late`: called in a thread of
    its own). None, after a warning, when what it would change cannot be read now (the component was
    deregistered, the store is unreachable): the answer is then only logged."""
    try:
        expected = _expect(kb, classes, call)
    except (KnowledgeBaseError, ValueError) as error:
        log.warning("%s; its answer, if it comes, changes no belief: %s", call.said("is out"), error)
        return None
    return lambda done: _settle(kb, classes, call, expected, read, done)


def _expect(kb: KnowledgeBase, classes: Classes, call: GivenUp | SentAndFailed) -> _Expected:
    try:
        description = kb.description(call.component)
        said_deletes, said_effects = description.deletes, description.effects
    except NotFoundError:  # deregistered while the call was out: the device may have acted all the same
        if not (call.effects or call.deletes):
            raise
        said_deletes, said_effects = call.deletes, call.effects
    untested = [s for s in (*said_deletes, *said_effects) if not _tested(kb, s.predicate)]
    quality = OwnQualities(kb, classes.is_a)
    grounded = {s: _grounded(kb, classes, quality, s, call.inputs) for s in untested}
    deletes = tuple(f for s in said_deletes if (f := grounded.get(s)) is not None)
    adds = tuple(f for s in said_effects if (f := grounded.get(s)) is not None)
    functional = frozenset(row["property"].value for row in kb.select("functional_properties"))
    pairs = {(s, p) for s, p, _ in (*deletes, *adds)}
    missed = [s for s, fact in grounded.items() if fact is None]
    passing = tuple(
        s
        for s in missed
        if quality.passing(s.predicate, s.object) and _thing(kb, classes, s.object, call.inputs, None) is None
    )
    ungrounded = tuple(s for s in missed if s not in passing)
    return _Expected(deletes, adds, believed(kb, pairs), ungrounded, functional, passing)


def _tested(kb: KnowledgeBase, predicate: str) -> bool:
    """Whether a test of the store decides ``predicate`` (then perception believes it, not a step)."""
    return bool(kb.select("computables", {"relation": ox.NamedNode(predicate)}))


def _grounded(
    kb: KnowledgeBase, classes: Classes, quality: OwnQualities, statement: Statement, inputs: Mapping[str, Any]
) -> Fact | None:
    """``statement`` (between classes) about the step's things: each side the one thing the step was
    given of its class; an object no given thing is and that is a quality (``home:Opened``) of the subject
    (``quality``: by a relation of ``home:hasQualityPart``'s family) stands for itself. None when a side
    means no given thing or several, or the object is a quality class the relation does not make the
    subject's own (an alert about a status)."""
    obj = _thing(kb, classes, statement.object, inputs, None)
    if obj is None and quality(statement.predicate, statement.object):
        obj = statement.object
    subject = _thing(kb, classes, statement.subject, inputs, obj)
    return (subject, statement.predicate, obj) if subject is not None and obj is not None else None


def _thing(
    kb: KnowledgeBase, classes: Classes, concept: str, inputs: Mapping[str, Any], besides: str | None
) -> str | None:
    found = set()
    for value in inputs.values():
        if not isinstance(value, dict) or not isinstance(value.get("@id"), str) or value["@id"] == besides:
            continue
        thing = value["@id"]
        try:
            node = ox.NamedNode(thing)
        except ValueError:  # not an IRI: no thing of the map, nor of the world graph
            continue
        rows = kb.select("map_types", {"thing": node})
        kinds = {row["type"].value for row in rows} | set(_given_as(value))
        if any(classes.is_a(kind, concept) for kind in kinds):
            found.add(thing)
    return found.pop() if len(found) == 1 else None


def _given_as(value: Mapping[str, Any]) -> Iterable[str]:
    """The class an input names by its ``@type``; :class:`~actions.answers.UnknownTypeError` for one that
    names none (it was dropped, and the input grounded no effect without a word: :func:`watch` and
    :func:`unsettle` now say which type)."""
    written = value.get("@type")
    if isinstance(written, str):
        yield class_named(written)


def _settle(
    kb: KnowledgeBase, classes: Classes, call: GivenUp, expected: _Expected, read: Read, done: Future[dict[str, Any]]
) -> None:
    """What ``done``'s ending does to the belief, logged as one warning."""
    error = done.exception() if not done.cancelled() else None
    if done.cancelled() or (error is not None and not isinstance(error, RemoteCallError)):
        log.warning(
            "%s: nothing is believed of it, and what the store believes of the device's effects may be stale; "
            "check the device (docs/execution.md, 'An actuator is sent one command at a time')",
            call.said(f"ended without an answer ({error or 'cancelled'})"),
        )
        return
    if error is None:
        try:
            read(done.result())
        except ActionsError as refused:
            log.warning(
                "%s, and the answer is refused as one in time would be: %s. The belief is left as it was, and "
                "may be stale: check the device",
                call.said("answered"),
                refused,
            )
            return
        except Exception as broken:  # the checks themselves broke (the store went away): believe nothing
            log.warning(
                "%s, but the answer could not be checked (%s): the belief is left as it was",
                call.said("answered"),
                broken,
            )
            return
    try:
        outcome = _believe(kb, classes, expected, failed=error is not None)
    except Exception as broken:  # a thread of its own: say what broke, never end in silence
        log.warning("%s, but the belief could not be corrected: %s", call.said("answered"), broken)
        return
    log.warning("%s", _told(call, expected, outcome, error))


@dataclass(frozen=True)
class _Outcome:
    believed: frozenset[Fact]  # now held, by this answer
    unknown: frozenset[Pair]  # no value believed any more
    changed: frozenset[Pair]  # of those, the ones a newer belief had changed since the call was given up


def _believe(kb: KnowledgeBase, classes: Classes, expected: _Expected, failed: bool) -> _Outcome:
    unknown: set[Pair] = set()
    changed: set[Pair] = set()
    believed_now: set[Fact] = set()

    def decide(now: frozenset[Fact]) -> frozenset[Fact]:
        held: set[Fact] = set()
        for pair in sorted(expected.pairs):
            current = _of(now, pair)
            wanted = _applied(classes, expected, pair, current)
            if failed:
                unknown.add(pair)
            elif current == _of(expected.before, pair) or wanted == current:
                held |= wanted
                believed_now.update(f for f in wanted if f in expected.adds)
            else:
                unknown.add(pair)
                changed.add(pair)
        return frozenset(held)

    if expected.pairs:
        correct(kb, expected.pairs, decide)
    return _Outcome(frozenset(believed_now), frozenset(unknown), frozenset(changed))


def _of(facts: Iterable[Fact], pair: Pair) -> frozenset[Fact]:
    return frozenset(f for f in facts if (f[0], f[1]) == pair)


def _applied(classes: Classes, expected: _Expected, pair: Pair, current: frozenset[Fact]) -> frozenset[Fact]:
    """``current`` (the facts of ``pair``) after the effects, as in STRIPS: the deletes go, then each
    effect comes and takes the place of the values it excludes."""
    facts = set(current) - set(expected.deletes)
    for add in (f for f in expected.adds if (f[0], f[1]) == pair):
        facts = {f for f in facts if not _excludes(classes, expected, f[1], f[2], add[2])}
        facts.add(add)
    return frozenset(facts)


def _excludes(classes: Classes, expected: _Expected, predicate: str, old: str, new: str) -> bool:
    """Whether a thing cannot have both values of ``predicate``: a functional relation, or two values the
    store declares disjoint classes (a door Closed is not Opened)."""
    return old != new and (predicate in expected.functional or classes.disjoint(old, new))


def _told(call: GivenUp, expected: _Expected, outcome: _Outcome, error: BaseException | None) -> str:
    parts = [call.said(f"failed ({error})" if error is not None else "answered")]
    if outcome.believed:
        parts.append(f"now believed, as its effects: {', '.join(_fact(f) for f in sorted(outcome.believed))}")
    if outcome.changed:
        pairs = ", ".join(_pair(p) for p in sorted(outcome.changed))
        parts.append(
            f"the belief of {pairs} changed after the call was given up, and which came last cannot be told: "
            "no value of it is believed now"
        )
    if outcome.unknown - outcome.changed:
        pairs = ", ".join(_pair(p) for p in sorted(outcome.unknown - outcome.changed))
        parts.append(f"it may have acted in part, so no value of {pairs} is believed now")
    if expected.ungrounded:
        statements = ", ".join(_statement(s) for s in expected.ungrounded)
        parts.append(f"not believed: {statements} (no one thing of the step's inputs is meant)")
    if expected.passing:
        statements = ", ".join(_statement(s) for s in expected.passing)
        parts.append(f"not believed: {statements} (a quality class no quality of its subject: no lasting state)")
    if not expected.pairs and not expected.ungrounded and not expected.passing:
        parts.append("none of its effects is a belief that only a step sets: the next run perceives them")
    return "; ".join(parts)


def _fact(fact: Fact) -> str:
    return "(" + ", ".join(shorten(term) for term in fact) + ")"


def _pair(pair: Pair) -> str:
    return f"{shorten(pair[0])} {shorten(pair[1])}"


def _statement(statement: Statement) -> str:
    return _fact((statement.subject, statement.predicate, statement.object))
