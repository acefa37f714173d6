"""The simulation as an execution environment: components for the home's advertised services.

Each advertised component that acts in the home is implemented by the skill its service names
(``LocateMobileRobot``, ``ApproachToObject``...: :data:`sim.services.SKILLS`), on the device the store
says it runs on: a ceiling camera's localiser uses that camera, wherever it hangs. One tick of a
component runs one whole skill (the skill steps the physics itself), so an executor tick is a unit of
work, not of time; durations are reported in simulated seconds. A component the store says how to call
in another process is a remote one instead.

Nothing here names an object, a place or an arm. ``SimEnvironment`` resolves a task's inputs to
things of the semantic map by SPARQL (:func:`kb.semantic_map.designate`) and refuses a plan the home
cannot carry out before anything moves (:mod:`sim.run_checks`); components read what they need of a
thing (its size, colour, grasp, docking pose) from the map (:mod:`sim.grounding`), the arm is the one
that reaches and can (:mod:`sim.arm_choice`), and a statement is verified by the generic test the store
maps its predicate to (``home:computedBy``: inside, on, near, above, grasped-by, with, contains,
localised-in, perceived).

Every value a component gives or takes is plain JSON of its port's type (:mod:`sim.values`), so that
a component outside this process could stand in for any of these: each work function decodes its
inputs first and encodes its outputs last.
"""

from __future__ import annotations

import contextlib
import logging
import math
import time
from collections.abc import Callable, Iterator, Mapping, Sequence
from dataclasses import dataclass
from typing import Any

from cbrs.actions.answers import StoreClasses, check_designation
from cbrs.actions.belief import Heard, Observation
from cbrs.actions.breaker import BreakerPolicy, passed_over
from cbrs.actions.components import Component, Registry, Status
from cbrs.actions.plan import Plan, PlanStep
from cbrs.actions.qualities import OwnQualities
from cbrs.actions.remote import RemoteComponent, Transport
from cbrs.kb import KnowledgeBase, Requirement, Statement
from cbrs.kb.errors import NotFoundError
from cbrs.kb.model import Advertisement
from cbrs.kb.namespaces import PREFIXES
from cbrs.kb.semantic_map import designate_each
from cbrs.kb.stated_quantities import guaranteed_statuses
from cbrs.kb.vocab import CBRS
from cbrs.settings import setting
from cbrs.sim import predicates as pred
from cbrs.sim import skills
from cbrs.sim.context import SimContext, SkillFailed, Work
from cbrs.sim.errors import SimulationError
from cbrs.sim.geometry import Region
from cbrs.sim.hold_choice import GraspChoice
from cbrs.sim.perceived import PerceivedWorld
from cbrs.sim.perception import RobotPoseEstimate
from cbrs.sim.referee import Referee
from cbrs.sim.relations import Grounded, Judge
from cbrs.sim.run_checks import (
    CannotLoadError,
    OutOfReachError,
    PlaceCrowdedError,
    PlanChecks,
    base_components,
    own_camera,
    without_base,
    without_camera,
)
from cbrs.sim.services import SKILLS, WITH_BASE
from cbrs.sim.values import GRASP_POSE, GraspPlan, MalformedValueError, check, decode, designator
from cbrs.sim.world import HomeWorld

__all__ = [
    "CannotLoadError",
    "GraspChoice",
    "GraspPlan",
    "OutOfReachError",
    "PlaceCrowdedError",
    "SimContext",
    "SimEnvironment",
    "designator",
    "implementations",
    "simulated",
]

HOME = PREFIXES["home"]

log = logging.getLogger("cbrs.sim")

LOCALISATION_TOLERANCE = 0.10
"""A localisation is believed (isLocalisedIn holds) when it agrees with the base's odometry within this
distance (m)."""
SETTLE_DISTANCE = 0.03
"""Before a re-plan, an arm lets go of what it holds only with its hand within 3 cm of where it took it."""


class SimComponent(Component):
    """A component whose invocation is one call of ``work`` on the shared context."""

    def __init__(self, iri: str, work: Work, device: str) -> None:
        super().__init__(iri)
        self._work = work
        self._device = device
        self._inputs: Mapping[str, Any] = {}
        self._context: SimContext | None = None

    def initialise(self, context: Any) -> None:
        if not isinstance(context, SimContext):
            raise TypeError(f"{self.iri} needs a SimContext, got {type(context).__name__}")
        self._context = context

    def begin(self, inputs: Mapping[str, Any]) -> None:
        self._inputs = inputs
        if self._context is not None:
            self._context.inputs = inputs  # the step's verification grounds its statements in them
            self._context.component = self.iri

    def update(self) -> Status:
        assert self._context is not None
        self._context.acted = True
        try:
            self.outputs = self._work(self._context, self._inputs, self._device)
        except (SimulationError, SkillFailed) as error:
            self.reason = str(error)
            return Status.FAILED
        return Status.SUCCEEDED


def simulated(kb: KnowledgeBase) -> list[str]:
    """The advertisements the simulation has a skill for, by one named query (no descriptions read):
    what a run may be told to fail, listed at once for the tasks page."""
    rows = kb.select("advertisements")
    return sorted(row["service"].value for row in rows if "serviceName" in row and row["serviceName"].value in SKILLS)


def implementations(
    kb: KnowledgeBase,
    world: HomeWorld | None = None,
    registry: Registry | None = None,
    transport: Transport | None = None,
    advertisements: Sequence[Advertisement] | None = None,
) -> Registry:
    """An implementation for every advertisement the store says how to invoke, added to ``registry``
    if given (a refresh): a remote component for one whose service port names a bridge service and its
    type (when there is a ``transport`` to reach it), else a simulated one where the simulation can
    perform its service on its device (cameras must exist in the world). ``advertisements``: those a
    caller has read already (a composer's), instead of reading them again."""
    registry = registry if registry is not None else Registry()
    calls = _RemoteCalls.read(kb) if transport is not None else None
    for ad in advertisements if advertisements is not None else kb.advertisements():
        remote = ad.bridge_port
        if remote is not None:
            if transport is not None and calls is not None and remote.topic is not None:
                registry.add(ad.iri, _remote(transport, remote.topic, ad, calls))
            continue
        work = SKILLS.get(ad.service_name or "")
        device = ad.device_name or ""
        if work is None:
            continue
        camera = own_camera(ad)  # a camera the world lacks: no implementation (sim.run_checks.unplaced_cameras)
        if world is not None and camera is not None and camera not in world.cameras:
            continue
        if world is not None and not world.base_names and work in WITH_BASE:  # no base to work: none either
            continue
        names = tuple(p.name for p in ad.outputs if p.name)
        registry.add(ad.iri, _maker(work, device, names))
    return registry


RESPONSE_TIME_MARGIN = 3.0
"""A remote component may take three times the ``cbrs:responseTime`` its advertisement states before a
call is given up: a stated time is a typical one, and a loaded machine or network stretches it."""


def call_timeout(ad: Advertisement, least: float | None = None) -> float:
    """Seconds a remote component has to answer one call: RESPONSE_TIME_MARGIN times the response time
    its advertisement states, but never less than ``least`` (the ``remote_call_timeout`` setting by
    default), which is also the time of one that states none (docs/execution.md, "Remote components")."""
    floor = least if least is not None else float(setting("remote_call_timeout").resolve())
    stated = [q.value for q in ad.qos if q.metric == CBRS.responseTime and math.isfinite(q.value) and q.value > 0]
    return max([floor, *(RESPONSE_TIME_MARGIN * value for value in stated)])


@dataclass(frozen=True)
class _RemoteCalls:
    """What every remote component of one environment shares: the store's classes (read at the first
    answer that needs them: an answer's ``@type`` may be a subclass of its port's class, also one a lab
    registered, docs/values.md), the settings a run reads when it starts, and who is live under which
    session."""

    classes: StoreClasses
    breaker: BreakerPolicy
    contradictions: str
    sessions: Mapping[str, str | None]

    @classmethod
    def read(cls, kb: KnowledgeBase) -> _RemoteCalls:
        breaker = BreakerPolicy(
            setting("remote_breaker_timeouts").resolve(), setting("remote_breaker_cooldown").resolve()
        )
        sessions = {iri: state.registered_by for iri, state in kb.liveness.states().items()}
        return cls(StoreClasses(kb), breaker, setting("remote_contradictions").resolve(), sessions)


def _remote(transport: Transport, service: str, ad: Advertisement, calls: _RemoteCalls) -> Callable[[str], Component]:
    """A remote component for ``ad`` (docs/execution.md, "Remote components")."""
    outputs = {p.name: p.type for p in ad.outputs if p.name}
    timeout = call_timeout(ad)
    exclusive = ad.kind == CBRS.PhysicalManipulationComponent

    def checked(concept: str, value: Any) -> dict[str, Any]:
        found = check(concept, value, calls.classes.is_a)
        check_designation(concept, found, calls.classes)  # the pen answered as a weight
        return found

    return lambda iri: RemoteComponent(
        iri,
        transport,
        service,
        outputs,
        checked,
        timeout,
        exclusive=exclusive,
        effects=ad.effects,
        deletes=ad.deletes,
        classes=calls.classes,
        contradictions=calls.contradictions,
        breaker=calls.breaker,
        session=calls.sessions.get(ad.iri),
    )


def _maker(work: Work, device: str, outputs: tuple[str, ...]) -> Callable[[str], Component]:
    return lambda iri: SimComponent(iri, _named(work, outputs), device)


def _named(work: Work, advertised: tuple[str, ...]) -> Work:
    """``work`` with its one output under the name the advertisement gives it (a second camera's
    tracker may call the person's position personLocation)."""
    if len(advertised) != 1:
        return work

    def renamed(ctx: SimContext, inputs: Mapping[str, Any], device: str) -> dict[str, Any]:
        outputs = work(ctx, inputs, device)
        if len(outputs) == 1 and advertised[0] not in outputs:
            return {advertised[0]: next(iter(outputs.values()))}
        return outputs

    return renamed


# -- the environment ------------------------------------------------------------------------------


def _grasped(inputs: Mapping[str, Any]) -> str | None:
    """The object a step's GraspPose input is about (its body name): the object at hand."""
    for value in inputs.values():
        if isinstance(value, dict) and value.get("@type") == GRASP_POSE:
            try:
                return decode(value, GraspPlan).model.name
            except MalformedValueError:
                continue
    return None


class SimEnvironment:
    """The pybullet home as an execution environment for ``actions.runner.run_task``.

    Verification and the world graph come from what the robots perceive and feel
    (:class:`~sim.perceived.PerceivedWorld`); the simulator's own state only answers :meth:`audit`,
    whether the task's goals really hold.
    """

    def __init__(self, world: HomeWorld, kb: KnowledgeBase, transport: Transport | None = None) -> None:
        self.world = world
        self.kb = kb
        self.transport = transport
        """How components in other processes are reached (a bridge connection); None: only simulated ones."""
        self.advertisements = self._read_advertisements()
        """Every advertisement by IRI as read when the registry was last filled (here and at :meth:`refresh`):
        the descriptions its implementations were made from, which the plan checks of :meth:`given` read too
        (one read of 20-30 ms instead of two, docs/simulation.md "Sixth round")."""
        self.registry = implementations(
            kb, world, transport=transport, advertisements=list(self.advertisements.values())
        )
        self.belief = PerceivedWorld(world)
        self.context = SimContext(world, kb, belief=self.belief)
        self.referee = Referee(world)
        self.effects: set[tuple[str, str, str]] = set()
        """Relations believed because a step with that effect succeeded, where no test decides them."""
        self._superclasses: dict[str, set[str]] | None = None
        self._computables: dict[str, str] | None = None
        self._exclusions: tuple[frozenset[str], tuple[tuple[str, str], ...]] | None = None
        self._qualities: OwnQualities | None = None  # the rule, read from the store at its first question
        self._heard = Heard(kb)  # before the world graph is read: a correction made after the read is heard
        self.effects |= self._untestable_beliefs()
        self._at_the_end = False  # the task's goals are being checked: "a gripper" is any arm (:meth:`at_the_end`)

    def clock(self) -> float:
        return self.world.time

    @contextlib.contextmanager
    def at_the_end(self) -> Iterator[None]:
        """Within the block the task's goals are checked, after its last step: a statement about "a
        gripper" (the class) holds of any arm. A step's own effect is decided for the arm at work (a
        hand-over's take is the taking arm's), but at the end the arm at work is the last step's, so
        EraserCupPen's cup, kept in the left hand while the right set the pen down, was judged not grasped
        and the run failed (since 78b8ac1 checks that goal)."""
        self._at_the_end = True
        try:
            yield
        finally:
            self._at_the_end = False

    def passed_over(self) -> dict[str, str]:
        """The remote components a plan leaves out now, with why (``actions.breaker``): their calls timed
        out and the cool-down is on, or an actuator is still executing a call given up."""
        if self.transport is None:
            return {}
        sessions = {iri: state.registered_by for iri, state in self.kb.liveness.states().items()}
        return passed_over(self.transport, time.monotonic(), sessions)

    def unimplemented(self, advertisements: Sequence[Advertisement]) -> dict[str, str]:
        """Why the simulation has no implementation of those of ``advertisements`` it lacks a camera for
        (``sim.run_checks.without_camera``) or a mobile base for (``without_base``), for the run's account of
        what it cannot run."""
        return {
            **without_camera(advertisements, self.world.cameras),
            **without_base(advertisements, self.world.base_names),
        }

    def looked_for(self) -> frozenset[str]:
        """The things (IRIs) a camera looked for by colour for the run's steps and to verify their effects,
        so far: not the look at everything before a plan. What a run's colour warnings are of, besides the
        things its plans perceive (``actions.colour_warnings``)."""
        return frozenset(self.context.looked_for)

    def base_components(self) -> dict[str, frozenset[str]]:
        """Each mobile base's own components, in a home of several (``sim.run_checks.base_components``): a
        plan works one base (``actions.runner``)."""
        return base_components(self.world, self.kb)

    def refresh(self) -> None:
        """Before a new plan: forget the measured map (the world may have changed) and add the
        components registered since."""
        self.context.grid = None
        self.advertisements = self._read_advertisements()
        implementations(self.kb, self.world, self.registry, self.transport, list(self.advertisements.values()))

    def _read_advertisements(self) -> dict[str, Advertisement]:
        return {ad.iri: ad for ad in self.kb.advertisements()}

    def settle(self) -> None:
        """Before a re-plan: an arm still holding an object (its plan failed between picking it up and
        putting it down) sets it down where it took it from, and the arms fold home. Nothing else moves."""
        for side, arm in sorted(self.world.arms.items()):
            grasp = arm.held_grasp
            if arm.held is None or grasp is None:
                continue
            x, y, z = grasp.position  # where the hand closed on it, on the surface it stood on
            surface = z - grasp.bottom_offset
            spot = Region("TakenFrom", x - 0.02, x + 0.02, y - 0.02, y + 0.02, surface, surface + 0.3)
            skills.carry_object(self.world, side, spot)  # its verdict may fail on an object askew in the hand
            hand = arm.ee_pose().position
            if math.hypot(hand[0] - x, hand[1] - y) > SETTLE_DISTANCE:
                continue  # not back over where it was taken: better held than dropped elsewhere
            put = skills.put_down_object(self.world, side, spot)
            if arm.held is not None:  # lowering it failed: lower it into the hand's pose of the taking instead
                taken = arm.move_to(grasp.position, grasp.orientation, speed=skills.PLACE_SPEED, symmetric=False)
                arm.detach()
                arm.open_gripper()
                # back off along the approach before folding: folded from beside it, the arm swept a
                # side-grasped bottle over and 34 cm away (nu16 repro 18)
                let_go = arm.ee_pose()
                back = grasp.backed_off(let_go.position)
                arm.move_to(back, let_go.orientation, speed=skills.PLACE_SPEED, symmetric=False)
                self.world.step(skills.SETTLE_TIME)
                arm.home()
                log.warning(
                    "settling before a re-plan: putting the %s down failed (%s); %s, let go and backed off",
                    grasp.model.name,
                    put.reason,
                    "lowered it where it was taken"
                    if taken.reached
                    else f"lowering it where it was taken failed too ({taken.reason})",
                )

    def perceive(self) -> None:
        """Look at everything with every working camera (before a plan, and before a re-plan)."""
        self.belief.look()

    def given(self, plan: Plan, requirements: Mapping[str, Requirement]) -> dict[str, Any]:
        """The world's thing for each input a requirement gives: the one individual of the input's class."""
        wanted: dict[str, tuple[str, str | None]] = {}  # input name -> (its class, the requesting robot)
        guaranteed: dict[str, tuple[str, ...]] = {}  # input name -> the statuses the task guarantees of its thing
        for step in plan.steps:
            for binding in step.inputs:
                source = binding.source
                if source.step is not None or source.name in wanted:
                    continue
                requirement = requirements.get(source.requirement or "")
                if requirement is None:
                    continue
                for parameter in requirement.inputs:
                    if parameter.name == source.name:
                        wanted[source.name] = (parameter.type, requirement.requested_by)
                        guaranteed[source.name] = guaranteed_statuses(requirement, parameter.type, self.is_a)
        # every input's thing asked at once: one request to a remote store, not one per input
        things = designate_each(self.kb, list(wanted.values()), guarantees=list(guaranteed.values())) if wanted else []
        values: dict[str, Any] = {
            name: designator(iri, concept) for (name, (concept, _)), iri in zip(wanted.items(), things, strict=True)
        }
        self.context.designated = frozenset(str(value["@id"]) for value in values.values())
        self.context.plan, self.context.given = plan, values  # where a hold ends, for the approach
        self.context.step, self.context.known = None, {}
        if not self.context.acted:  # checked before anything moved; a re-plan fails by its steps
            PlanChecks(self.world, self.kb, self.belief, self.context, self.is_a, self.advertisements).check(
                plan, values
            )
        return values

    def starting(self, step: PlanStep, known: Mapping[int, Mapping[str, Any]]) -> None:
        """The executor starts ``step``; ``known`` holds every step's inputs known now. Kept so that a
        component knows which step of the plan it runs and where a later step takes what it holds."""
        self.context.step, self.context.known = step, known

    # -- verification: the generic test the store maps each predicate to ---------------------

    def is_a(self, concept: str, superclass: str) -> bool:
        if self._superclasses is None:
            table: dict[str, set[str]] = {}
            for row in self.kb.select("subclasses"):
                table.setdefault(row["class"].value, set()).add(row["superclass"].value)
            self._superclasses = table
        return concept == superclass or superclass in self._superclasses.get(concept, set())

    def computable(self, predicate: str) -> str | None:
        if self._computables is None:
            table: dict[str, str] = {}
            for row in self.kb.select("computables"):  # nearest ancestor first
                table.setdefault(row["relation"].value, row["computable"].value)
            self._computables = table
        return self._computables.get(predicate)

    def _ground(self, concept: str, inputs: Mapping[str, Any], besides: Grounded | None = None) -> Grounded | None:
        """The thing a class-level statement means at this step: a thing the step was given, else what
        is at hand (the arm's object, its gripper, the base, the person, the target). ``besides`` is what
        the statement's other side means, never taken for this side: a cupboard a carry is given as its
        place is a physical object too, and without this it stood for both sides of "object above place",
        so the belief held the cupboard above itself and a re-plan put down nothing."""
        people = self.world.map.people
        for value in inputs.values():
            if isinstance(value, dict) and "@id" in value:
                iri = str(value["@id"])
                if besides is not None and besides.role == "thing" and besides.name == iri:
                    continue
                types = (*self.world.map.types.get(iri, ()), str(value.get("@type", "")))
                if any(self.is_a(t, concept) for t in types):
                    return Grounded("person", people[iri].name) if iri in people else Grounded("thing", iri)
        ctx = self.context
        if self.is_a(concept, HOME + "Gripper") or self.is_a(concept, HOME + "Arm"):
            return Grounded("gripper", ctx.arm.value)
        base = self.world.mobile  # None in a home with no mobile base: nothing to ground the base's statements in
        if self.is_a(concept, HOME + "RobotPlatform"):
            return Grounded("platform", base.name) if base is not None else None
        if self.is_a(concept, HOME + "MobileRobot"):
            return Grounded("base", base.name) if base is not None else None
        if self.is_a(concept, HOME + "Robot"):
            return Grounded("robot", "")
        if self.is_a(concept, HOME + "Person"):
            classes = self.world.map.types
            kind = sorted(iri for iri in people if any(self.is_a(t, concept) for t in classes.get(iri, ())))
            meant = [iri for iri in kind if iri in self.context.designated] or kind
            return Grounded("person", people[meant[0]].name) if len(meant) == 1 else None  # nobody, or who?
        if self.is_a(concept, HOME + "Substance"):
            return Grounded("substance", concept)
        held = _grasped(inputs) if self.is_a(concept, HOME + "PhysicalObject") else None
        if held is not None:
            return Grounded("object", held)
        # a class only one thing of the world belongs to (the Pen) means that thing, whatever is at hand
        candidates = [iri for iri, types in self.world.map.types.items() if any(self.is_a(t, concept) for t in types)]
        if len(candidates) == 1:
            return Grounded("thing", candidates[0])
        if self.is_a(concept, HOME + "PhysicalObject") and ctx.object is not None:
            return Grounded("object", ctx.object)
        if self.is_a(concept, HOME + "Place") and ctx.region is not None:
            return Grounded("region", ctx.region.name)
        return None

    def verify(self, step: PlanStep | None, statement: Statement, outputs: Mapping[str, Any]) -> bool | None:
        """Decide a (class-level) statement by its predicate's computable, for the things at hand, on
        what the robots perceive now. A statement the store maps to no test is believed from the step
        with that effect on (:meth:`_believe_effect`): True once it is (the task's goal checked at the
        end, a later step's), None at that step itself (no test decided it) and when its things cannot
        be told. Without a step (a goal that held at the start) the things at hand are the task's."""
        if step is None:
            self.context.inputs = dict(self.context.given)
        self._hear()
        found = self._judge(self.belief, statement, outputs, look=True)
        if found is not None:
            return found
        fact = self._believe_effect(statement)
        if fact is None or fact not in self.effects:
            if fact is not None:
                self._believe(fact)
            return None
        return True

    def holds(self, statement: Statement) -> bool | None:
        """Whether ``statement`` about the task's things holds by what the robots perceive now, decided by
        :meth:`verify`'s tests without a step; None where no test decides it before a step (a relation
        with no test, a perception's result, a localisation). A question only: nothing is looked at again
        and nothing believed (a task's precondition, before the first step: ``actions.task_preconditions``)."""
        kept = self.context.inputs
        self.context.inputs = dict(self.context.given)
        try:
            return self._judge(self.belief, statement, {}, look=False)
        finally:
            self.context.inputs = kept

    def succeeded(self, step: PlanStep, component: str) -> None:
        """``component`` did ``step``: of the relations no test decides, what its description deletes stops
        being believed, then what it adds is believed (in that order, as in STRIPS, so a statement both
        deleted and added stays). Effects nobody relied on count too: the door a step opened on the way
        is open for the next task."""
        try:
            description = self.kb.description(component)
        except NotFoundError:  # deregistered while it ran: what it did is no longer described
            log.warning("%s did a step but is no longer described: its effects are not believed", component)
            return
        self._hear()  # what was corrected before the step, so that the step's own act is the newer
        for statement in description.deletes:
            fact = self._untestable(statement)
            if fact is not None:
                self.effects.discard(fact)
        for statement in description.effects:
            fact = self._untestable(statement)
            if fact is not None:
                self._believe(fact)

    def _hear(self) -> None:
        """Take the corrections of the world graph made since (an actuator's late answer:
        :class:`actions.belief.Heard`) into :attr:`effects`, those of relations no test decides: a later step
        that sets one back then changes the belief, and the run's writes say so."""
        self.effects = self._heard.take(self.effects, lambda pair: self.computable(pair[1]) is None)

    def _untestable(self, statement: Statement) -> tuple[str, str, str] | None:
        """The statement grounded in the things at hand, when the store maps its relation to no test."""
        return self._believe_effect(statement) if self.computable(statement.predicate) is None else None

    def _believe(self, fact: tuple[str, str, str]) -> None:
        """Believe ``fact`` and stop believing what it contradicts: another value of the same relation of
        the same thing, when the two values are classes declared disjoint (a door Closed is no longer
        Opened) or the relation is functional (owl:FunctionalProperty: one value at a time)."""
        subject, predicate, value = fact
        self.effects = {
            (s, p, o)
            for s, p, o in self.effects
            if not (s == subject and p == predicate and o != value and self._exclusive(predicate, o, value))
        }
        self.effects.add(fact)

    def _exclusive(self, predicate: str, first: str, second: str) -> bool:
        """Whether a thing cannot have both values of ``predicate`` at once."""
        if self._exclusions is None:
            functional = frozenset(row["property"].value for row in self.kb.select("functional_properties"))
            disjoint = tuple((row["first"].value, row["second"].value) for row in self.kb.select("taxonomy_disjoint"))
            self._exclusions = (functional, disjoint)
        functional, disjoint = self._exclusions
        return predicate in functional or any(
            (self.is_a(first, a) and self.is_a(second, b)) or (self.is_a(first, b) and self.is_a(second, a))
            for a, b in disjoint
        )

    def _believe_effect(self, statement: Statement) -> tuple[str, str, str] | None:
        """The relation no test decides that a step with it as its effect makes believed: it joins the
        world graph, grounded in the things at hand. Its object may be a status or another quality
        (``home:Opened`` in (Door, hasStatus, Opened)): a class no thing of the world stands for, which is
        then the object itself, as ``home:Water`` is in (Cup, contains, Water)."""
        grounded = self._ground(statement.object, self.context.inputs)
        side = self._ground(statement.subject, self.context.inputs, besides=grounded)
        subject = self._iri_of(side) if side is not None else None
        if grounded is not None:
            obj = self._iri_of(grounded)
        else:
            obj = statement.object if self._own_quality(statement.predicate, statement.object) else None
        if subject is None or obj is None:
            return None
        return (subject, statement.predicate, obj)

    def _own_quality(self, predicate: str, value: str) -> bool:
        """Whether ``value``, a class, stands for itself as ``predicate``'s value: a quality of the subject
        (:class:`actions.qualities.OwnQualities`, the rule late answers share; docs/components.md)."""
        return self._quality_rule()(predicate, value)

    def _quality_rule(self) -> OwnQualities:
        if self._qualities is None:
            self._qualities = OwnQualities(self.kb, self.is_a)
        return self._qualities

    def _untestable_beliefs(self) -> set[tuple[str, str, str]]:
        """The relations about things of this world that the world graph (an earlier run's belief) holds
        and no test decides: no sense can see them again (a door a remote motor opened), so they stay
        believed; the relations a test decides are perceived afresh."""
        kept = set()
        for row in self.kb.select("world_facts"):
            fact = (row["thing"].value, row["relation"].value, row["other"].value)
            if fact[0] in self.world.map.types and self.computable(fact[1]) is None:
                if self._quality_rule().passing(fact[1], fact[2]):
                    continue  # an alert an earlier run believed (see _own_quality)
                kept.add(fact)
        return kept

    def _iri_of(self, grounded: Grounded) -> str | None:
        world = self.world
        if grounded.role in ("thing", "substance"):
            return grounded.name
        if grounded.role == "object":
            return world.objects[grounded.name].iri if grounded.name in world.objects else None
        if grounded.role == "person":
            person = world.people.get(grounded.name)
            return person.iri if person is not None else None
        if grounded.role == "base":
            return world.robot.iri
        if grounded.role == "platform":
            return world.robot.platform
        return None

    def audit(self, statement: Statement) -> bool | None:
        """Whether ``statement`` really holds in the simulated world now (the referee, not the robots)."""
        return self._judge(self.referee, statement, {}, look=False)

    def _judge(self, judge: Judge, statement: Statement, outputs: Mapping[str, Any], look: bool) -> bool | None:
        test = self.computable(statement.predicate)
        if test is None:
            return None
        if test == "perceived":
            return bool(outputs) if look else None
        if test == "localised-in":
            if not look:
                return None
            try:
                estimate = decode(outputs.get("robotLocation"), RobotPoseEstimate)
            except MalformedValueError:
                return False
            odometry = self.world.base_pose()  # the base's own estimate of where it is
            return math.hypot(estimate.x - odometry.x, estimate.y - odometry.y) <= LOCALISATION_TOLERANCE
        inputs = self.context.inputs
        obj = self._ground(statement.object, inputs)
        subject = self._ground(statement.subject, inputs, besides=obj)
        if subject is None or obj is None:
            return None
        if look and isinstance(judge, PerceivedWorld):
            self._look_for(judge, test, subject, obj)
        arm = None if self._at_the_end else self.context.arm
        return judge.decide(test, subject, obj, arm, self.context.region)

    def _look_for(self, belief: PerceivedWorld, test: str, subject: Grounded, obj: Grounded) -> None:
        """Perceive what a test is about: the object in a region or a container's water by the cameras,
        the person the base should be near by the ceiling cameras; the rest the robots feel."""
        thing = belief.object_name(subject)
        smap, looked = self.world.map, self.context.looked_for
        if test in ("inside", "on", "contains") and thing is not None and obj.role != "platform":
            belief.look([thing], people=False)
            looked.add(self.world.objects[thing].iri)
            if thing in self.world.containers and belief.water_colour is not None:  # its water, by its colour
                looked.update(smap.of_type(HOME + "Water"))
        elif test == "near" and obj.role == "person":
            belief.look([], people=True)
            looked.update(person.iri for person in smap.people.values() if person.name == obj.name)
        elif test == "near" and subject.role == "gripper" and belief.object_name(obj) is not None:
            names = [name for name in [belief.object_name(obj)] if name is not None]
            belief.look(names, people=False)
            looked.update(self.world.objects[name].iri for name in names)
        else:
            belief.feel()

    # -- the belief state ----------------------------------------------------------------------

    def observe(self) -> Observation:
        """Types, the relations believed to hold now among the world's things (what each hand holds among
        them: its gripper as the store names it), and where they are believed to be: from the robots'
        perception and proprioception (no new images are taken), and the relations only steps set, with the
        store's corrections heard since taken in (a failed step's)."""
        self._hear()
        belief = self.belief
        belief.feel()
        self._hear()
        world, smap = self.world, self.world.map
        arm = self.context.arm
        facts: set[tuple[str, str, str]] = set()
        supports = [smap.things[iri] for iri in sorted(smap.furniture) if iri in smap.things]
        regions = [smap.things[iri] for iri in sorted(smap.regions) if iri in smap.things]
        base = world.mobile  # None in a home with no mobile base: nothing is said of a base
        base_iri = base.iri if base is not None else None
        people = world.people
        for obj in smap.objects.values():
            name = obj.name
            here = Grounded("object", name)
            for region in regions:
                if belief.decide("inside", here, Grounded("thing", region.iri), arm):
                    facts.add((obj.iri, HOME + "isLocated", region.iri))
            for support in supports:  # an object in a region on the table is on the table too
                box = support.box
                top = Region(support.name, box.min_x, box.max_x, box.min_y, box.max_y, box.max_z, box.max_z)
                if belief.located_in(name, top, upright=False):
                    facts.add((obj.iri, HOME + "isLocatedOn", support.iri))
            if base is not None and base.platform is not None and belief.on_platform(name):
                facts.add((obj.iri, HOME + "isLocatedOn", base.platform))
            for person in people.values():
                if belief.with_person(name, person.name):
                    facts.add((obj.iri, HOME + "isWith", person.iri))
            if name in world.containers and belief.contains_water(name):
                facts.add((obj.iri, HOME + "contains", HOME + "Water"))
            for side, holder in world.arms.items():  # what a hand holds, as it feels it (a re-plan keeps it)
                if holder.hand.iri and belief.grasped(name, side):
                    facts.add((obj.iri, HOME + "isGraspedBy", holder.hand.iri))
        positions: dict[str, tuple[float, float, float]] = {}
        if base_iri is not None:
            for person in people.values():
                if belief.base_near_person(person.name):
                    facts.add((base_iri, HOME + "isNear", person.iri))
            odometry = world.base_pose()
            for support in supports:
                if (
                    support.dock is not None
                    and odometry.distance_to(support.dock.x, support.dock.y) <= pred.BASE_NEAR_DISTANCE
                ):
                    facts.add((base_iri, HOME + "isNear", support.iri))
            positions[base_iri] = (odometry.x, odometry.y, 0.0)
        for obj in smap.objects.values():
            where = belief.position(obj.name)
            if where is not None:
                positions[obj.iri] = where
        for person in people.values():
            seen = belief.people.get(person.name)
            if seen is not None:
                positions[person.iri] = seen.position
        rooms = [smap.things[iri] for iri in sorted(smap.rooms) if iri in smap.things]
        for iri, (x, y, _) in positions.items():
            if iri == base_iri or iri in smap.people:
                for room in rooms:
                    if room.box.contains_xy(x, y):
                        facts.add((iri, HOME + "isLocated", room.iri))
        facts |= self.effects
        types = {iri: kinds[0] for iri, kinds in smap.types.items() if kinds and not iri.endswith("/world")}
        return Observation(types, frozenset(facts), positions, world.time, heard=self._heard.taken)
