"""RS2 — non-protocol serial send/receive, FX3U/FX3G (FNC 87) and FX5.

ST call (docs/st-dialect.md): `RS2(EN, s, m, n, n1, d)` — s send head, m bytes to send, n
bytes to receive, n1 channel, d receive head.  Behaviour and devices: docs/instructions.md
("RS2"), each with its manual page or marked ASSUMPTION.
"""
from __future__ import annotations

from ..refs import operand_key
from ..rs2_devices import Rs2Devices
from ..serial import ROBOT_LINE, LineFormat, SerialChannel


_FX3_BAUD = {0b0011: 300, 0b0100: 600, 0b0101: 1200, 0b0110: 2400, 0b0111: 4800,
             0b1000: 9600, 0b1001: 19200, 0b1010: 38400, 0b1011: 57600, 0b1101: 115200}


def decode_fx3_format(word: int) -> tuple[LineFormat | None, list[str]]:
    """D8400/D8420 communication format -> line format, plus what the simulator does not
    model (headers, terminators, sum check, protocol mode)."""
    w = word & 0xFFFF
    problems = []
    baud = _FX3_BAUD.get((w >> 4) & 0xF)
    if baud is None:
        problems.append(f"baud code {(w >> 4) & 0xF:04b}B in b7..b4 is not a valid rate")
    parity = {0b00: "N", 0b01: "O", 0b11: "E"}.get((w >> 1) & 0b11)
    if parity is None:
        problems.append("parity bits b2,b1 = 10 are not valid")
    if w & (1 << 8):
        problems.append("b8 header is set: headers are not modelled")
    if w & (1 << 9):
        problems.append("b9 terminator is set: terminators are not modelled")
    if w & (1 << 13):
        problems.append("b13 sum check is set: sum check is not modelled")
    if w & (1 << 14):
        problems.append("b14 is set: that selects the protocol mode, not non-protocol (RS2)")
    if baud is None or parity is None:
        return None, problems
    fmt = LineFormat(baud=baud, data_bits=8 if w & 1 else 7, parity=parity,
                     stop_bits=2 if w & (1 << 3) else 1)
    return fmt, problems


class Rs2Port:
    """One RS2 channel: send on the send-request flag, receive until n bytes or time-out."""

    def __init__(self, rt, channel: SerialChannel, devices: Rs2Devices, family: str):
        self.rt = rt
        self.channel = channel
        self.family = family
        dev = rt.dev
        self.d = devices
        self._send_req = dev.address(devices.send_request)
        # the send-request flag is read on every call: its cell list and index, held
        self._send_req_cells, self._send_req_index = dev.areas[self._send_req.area], self._send_req.index
        self._recv_done = dev.address(devices.receive_complete)
        self._timeout_flag = dev.address(devices.timeout_flag)
        self._send_remaining = dev.address(devices.send_remaining)
        self._recv_count = dev.address(devices.receive_count)
        self._timeout = dev.address(devices.timeout_setting)
        self._eight_bit = dev.address(devices.eight_bit_mode) if devices.eight_bit_mode else None
        self._format = dev.address(devices.format_register) if devices.format_register else None
        self.last_call_scan = -2
        self.call_location: str | None = None
        self.s_ref = self.d_ref = None
        self.m = self.n = 0
        self.sending_until: int | None = None
        self.send_started = 0
        self.send_len = 0
        self.rx = bytearray()
        self.rx_last_t = 0
        self.rx_done = False
        # when the program last reset the receive-complete flag after a reception (None: never):
        # bytes dropped while it is ON may then be ones right after a reply, not a missing reset
        self.rearmed_at: int | None = None
        self.reported_format: int | None = None
        rt.pollers.append(self)

    # -- helpers -----------------------------------------------------------------------
    def _get(self, a):
        return self.rt.dev.areas[a.area][a.index]

    def _set(self, a, v):
        self.rt.dev.areas[a.area][a.index] = v

    def timeout_us(self) -> int:
        raw = self._get(self._timeout)
        if self.d.timeout_unit_ms == 10:  # FX3: 10 ms units, 0 = 100 ms (ASSUMPTION: as D8129)
            return (raw * 10 if raw > 0 else 100) * 1000
        return (raw if 1 <= raw <= 32767 else 10) * 1000  # FX5: ms, out of range = 10 ms

    def eight_bit(self) -> bool:
        return bool(self._eight_bit and self._get(self._eight_bit) == 1)

    def _check_format(self, location: str) -> None:
        if self._format is None:
            return
        word = self._get(self._format) & 0xFFFF
        if word == self.reported_format:
            return
        self.reported_format = word
        fmt, problems = decode_fx3_format(word)
        if fmt is not None:
            self.channel.format = fmt
        if fmt is None or problems or fmt != ROBOT_LINE:
            what = "; ".join(problems) if problems else f"it selects {fmt}"
            self.rt.warn(location, f"RS2 {self.channel.name}: communication format "
                                   f"{self.d.format_register}=H{word:04X}: {what} "
                                   "(the robot's line is 9600 8N1: H1C81 or H0C81 on RS-485, "
                                   "H0081 on its RS-232 route, docs/wiring-rs232.md)")

    # -- the instruction ---------------------------------------------------------------
    def call(self, en: bool, s_ref, m: int, n: int, d_ref, loc_id: int) -> bool:
        if not en:
            return False
        rt = self.rt
        self.last_call_scan = rt.scan_count
        self.call_location = rt.locations[loc_id]  # where a reception's trouble is reported
        self.s_ref, self.m, self.n, self.d_ref = s_ref, m, n, d_ref
        if self.sending_until is None and self._send_req_cells[self._send_req_index]:
            location = rt.locations[loc_id]
            self._check_format(location)
            if not 0 <= m <= 4096:
                rt.operation_error(loc_id, f"RS2 send count m={m} out of range")
                return True
            data = s_ref.get_low_bytes(m) if self.eight_bit() else s_ref.get_bytes(m)
            origin = rt.origins.get(self.channel.name) or location
            self.send_started = rt.now_us
            self.send_len = m
            self.sending_until = self.channel.transmit(data, rt.now_us, origin)
            self._set(self._send_remaining, m)
        return True

    # -- between scans (END processing) --------------------------------------------------
    def poll(self, now: int) -> None:
        """Called before every scan: kept lean for the common case of a quiet line."""
        if self.sending_until is not None:
            self._poll_send(now)
        if self.rx_done and not self._get(self._recv_done):
            # the program reset the receive-complete flag: the count is cleared with it
            self.rx_done = False
            self.rearmed_at = now
            self.rx.clear()
            self._set(self._recv_count, 0)
        got = self.channel.receive_until(now)
        if got:
            self._take(got, now)
        elif self.rx and not self.rx_done and now - self.rx_last_t >= self.timeout_us():
            self._complete(timed_out=True)
            self._set(self._recv_count, len(self.rx))

    # -- idle-scan skipping (verifier.sim.idle) -------------------------------------------
    def idle_deadline(self, now: int) -> float | None:
        """The first instant `poll` can change anything, or None when it may at `now`
        (sending: the remaining count moves on every scan)."""
        if self.sending_until is not None or (self.rx_done and not self._get(self._recv_done)):
            return None
        deadline = self.channel.quiet_until(now)
        if deadline is None:
            return None
        if self.rx and not self.rx_done:
            deadline = min(deadline, self.rx_last_t + self.timeout_us())
        return deadline

    def idle_state(self) -> tuple:
        """Everything `call` and `poll` change, the scan of the last call relative to now."""
        return (self.last_call_scan - self.rt.scan_count, operand_key(self.s_ref), operand_key(self.d_ref),
                self.m, self.n, self.sending_until,
                self.send_started, self.send_len, bytes(self.rx), self.rx_last_t, self.rx_done, self.rearmed_at,
                self.reported_format, self.channel.sent_count)

    def skipped(self, scan_count: int, scans: int) -> None:
        """`scans` idle scans after scan `scan_count` - 1 were skipped: one that called RS2
        called it in each of them."""
        if self.last_call_scan == scan_count - 1:
            self.last_call_scan += scans

    def _poll_send(self, now: int) -> None:
        if now >= self.sending_until:
            self.sending_until = None
            self._set(self._send_req, False)
            self._set(self._send_remaining, 0)
        else:
            sent = int((now - self.send_started) / self.channel.format.byte_time_us)
            self._set(self._send_remaining, max(self.send_len - sent, 0))

    def _take(self, got, now: int) -> None:
        driven = self.last_call_scan >= self.rt.scan_count - 1
        timeout = self.timeout_us()
        dropped = 0
        for value, t in got:
            if self.rx and not self.rx_done and t - self.rx_last_t > timeout:
                self._complete(timed_out=True)
            if not driven or self.rx_done or self.n <= 0:
                dropped += 1
                continue
            self.rx.append(value)
            self.rx_last_t = t
            if len(self.rx) >= self.n:
                self._complete(timed_out=False)
        if self.rx and not self.rx_done and now - self.rx_last_t >= timeout:
            self._complete(timed_out=True)
        self._set(self._recv_count, len(self.rx))
        if dropped:
            flag = self.d.receive_complete
            if not driven:
                why = "RS2 was not executed"
            elif self.rx_done and self.rearmed_at is not None:
                # when the program last reset the flag, not a guess whether it still does: a
                # program that re-armed once and then stopped reads the old time here
                why = (f"they came while {flag} was ON after a complete reception, before the program reset it: "
                       "bytes right after a complete reply (a late reply, noise) are lost so, as on the CPU; "
                       f"the program last reset {flag} at {self.rearmed_at / 1e6:.3f} s: if it resets it after "
                       "every reception, the receptions after them go on; if not, reset it once the received "
                       "data is read (docs/instructions.md §7)")
            elif self.rx_done:
                why = (f"{flag} was still ON: reset {flag} (receive complete) once the received data "
                       "is read, or RS2 receives nothing more (docs/instructions.md §7)")
            else:
                why = "n = 0"
            self.rt.warn(self.call_location, f"RS2 {self.channel.name}: {dropped} received byte(s) discarded "
                                             f"because {why}")

    def _complete(self, timed_out: bool) -> None:
        data = bytes(self.rx[: self.n])
        if self.d_ref is not None:
            if self.eight_bit():
                self.d_ref.put_low_bytes(data)
            else:
                self.d_ref.put_bytes(data)
        self.rx_done = True
        self._set(self._recv_done, True)
        if timed_out:
            self._set(self._timeout_flag, True)
