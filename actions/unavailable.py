"""Naming the live components a plan lacks because they are unavailable now.

The store leaves a live component whose program stopped or whose lease lapsed out of composition, so a
task only it could do had the answer "no component provides ...; register a component whose effect is
...", to a user who had registered one. :func:`name_unavailable` composes once more over every
advertisement, only on the way to such an answer, and names those components with why. A run does it
before it gives up (``actions.runner``), and so does every answer that shows what a run would do
(``cbrs plan``, the plans page, the bridge's ``/cbrs/plan``, through ``actions.base_choice``).
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
    unavailable now that a plan would use, each with why (``unrunnable`` of each unmet need). ``avoid``:
    components the caller leaves out on purpose, never named; ``belief``: compose as ``composition`` was.
    Unchanged when no live component is unavailable, or none would help."""
    if composition.plan is not None:
        return composition
    gone = {iri: state for iri, state in kb.liveness.states().items() if not state.live and iri not in avoid}
    if not gone:
        return composition
    everyone = [ad for ad in kb.advertisements(include_unavailable=True) if ad.iri not in avoid]
    would = Composer(kb, config, advertisements=everyone).compose(task, belief=belief).plan
    if would is None:
        return composition
    wanted = {c for step in would.steps for c in step.candidates if c in gone}
    why = tuple((iri, f"unavailable: {gone[iri].reason or 'not live'}") for iri in sorted(wanted))
    if not why:
        return composition
    return replace(composition, unsatisfied=tuple(replace(u, unrunnable=why) for u in composition.unsatisfied))
