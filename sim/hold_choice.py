"""Which of an object's grasp approaches an arm holds it by, for one hold.

An object's class lists the approaches it may be held by, best first (``ObjectModel.preference``). For
each hold (taking it, carrying it to a place, passing it to the other arm, loading the platform) the
approaches are checked in that order and the first that every check lets through is taken; each one
passed over keeps why, so the choice a run makes is readable (:class:`GraspChoice`). The arms' own
planning then dry-runs the chosen hold's moves (:func:`first_clear`), before anything moves.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, field

from cbrs.sim.arms import ArmSide
from cbrs.sim.errors import MovesRefusedError
from cbrs.sim.geometry import Region
from cbrs.sim.grasping import GraspKind, ObjectModel
from cbrs.sim.perception import ObjectEstimate


@dataclass(frozen=True)
class GraspChoice:
    """Which of an object's approaches an arm holds it by from where it takes it to where it lets it go
    (``model.grasp``), and why each approach its class prefers to that one was passed over."""

    arm: ArmSide
    model: ObjectModel
    purpose: str
    """What the hold is for: "taking the Cup", "loading the Cup onto the platform"..."""
    passed: tuple[tuple[GraspKind, str], ...] = ()

    def __str__(self) -> str:
        model = self.model
        text = f"{self.purpose}: the {self.arm.value} arm holds the {model.name} by its {model.grasp.value} grasp"
        if self.passed:
            text += " (" + "; ".join(f"not by its {kind.value} grasp: {why}" for kind, why in self.passed) + ")"
        return text


@dataclass
class Candidates:
    """The approaches an arm may hold an object by for one hold, best first, and why each other one is
    ruled out (each check says why not, or nothing)."""

    models: list[ObjectModel]
    ruled_out: list[tuple[GraspKind, str]] = field(default_factory=list)

    @classmethod
    def of(cls, model: ObjectModel, *checks: Callable[[ObjectModel], str]) -> Candidates:
        found = cls([])
        for kind in model.preference:
            held = model.by(kind)
            why = next((reason for reason in (check(held) for check in checks) if reason), "")
            if why:
                found.ruled_out.append((kind, why))
            else:
                found.models.append(held)
        return found

    def refusal(self) -> str:
        return "; ".join(why for _, why in self.ruled_out)

    def choice(self, side: ArmSide, held: ObjectModel, purpose: str, unplaced: str = "") -> GraspChoice:
        """The choice of ``held`` among these, with why each approach preferred to it was not taken (a
        candidate passed over for want of a spot says ``unplaced``)."""
        order = held.preference
        rank = order.index(held.grasp)
        reasons = dict(self.ruled_out)
        passed = tuple((kind, reasons.get(kind, unplaced)) for kind in order[:rank])
        return GraspChoice(side, held, purpose, passed)


def first_clear(
    candidates: Candidates,
    side: ArmSide,
    purpose: str,
    moves: Callable[[ObjectModel], str],
    spots: Mapping[GraspKind, Region] | None = None,
) -> GraspChoice:
    """The first of ``candidates`` whose ``moves`` the arm's planning would make, as they are asked (a dry
    run: :func:`skills.can_carry`, over the spot of ``spots`` the carry by that approach will aim at): one
    it would refuse is passed over saying why. A lone candidate is asked too. :class:`MovesRefusedError`
    when it would refuse every one: the real moves are planned by the same planning from the same
    posture, so they would fail the same way, only after the arm has moved (nu16 repro 04)."""
    passed = list(candidates.ruled_out)
    refused: list[tuple[str, tuple[float, float] | None, str]] = []
    for held in candidates.models:
        why = moves(held)
        if not why:
            return Candidates([held], passed).choice(side, held, purpose)
        passed.append((held.grasp, why))
        spot = (spots or {}).get(held.grasp)
        refused.append((held.grasp.value, (spot.center[0], spot.center[1]) if spot is not None else None, why))
    name = candidates.models[0].name if candidates.models else ""
    ruled_out = [(kind.value, why) for kind, why in candidates.ruled_out]
    raise MovesRefusedError(name, side.value, purpose, refused, ruled_out)


def refuse_moves(
    why: str, held: ObjectModel, side: ArmSide, purpose: str, spot: Region, before: str = "anything moved"
) -> None:
    """A hold of a relay whose moves the arm's planning would refuse (``why``, from a dry run) fails the
    step before the relay moves anything, as a refused hold of the approach choice does (:func:`first_clear`)."""
    if why:
        cx, cy, _ = spot.center
        raise MovesRefusedError(held.name, side.value, purpose, [(held.grasp.value, (cx, cy), why)], before=before)


def seen_extent(estimate: ObjectEstimate) -> tuple[float, float]:
    """What perception saw of an object along x and y: how wide a box whose long axis it did not see is
    across jaws closing along x or y (:meth:`ObjectModel.across`)."""
    return (estimate.size[0], estimate.size[1])
