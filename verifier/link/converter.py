"""A virtual serial-to-TCP converter between the PLC's Ethernet port and the robot's line.

The robot's optional TCP route (vendor manual, 硬體組成 / 通訊說明) is a converter module
at the robot: a TCP server in transparent mode on one side, the robot's RS-485 line on
the other. The bytes are Modbus RTU frames either way (CRC included, no MBAP header).

Time is virtual (integer µs), as on :class:`verifier.link.Line`, which this class drives
on its serial side: the rules of ``uitamr verify`` (pacing, format, CRC ...) are judged
on that line's trace, the robot's side of the converter.

What is modelled (each a scenario setting, ``[converter]`` in docs/scenarios.md):

* **Connect.** An active open reaches the converter; after ``connect_us`` the PLC learns
  the result: accepted, refused (the converter answers with a reset: before
  ``refuse_until_us``, or a wrong port) or unreachable (a wrong IP address: nothing
  answers; the PLC learns it after ``unreachable_us``). One client at a time: a second
  open while one is connected is refused.
* **PLC → robot.** A TCP segment reaches the converter ``delay_us`` after the PLC sent
  it; the converter starts sending its bytes on the line then (back to back).
* **Robot → PLC.** The converter collects the robot's bytes and forwards them once the
  line has been silent for ``pack_us`` (its packing interval); they reach the PLC
  ``delay_us`` later, as one TCP segment - or, with ``split_reply``, as two segments
  ``split_gap_us`` apart (a reply split across TCP segments).
* **Drop.** For each time in ``drops``: the converter forwards the first request it gets
  at or after that time to the robot and then closes the connection (mid-transaction).
  The PLC sees the close ``delay_us`` later; the robot's reply is lost.
* **Close.** The PLC may close at any time; bytes still under way are dropped.

ASSUMPTION (not in the vendor manual, which names no converter model): a transparent
converter packs serial bytes by silence and forwards TCP data at once; the delays are
scenario settings because they depend on the module (docs/tcp-converter.md).
"""
from __future__ import annotations

from collections import deque
from dataclasses import dataclass, replace

from verifier.link.line import Line
from verifier.link.trace import LineEvent
from verifier.protocol.codec import hex_bytes

_NEVER = float("inf")


@dataclass(frozen=True)
class ConverterConfig:
    ip: str = "192.168.3.50"
    port: int = 4001
    delay_us: int = 2_000
    connect_us: int = 1_000
    pack_us: int = 5_000
    refuse_until_us: int = 0
    unreachable_us: int = 3_000_000
    drops: tuple[int, ...] = ()
    split_reply: bool = False
    split_gap_us: int = 20_000
    # listen wherever the PLC opens (ip and port unused): a run whose converter was not
    # written for the program's constants (a bundled scenario under --matrix, the run
    # without a scenario file) tests the program, not its converter address
    any_address: bool = False

    def describe(self) -> str:
        where = "at the address the program opens" if self.any_address else f"{self.ip}:{self.port}"
        parts = [f"converter {where}", f"delay {self.delay_us / 1000:g} ms",
                 f"packing {self.pack_us / 1000:g} ms"]
        if self.refuse_until_us:
            parts.append(f"refuses connections before {self.refuse_until_us / 1e6:g} s")
        if self.drops:
            parts.append("drops the connection at " + ", ".join(f"{t / 1e6:g} s" for t in self.drops))
        if self.split_reply:
            parts.append(f"replies in two TCP segments {self.split_gap_us / 1000:g} ms apart")
        return ", ".join(parts)


@dataclass(frozen=True)
class OpenResult:
    """What an active open comes to: `ok`, and when the PLC learns it."""

    ok: bool
    done_us: int
    reason: str  # "" | "refused" | "unreachable" | "busy"
    connection: int  # connection number at the converter (0 when not accepted)


class Converter:
    """The converter as the PLC's TCP endpoint; drives `line` on the robot's side."""

    def __init__(self, line: Line, config: ConverterConfig | None = None) -> None:
        self.line = line
        self.config = config if config is not None else ConverterConfig()
        self.events: list[LineEvent] = []
        self.event_count = 0  # events made so far (a run judged as it goes may drop old ones)
        self.connection = 0  # current accepted connection (0: none)
        self.open_count = 0  # opens the PLC tried
        self.first_failed_open: str | None = None  # why the first open that failed did (for a silent run's note)
        self._count = 0
        self._closed_at: dict[int, int] = {}  # connection the converter dropped -> when the PLC learns it
        self._to_line: deque[tuple[int, int, bytes, str | None]] = deque()  # (t, connection, data, origin)
        self._serial: list[tuple[int, int]] = []  # robot bytes not yet forwarded: (value, t)
        self._to_plc: deque[tuple[int, bytes]] = deque()  # (arrival t at the PLC, segment)
        self._drops = sorted(self.config.drops)
        self.now_us = 0

    @property
    def accepted_count(self) -> int:
        """Connections the converter has accepted so far."""
        return self._count

    # ---- the PLC's side ------------------------------------------------------------------

    def open(self, t_us: int, ip: str, port: int) -> OpenResult:
        """An active open from the PLC at `t_us` to ip:port."""
        self._work_until(t_us)
        self.open_count += 1
        cfg = self.config
        done = t_us + cfg.connect_us
        target = f"{ip}:{port}"
        if cfg.any_address:
            cfg = replace(cfg, ip=ip, port=port)
        if ip != cfg.ip:
            self._event(t_us, "converter.unreachable",
                        f"the PLC opens a connection to {target}: nothing answers there (the converter is at "
                        f"{cfg.ip}:{cfg.port})")
            return OpenResult(False, t_us + cfg.unreachable_us, "unreachable", 0)
        if port != cfg.port:
            self._event(t_us, "converter.refused",
                        f"the PLC opens a connection to {target}: refused, the converter listens at {cfg.ip}:{cfg.port}")
            return OpenResult(False, done, "refused", 0)
        if t_us < cfg.refuse_until_us:
            self._event(t_us, "converter.refused",
                        f"the converter refuses the PLC's connection (scenario: refuse_until "
                        f"{cfg.refuse_until_us / 1e6:g} s)")
            return OpenResult(False, done, "refused", 0)
        if self.connection:
            self._event(t_us, "converter.refused",
                        "the converter refuses a second connection: it serves one client and one is connected")
            return OpenResult(False, done, "busy", 0)
        self._count += 1
        self.connection = self._count
        self._to_plc.clear()
        self._event(t_us, "converter.accepted", f"the converter accepts connection {self.connection} from the PLC")
        return OpenResult(True, done, "", self.connection)

    def send(self, t_us: int, connection: int, data: bytes, origin: str | None = None) -> bool:
        """The PLC sends `data` on `connection` at `t_us`; False if that connection is gone."""
        self._work_until(t_us)
        if connection != self.connection or connection == 0:
            return False
        arrive = t_us + self.config.delay_us
        if self._to_line and self._to_line[-1][0] > arrive:
            arrive = self._to_line[-1][0]  # TCP keeps the order
        self._to_line.append((arrive, connection, bytes(data), origin))
        return True

    def receive_until(self, t_us: int, connection: int) -> list[tuple[int, bytes]]:
        """TCP segments of `connection` that reached the PLC by `t_us`: [(t, bytes)]."""
        self._work_until(t_us)
        if connection != self.connection or connection == 0:
            return []
        out = []
        while self._to_plc and self._to_plc[0][0] <= t_us:
            out.append(self._to_plc.popleft())
        return out

    def peer_closed(self, t_us: int, connection: int) -> bool:
        """Has the PLC learnt by `t_us` that the converter closed `connection`?"""
        self._work_until(t_us)
        if connection == 0:
            return False
        if connection in self._closed_at:
            return self._closed_at[connection] <= t_us
        return connection != self.connection

    def close(self, t_us: int, connection: int) -> None:
        """The PLC closes `connection` (whatever is under way to the PLC is dropped)."""
        self._work_until(t_us)
        if connection and connection == self.connection:
            self._event(t_us, "converter.closed", f"the PLC closes connection {connection}")
            self._end_connection()

    # ---- idle-scan skipping (verifier.sim.idle) -------------------------------------------

    def quiet_until(self, connection: int) -> int | float:
        """Before this time nothing happens for `connection`: for ``now_us <= t <`` it,
        ``receive_until(t, connection)`` returns no segment, ``peer_closed(t, connection)``
        returns False, and both only move the clocks (``now_us``, the line's ``now_us``).
        ``now_us`` (no quiet time at all) when the close is already known."""
        first = self.line.quiet_until_us  # Line: a call before it only moves the line's clock
        if self._to_line:
            first = min(first, self._to_line[0][0])  # a segment reaches the converter
        if self._serial:  # what _pack left: one group, forwarded pack_us after its last byte
            first = min(first, self._serial[-1][1] + self.config.pack_us)
        if connection and connection == self.connection and self._to_plc:
            first = min(first, self._to_plc[0][0])  # a segment reaches the PLC
        if connection in self._closed_at:
            first = min(first, self._closed_at[connection])
        elif connection and connection != self.connection:
            return self.now_us  # peer_closed is True already
        return max(first, self.now_us)

    def idle_state(self) -> tuple:
        """What the PLC's calls change here (compared between scans; nothing counts them)."""
        return (self.connection, self._count, len(self._to_line), len(self._serial), len(self._to_plc),
                len(self._closed_at), len(self._drops), self.event_count)

    # ---- the converter's work ------------------------------------------------------------

    def advance(self, t_us: int) -> None:
        """Work out everything up to `t_us` (the end of a run)."""
        self._work_until(t_us)
        self.line.advance(max(t_us, self.line.now_us))

    def _work_until(self, t_us: int) -> None:
        if t_us == self.now_us and not (self._to_line and self._to_line[0][0] <= t_us):
            return  # worked out to this instant already (the PLC's calls of one scan share it)
        if t_us < self.now_us:
            raise ValueError(f"converter at {t_us} µs: already at {self.now_us} µs (virtual time only moves forward)")
        line = self.line
        while self._to_line and self._to_line[0][0] <= t_us:
            t, connection, data, origin = self._to_line.popleft()
            if connection != self.connection:
                continue  # sent on a connection that is gone
            self._serial.extend(line.receive_until(max(t, line.now_us)))
            line.send(data, max(t, line.now_us), origin)
            if self._drops and self._drops[0] <= t:
                while self._drops and self._drops[0] <= t:
                    self._drops.pop(0)
                self._event(t, "converter.dropped",
                            f"the converter forwards {hex_bytes(data)} to the robot and drops connection "
                            f"{connection} (scenario: drops)", (data,))
                self._closed_at[connection] = t + self.config.delay_us
                self._end_connection()
        if t_us > line.now_us:
            self._serial.extend(line.receive_until(t_us))
        self._pack(t_us)
        self.now_us = t_us

    def _pack(self, t_us: int) -> None:
        """Forward robot bytes once the line has been quiet for the packing interval."""
        serial = self._serial
        if not serial:
            return
        pack = self.config.pack_us
        start = 0
        for k in range(1, len(serial) + 1):
            last_t = serial[k - 1][1]
            if k < len(serial) and serial[k][1] - last_t <= pack:
                continue
            if k == len(serial) and t_us - last_t < pack:
                break
            self._forward(bytes(v for v, _ in serial[start:k]), last_t + pack)
            start = k
        del serial[:start]

    def _forward(self, data: bytes, t_us: int) -> None:
        if not self.connection:
            self._event(t_us, "converter.lost",
                        f"robot bytes {hex_bytes(data)} reach the converter with no connection open: lost", (data,))
            return
        arrive = t_us + self.config.delay_us
        if self.config.split_reply and len(data) > 1:
            half = len(data) // 2
            self._to_plc.append((arrive, data[:half]))
            self._to_plc.append((arrive + self.config.split_gap_us, data[half:]))
            self._event(t_us, "converter.split",
                        f"the converter forwards {hex_bytes(data)} in two TCP segments "
                        f"{self.config.split_gap_us / 1000:g} ms apart (scenario: split_reply)", (data,))
        else:
            self._to_plc.append((arrive, data))

    def _end_connection(self) -> None:
        self.connection = 0
        self._to_plc.clear()
        self._to_line.clear()

    def _event(self, t_us: int, kind: str, message: str, frames: tuple[bytes, ...] = ()) -> None:
        if kind in ("converter.unreachable", "converter.refused") and self.first_failed_open is None:
            self.first_failed_open = message
        self.events.append(LineEvent(t_us, kind, message, frames))
        self.event_count += 1
