"""A monitoring session: chunks in, classified frames and the verifier's findings out.

The rules are `uitamr verify`'s own (`verifier.verify.rules`, over a `RunEvidence`); only
the evidence differs: frames timed by the host instead of the simulator, no PLC variables.
`check` judges the frames the line has settled since the last call (a request whose reply
or time-out is known; the next frame may still come at any time, so a reply time-out and
the frames at the line's last instant stay open) and returns the findings they make, so a
live view prints each once and a long session does not judge its whole past again at
every call; `result` is the final judgement, in the shape every report of `uitamr
verify` reads, and the same as judging the whole capture at once (`violations`).
"""
from __future__ import annotations

from bisect import bisect_right
from dataclasses import dataclass, field, replace
from typing import Sequence

from verifier import protocol
from verifier.protocol.codec import MAX_FRAME
from verifier.protocol.stream import ROBOT_LINE, garbled, garbled_note
from verifier.verify.evidence import RuleOptions, RunEvidence, Samples, Violation
from verifier.verify.result import CAPTURED_FROM_FILE, LINE, LineEvent, ScenarioResult, TraceRecord, judged_with
from verifier.verify.rules import Judgement, check_all
from verifier.verify.traffic import Exchange, Pairing, analyse, converter_drops

from .capture import Chunk
from .classify import Classifier
from .framer import Framer, LineTiming

POWER_ON_RULE = "UITAMR-POWERON-STOP"
PROVISIONAL_RULE = "UITAMR-RESPONSE-HANDLING"  # the one rule with early word (Judgement.provisional)


@dataclass
class CaptureInfo:
    """What the reports say about where the bytes came from."""

    name: str
    source: str  # "/dev/ttyUSB0", "tcp 192.168.0.50:4001", "capture.txt"
    channel: str = "rs485"  # rs485 / tcp / capture (CAPTURED_FROM_FILE)
    line: str = ROBOT_LINE  # the line's speed and framing, as the monitor was told them
    notes: list[str] = field(default_factory=list)


class MonitorSession:
    def __init__(self, info: CaptureInfo, settings: protocol.Settings = protocol.DEFAULT_SETTINGS,
                 options: RuleOptions = RuleOptions(), timing: LineTiming = LineTiming(),
                 from_power_on: bool = True, signal_held: Sequence[tuple[int, int | None]] | None = None,
                 events: Sequence[LineEvent] = ()):
        """`signal_held`: when the program's response signal (`options.response_signal`)
        held, for a trace of `uitamr verify` that recorded it; None (a line): the program's
        outputs are not seen, and UITAMR-RESPONSE-HANDLING says so. `events`: the line
        events the rules read that a trace recorded (RULE_EVENTS: pauses inside PLC frames,
        a converter's drops), on the trace's clock."""
        self.info = info
        self.settings = settings
        self.timing = timing
        self.options = replace(options, timing_tolerance_us=timing.tolerance_us, outputs_visible=signal_held is not None)
        self.signal_held = None if signal_held is None else list(signal_held)
        self.samples = Samples()  # the PLC's variables: none on a line
        self.events = sorted(events, key=lambda e: e.t_us)
        self._drops = converter_drops(self.events)  # the next request at or after each lost its reply
        self._drops_passed = 0
        if self.options.outputs_visible and self.options.response_signal is not None:
            self.samples.given(self.options.response_signal, self.signal_held)
        self.from_power_on = from_power_on
        self.framer = Framer(timing)
        self.classifier = Classifier(settings, self.options.reply_timeout_us, timing.tolerance_us)
        self.chunks: list[Chunk] = []
        self.frames: list[TraceRecord] = []
        self._origin_us: int | None = None  # host time of the first byte: t = 0 in reports
        self.last_us = 0
        self._ended_us: int | None = None  # the run's end as a trace's end record gives it (`end_at`)
        self._gone = False  # the port went away (`went_away`)
        self.cut_short: str | None = None  # what the result says of a run its port cut short
        # the live judgement: frames go to the pairing once no frame still to come can sort
        # before them (they start before the end of the latest frame), the rules judge what
        # the pairing has settled
        self._pairing = Pairing(settings, self.options)
        self._evidence = RunEvidence(settings, self.frames, 0, self.events, self.samples, self.options)
        self._judgement = Judgement(self._evidence, self._pairing.traffic)
        self.judged_frames = 0  # frames handed to the rules (each once)
        self._line_end_us: int | None = None  # the end of the latest frame
        self._in_line_order = True  # every frame started after the one before it ended
        self._closed = False
        self._shown: set = set()  # early findings (Judgement.provisional) check has returned
        self.cut_off = b""  # the start of a frame the end of the capture cut (`close`)

    # --- input ---------------------------------------------------------------------------
    def feed(self, chunk: Chunk) -> list[TraceRecord]:
        """Take the next chunk (host times in µs, any origin); the frames it completed. A
        chunk with no bytes says nothing came until its time (`poll`)."""
        if not chunk.data:
            return self.poll(chunk.t_us)
        self._open()
        if self._origin_us is None:
            # a trace's frames (their start given) are on the clock of the run that wrote
            # them (a monitor's 0: its first byte; verify's: power-on), which the trace's
            # end record counts on too; host chunks, from any origin, begin at the first byte
            self._origin_us = 0 if chunk.t_start_us is not None else chunk.t_us - self.timing.frame_us(len(chunk.data))
        local = replace(chunk, t_us=chunk.t_us - self._origin_us,
                        t_start_us=None if chunk.t_start_us is None else chunk.t_start_us - self._origin_us)
        self.chunks.append(local)
        self.last_us = max(self.last_us, local.t_us)
        return self._take(self.framer.feed(local))

    def poll(self, host_us: int) -> list[TraceRecord]:
        """Frames ended by silence up to host time `host_us`."""
        self._open()
        if self._origin_us is None:
            return []
        now = host_us - self._origin_us
        self.last_us = max(self.last_us, now)
        frames = self.framer.poll(now)
        if frames and self.info.channel != CAPTURED_FROM_FILE:
            # the line was seen silent until now, and that ended a frame: the capture keeps it
            # (a `silence` line, `format_plain`), or its replay, which dates each chunk's bytes
            # back to back before its arrival, joined bytes that a pty or a TCP converter had
            # handed over faster than the line: a request and a reply 8 ms later were one
            # garbled frame in the replay and two frames live
            self.chunks.append(Chunk(now, b""))
        return self._take(frames)

    def end_at(self, host_us: int, cut_short: str | None = None) -> None:
        """The run ended at host time `host_us` (a trace's end record): its length and the
        end the rules judge to, also when a frame that began before it was still on the line
        then (`uitamr verify --duration` cut it; the trace holds it whole), as the run was
        judged; the latest byte or poll otherwise. `cut_short`: what the end record says of
        a monitor whose port went away (`went_away`): the replay is not the whole session either."""
        if self._origin_us is not None:
            self._ended_us = host_us - self._origin_us
        # with no byte before it nothing was verified: no traffic alone, as `went_away` says
        self.cut_short = cut_short if self._origin_us is not None else None

    def went_away(self, listened_us: int, asked_us: int | None) -> None:
        """The port went away (unplugged, the converter closed or reset the connection) after
        `listened_us` of a session asked to last `asked_us` (None: until Ctrl-C), after the
        `close`. With frames seen the run is cut short: not the whole session, so frames that
        broke no rule do not pass it; with none, the silence says the port went away."""
        self._gone = True
        if not self.frames:
            return
        asked = "before Ctrl-C" if asked_us is None else f"of the {asked_us / 1_000_000:g} s asked"
        check = ("the converter (its power, its network, that no other client took its one connection)"
                 if self.info.channel == "tcp" else "the USB adapter's cable and power")
        self.cut_short = (f"{self.info.source} went away after {listened_us / 1_000_000:.1f} s {asked}: the "
                          f"{len(self.frames)} frame(s) before it were verified, but the run is not the whole "
                          f"session; check {check}, then monitor the whole session again")

    @property
    def run_end_us(self) -> int:
        """Where the run ends: `end_at`'s time, else the latest byte or poll."""
        return self.last_us if self._ended_us is None else self._ended_us

    def _open(self) -> None:
        if self._closed:
            raise RuntimeError("the monitoring session has ended: it takes no more bytes")

    def close(self) -> list[TraceRecord]:
        """The end of the capture: the pending bytes as a frame; nothing more comes. Bytes
        that begin a frame of known length but stop short of it were cut by the end of the
        capture (Ctrl-C, --duration, a converter that dropped the connection, the end of
        the file), not sent short by the PLC: they are noted (`cut_off`), not judged."""
        frames, self.cut_off = self.framer.finish()
        frames = self._take(frames)
        self._closed = True
        return frames

    def _take(self, frames) -> list[TraceRecord]:
        records = []
        for frame in frames:
            direction = self.classifier.direction(frame)
            record = TraceRecord(frame.t_start_us, frame.t_end_us, direction, frame.data)
            if self._line_end_us is not None and record.t_start_us < self._line_end_us:
                self._in_line_order = False  # frames of a trace that overlap: judged as a whole at the end
            self._line_end_us = max(record.t_end_us, self._line_end_us or record.t_end_us)
            records.append(record)
        self.frames += records
        return records

    # --- judgement -----------------------------------------------------------------------
    def violations(self, end_us: int | None = None) -> dict[str, list[Violation]]:
        """The whole capture judged at once, as if it ended at `end_us` (default: the latest
        byte or poll)."""
        end = self.run_end_us if end_us is None else end_us
        evidence = RunEvidence(self.settings, self.frames, end, self.events, self.samples, self.options)
        found = check_all(evidence, analyse(self.frames, self.settings, self.options, self._drops))
        if not self.from_power_on:
            found[POWER_ON_RULE] = []
        return found

    def check(self) -> list[Violation]:
        """Findings not returned by an earlier call, in time order: each violation once it is
        final (no frame still to come can change it; after `close`, all the rest), and early
        word of replies that are still failing after the bound of UITAMR-RESPONSE-HANDLING
        (its final finding is then not returned again), also when the line has gone silent
        after a request whose reply is overdue."""
        self._evidence.end_us = self.run_end_us  # the run lasts at least this long
        if not self._in_line_order:
            new = self._judged_whole() if self._closed else []
        elif self._closed:
            self._give(len(self.frames))
            new = self._judgement.finish()
        else:
            self._give(self._ready())
            settled = self._pairing.settled(self._line_end_us)
            new = self._judgement.advance(settled)
            # what is still open goes on at least until the first request not settled has
            # ended (its reply starts after it) or, when all are, until the line's last frame
            exchanges = self._pairing.traffic.exchanges
            open_until = exchanges[settled].request.t_end_us if settled < len(exchanges) else self._line_end_us
            silence = self._silent_since(settled)
            if silence is None:
                new += self._judgement.provisional(open_until)
            else:  # the latest request failed, and the failure lasts while the line is silent
                overdue, silent_since = silence
                new += self._judgement.provisional(silent_since, overdue)
        shown = []
        for violation in new:
            if violation.rule == POWER_ON_RULE and not self.from_power_on:
                continue
            if violation.rule == PROVISIONAL_RULE:
                # the episode's first request and when it showed: early word of an overdue
                # reply names the request alone; a late reply may join it in the final words
                key = (violation.rule, violation.t_us, violation.frames[:1])
                if key in self._shown:
                    continue
                self._shown.add(key)
            shown.append(violation)
        return sorted(shown, key=lambda v: (v.t_us, v.rule))

    def _silent_since(self, settled: int) -> tuple[Exchange, int] | None:
        """The latest request and since when the line is known silent, when the line has
        gone silent after it and its reply can no longer come in time: it is the one
        exchange not settled, it has no reply, every frame seen is with the pairing, none
        is pending in the framer, and a frame still to come (bytes a later read returns)
        starts after its deadline: no earlier than the latest frame's end, nor than one
        longest frame (and the host's tolerance) before now."""
        exchanges = self._pairing.traffic.exchanges
        if settled != len(exchanges) - 1 or exchanges[-1].rx:
            return None
        if self.judged_frames < len(self.frames) or self.framer.pending:
            return None
        silent = max(self._line_end_us, self.last_us - self.timing.frame_us(MAX_FRAME) - self.timing.tolerance_us)
        return (exchanges[-1], silent) if silent > exchanges[-1].deadline_us else None

    def _ready(self) -> int:
        """How many frames (from the first) no frame still to come can sort before: those
        that started before the latest frame ended."""
        ready = self.judged_frames
        while ready < len(self.frames) and self.frames[ready].t_start_us < self._line_end_us:
            ready += 1
        return ready

    def _give(self, upto: int) -> None:
        """Hand frames up to `upto` to the pairing, in `analyse`'s order."""
        for frame in sorted(self.frames[self.judged_frames:upto], key=lambda f: (f.t_start_us, f.direction != "tx")):
            self._pairing.give(frame)
            if frame.direction == "tx":
                self._lost_at_converter(frame)
        self.judged_frames = max(self.judged_frames, upto)

    def _lost_at_converter(self, request: TraceRecord) -> None:
        """The request just given is the first at or after a converter's drop: its reply never
        reached the PLC (as `analyse` marks it, `dropped_at`)."""
        passed = bisect_right(self._drops, request.t_start_us)
        if passed > self._drops_passed:
            self._pairing.traffic.exchanges[-1].lost_at_converter = True
            self._drops_passed = passed

    def _judged_whole(self) -> list[Violation]:
        """Frames that overlap (only a trace file's can; bytes from a line never do) make the
        pairing of earlier frames change with later ones: the whole capture is judged once,
        at the end (findings an earlier check returned come again)."""
        if self._judgement.finished:
            return []
        self._judgement.finished = True
        self._judgement.found = self.violations()
        self.judged_frames = len(self.frames)
        return [v for found in self._judgement.found.values() for v in found]

    def _final(self) -> dict[str, list[Violation]]:
        if not self._judgement.finished:
            self._closed = True
            self.check()
        found = self._judgement.violations()
        if not self.from_power_on:
            found[POWER_ON_RULE] = []
        return found

    def result(self, listened_us: int | None = None) -> ScenarioResult:
        """The final judgement; `listened_us`: how long a live session listened (for a line
        on which nothing was seen)."""
        end = self.run_end_us
        notes = list(self.info.notes)
        if self.timing.tolerance_us:
            notes.append(f"frames timed by the host; timing rules allow {self.timing.tolerance_us / 1000:g} ms "
                         "for the adapter's latency (--tolerance)")
        else:  # a verify trace, tx/rx lines or --tolerance 0: the times are the wire's
            notes.append("frames taken as exactly timed; timing rules allow 0 ms for latency (--tolerance)")
        if self.signal_held is not None:
            signal = self.options.response_signal
            notes.append("the program's outputs as the trace recorded them: "
                         + (f"{PROVISIONAL_RULE} judged by '{signal}'" if signal is not None
                            else f"the run had no response signal for {PROVISIONAL_RULE}"))
        if not self.from_power_on:
            notes.append(f"the capture began after power-on: {POWER_ON_RULE} is not judged")
        if self.cut_off:
            notes.append(f"the capture ended inside a frame: its first {len(self.cut_off)} byte(s) "
                         f"({protocol.hex_bytes(self.cut_off)}) were not judged")
        if self.frames and all(garbled(record.data) for record in self.frames):
            notes.append(garbled_note(len(self.frames), self.info.line))
        no_traffic = None
        if not self.frames:
            no_traffic = self._silence(listened_us)
            end = listened_us or 0
        return ScenarioResult(
            name=self.info.name,
            file=self.info.source,
            description=f"traffic captured on {self.info.source} at {self.info.line}",
            program=None,
            platform=LINE,
            channel=self.info.channel,
            sources=[],
            duration_us=end,
            scan_us=0,
            seed=0,
            settings=self.settings,
            **judged_with(self.options),
            signal_held=self.signal_held,
            rule_events=list(self.events),
            trace=list(self.frames),
            violations=self._final(),
            ended_us=end,
            notes=notes,
            no_traffic=no_traffic,
            timing_tolerance_us=self.timing.tolerance_us,
            cut_short=self.cut_short,
        )

    def _silence(self, listened_us: int | None) -> str:
        """What a session that saw no bytes says: nothing was verified, and what to check
        (on site it is almost always the wiring, the port or the line's settings)."""
        source, line = self.info.source, self.info.line
        # the start of a frame the end cut (`cut_off`, the note names it) is all there was
        some = f"only {len(self.cut_off)} byte(s) ({protocol.hex_bytes(self.cut_off)}), no whole frame,"
        if self.info.channel == CAPTURED_FROM_FILE:
            holds = f"{source} holds {some}" if self.cut_off else f"{source} holds no bytes,"
            return (f"{holds} so nothing was verified: capture the line again once "
                    f"the monitor shows frames (check the wiring, the port name and {line})")
        during = "" if listened_us is None else f" in {listened_us / 1_000_000:.1f} s"
        if self._gone:
            during += ", before it went away"
        seen = f"{some} were seen" if self.cut_off else "no bytes were seen"
        if self.info.channel == "tcp":
            return (f"{seen} on {source}{during}: check that the converter streams the line "
                    f"to this port, its wiring to the line and its serial settings ({line})")
        return f"{seen} on {source}{during}: check the wiring (A, B, GND), the port name and {line}"
