"""The simulator's ground truth as a judge: whether a statement really holds in the world.

The robots never ask it. A run's executor and belief work from perception and proprioception
(:mod:`sim.perceived`); when the run ends, the referee says, separately, whether the task's goals
really hold, so that a belief that went wrong is reported as a failure and not as a success.
"""

from __future__ import annotations

from cbrs.sim import predicates as pred
from cbrs.sim.arms import ArmSide
from cbrs.sim.geometry import Pose2D, Region
from cbrs.sim.relations import Judge

__all__ = ["Referee"]


class Referee(Judge):
    """Decides the relations on the simulator's state (``sim.predicates``)."""

    def gripper_near(self, side: ArmSide, name: str) -> bool:
        return pred.gripper_near(self.world, side, name)

    def base_near_person(self, person: str) -> bool:
        return pred.base_near_person(self.world, person)

    def base_near(self, dock: Pose2D) -> bool:
        return pred.base_near(self.world, dock, heading=True)

    def grasped(self, name: str, side: ArmSide | None) -> bool:
        return pred.is_grasped(self.world, name, side)

    def with_person(self, name: str, person: str | None) -> bool:
        return pred.with_person(self.world, name, person)

    def contains_water(self, name: str) -> bool:
        return pred.contains_water(self.world, name)

    def on_platform(self, name: str) -> bool:
        return pred.on_platform(self.world, name)

    def above(self, name: str, region: Region) -> bool:
        return pred.object_above_region(self.world, name, region)

    def located_in(self, name: str, region: Region, upright: bool) -> bool:
        if upright:
            return pred.upright_in(self.world, name, region)
        return pred.object_located_in(self.world, name, region)
