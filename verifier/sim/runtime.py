"""The simulated CPU's run-time state: virtual clock, device memory, special relays,
operation errors and the I/O models polled between scans.

Virtual time is integer microseconds.  A scan starts at `now_us`; everything the program
does in that scan happens at that instant (the simulator does not model instruction
execution time); the next scan starts `scan_us` (+/- seeded jitter) later.  Between two
scans the I/O models (serial ports, modules) bring their state up to the new scan's start
time — the CPU's END processing.
"""
from __future__ import annotations

import random

from .cpu import TIMER_RESOLUTIONS_MS, CpuProfile
from .devices import BUFFER_WORDS, DeviceMemory
from .errors import SimDiagnostic, SimulationError
from .serial import SerialChannel


class Runtime:
    def __init__(self, cpu: CpuProfile, scan_us: int = 10_000, jitter_us: int = 0,
                 seed: int = 0, stop_on_operation_error: bool | None = None,
                 timer_resolution_ms: int = 1):
        if scan_us <= 0:
            raise ValueError("scan time must be positive")
        if type(timer_resolution_ms) is not int or timer_resolution_ms not in TIMER_RESOLUTIONS_MS:
            *others, last = map(str, TIMER_RESOLUTIONS_MS)
            raise ValueError(f"the timer resolution (timer_resolution_ms) must be {', '.join(others)} or {last} "
                             f"ms, the resolutions the CPU's timers count in; got {timer_resolution_ms!r}")
        # timers (TON/TOF/TP) read `now_ms`: virtual time in whole ticks of the resolution
        self.timer_resolution_ms = timer_resolution_ms
        self._tick_us = timer_resolution_ms * 1000
        if jitter_us < 0 or jitter_us >= scan_us:
            raise ValueError("jitter must be >= 0 and smaller than the scan time")
        self.cpu = cpu
        self.dev = DeviceMemory(cpu)
        self.scan_us = int(scan_us)
        self.jitter_us = int(jitter_us)
        self.rng = random.Random(seed)
        self.now_us = 0
        self.now_ms = 0
        self.scan_count = 0
        self.diagnostics: list[SimDiagnostic] = []
        self.locations: list[str] = []  # location id -> "file:line:col"
        self.pollers: list = []  # objects with poll(now_us), run before each scan
        # (cells, index) of every cell an instruction operand wrote, while a run skips idle
        # scans (verifier.sim.idle); None otherwise
        self.dirty_log: list | None = None
        self.after_scan: list = []  # objects with after_scan(now_us), run after each scan
        self.ports: dict[str, SerialChannel] = {}  # channel name ("fx3:1") -> byte stream
        self.keep_sent = True  # the channels log what they send (Project.keep_serial_log)
        self.buffers: dict[int, list[int]] = {}  # module start I/O -> buffer memory words
        # QJ71C24N channel -> settings for whichever module the program's G_OUTPUT/G_INPUT
        # address first (Project.configure_c24 with un=None)
        self.c24_for_program: dict[int, dict] = {}
        # (module, word) of those settings the program's own assignments wrote (U2\G310 := 1):
        # the program's value stands, as it would over a setting made in GX Works
        self.c24_written: set[tuple[int, int]] = set()
        self.origins: dict[str, str] = {}  # channel -> location of the last send-request flag write
        self.tcp_endpoint = None  # the Ethernet port's peer (verifier.link.converter.Converter)
        self.stop_on_operation_error = (cpu.stops_on_op_error if stop_on_operation_error is None
                                        else stop_on_operation_error)
        self._always_on = [self.dev.address(n) for n in cpu.always_on]
        self._always_off = [self.dev.address(n) for n in cpu.always_off]
        self._first_on = [self.dev.address(n) for n in cpu.first_scan_on]
        self._first_off = [self.dev.address(n) for n in cpu.first_scan_off]
        self._op_flags = [self.dev.address(n) for n in cpu.op_error_flags]
        self._op_code = self.dev.address(cpu.op_error_code)
        self._clocks = [(self.dev.areas[a.area], a.index, period * 500)
                        for a, period in ((self.dev.address(n), p) for n, p in cpu.clocks.items())]
        self._settable_clocks = [(self.dev.address(relay), self.dev.address(register), unit_us, n)
                                 for relay, (register, unit_us, n) in cpu.settable_clocks.items()]
        self.power_on_devices()
        self.begin_scan = self._make_begin_scan()

    def power_on_devices(self) -> None:
        """The values the CPU writes into special registers at power-on (SD414/SD415)."""
        for _, register, _, n in self._settable_clocks:
            self.dev.areas[register.area][register.index] = n

    def buffer(self, module: int) -> list[int]:
        """Buffer memory of the intelligent module at start I/O `module` (U0\\G...)."""
        buf = self.buffers.get(module)
        if buf is None:
            buf = self.buffers[module] = [0] * BUFFER_WORDS  # up to 5FFFH (QJ71E71 status area)
        return buf

    def channel(self, name: str) -> SerialChannel:
        ch = self.ports.get(name)
        if ch is None:
            ch = self.ports[name] = SerialChannel(name, self.keep_sent)
        return ch

    # ---- locations -------------------------------------------------------------
    def location_id(self, location: str) -> int:
        self.locations.append(location)
        return len(self.locations) - 1

    # ---- scan framing ------------------------------------------------------------
    def _make_begin_scan(self):
        """The per-scan special-relay updates and I/O polls as one generated function
        (called 360,000 times for an hour of 10 ms scans, so it is kept lean)."""
        lines = ["def begin_scan():", "    now = rt.now_us", "    first = rt.scan_count == 0"]
        env = {"rt": self}
        for name, addrs, value in (("on", self._always_on, "True"), ("off", self._always_off, "False"),
                                   ("fon", self._first_on, "first"), ("foff", self._first_off, "not first")):
            for i, a in enumerate(addrs):
                env[f"{name}{i}"] = self.dev.areas[a.area]
                lines.append(f"    {name}{i}[{a.index}] = {value}")
        for i, (cells, index, half_us) in enumerate(self._clocks):
            env[f"clk{i}"] = cells
            lines.append(f"    clk{i}[{index}] = now // {half_us} % 2 == 1")
        for i, (relay, register, unit_us, _) in enumerate(self._settable_clocks):
            env[f"sclk{i}"], env[f"sreg{i}"] = self.dev.areas[relay.area], self.dev.areas[register.area]
            # n < 1 is out of range: the relay keeps its state (ASSUMPTION)
            lines.append(f"    n = sreg{i}[{register.index}]")
            lines.append("    if n > 0:")
            lines.append(f"        sclk{i}[{relay.index}] = now // (n * {unit_us}) % 2 == 1")
        lines.append("    for p in rt.pollers:")
        lines.append("        p.poll(now)")
        exec("\n".join(lines), env)
        return env["begin_scan"]

    def end_scan(self) -> None:
        for p in self.after_scan:
            p.after_scan(self.now_us)
        self.scan_count += 1
        step = self.scan_us
        if self.jitter_us:
            step += self.rng.randint(-self.jitter_us, self.jitter_us)
        self.now_us += step
        self.now_ms = self.now_us // self._tick_us * self.timer_resolution_ms

    def advance_to(self, t_us: int) -> None:
        """Move the clock without scanning (the CPU in STOP, or a test skipping time)."""
        if t_us < self.now_us:
            raise ValueError("virtual time cannot go backwards")
        self.now_us = t_us
        self.now_ms = t_us // self._tick_us * self.timer_resolution_ms

    # ---- operation errors ----------------------------------------------------------
    def operation_error(self, loc_id: int | None, message: str, code: int | None = None) -> None:
        """What the CPU does on an operation error (division by zero, operand out of range):
        set SM0/M8067 (and the latched flag), store the error code, and either continue
        (FX default) or stop (Q default: 'operation error: stop' in the PLC parameters)."""
        code = self.cpu.op_error_default_code if code is None else code
        dev = self.dev
        for a in self._op_flags:
            dev.areas[a.area][a.index] = True
        dev.areas[self._op_code.area][self._op_code.index] = ((code + 0x8000) & 0xFFFF) - 0x8000
        loc = self.locations[loc_id] if loc_id is not None else None
        flags = "/".join(self.cpu.op_error_flags)
        self.diagnostics.append(SimDiagnostic(self.now_us, loc, code,
                                              f"operation error: {message} ({flags} set)"))
        if self.stop_on_operation_error:
            raise SimulationError(f"operation error: {message}; the CPU stops "
                                  f"(error code {code})", loc, self.now_us)

    def fail(self, loc_id: int | None, message: str):
        loc = self.locations[loc_id] if loc_id is not None else None
        raise SimulationError(message, loc, self.now_us)

    def warn(self, location: str | None, message: str, code: int = 0) -> None:
        self.diagnostics.append(SimDiagnostic(self.now_us, location, code, message))
