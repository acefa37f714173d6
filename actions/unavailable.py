"""Naming the live components a plan lacks because they are unavailable now.

The store leaves a live component whose program stopped or whose lease lapsed out of composition, so a
task only it could do had the answer "no component provides ...; register a component whose effect is
...", to a user who had registered one. :func:`name_unavailable` composes once more over every
advertisement, only on the way to such an answer, and names those components with why. A run does it
before it gives up (``actions.runner``), beside the components it found it cannot run (a bundled one the
simulation has no skill for: named alone, it hid the lab's component that ran the task before), and so
does every answer that shows what a run would do (``cbrs plan``, the plans page, the bridge's
``/cbrs/plan``, through ``actions.base_choice``).
"""

from __future__ import annotations

from dataclasses import replace

from cbrs.actions.composer import ComposeConfig, Composer, CompositionResult
from cbrs.kb import KnowledgeBase, Requirement


def name_unavailable(
    kb: KnowledgeBase,
    config: ComposeConfig,
    task: str | Requirement,
    composition: CompositionResult,
    avoid: frozenset[str] = frozenset(),
    belief: bool = False,
) -> CompositionResult:
    """``composition``, which has no plan, with the live components it lacks named: those registered but
    unavailable now that a plan would use, each with why, added to what each unmet need names already
    (``unrunnable``: a component planned but that cannot run here, say). ``avoid``: components the caller
    leaves out on purpose or cannot run, never named; ``belief``: compose as ``composition`` was.
    Unchanged when no live component is unavailable, or none would help."""
    if composition.plan is not None:
        return composition
    why = would_serve(kb, config, task, avoid, belief)
    if not why:
        return composition
    return replace(
        composition,
        unsatisfied=tuple(replace(u, unrunnable=merged(u.unrunnable, why)) for u in composition.unsatisfied),
    )


def would_serve(
    kb: KnowledgeBase,
    config: ComposeConfig,
    task: str | Requirement,
    avoid: frozenset[str] = frozenset(),
    belief: bool = False,
) -> tuple[tuple[str, str], ...]:
    """The live components unavailable now that a plan of ``task`` without ``avoid`` would use, each with
    why, in IRI order; () when none is unavailable or no plan would use one (a composition, only then)."""
    gone = {iri: state for iri, state in kb.liveness.states().items() if not state.live and iri not in avoid}
    if not gone:
        return ()
    everyone = [ad for ad in kb.advertisements(include_unavailable=True) if ad.iri not in avoid]
    would = Composer(kb, config, advertisements=everyone).compose(task, belief=belief).plan
    if would is None:
        return ()
    wanted = {c for step in would.steps for c in step.candidates if c in gone}
    return tuple((iri, f"unavailable: {gone[iri].reason or 'not live'}") for iri in sorted(wanted))


def merged(first: tuple[tuple[str, str], ...], then: tuple[tuple[str, str], ...]) -> tuple[tuple[str, str], ...]:
    """``first`` then those of ``then`` whose component it does not name: (component, why) pairs."""
    named = {component for component, _ in first}
    return (*first, *(pair for pair in then if pair[0] not in named))
