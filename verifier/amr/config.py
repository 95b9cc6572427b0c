"""How the emulated robot behaves where the manual is silent: task durations, speeds, the
battery, the power-on state and what it does with requests that break the rules.

All values are in human units (seconds, milliseconds, m/s, percent) because people write
them in TOML; the robot converts them to integer microseconds once.
"""
from __future__ import annotations

from dataclasses import dataclass, field, fields
from typing import Any, Mapping

from verifier.amr import schema
from verifier.protocol.catalogue import POINT_NUMBERS

#: What the robot does with a request that starts less than 250 ms after the previous one.
#: The manual does not say; the checker flags such requests whatever the robot does.
PACING_POLICIES = ("answer", "ignore", "late")
#: What the robot does with motion commands before the power-on stop command.
BEFORE_STOP_POLICIES = ("ignore", "obey")
#: The unit of the 0.01 step of codes 12/13 (the manual does not name it).
ROTATION_UNITS = ("rad", "deg")

Stages4 = tuple[float, float, float, float]
Pose = tuple[float, float, float]


@dataclass(frozen=True)
class RobotConfig:
    """The emulated robot's behaviour. Every field can be set from a scenario's table.

    turnaround_ms
        Time from the end of a request's last byte to the first byte of the reply. A
        slave cannot answer before t3.5 of silence has ended the request, so the line
        never starts a reply earlier than that, whatever this says.
    point_duration_s, point_durations_s
        How long a code-01 point/script run takes: the default, and per point number.
    taught_points
        Point numbers that were taught; ``None`` = all of 1-21. A run of an untaught point
        is accepted and does nothing: the robot stays where it is and reports idle (the
        manual's note 1).
    point_poses
        Where each point is, ``{n: [x_m, y_m, heading_rad]}``; a finished run puts the
        robot there. Points without a pose leave the position unchanged.
    tape_seek_s, tape_follow_s, tape_rotate_s
        Durations of the magnetic-tape commands (seek, follow one segment, rotate 90°).
    trackless_speeds_mps, magnetic_speeds_mps, rotation_speeds_radps
        Speed for each of the four speed stages (0-3); relative moves (codes 06-13) take
        distance / speed.
    manual_speed_mps, manual_turn_radps
        Speed of manual moves (code 05).
    rotation_unit
        Unit of the 0.01 step of codes 12/13: ``"rad"`` (default) or ``"deg"``.
    speed_stage, magnetic_speed_stage, collision_range_stage
        Power-on settings (0-3). Collision range 0 (0 m) switches the ultrasonic
        anti-collision off, so scripted anti-collision faults have no effect then.
    battery_pct, battery_low_pct
        Charge at power-on and the warning threshold: at or below it the battery query
        answers 1 and the error byte says 03.
    battery_drain_running_pct_per_min, battery_drain_idle_pct_per_min
        Drain while a task runs / while idle.
    start_pose
        Position at power-on ``[x_m, y_m, heading_rad]``.
    pacing
        A request that starts less than 250 ms after the previous one: ``"answer"``
        normally (default; the checker flags it), ``"ignore"`` it (no reply, no action),
        or answer it ``"late"``, as if it had been queued until the period was over.
    before_stop
        Motion commands before the first stop command after power-on: ``"ignore"``
        (default: accepted and echoed, the robot does not move) or ``"obey"``.
    """

    turnaround_ms: float = 5.0
    point_duration_s: float = 8.0
    point_durations_s: Mapping[int, float] = field(default_factory=dict)
    taught_points: tuple[int, ...] | None = None
    point_poses: Mapping[int, Pose] = field(default_factory=dict)
    tape_seek_s: float = 3.0
    tape_follow_s: float = 10.0
    tape_rotate_s: float = 4.0
    trackless_speeds_mps: Stages4 = (0.2, 0.4, 0.6, 0.8)
    magnetic_speeds_mps: Stages4 = (0.2, 0.3, 0.4, 0.5)
    rotation_speeds_radps: Stages4 = (0.3, 0.5, 0.7, 0.9)
    manual_speed_mps: float = 0.3
    manual_turn_radps: float = 0.5
    rotation_unit: str = "rad"
    speed_stage: int = 0
    magnetic_speed_stage: int = 0
    collision_range_stage: int = 2
    battery_pct: float = 100.0
    battery_low_pct: float = 20.0
    battery_drain_running_pct_per_min: float = 0.5
    battery_drain_idle_pct_per_min: float = 0.05
    start_pose: Pose = (0.0, 0.0, 0.0)
    pacing: str = "answer"
    before_stop: str = "ignore"

    def __post_init__(self) -> None:
        # Programmatic construction gets the same checks (and normal forms) as from_dict.
        for f in fields(self):
            value = _READERS[f.name](_plain(getattr(self, f.name)), f"robot.{f.name}")
            object.__setattr__(self, f.name, value)

    # ---- derived values in integer microseconds --------------------------------------

    @property
    def turnaround_us(self) -> int:
        return round(self.turnaround_ms * 1000)

    def point_duration_us(self, point: int) -> int:
        return round(self.point_durations_s.get(point, self.point_duration_s) * 1_000_000)

    def is_taught(self, point: int) -> bool:
        return self.taught_points is None or point in self.taught_points

    # ---- loading -----------------------------------------------------------------------

    @classmethod
    def from_dict(cls, data: Mapping[str, Any] | None, path: str = "robot") -> "RobotConfig":
        """Build a config from a TOML-style table; ConfigError names any bad key."""
        data = schema.require_mapping(data if data is not None else {}, path)
        names = [f.name for f in fields(cls)]
        schema.reject_unknown_keys(data, names, path)
        values: dict[str, Any] = {}
        for key, raw in data.items():
            values[key] = _READERS[key](raw, schema.join(path, key))
        return cls(**values)


def _plain(value: Any) -> Any:
    """A dataclass field value back in the shape from_dict accepts."""
    if isinstance(value, tuple):
        return list(value)
    if isinstance(value, Mapping):
        return {str(k): _plain(v) for k, v in value.items()}
    return value


def _seconds(raw: Any, path: str) -> float:
    return schema.as_number(raw, path, minimum=0.0)


def _positive(raw: Any, path: str) -> float:
    return schema.as_number(raw, path, strictly_positive=True)


def _stage(raw: Any, path: str) -> int:
    return schema.as_int(raw, path, minimum=0, maximum=3)


def _percent(raw: Any, path: str) -> float:
    return schema.as_number(raw, path, minimum=0.0, maximum=100.0)


def _point(raw: Any, path: str) -> int:
    return schema.as_int(raw, path, minimum=POINT_NUMBERS.start, maximum=POINT_NUMBERS.stop - 1)


def _four_speeds(raw: Any, path: str) -> Stages4:
    if not isinstance(raw, (list, tuple)) or len(raw) != 4:
        raise schema.ConfigError(path, "expected four speeds, one per stage (stage 1 to 4)")
    return tuple(_positive(v, schema.join(path, i)) for i, v in enumerate(raw))  # type: ignore[return-value]


def _pose(raw: Any, path: str) -> Pose:
    if not isinstance(raw, (list, tuple)) or len(raw) != 3:
        raise schema.ConfigError(path, "expected [x_m, y_m, heading_rad]")
    return tuple(schema.as_number(v, schema.join(path, i)) for i, v in enumerate(raw))  # type: ignore[return-value]


def _point_durations(raw: Any, path: str) -> dict[int, float]:
    table = schema.as_int_keyed(raw, path)
    return {_point(k, schema.join(path, str(k))): _seconds(v, schema.join(path, str(k)))
            for k, v in table.items()}


def _point_poses(raw: Any, path: str) -> dict[int, Pose]:
    table = schema.as_int_keyed(raw, path)
    return {_point(k, schema.join(path, str(k))): _pose(v, schema.join(path, str(k)))
            for k, v in table.items()}


def _taught(raw: Any, path: str) -> tuple[int, ...] | None:
    if raw is None:
        return None
    if raw == "all":
        return None
    if not isinstance(raw, (list, tuple)):
        raise schema.ConfigError(path, 'expected a list of point numbers 1-21, or "all"')
    return tuple(sorted({_point(v, schema.join(path, i)) for i, v in enumerate(raw)}))


_READERS = {
    "turnaround_ms": _seconds,
    "point_duration_s": _seconds,
    "point_durations_s": _point_durations,
    "taught_points": _taught,
    "point_poses": _point_poses,
    "tape_seek_s": _seconds,
    "tape_follow_s": _seconds,
    "tape_rotate_s": _seconds,
    "trackless_speeds_mps": _four_speeds,
    "magnetic_speeds_mps": _four_speeds,
    "rotation_speeds_radps": _four_speeds,
    "manual_speed_mps": _positive,
    "manual_turn_radps": _positive,
    "rotation_unit": lambda raw, path: schema.as_choice(raw, path, ROTATION_UNITS, "unit"),
    "speed_stage": _stage,
    "magnetic_speed_stage": _stage,
    "collision_range_stage": _stage,
    "battery_pct": _percent,
    "battery_low_pct": _percent,
    "battery_drain_running_pct_per_min": lambda raw, path: schema.as_number(raw, path, minimum=0.0),
    "battery_drain_idle_pct_per_min": lambda raw, path: schema.as_number(raw, path, minimum=0.0),
    "start_pose": _pose,
    "pacing": lambda raw, path: schema.as_choice(raw, path, PACING_POLICIES, "pacing policy"),
    "before_stop": lambda raw, path: schema.as_choice(raw, path, BEFORE_STOP_POLICIES, "policy"),
}
