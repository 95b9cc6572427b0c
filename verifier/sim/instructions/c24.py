"""QJ71C24N(-R2/-R4) non-procedural protocol: G_OUTPUT / G_INPUT (ladder G.OUTPUT /
G.INPUT) with the module's buffer memory and input signals.

ST calls (docs/st-dialect.md): `G_OUTPUT(EN, Un, s1, s2, d)`, `G_INPUT(EN, Un, s, d1, d2)`.
Behaviour, buffer addresses and what is an ASSUMPTION: docs/instructions.md ("QJ71C24N").
"""
from __future__ import annotations

from verifier.plcfacts import C24_ABNORMAL as ABNORMAL, C24_BUFFER as BUFFER, C24_READ_REQUEST as READ_REQUEST

from ..datatypes import wrap16
from ..refs import operand_key, pulse_keys

# BUFFER: buffer memory (word addresses) per channel: receive data count, receive end code,
# word/byte unit designation (verifier.plcfacts)
DEFAULTS = {"recv_count": 511, "end_code": 0x0D0A, "unit": 0}
# configure()'s settings that are buffer-memory words, by the word's name in BUFFER
SETTING_NAMES = {"byte_units": "unit", "receive_count": "recv_count", "end_code": "end_code"}
#: the buffer-memory words of those settings (any channel): a program's own assignment to
#: one is recorded (codegen), so that a setting for "the module the program drives" does
#: not replace it
SETTING_WORDS = frozenset(addr for words in BUFFER.values() for addr in words.values())
# READ_REQUEST, ABNORMAL: input signals (offset from the module's start I/O): reception data
# read request and reception abnormal detection per channel (verifier.plcfacts)
# result codes the simulator writes (ASSUMPTION: the module's own codes are not modelled)
ERR_CHANNEL = 0x7FF1
ERR_TOO_LONG = 0x7FF2
# the code stored for a message ended by timer 0 in format 0 (ASSUMPTION: the module's own
# code for a no-reception time-out is not modelled)
ERR_NO_RECEPTION = 0x7FF3


class _Channel:
    def __init__(self, module: "C24Module", ch: int):
        self.module = module
        self.ch = ch
        self.port = module.rt.channel(f"q:{ch}")
        self.sending_until: int | None = None
        self.out_done = None  # (s1 ref, d ref) awaiting completion
        self.rx = bytearray()
        self.rx_last_t = 0
        self.rx_first_t = 0  # when the first byte of the unfinished message arrived
        # messages waiting for G_INPUT: (data, error code; 0 = a normal reception, when its
        # last byte arrived in µs)
        self.frames: list[tuple[bytes, int, int]] = []
        self.no_reception_us: int | None = None  # timer 0, off by default
        # what timer 0 running out does (C24 (Application) 6.1): format 1 ends the message
        # normally (X3/XA), format 0 reports a reception error (X4/XB, error code)
        self.no_reception_format = 1
        # the first G_OUTPUT sent in word units: (count, bytes sent), for the report's note
        # when the frames it sent were not the robot's (a port that counts bytes)
        self.word_send: tuple[int, int] | None = None
        # the first message completed across a silence, without timer 0: (when its first
        # byte came in µs, bytes before the silence, the silence in µs), for the report's
        # note (a short reply waited for the received data count: every later one out of step)
        self.joined: tuple[int, int, int] | None = None


#: a silence inside one received message this many character times long (20.8 ms at 9600
#: 8N1) is no gap between a reply's bytes: two replies, or a reply and noise, joined into
#: one message; measured in the channel's own line format, so that it holds at any speed
JOINED_GAP_CHARS = 20


class C24Module:
    def __init__(self, rt, un: int):
        self.rt = rt
        self.un = un
        self.buffer = rt.buffer(un)
        for addrs in BUFFER.values():
            for name, addr in addrs.items():
                if self.buffer[addr] == 0:
                    self.buffer[addr] = wrap16(DEFAULTS[name])
        self.channels = {ch: _Channel(self, ch) for ch in (1, 2)}
        # a module no G_OUTPUT / G_INPUT has addressed yet is not wired to the robot's line:
        # settings made for it (configure_c24) must not let it take the bytes the program's
        # own module is waiting for
        self.addressed = False
        self.pulses: list[tuple] = []  # (ref, bit offset) ON for one scan
        self.pending: list[tuple] = []  # completion bits to turn ON at the next END
        rt.pollers.append(self)

    # -- helpers -------------------------------------------------------------------------
    def _x(self, offset: int) -> int:
        return self.un * 16 + offset

    def _set_x(self, offset: int, value: bool) -> None:
        xs = self.rt.dev.areas["X"]
        i = self._x(offset)
        if i < len(xs):
            xs[i] = value

    def _word(self, ch: int, name: str) -> int:
        return self.buffer[BUFFER[ch][name]] & 0xFFFF

    def _channel(self, ref, loc_id):
        ch = ref.get(0)
        if ch not in (1, 2):
            self.rt.warn(self.rt.locations[loc_id], f"C24 at U{self.un:X}: channel {ch} does not exist "
                                                    f"(control data word 0 must be 1 or 2)")
            return None
        return self.channels[ch]

    def _finish(self, d_ref, ok: bool) -> None:
        """Completion bits: d[0] done and d[1] error go ON at the END of this scan, for one scan."""
        self.pending.append((d_ref, 0))
        if not ok:
            self.pending.append((d_ref, 1))

    def configure(self, channel: int, *, byte_units: bool | None = None, receive_count: int | None = None,
                  end_code: int | None = None, no_reception_ms: float | None = None,
                  no_reception_format: int | None = None) -> None:
        """Settings made in GX Works for one channel (None: left as they are)."""
        addr = BUFFER[channel]
        if byte_units is not None:
            self.buffer[addr["unit"]] = 1 if byte_units else 0
        if receive_count is not None:
            self.buffer[addr["recv_count"]] = receive_count
        if end_code is not None:
            self.buffer[addr["end_code"]] = wrap16(end_code)
        if no_reception_ms is not None:
            self.channels[channel].no_reception_us = round(no_reception_ms * 1000)
        if no_reception_format is not None:
            self.channels[channel].no_reception_format = no_reception_format

    def _addressed_now(self) -> None:
        """The first G_OUTPUT / G_INPUT on this module: it is the program's, so it is on the
        line, and settings made for "the module the program drives" apply to it."""
        self.addressed = True
        for channel, settings in self.rt.c24_for_program.items():
            self.configure_for_program(channel, settings)

    def configure_for_program(self, channel: int, settings: dict) -> None:
        """`configure` with settings made for "the module the program drives": a word the
        program has written keeps the program's value (made in GX Works, the setting would
        have been in force from power-on, under the write)."""
        written = self.rt.c24_written
        words = BUFFER[channel]
        self.configure(channel, **{name: value for name, value in settings.items()
                                   if name not in SETTING_NAMES
                                   or (self.un, words[SETTING_NAMES[name]]) not in written})

    # -- G_OUTPUT ----------------------------------------------------------------------------
    def output(self, s1, s2, d, loc_id) -> bool:
        if not self.addressed:
            self._addressed_now()
        chan = self._channel(s1, loc_id)
        if chan is None:
            s1.set(1, ERR_CHANNEL)
            self._finish(d, ok=False)
            return True
        if chan.sending_until is not None:
            return True  # already sending: the running G_OUTPUT finishes first (ASSUMPTION)
        count = s1.get(2)
        nbytes = count if self._word(chan.ch, "unit") == 1 else 2 * count
        if nbytes != count and chan.word_send is None:
            chan.word_send = (count, nbytes)
        data = s2.get_bytes(nbytes)
        origin = self.rt.locations[loc_id]
        chan.sending_until = chan.port.transmit(data, self.rt.now_us, origin)
        chan.out_done = (s1, d)
        return True

    # -- G_INPUT -------------------------------------------------------------------------------
    def input(self, s, d1, d2, loc_id) -> bool:
        if not self.addressed:
            self._addressed_now()
        chan = self._channel(s, loc_id)
        if chan is None:
            s.set(1, ERR_CHANNEL)
            self._finish(d2, ok=False)
            return True
        if not chan.frames:
            return True  # nothing received: the instruction does nothing (ASSUMPTION)
        data, error, _ = chan.frames.pop(0)
        words = (len(data) + 1) // 2
        count = len(data) if self._word(chan.ch, "unit") == 1 else words
        if count > s.get(3):
            s.set(1, ERR_TOO_LONG)
            self._finish(d2, ok=False)
        else:
            # a reception error: the data up to the error are read, the instruction ends with
            # its completion device + 1 ON and the code in (s)+1 (C24 (Basic) 6.1.5)
            d1.put_bytes(data)
            s.set(2, count)
            s.set(1, error)
            self._finish(d2, ok=not error)
        self._signals(chan)
        return True

    def _signals(self, chan: _Channel) -> None:
        """X3/XA while a normal message waits, X4/XB while one ended by an error waits."""
        self._set_x(READ_REQUEST[chan.ch], any(not frame[1] for frame in chan.frames))
        self._set_x(ABNORMAL[chan.ch], any(frame[1] for frame in chan.frames))

    def unread(self) -> list[tuple[int, int, int]]:
        """(channel, messages waiting, since when in µs) for each channel whose received
        messages no G_INPUT has taken."""
        return [(ch, len(c.frames), c.frames[0][2]) for ch, c in self.channels.items() if c.frames]

    def unfinished(self) -> list[tuple[int, int, int, int, int]]:
        """(channel, bytes, since µs, received data count, end code) of the bytes each
        channel holds that no message end (count, end code, timer 0) has closed."""
        return [(ch, len(c.rx), c.rx_first_t, self._word(ch, "recv_count"), self._word(ch, "end_code"))
                for ch, c in self.channels.items() if c.rx]

    def joined_messages(self) -> list[tuple[int, int, int, int]]:
        """(channel, when the first byte came in µs, bytes before the silence, silence in µs)
        of the first message each channel completed across a silence, timer 0 being off."""
        return [(ch, *c.joined) for ch, c in self.channels.items() if c.joined is not None]

    def word_unit_sends(self) -> list[tuple[int, int, int]]:
        """(channel, count, bytes sent) of the first G_OUTPUT each channel sent in word units."""
        return [(ch, *c.word_send) for ch, c in self.channels.items() if c.word_send is not None]

    # -- between scans ---------------------------------------------------------------------------
    def poll(self, now: int) -> None:
        for ref, bit in self.pulses:
            ref.set(bit, False)
        self.pulses = self.pending
        self.pending = []
        for ref, bit in self.pulses:
            ref.set(bit, True)
        for chan in self.channels.values():
            if chan.sending_until is not None and now >= chan.sending_until:
                chan.sending_until = None
                s1, d = chan.out_done
                s1.set(1, 0)
                d.set(0, True)
                self.pulses.append((d, 0))
            if self.addressed:
                self._receive(chan, now)

    # -- idle-scan skipping (verifier.sim.idle) -------------------------------------------
    def idle_deadline(self, now: int) -> float | None:
        """The first instant `poll` can change anything, or None when it may at `now` (a
        completion bit to turn ON or OFF)."""
        if self.pulses or self.pending:
            return None
        deadline = float("inf")
        if not self.addressed:
            return deadline  # not on the line: nothing arrives for it (an instruction call is a scan)
        for chan in self.channels.values():
            if chan.sending_until is not None:
                deadline = min(deadline, chan.sending_until)
            quiet = chan.port.quiet_until(now)
            if quiet is None:
                return None
            deadline = min(deadline, quiet)
            if chan.rx and chan.no_reception_us is not None:
                # the frame ends once more than the no-reception time has passed (integer µs)
                deadline = min(deadline, chan.rx_last_t + chan.no_reception_us + 1)
        return deadline

    def idle_state(self) -> tuple:
        """Everything the instructions and `poll` change (nothing counts scans)."""
        channels = tuple(
            (c.sending_until, None if c.out_done is None else tuple(map(operand_key, c.out_done)),
             bytes(c.rx), c.rx_last_t, tuple(c.frames), c.no_reception_us, c.no_reception_format,
             c.port.sent_count)
            for c in self.channels.values())
        return self.addressed, channels, pulse_keys(self.pulses), pulse_keys(self.pending)

    def skipped(self, scan_count: int, scans: int) -> None:
        """Nothing here depends on the scan count."""

    def _receive(self, chan: _Channel, now: int) -> None:
        target = 2 * self._word(chan.ch, "recv_count") if self._word(chan.ch, "unit") == 0 \
            else self._word(chan.ch, "recv_count")
        end_code = self._word(chan.ch, "end_code")
        for value, t in chan.port.receive_until(now):
            if chan.rx and chan.no_reception_us is not None and t - chan.rx_last_t > chan.no_reception_us:
                self._timed_out(chan)
            if (chan.rx and chan.no_reception_us is None and chan.joined is None
                    and t - chan.rx_last_t > JOINED_GAP_CHARS * chan.port.format.byte_time_us):
                chan.joined = (chan.rx_first_t, len(chan.rx), t - chan.rx_last_t)
            if not chan.rx:
                chan.rx_first_t = t
            chan.rx.append(value)
            chan.rx_last_t = t
            if (end_code != 0xFFFF and len(chan.rx) >= 2
                    and chan.rx[-2] == end_code >> 8 and chan.rx[-1] == end_code & 0xFF):
                self._frame(chan)
            elif target and len(chan.rx) >= target:
                self._frame(chan)
        if chan.rx and chan.no_reception_us is not None and now - chan.rx_last_t > chan.no_reception_us:
            self._timed_out(chan)

    def _timed_out(self, chan: _Channel) -> None:
        self._frame(chan, 0 if chan.no_reception_format == 1 else ERR_NO_RECEPTION)

    def _frame(self, chan: _Channel, error: int = 0) -> None:
        chan.frames.append((bytes(chan.rx), error, chan.rx_last_t))
        chan.rx.clear()
        self._signals(chan)
