"""What each motion command does: how long it takes and where it takes the robot.

Pure functions over a pose ``(x_m, y_m, heading_rad)``. The manual gives no kinematics, so
this is the model (documented in docs/emulator.md):

* codes 06-09 move along the world x axis (06/08 towards +x, 07/09 towards -x; 06/07
  front first, 08/09 rear first), codes 10/11 along the world y axis, codes 12/13 turn the
  heading; each at the speed of the current trackless speed stage;
* tape follow moves one segment (``tape_follow_s`` at the magnetic speed stage) along the
  heading (forward/backward) or across it (left/right); a tape rotation turns 90°;
  seeking the tape does not change the recorded pose;
* a point run ends at the point's pose when one is configured;
* manual moves go on at ``manual_speed_mps`` / ``manual_turn_radps`` until 05/00.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

from verifier.amr.config import Pose, RobotConfig
from verifier.protocol.catalogue import (
    METRES_PER_UNIT,
    ROTATION_PER_UNIT,
    ControlCode,
    ManualMove,
    RobotCommand,
)

MAGNETIC, TRACKLESS = "magnetic", "trackless"


@dataclass
class Motion:
    """A motion in progress.

    A finite motion goes from ``start`` by ``delta`` in ``duration_us``; an endless one
    (manual move, ``duration_us`` None) changes the pose by ``delta`` per second.
    ``elapsed_us`` counts only the time it actually moved (pauses excluded).
    """

    title: str
    kind: str  # "point", "tape", "move" or "manual"
    start: Pose
    delta: Pose
    duration_us: int | None
    elapsed_us: int = 0
    world_frame: bool = True

    @property
    def uses_tape(self) -> bool:
        return self.kind == "tape"

    @property
    def remaining_us(self) -> int | None:
        return None if self.duration_us is None else max(0, self.duration_us - self.elapsed_us)

    def pose(self) -> Pose:
        """Where the robot is after ``elapsed_us`` of this motion."""
        if self.duration_us is None:
            share = self.elapsed_us / 1_000_000
        elif self.duration_us == 0:
            share = 1.0
        else:
            share = min(1.0, self.elapsed_us / self.duration_us)
        dx, dy, dh = (d * share for d in self.delta)
        if not self.world_frame:  # delta given along / across the heading at the start
            heading = self.start[2]
            dx, dy = (dx * math.cos(heading) - dy * math.sin(heading),
                      dx * math.sin(heading) + dy * math.cos(heading))
        x, y, h = self.start
        return (x + dx, y + dy, h + dh)


def _us(seconds: float) -> int:
    return round(seconds * 1_000_000)


def relative_move(code: ControlCode, units: int, pose: Pose, config: RobotConfig, stage: int,
                  title: str) -> Motion:
    """Codes 06-13: a trackless move of ``units`` × 0.1 m or a turn of ``units`` × 0.01."""
    if code in (ControlCode.ROTATE_POS, ControlCode.ROTATE_NEG):
        angle = units * ROTATION_PER_UNIT
        if config.rotation_unit == "deg":
            angle = math.radians(angle)
        sign = 1 if code == ControlCode.ROTATE_POS else -1
        duration = _us(angle / config.rotation_speeds_radps[stage])
        return Motion(title, "move", pose, (0.0, 0.0, sign * angle), duration)
    distance = units * METRES_PER_UNIT
    delta = {
        ControlCode.MOVE_FRONT_POS: (distance, 0.0),
        ControlCode.MOVE_FRONT_NEG: (-distance, 0.0),
        ControlCode.MOVE_REAR_POS: (distance, 0.0),
        ControlCode.MOVE_REAR_NEG: (-distance, 0.0),
        ControlCode.MOVE_Y_POS: (0.0, distance),
        ControlCode.MOVE_Y_NEG: (0.0, -distance),
    }[ControlCode(code)]
    duration = _us(distance / config.trackless_speeds_mps[stage])
    return Motion(title, "move", pose, (delta[0], delta[1], 0.0), duration)


def tape_motion(command: RobotCommand, pose: Pose, config: RobotConfig, stage: int,
                title: str) -> Motion:
    """Table-2 seek / follow / rotate commands on the magnetic tape."""
    if command in (RobotCommand.SEEK_FORWARD, RobotCommand.SEEK_BACKWARD):
        return Motion(title, "tape", pose, (0.0, 0.0, 0.0), _us(config.tape_seek_s))
    if command in (RobotCommand.ROTATE_LEFT, RobotCommand.ROTATE_RIGHT):
        sign = 1 if command == RobotCommand.ROTATE_LEFT else -1
        return Motion(title, "tape", pose, (0.0, 0.0, sign * math.pi / 2), _us(config.tape_rotate_s))
    length = config.magnetic_speeds_mps[stage] * config.tape_follow_s
    along, across = {
        RobotCommand.FOLLOW_FORWARD: (length, 0.0),
        RobotCommand.FOLLOW_BACKWARD: (-length, 0.0),
        RobotCommand.FOLLOW_LEFT: (0.0, length),
        RobotCommand.FOLLOW_RIGHT: (0.0, -length),
    }[RobotCommand(command)]
    return Motion(title, "tape", pose, (along, across, 0.0), _us(config.tape_follow_s),
                  world_frame=False)


def point_run(point: int, pose: Pose, config: RobotConfig, title: str) -> Motion:
    """Code 01 with a point / script number: ``point_duration_s`` to reach its pose."""
    target = config.point_poses.get(point)
    delta = (0.0, 0.0, 0.0) if target is None else tuple(t - p for t, p in zip(target, pose))
    return Motion(title, "point", pose, delta, config.point_duration_us(point))  # type: ignore[arg-type]


def manual_motion(move: ManualMove, pose: Pose, config: RobotConfig, title: str) -> Motion:
    """Code 05: move at manual speed until 05/00 (along/across the heading)."""
    v, w = config.manual_speed_mps, config.manual_turn_radps
    rate = {
        ManualMove.FORWARD: (v, 0.0, 0.0),
        ManualMove.BACKWARD: (-v, 0.0, 0.0),
        ManualMove.ROTATE_LEFT: (0.0, 0.0, w),
        ManualMove.ROTATE_RIGHT: (0.0, 0.0, -w),
        ManualMove.SHIFT_LEFT: (0.0, v, 0.0),
        ManualMove.SHIFT_RIGHT: (0.0, -v, 0.0),
    }[ManualMove(move)]
    return Motion(title, "manual", pose, rate, None, world_frame=False)
