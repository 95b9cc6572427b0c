"""ADPRW — MODBUS RTU master (FX3U-485ADP-MB on FX3U/FX3G; FX5 built-in RS-485 / FX5-485
with the MODBUS master parameters).

ST calls (docs/st-dialect.md): FX3 `ADPRW(EN, s, s1, s2, s3, s4d)`, FX5
`ADPRW(EN, s, s1, s2, s3, s4d1, d2)` — s slave address, s1 function code, s2 MODBUS
address, s3 count, s4d data head, d2 completion bits (d2[0] done, d2[1] error).
Modelled function codes: 01 (read coils) and 06 (write single register), the two the
robot uses.  Frames are built and checked with verifier.protocol (CRC-16/MODBUS).
Behaviour, devices and ASSUMPTIONs: docs/instructions.md ("ADPRW").
"""
from __future__ import annotations

from verifier.protocol import crc_ok, with_crc

from ..refs import operand_key, pulse_keys
from ..rs2_devices import FX3_MODBUS_CHANNELS

# FX5 (SD8500): simulator error codes (ASSUMPTION: the FX5 manual's codes are not modelled)
ERR_TIMEOUT = 1
ERR_CRC = 2
ERR_FRAME = 3
ERR_FUNCTION = 4
ERR_EXCEPTION = 0x100  # + MODBUS exception code

# FX3 (D8402/D8422 code, D8403/D8423 details): FX3U MODBUS Serial Communication Edition
# §12.6 "MODBUS Error Code List" (manual pages 106-108); read as decimal, as the list's own
# cross reference "Error Code 207" reads (docs/instructions.md, ADPRW)
FX3_ERR_CRC = 205             # CRC/LRC error
FX3_ERR_LENGTH = 207          # data length mismatch (byte count)
FX3_ERR_TIMEOUT = 211         # communication time-out after the set retries
FX3_ERR_EXCEPTION = 212       # exception response; details H: abnormal function code, L: exception code
FX3_ERR_SLAVE = 213           # slave address mismatch; details H: requested, L: received
FX3_ERR_FUNCTION = 214        # function code mismatch; details H: requested, L: received


FX5_RESPONSE_TIMEOUT_US = 400_000  # "Slave Response Timeout 400 ms" (docs/import-gxworks3.md §4)


class AdprwMaster:
    """One MODBUS master channel: one transaction at a time."""

    def __init__(self, rt, channel: int = 1):
        self.rt = rt
        self.family = rt.cpu.family
        self.port = rt.channel(f"adp:{channel}")
        dev = rt.dev
        if self.family == "fx3":
            # D8409 slave response time-out ms (0 = 3 s), D8412 retries (MODBUS manual p.33/34)
            devices = FX3_MODBUS_CHANNELS[channel]
            self._timeout = dev.address(devices.response_timeout)
            self._retries = dev.address(devices.retries)
            self._err_code = dev.address(devices.error_code)
            self._err_flag = dev.address(devices.error_flag)
            self._err_details = dev.address(devices.error_details)
            self._serial_err = dev.address(devices.serial_error)
            self._serial_err_code = devices.serial_error_code
            self._err_code_flag = dev.address(devices.code_flag)
            self._err_details_flag = dev.address(devices.details_flag)
            self._done_flag = dev.address("M8029")
        else:
            self._timeout = self._retries = None
            self._err_code = dev.address("SD8500")
            self._err_details = self._serial_err = None
            self._err_flag = None
            self._done_flag = None
        self.busy = False
        self.completed = False  # a transaction ended and its execution has not reported it yet
        self.request = b""
        self.expect = 0
        self.deadline = 0
        self.attempts_left = 0
        self.rx = bytearray()
        self.job = None  # (fc, count, data ref, d2 ref)
        self.pulses: list = []
        self.pending: list = []
        rt.pollers.append(self)

    def _get(self, a):
        return self.rt.dev.areas[a.area][a.index]

    def _set(self, a, v):
        self.rt.dev.areas[a.area][a.index] = v

    def timeout_us(self) -> int:
        if self._timeout is None:
            # FX5: a module parameter, not a device: the 400 ms docs/import-gxworks3.md §4 has
            # the integrator set (less than the engine's 500 ms reply time-out, 0 retries)
            return FX5_RESPONSE_TIMEOUT_US
        raw = self._get(self._timeout)
        return (raw if raw > 0 else 3000) * 1000

    # -- the instruction ---------------------------------------------------------------
    def call(self, en, slave, fc, addr, count, data, d2, loc_id) -> bool:
        if not en:
            return False
        reported = self.completed
        self.completed = False
        if self._done_flag is not None:
            # FX3: the execution that reports the completion turns M8029 ON, others OFF
            self._set(self._done_flag, reported)
        if self.busy or reported:
            return True  # a finished transaction is reported; the next execution starts anew
        location = self.rt.locations[loc_id]
        if fc == 1:
            if not 1 <= count <= 2000:
                return self._fail_now(d2, ERR_FRAME, location, f"ADPRW FC01 count {count} is outside 1..2000")
            body = bytes([slave & 0xFF, 1, (addr >> 8) & 0xFF, addr & 0xFF, (count >> 8) & 0xFF, count & 0xFF])
            self.expect = 5 + (count + 7) // 8
        elif fc == 6:
            value = data.get_u16(0)
            body = bytes([slave & 0xFF, 6, (addr >> 8) & 0xFF, addr & 0xFF, value >> 8, value & 0xFF])
            self.expect = 8
        else:
            return self._fail_now(d2, ERR_FUNCTION, location,
                                  f"ADPRW function code {fc} is not modelled (01 and 06 are)")
        self.request = with_crc(body)
        self.job = (fc, count, data, d2)
        self.busy = True
        self.attempts_left = (max(0, min(self._get(self._retries), 20)) if self._retries else 0) + 1
        self._send(location)
        return True

    def _send(self, origin) -> None:
        self.rx.clear()
        self.attempts_left -= 1
        end = self.port.transmit(self.request, self.rt.now_us, origin)
        self.deadline = end + self.timeout_us()

    def _fail_now(self, d2, code, location, message) -> bool:
        self.rt.warn(location, message)
        self.job = (0, 0, None, d2)
        self._complete(code, in_scan=True)
        return True

    # -- between scans -------------------------------------------------------------------
    def _flag(self, ref, bit, value: bool) -> None:
        if ref is None:
            self._set(bit, value)  # a special relay (M8029)
        else:
            ref.set(bit, value)

    def poll(self, now: int) -> None:
        for ref, bit in self.pulses:
            self._flag(ref, bit, False)
        self.pulses, self.pending = self.pending, []
        for ref, bit in self.pulses:
            self._flag(ref, bit, True)
        if not self.busy:
            self.port.receive_until(now)  # nothing is expected: stray bytes are dropped
            return
        for value, _t in self.port.receive_until(now):
            self.rx.append(value)
            if len(self.rx) >= 2 and self.rx[1] & 0x80 and len(self.rx) >= 5:
                self._reply()
                return
            if len(self.rx) >= self.expect:
                self._reply()
                return
        if now >= self.deadline:
            if self.attempts_left > 0:
                self._send(None)
            else:
                self._complete(FX3_ERR_TIMEOUT if self.family == "fx3" else ERR_TIMEOUT)

    # -- idle-scan skipping (verifier.sim.idle) -------------------------------------------
    def idle_deadline(self, now: int) -> float | None:
        """The first instant `poll` can change anything, or None when it may at `now` (a
        completion bit to turn ON or OFF, a line with something under way)."""
        if self.pulses or self.pending:
            return None
        deadline = self.port.quiet_until(now)
        if deadline is None:
            return None
        if self.busy:
            deadline = min(deadline, self.deadline)  # the slave response time-out (or a retry)
        return deadline

    def idle_state(self) -> tuple:
        """Everything `call` and `poll` change (nothing counts scans)."""
        fc, count, data, d2 = self.job if self.job is not None else (None, None, None, None)
        return (self.busy, self.completed, self.request, self.expect, self.deadline, self.attempts_left,
                bytes(self.rx), fc, count, operand_key(data), operand_key(d2),
                pulse_keys(self.pulses), pulse_keys(self.pending), self.port.sent_count)

    def skipped(self, scan_count: int, scans: int) -> None:
        """Nothing here depends on the scan count."""

    def _reply(self) -> None:
        frame = bytes(self.rx)
        fc, count, data, _ = self.job
        fx3 = self.family == "fx3"
        if not crc_ok(frame):
            self._complete(FX3_ERR_CRC if fx3 else ERR_CRC)
        elif frame[0] != self.request[0]:
            self._complete(FX3_ERR_SLAVE if fx3 else ERR_FRAME, self.request[0] << 8 | frame[0])
        elif frame[1] & 0x7F != fc:
            self._complete(FX3_ERR_FUNCTION if fx3 else ERR_FRAME, fc << 8 | frame[1] & 0x7F)
        elif frame[1] & 0x80:
            if fx3:
                self._complete(FX3_ERR_EXCEPTION, frame[1] << 8 | frame[2])
            else:
                self._complete(ERR_EXCEPTION + frame[2])
        elif fc == 1 and frame[2] != (count + 7) // 8:
            self._complete(FX3_ERR_LENGTH if fx3 else ERR_FRAME, frame[2])
        else:
            if fc == 1:
                # coils packed 16 per word, the first coil in bit 0 (ASSUMPTION)
                bits = int.from_bytes(frame[3:3 + frame[2]], "little")
                for k in range((count + 15) // 16):
                    data.set(k, (bits >> (16 * k)) & 0xFFFF & ((1 << min(16, count - 16 * k)) - 1))
            self._complete(0)

    def _complete(self, error: int, details: int = 0, in_scan: bool = False) -> None:
        """FX5 completion bits go ON for one scan: from this scan when the END processing
        between scans saw the reply, from the next one when the call itself failed.  FX3
        reports through M8029 at the next execution of ADPRW."""
        self.busy = False
        _, _, _, d2 = self.job
        flags = []
        if self.family != "fx3" or error:
            # FX3: D8402/D8403 hold the last error until power-on or STOP->RUN (FX-MB 6.1,
            # "Special clear conditions"): a transaction that succeeds does not clear them
            self._set(self._err_code, error)
        if self.family == "fx3":
            self.completed = True
            if error:
                self._set(self._err_flag, True)
                self._set(self._err_details, details)
                self._set(self._serial_err, self._serial_err_code)
                # FX-MB §12.6: M8402 and M8403 (ch1) go ON with D8402 and D8403; when the
                # CPU turns them OFF is not on the pages read (ASSUMPTION: not before the
                # program, power-on or STOP->RUN does, as M8063)
                self._set(self._err_code_flag, True)
                self._set(self._err_details_flag, True)
        elif d2 is not None:
            flags.append((d2, 0))
            if error:
                flags.append((d2, 1))
        if in_scan:
            self.pending.extend(flags)
        else:
            for ref, bit in flags:
                self._flag(ref, bit, True)
            self.pulses.extend(flags)
