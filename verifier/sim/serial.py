"""The byte stream at the end of every serial instruction model.

A `SerialChannel` is one physical port of the simulated PLC ("fx3:1", "q:2", ...).  Bytes
the PLC sends go to the attached endpoint (the ROBOT engineer's `verifier.link.Line`, or
any object with the same master interface: `send(data, t_us, origin)` and
`receive_until(t_us) -> [(byte, arrival_t_us), ...]`; optionally `now_us` and
`quiet_until_us`, see `SerialChannel.attach`) and are logged with their times. An
endpoint with `accepts_unreadable` (the Line) is told when the port sends at a line format
the robot's 9600 8N1 receiver cannot read (`send(..., unreadable=why)`, `LineFormat.read_at`).
With no endpoint attached the line is silent: what is sent is only logged.
"""
from __future__ import annotations

from dataclasses import dataclass
from fractions import Fraction


@dataclass(frozen=True, slots=True)
class SentFrame:
    t_start_us: int
    t_end_us: int
    data: bytes
    origin: str | None


@dataclass(frozen=True)
class LineFormat:
    baud: int = 9600
    data_bits: int = 8
    parity: str = "N"  # "N" | "O" | "E"
    stop_bits: int = 1

    @property
    def bits_per_byte(self) -> int:
        return 1 + self.data_bits + (0 if self.parity == "N" else 1) + self.stop_bits

    @property
    def byte_time_us(self) -> Fraction:
        return Fraction(self.bits_per_byte * 1_000_000, self.baud)

    def duration_us(self, n_bytes: int) -> int:
        """Time n back-to-back characters take, rounded to the nearest µs (no drift)."""
        return (n_bytes * self.bits_per_byte * 1_000_000 + self.baud // 2) // self.baud

    def read_at(self, receiver: "LineFormat") -> bool:
        """Whether a UART set to `receiver` reads what is sent at this format: the same
        speed, data bits and parity. A receiver checks one stop bit, so more stop bits than
        it expects are only a longer idle before the next start bit (8N2 reads as 8N1)."""
        return ((self.baud, self.data_bits, self.parity) == (receiver.baud, receiver.data_bits, receiver.parity)
                and self.stop_bits >= receiver.stop_bits)

    def __str__(self) -> str:
        return f"{self.baud} {self.data_bits}{self.parity}{self.stop_bits}"


NINE_SIX_8N1 = LineFormat()
ROBOT_LINE = NINE_SIX_8N1  # the robot's port (its manual: 9600 8N1)


class SerialChannel:
    def __init__(self, name: str, keep_sent: bool = True):
        self.name = name
        self.endpoint = None
        self.knows_quiet = False
        self.format = NINE_SIX_8N1
        # every frame sent, for `Project.serial_log`; a run whose line records the traffic
        # itself (uitamr verify) does not keep a second copy (`keep_sent` False)
        self.keep_sent = keep_sent
        self.sent: list[SentFrame] = []
        self.sent_count = 0

    def attach(self, endpoint) -> None:
        for attr in ("send", "receive_until"):
            if not callable(getattr(endpoint, attr, None)):
                raise TypeError(f"serial endpoint for {self.name} needs a {attr}() method "
                                "(the verifier.link.Line master interface)")
        if self.endpoint is not None and self.endpoint is not endpoint:
            # replacing it would leave the first line deaf from here on (a fixture's line
            # that never hears a frame), and lose a frame half sent on it
            raise ValueError(f"channel {self.name} is already attached to a {type(self.endpoint).__name__}; a channel "
                             "has one line: load the project again (verifier.load) to attach another")
        self.endpoint = endpoint
        # an endpoint with `quiet_until_us` and `now_us` (verifier.link.Line) promises that
        # receive_until(t) for now_us <= t < quiet_until_us only sets now_us = t: the port
        # does that itself then, without the call on every scan
        self.knows_quiet = hasattr(endpoint, "quiet_until_us") and hasattr(endpoint, "now_us")

    def transmit(self, data: bytes, t_us: int, origin: str | None) -> int:
        """Start sending `data` at t_us; returns the time the last stop bit is out."""
        data = bytes(data)
        end = t_us + self.format.duration_us(len(data))
        if self.endpoint is not None and data:
            if not self.format.read_at(ROBOT_LINE) and getattr(self.endpoint, "accepts_unreadable", False):
                # the robot's UART reads framing errors or other bytes: it discards the frame
                self.endpoint.send(data, t_us, origin, unreadable=f"sent at {self.format}, the robot's line runs "
                                                                  f"at {ROBOT_LINE}: its receiver cannot read it")
            else:
                self.endpoint.send(data, t_us, origin)
        if self.keep_sent:
            self.sent.append(SentFrame(t_us, end, data, origin))
        self.sent_count += 1
        return end

    def quiet_until(self, now: int) -> float | None:
        """Until when `receive_until` brings nothing (idle-scan skipping, verifier.sim.idle):
        the line's quiet time, infinity with nothing attached, None when not known quiet at
        `now`."""
        endpoint = self.endpoint
        if endpoint is None:
            return float("inf")
        if self.knows_quiet and endpoint.now_us <= now < endpoint.quiet_until_us:
            return endpoint.quiet_until_us
        return None

    def receive_until(self, t_us: int) -> list[tuple[int, int]]:
        endpoint = self.endpoint
        if endpoint is None:
            return ()
        if self.knows_quiet and endpoint.now_us <= t_us < endpoint.quiet_until_us:
            endpoint.now_us = t_us  # all a call would do on a quiet line (Line.quiet_until_us)
            return ()
        return endpoint.receive_until(t_us)
