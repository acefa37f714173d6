"""The mobile base (a Pioneer 3-DX with a carrying platform) and its path-following controller.

The base is a dynamic body pulled by a fixed constraint towards a set-point pose that a unicycle
model integrates from velocity commands. Because the body really moves (it has velocities, unlike a
teleported one), friction carries the pen on its platform along. The controller turns on the spot
towards the next waypoint, then drives with bounded speed and acceleration; it stops by itself at
the goal and gives up when blocked or out of time.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import pybullet as p

from cbrs.sim.geometry import Pose2D, quat_from_yaw, wrap_angle, yaw_of

__all__ = ["DriveResult", "MobileBase"]

MAX_SPEED = 0.6
"""m/s"""
MAX_TURN_RATE = 1.2
"""rad/s"""
MAX_ACCELERATION = 0.8
"""m/s^2: low enough that the pen does not slide on the platform (friction 1.0 holds up to ~9.8)."""
TURN_IN_PLACE = 0.3
"""Above this heading error (rad) the base turns on the spot before driving."""
WAYPOINT_TOLERANCE = 0.10
"""An intermediate waypoint counts as passed within 10 cm (it is only a corner of the path)."""
GOAL_TOLERANCE = 0.02
HEADING_TOLERANCE = 0.02
BLOCKED_DISTANCE = 0.15
"""If the body lags its set-point by more than this, something is in the way."""
CONTROL_PERIOD = 1.0 / 240.0
"""The set-point moves every physics step: moved in coarser jumps, the constraint would jerk the body
(and shake the pen off the platform)."""
CONSTRAINT_FORCE = 3000.0
_TAU = 2.0 * math.pi


@dataclass(frozen=True)
class DriveResult:
    succeeded: bool
    reason: str
    final: Pose2D
    seconds: float
    distance: float
    """Distance actually driven by the set-point (m)."""


class MobileBase:
    """The base of one world; the pose it reports is the simulator's (its wheel odometry, without drift)."""

    def __init__(self, client: int, body: int, step: Callable[[float], None]) -> None:
        self.client = client
        self.body = body
        self._step = step
        self.height = float(p.getBasePositionAndOrientation(body, physicsClientId=client)[0][2])
        """Height of the chassis centre (the body's origin) above the floor, kept while it drives."""
        pose = self.pose()
        self._setpoint = pose
        self._constraint = p.createConstraint(
            body,
            -1,
            -1,
            -1,
            p.JOINT_FIXED,
            (0.0, 0.0, 0.0),
            (0.0, 0.0, 0.0),
            (pose.x, pose.y, self.height),
            childFrameOrientation=quat_from_yaw(pose.theta),
            physicsClientId=client,
        )
        p.changeConstraint(self._constraint, maxForce=CONSTRAINT_FORCE, physicsClientId=client)

    def pose(self) -> Pose2D:
        pos, orn = p.getBasePositionAndOrientation(self.body, physicsClientId=self.client)
        return Pose2D(float(pos[0]), float(pos[1]), yaw_of((orn[0], orn[1], orn[2], orn[3])))

    def _command(self, pose: Pose2D) -> None:
        self._setpoint = pose
        p.changeConstraint(
            self._constraint,
            jointChildPivot=(pose.x, pose.y, self.height),
            jointChildFrameOrientation=quat_from_yaw(pose.theta),
            maxForce=CONSTRAINT_FORCE,
            physicsClientId=self.client,
        )

    def place(self, pose: Pose2D) -> None:
        """Put the base at ``pose`` at once (scenario set-up and tests; not a motion)."""
        p.resetBasePositionAndOrientation(
            self.body, (pose.x, pose.y, self.height), quat_from_yaw(pose.theta), physicsClientId=self.client
        )
        p.resetBaseVelocity(self.body, (0.0, 0.0, 0.0), (0.0, 0.0, 0.0), physicsClientId=self.client)
        self._command(pose)

    def _lagging(self) -> bool:
        (x, y, _), _ = p.getBasePositionAndOrientation(self.body, physicsClientId=self.client)
        return math.hypot(x - self._setpoint.x, y - self._setpoint.y) > BLOCKED_DISTANCE  # the pose without its yaw

    def follow(
        self, waypoints: Sequence[tuple[float, float]], final_heading: float | None = None, time_limit: float = 0.0
    ) -> DriveResult:
        """Drive through ``waypoints`` (world x, y), stop at the last one, then turn to ``final_heading``.

        ``time_limit`` (simulated seconds) defaults to three times the time the path needs at full
        speed plus 10 s of turning.
        """
        start = self.pose()
        self._command(start)
        length = 0.0
        previous = start.xy
        for point in waypoints:
            length += math.dist(previous, point)
            previous = point
        limit = time_limit if time_limit > 0.0 else 3.0 * length / MAX_SPEED + 10.0
        elapsed = 0.0
        driven = 0.0
        speed = 0.0
        dt = CONTROL_PERIOD

        def fail(reason: str) -> DriveResult:
            self._command(self.pose())
            self._step(0.1)
            return DriveResult(False, reason, self.pose(), elapsed, driven)

        # The control loop runs once per physics step: on plain floats, its pybullet calls bound once (the
        # same calls with the same arguments as _command and _lagging make, and the same arithmetic).
        x, y, theta = start.x, start.y, start.theta
        body, client, constraint, height = self.body, self.client, self._constraint, self.height
        change, base_pose, sin, cos, hypot = (
            p.changeConstraint,
            p.getBasePositionAndOrientation,
            math.sin,
            math.cos,
            math.hypot,
        )
        for index, (wx, wy) in enumerate(waypoints):
            last = index == len(waypoints) - 1
            tolerance = GOAL_TOLERANCE if last else WAYPOINT_TOLERANCE
            while True:
                dx, dy = wx - x, wy - y
                distance = hypot(dx, dy)
                if distance <= tolerance:
                    break
                if elapsed >= limit:
                    return fail(f"time limit {limit:.1f} s reached {distance:.2f} m from waypoint {index}")
                error = (math.atan2(dy, dx) - theta + math.pi) % _TAU - math.pi  # wrap_angle
                if abs(error) > TURN_IN_PLACE:
                    speed = max(0.0, speed - MAX_ACCELERATION * dt)
                else:
                    wanted = MAX_SPEED if not last else min(MAX_SPEED, math.sqrt(2 * MAX_ACCELERATION * distance))
                    wanted = min(wanted, 2.0 * distance / dt)
                    speed = min(wanted, speed + MAX_ACCELERATION * dt)
                turn = max(-MAX_TURN_RATE, min(MAX_TURN_RATE, 3.0 * error))
                step = min(speed * dt, distance)
                x, y, theta = (
                    x + step * cos(theta),
                    y + step * sin(theta),
                    (theta + turn * dt + math.pi) % _TAU - math.pi,
                )
                driven += step
                change(  # _command
                    constraint,
                    jointChildPivot=(x, y, height),
                    jointChildFrameOrientation=(0.0, 0.0, sin(theta / 2.0), cos(theta / 2.0)),
                    maxForce=CONSTRAINT_FORCE,
                    physicsClientId=client,
                )
                self._step(dt)
                elapsed += dt
                (bx, by, _), _ = base_pose(body, physicsClientId=client)  # _lagging
                if hypot(bx - x, by - y) > BLOCKED_DISTANCE:
                    return fail(f"blocked near ({x:.2f}, {y:.2f})")
        self._setpoint = Pose2D(x, y, theta)
        pose = self._setpoint
        speed = 0.0
        if final_heading is not None:
            while abs(wrap_angle(final_heading - pose.theta)) > HEADING_TOLERANCE / 2.0:
                if elapsed >= limit:
                    return fail("time limit reached while turning to the final heading")
                error = wrap_angle(final_heading - pose.theta)
                turn = max(-MAX_TURN_RATE, min(MAX_TURN_RATE, 3.0 * error))
                pose = Pose2D(pose.x, pose.y, wrap_angle(pose.theta + turn * dt))
                self._command(pose)
                self._step(dt)
                elapsed += dt
        self._step(0.2)
        elapsed += 0.2
        return DriveResult(True, "", self.pose(), elapsed, driven)
