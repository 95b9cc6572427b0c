"""What the virtual line records: every frame both ways, and what went wrong on it."""
from __future__ import annotations

from dataclasses import dataclass

TX = "tx"  # PLC -> robot
RX = "rx"  # robot -> PLC


@dataclass(frozen=True, slots=True)
class TraceFrame:
    """One frame on the wire, seen from the PLC: ``tx`` = PLC to robot, ``rx`` = robot to PLC.

    ``t_start_us`` is when its first byte's start bit began, ``t_end_us`` when its last
    byte's stop bit ended. ``origin`` is the ST location ("file:line:col") whose
    instruction sent it (tx frames only).
    """

    t_start_us: int
    t_end_us: int
    direction: str
    data: bytes
    origin: str | None = None

    @property
    def hex(self) -> str:
        return " ".join(f"{b:02X}" for b in self.data)


@dataclass(frozen=True)
class LineEvent:
    """Something that happened on the line (or, ``robot.*`` kinds, in the robot).

    Line kinds: ``collision`` (both sides transmitted at once; ``frames`` = (PLC bytes,
    robot bytes)), ``gap`` (a silence over t1.5 inside a frame), ``discarded`` (a frame
    the robot's receiver threw away, with the reason; ``frames`` = (its bytes,)).
    Robot kinds are the robot's own event kinds prefixed with ``robot.``.
    """

    t_us: int
    kind: str
    message: str
    frames: tuple[bytes, ...] = ()
