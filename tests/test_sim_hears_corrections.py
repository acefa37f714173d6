"""A simulation environment hears a correction of the belief made while it runs (an actuator's late answer:
actions.belief.correct, Heard) and takes it into its own belief of the relations only steps set
(SimEnvironment.effects): a later step of the run that sets the door back to what the world graph held
before the correction is then a change its writes carry. Before, the environment never heard of it, the
step looked like no change, and the run's last write left the correction standing. The world is built,
not stepped: the correction is written directly, and the step's success is told to the environment."""

from __future__ import annotations

from pathlib import Path

from cbrs.actions.belief import BeliefState, Observation, correct
from cbrs.kb.semantic_map import SemanticMap
from cbrs.sim.components import SimEnvironment
from cbrs.sim.world import open_world
from tests.test_status_effects import CLOSER, DOOR, HOME, OPENED, DoorMotor, _with_closing

CLOSED = (DOOR, HOME + "hasStatus", HOME + "Closed")
STATUS = (DOOR, HOME + "hasStatus")


def test_the_environment_hears_a_correction_and_its_own_later_step_sets_the_door_back(tmp_path: Path) -> None:
    kb = _with_closing(tmp_path)
    BeliefState(kb).write(Observation(facts=frozenset({CLOSED})), whole=True)  # an earlier run closed it
    with open_world(seed=0, semantic_map=SemanticMap.read(kb)) as world:
        environment = SimEnvironment(world, kb, DoorMotor())
        assert environment.effects == {CLOSED}
        running = BeliefState(kb)
        running.write(environment.observe(), whole=True)
        correct(kb, {STATUS}, lambda now: frozenset({OPENED}))  # the motor's late answer: open
        seen = environment.observe()
        assert OPENED in seen.facts and CLOSED not in seen.facts and len(seen.heard) == 1
        assert environment.effects == {OPENED}
        running.write(seen)
        environment.context.inputs = {"door": {"@id": DOOR, "@type": HOME + "Door"}}
        step = None  # succeeded reads the component's description and the things at hand, not the step
        environment.succeeded(step, CLOSER)  # type: ignore[arg-type]
        assert environment.effects == {CLOSED}
        running.write(environment.observe(), whole=True)  # the run's last write
    facts = BeliefState(kb).facts()
    assert CLOSED in facts and OPENED not in facts
