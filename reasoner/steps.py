"""Steps of a decomposition: a service that prepares what another one needs to achieve a requested effect.

The paper composes services through their resources: one service's output is another's input. For a
requested effect, an advertisement *achieves* it when one of its effects states at least that change
(each of subject, predicate and object is the requested one or an is-a superclass of it: picking up any
PhysicalObject for the Robot achieves picking up the Cup) and matches it at the pair threshold. When the
achiever needs an input the requester does not provide (neither that concept nor a subclass of it: the
GraspPose of a pick-up service, for a requester that only knows where the cup is), an advertisement
that changes nothing but outputs that input (or a subclass of it) is a step of the decomposition, the
grasp planner. Its effects part is at least MatchConfig.decomposition_weight times the achiever's
effects part, times the delivered floor of its output (1 - specialisation_step per is-a link below).
The same holds for preconditions (MatchConfig.precondition_steps): when an achiever has a precondition
the requester does not guarantee (hand over the item the robot holds, for a requester whose robot holds
nothing), an advertisement whose effect brings it about for what the request is about (picking the
item up) is a step, with the same share.
With MatchConfig.consumer_steps, an advertisement that changes nothing but takes such an input as it is
(that concept or an is-a superclass of it) is a step too, with a producer's share: the path planner that
takes the NavigationGoal a drive service needs works on the same goal before it is reached. One that
needs what the requester asks to get is not: it comes after the request (the price of the ordered book).

Both scoring paths use these rules: reasoner/batch.py over the whole pool, ``Matchmaker.score`` one
advertisement at a time through ``achievers`` and ``feeds``.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

from cbrs.kb import Advertisement, Requirement, Statement
from cbrs.reasoner.config import MatchConfig
from cbrs.reasoner.similarity import EntityMeasure
from cbrs.reasoner.statements import best_statement_matches
from cbrs.reasoner.taxonomy import TaxonomyIndex


@dataclass(frozen=True)
class Achiever:
    """An advertisement that achieves the requested effects, its effects part, the inputs it needs that
    the requester does not provide, and its preconditions that the requester does not guarantee."""

    advertisement: Advertisement
    value: float
    missing: tuple[str, ...]
    unmet: tuple[Statement, ...] = ()


def at_or_above(index: TaxonomyIndex, requested: str, offered: str) -> bool:
    """Is ``offered`` the ``requested`` concept (or property) or an is-a superclass of it?"""
    if requested == offered:
        return True
    if requested not in index or offered not in index:
        return False
    return index.canonical(offered) in index.is_a_ancestors(requested)


def provided(index: TaxonomyIndex, requirement: Requirement, concept: str) -> bool:
    """Does the requester provide ``concept`` or a subclass of it (an input it can pass as it is)?"""
    return any(at_or_above(index, given.type, concept) for given in requirement.inputs)


def achievers(
    index: TaxonomyIndex,
    requirement: Requirement,
    ads: Sequence[Advertisement],
    measure: EntityMeasure,
    config: MatchConfig,
) -> list[Achiever]:
    """The advertisements that achieve every requested effect (each position the requested one or an is-a
    superclass, effects part at the pair threshold or above) and need an input the requester does not
    provide or a precondition it does not guarantee."""
    if not requirement.effects:
        return []
    # each requested position's concept and its is-a ancestors, once: the scan over the pool is then
    # set lookups (a pool of 10,000 advertisements took 11 ms reading the ancestors per pair)
    wanted = [
        (_at_or_above_set(index, e.subject), _at_or_above_set(index, e.predicate), _at_or_above_set(index, e.object))
        for e in requirement.effects
    ]
    found = []
    for ad in ads:
        if not ad.effects:
            continue
        if not all(
            any(
                _within(index, got.predicate, predicates)
                and _within(index, got.subject, subjects)
                and _within(index, got.object, objects)
                for got in ad.effects
            )
            for subjects, predicates, objects in wanted
        ):
            continue
        matches = best_statement_matches(requirement.effects, ad.effects, measure, config)
        value = sum(m.value for m in matches) / len(matches)
        missing = tuple(dict.fromkeys(p.type for p in ad.inputs if not provided(index, requirement, p.type)))
        unmet = unmet_conditions(index, requirement, ad)
        if value >= config.pair_threshold and (missing or unmet):
            found.append(Achiever(ad, value, missing, unmet))
    return found


def guaranteed(index: TaxonomyIndex, requirement: Requirement, condition: Statement) -> bool:
    """Does the requester guarantee ``condition``: one of its preconditions states it or a more specific
    fact (each position the condition's concept or an is-a subclass of it)?"""
    return any(states_at_least(index, held, condition) for held in requirement.preconditions)


def states_at_least(index: TaxonomyIndex, stated: Statement, wanted: Statement) -> bool:
    """Does the fact ``stated`` make ``wanted`` true: each of its positions ``wanted``'s concept or an is-a
    subclass of it ((Cup, isGraspedBy, Robot) makes (HouseholdItem, isGraspedBy, Robot) true)?"""
    return all(at_or_above(index, getattr(stated, at), getattr(wanted, at)) for at in _POSITIONS)


def establishes(index: TaxonomyIndex, effect: Statement, condition: Statement) -> bool:
    """Does an advertised ``effect`` bring ``condition`` about: each position the condition's concept or an
    is-a superclass of it, as an achiever's does (grasping any PhysicalObject grasps the Cup)?"""
    return all(at_or_above(index, getattr(condition, at), getattr(effect, at)) for at in _POSITIONS)


def unmet_conditions(index: TaxonomyIndex, requirement: Requirement, ad: Advertisement) -> tuple[Statement, ...]:
    """The preconditions of an achiever ``ad`` that the requester does not guarantee, each about what the
    request is about: a concept of the achiever's effect stands for the requested concept it achieves the
    effect for, in its preconditions too (a hand-over of any Item that needs the Item held, asked to hand
    over Spectacles, needs the Spectacles held: picking up any PersonalItem brings that about, carrying a
    Person does not)."""
    binding: dict[str, str] = {}
    for wanted in requirement.effects:
        for got in ad.effects:
            if establishes(index, got, wanted):
                for at in _POSITIONS:
                    binding.setdefault(getattr(got, at), getattr(wanted, at))
    bound = (Statement(*(binding.get(getattr(c, at), getattr(c, at)) for at in _POSITIONS)) for c in ad.preconditions)
    return tuple(dict.fromkeys(c for c in bound if not guaranteed(index, requirement, c)))


_POSITIONS = ("subject", "predicate", "object")


def _at_or_above_set(index: TaxonomyIndex, requested: str) -> tuple[str, frozenset[str] | None]:
    """``requested`` with its canonical is-a ancestors (None when the taxonomy does not know it): what
    at_or_above reads for it, read once."""
    return requested, (frozenset(index.is_a_ancestors(requested)) if requested in index else None)


def _within(index: TaxonomyIndex, offered: str, above: tuple[str, frozenset[str] | None]) -> bool:
    """at_or_above(index, requested, offered), with ``above`` = _at_or_above_set(index, requested)."""
    requested, ancestors = above
    if offered == requested:
        return True
    if ancestors is None or offered not in index:
        return False
    return index.canonical(offered) in ancestors


def feeds(index: TaxonomyIndex, output: str, needed: str, step: float) -> float:
    """The delivered floor of ``output`` as the ``needed`` input: 1 - step * k when it is ``needed`` or k
    is-a links below it, else 0."""
    if output == needed:
        return 1.0
    if output not in index or needed not in index:
        return 0.0
    links = index.is_a_ancestors(output).get(index.canonical(needed))
    return 0.0 if links is None else max(0.0, 1.0 - step * links)


def works_towards(index: TaxonomyIndex, requirement: Requirement, ad: Advertisement, needed: str) -> bool:
    """Does ``ad`` take ``needed`` as it is (an input that is the concept or an is-a superclass of it)
    without needing anything the requester asks to get (no input that would take a requested output)?"""
    takes = any(at_or_above(index, needed, given.type) for given in ad.inputs)
    return takes and not any(
        at_or_above(index, wanted.type, given.type) for wanted in requirement.outputs for given in ad.inputs
    )
