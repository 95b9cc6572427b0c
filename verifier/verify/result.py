"""The outcome of one scenario run: everything the reports print, and the verdict.

Plain dataclasses so that results travel between worker processes (`--jobs`) and every
report reads the same thing.
"""
from __future__ import annotations

import re
from collections import Counter
from dataclasses import dataclass, field
from typing import Any

from verifier import protocol
from verifier.place import Place

from .durations import format_seconds
from .evidence import DEFAULT_RESPONSE_WITHIN_US, RuleOptions, Violation
from .expectations import Expectation, ExpectationResult


@dataclass(frozen=True)
class Keep:
    """What a run keeps beyond its verdict, for the reports that list it: every frame
    (`--trace`, `--html`); the watched labels' changes and the line's and robot's events
    (`--json`, `--html`). A run that keeps no frames is judged as it goes
    (verifier.verify.stream) and holds little more than its findings however long it runs;
    so is one whose frames go to a file (`frames_to_file`, what `uitamr verify` does for
    `--trace` and `--html`)."""

    frames: bool = True
    details: bool = True
    # with `details`, the watched labels' changes too (only `--json` lists them; the page
    # draws the events alone, and an o_wTxCount watched changes on every request)
    watched: bool = True
    # the frames go to a file in this folder as the run goes (`ScenarioResult.trace_file`)
    # instead of being held, and the run is judged as it goes; the trace and the page read
    # them from there. The folder is the caller's to remove (`uitamr verify` makes a hidden
    # one beside the trace or the page), with whatever a run that failed midway left in it
    frames_to_file: str | None = None
    # with `details`, keep only the events a report that shows at most this many of them
    # can show (verifier.verify.events_shown; the page: events_shown.EVENTS_AT_MOST), the
    # others counted in `ScenarioResult.events_dropped`; None: every event (`--json`)
    events_at_most: int | None = None


KEEP_ALL = Keep()

#: the verdict of a capture that saw no bytes (`uitamr monitor`, `uitamr replay`)
NO_TRAFFIC = "no-traffic"
#: the verdict of a capture whose port went away before the session's end (`uitamr monitor`,
#: `uitamr replay` of its trace) and whose frames broke no rule: not the whole session
CUT_SHORT = "cut-short"
#: the verdicts of a capture that neither passes nor fails, as they rank after "fail"
UNVERIFIED = (NO_TRAFFIC, CUT_SHORT)

#: the `platform` of a capture's result (`uitamr monitor`, `uitamr replay`): a real line,
#: no simulated CPU, program, scan or seed
LINE = "line"
#: the `channel` of a capture read from a file (`uitamr replay`); a line listened to live
#: (`uitamr monitor`) has its port's kind: rs485, tcp
CAPTURED_FROM_FILE = "capture"


@dataclass(frozen=True)
class Mistake:
    """One mistake of a run that cannot start (exit 2), as its JUnit report lists it: the
    whole message, and the place in a file it names first, or none when it names no file's
    line (`--program MIAN`, a source file that does not exist)."""

    message: str
    place: Place | None = None


def mistakes_of(error: Exception) -> list[Mistake]:
    """The mistakes an exception of unusable input stands for, with their places as the
    exception holds them (`place`: ScenarioError, UnusableInput, CaptureError; `mistakes`
    for several, ScenarioMistakes); never read back from the message."""
    several = getattr(error, "mistakes", None)
    if several is not None:
        return list(several)
    place = getattr(error, "place", None)
    if place is None or place.file is None:
        return [Mistake(str(error))]
    return [Mistake(str(error), place)]


class UnusableInput(Exception):
    """Input the verifier cannot run (bad scenario, ST that does not load, unknown program).

    The message is complete and meant for people; the command exits 2 with it. `at`: the
    place in a file the message names first, for the JUnit report (`place`); `mistakes`:
    the several mistakes one message lists, each at its own place (the errors of ST that
    does not load), for the JUnit report's test cases."""

    def __init__(self, message: str, at: Place | None = None, mistakes: list[Mistake] | None = None):
        super().__init__(message)
        self.place = at
        if mistakes is not None:
            self.mistakes = list(mistakes)

    def __reduce__(self):  # across --jobs' worker processes with its places
        return _unusable_input, (type(self), str(self), self.place, getattr(self, "mistakes", None))


def _unusable_input(kind: type, message: str, at, mistakes) -> UnusableInput:
    """An UnusableInput (or a subclass, whatever its constructor takes: ScenarioMistakes) as
    pickled: its message, place and mistakes."""
    error = kind.__new__(kind, message)
    UnusableInput.__init__(error, message, at, mistakes)
    return error


class ScenarioMistakes(UnusableInput):
    """The mistakes of several scenario files, or several of one (its labels), each its own
    message (file:line:col) and place (`mistakes`)."""

    def __init__(self, errors: list[Exception]):
        self.mistakes = [mistake for error in errors for mistake in mistakes_of(error)]
        super().__init__("\n".join(mistake.message for mistake in self.mistakes))


@dataclass(frozen=True, slots=True)
class TraceRecord:
    t_start_us: int
    t_end_us: int
    direction: str
    data: bytes
    origin: str | None = None


@dataclass(frozen=True)
class LineEvent:
    t_us: int
    kind: str  # "collision", "gap", "discarded", "robot.<kind>" (see verifier.link)
    message: str


#: the line's events the rules read (UITAMR-FORMAT: a pause inside a PLC frame; the pairing:
#: a converter that dropped the connection after forwarding a request)
RULE_EVENTS = ("gap", "converter.dropped")


def judged_with(options: RuleOptions) -> dict[str, Any]:
    """The rules' settings a run was judged with, as ScenarioResult's fields (what its
    reports and a trace's end record say): the same for a simulated run and a line's."""
    signal = options.response_signal
    return {"min_period_us": options.min_period_us, "reply_timeout_us": options.reply_timeout_us,
            "response_within_us": options.response_within_us,
            "response_signal": None if signal is None else str(signal),
            "response_signal_hint": options.response_signal_hint}


@dataclass
class ScenarioResult:
    name: str
    file: str | None  # the scenario file (a capture's for monitor and replay), as the reports name it
    description: str
    program: str | None
    platform: str
    channel: str
    sources: list[str]
    duration_us: int
    scan_us: int
    seed: int
    settings: protocol.Settings
    scan_jitter_us: int = 0
    min_period_us: int = protocol.MIN_PERIOD_US
    reply_timeout_us: int = protocol.DEFAULT_REPLY_TIMEOUT_US
    # UITAMR-RESPONSE-HANDLING's bound ([response_handling] within); with the two above, what
    # a trace's end record carries so that its replay judges with the run's own settings
    response_within_us: int = DEFAULT_RESPONSE_WITHIN_US
    # the program's outputs as UITAMR-RESPONSE-HANDLING judged them, for a trace's end record:
    # the response signal (None: the run had none; `response_signal_hint` then names what
    # could be it) and when it held ((began, stopped) µs, stopped None while still holding);
    # `signal_held` None: the outputs were not seen (a line: monitor, replay of a capture)
    response_signal: str | None = None
    response_signal_hint: str = ""
    signal_held: list[tuple[int, int | None]] | None = None
    # the events the rules read besides the frames (RULE_EVENTS: a pause inside a PLC frame,
    # a converter's drop), which a trace carries because its frames do not show them
    rule_events: list[LineEvent] = field(default_factory=list)
    faults: list[str] = field(default_factory=list)
    converter: str | None = None  # the TCP route's converter, its settings and faults (not a fault itself)
    trace: list[TraceRecord] = field(default_factory=list)
    events: list[LineEvent] = field(default_factory=list)
    events_dropped: int = 0  # events let go of while the run went (Keep.events_at_most), not in `events`
    violations: dict[str, list[Violation]] = field(default_factory=dict)
    expectations: list[ExpectationResult] = field(default_factory=list)
    diagnostics: list[str] = field(default_factory=list)
    # the same grouped by place and message, one line each (summarize_diagnostics below):
    # what the console and the JUnit report show
    diagnostic_summary: list[str] = field(default_factory=list)
    watched: dict[str, list[tuple[int, Any]]] = field(default_factory=dict)
    aborted: str | None = None  # the program stopped the simulation (ST location inside)
    # where it stopped: the ST location "file:line:col", the file as the reports name ST files
    aborted_at: str | None = None
    ended_us: int = 0
    wall_s: float = 0.0  # real time the run took (for people; nothing judges it)
    notes: list[str] = field(default_factory=list)  # how the run differs from its scenario file
    frame_counts: tuple[int, int] | None = None  # (requests, replies) when `trace` was not kept
    # the frames as trace lines written while the run went (Keep.frames_to_file): a file
    # of report_trace.spool_lines lines, which report_trace.write completes and the HTML
    # page reads the frames it draws from
    trace_file: str | None = None
    # a capture that saw no bytes (`uitamr monitor`, `uitamr replay`): nothing was verified;
    # what was silent and what to check
    no_traffic: str | None = None
    # a capture whose port went away while it had frames (`uitamr monitor`, and a replay of
    # its trace, whose end record keeps this): how long it ran of what was asked, what to check
    cut_short: str | None = None
    # frames timed by the host (`uitamr monitor`, `uitamr replay`): how far their times may
    # be off; the trace records it so that a replay of the trace judges with it too
    timing_tolerance_us: int = 0
    # the ST file that defines the PROGRAM that ran, as the reports name ST files (None for
    # a capture): what a JUnit test case names when the run has no scenario file
    program_file: str | None = None

    @property
    def tx_count(self) -> int:
        """Frames the PLC sent (counted when the trace was not kept)."""
        if self.frame_counts is not None:
            return self.frame_counts[0]
        return sum(1 for frame in self.trace if frame.direction == "tx")

    @property
    def rx_count(self) -> int:
        """Frames the robot sent."""
        if self.frame_counts is not None:
            return self.frame_counts[1]
        return len(self.trace) - self.tx_count

    @property
    def violation_count(self) -> int:
        return sum(len(found) for found in self.violations.values())

    @property
    def failed_expectations(self) -> list[ExpectationResult]:
        return [result for result in self.expectations if not result.passed]

    def place_of(self, expectation: Expectation) -> Place | None:
        """Where the scenario file states `expectation` (`verify/no-reply.toml:21:1`, its
        kind's key, the file as the reports name it), so that a failed one says which table
        to look at; None for one no file states (the answered power-on stop a scenario
        without [[expect]], or a run without a file, expects)."""
        if self.file is None or expectation.place is None:
            return None
        return expectation.place.in_file(self.file)

    def broken_rules(self) -> list[list[Violation]]:
        """The violations of each broken rule, the rules in the order of their first
        violation (the rules' own order among those of the same time): as the console and
        the JUnit report list them."""
        return sorted((found for found in self.violations.values() if found), key=lambda found: found[0].t_us)

    @property
    def first_place(self) -> Place | None:
        """Where a CI annotation of this run belongs (the JUnit test case's `file` and
        `line`, the JSON's `place`, the HTML's "look first at"): the place of its first
        finding, as the reports list them, that has one (`first_finding`). None when no
        finding has a place (a pass, a capture)."""
        found = self.first_finding
        return None if found is None else found[0]

    @property
    def first_finding(self) -> tuple[Place, str] | None:
        """The place of the first finding that has one, and what was found there, for
        people: the ST statement where the program stopped the CPU; else the one that sent
        the frame of the first broken rule's first violation (`sent by`), which is what to
        fix; else the line of the first failed expectation in the scenario file
        (`place_of`). None when no finding has a place."""
        stopped = Place.of_location(self.aborted_at)
        if stopped is not None:
            return stopped, "the program stopped the CPU here"
        for found in self.broken_rules():
            sent_by = Place.of_location(found[0].origin)
            if sent_by is not None:
                return sent_by, f"sent the frame of the first {found[0].rule} violation"
        for outcome in self.failed_expectations:
            place = self.place_of(outcome.expectation)
            if place is not None:
                return place, f"expected {outcome.expectation.label}"
        return None

    @property
    def file_to_annotate(self) -> str | None:
        """The file a CI annotation of this run names when no finding has a place (the JUnit
        test case's `file` without `line`): the scenario file, else the ST file of its
        PROGRAM; for `uitamr replay` the capture file. None for a line `uitamr monitor`
        listened to: its port (`/dev/ttyUSB0`, `tcp 192.168.0.50:4001`) is no file of the
        repository a CI server could open."""
        if self.captured and self.channel != CAPTURED_FROM_FILE:
            return None
        return self.file or self.program_file

    @property
    def broke_nothing(self) -> bool:
        """No rule broken, no expectation failed, no stop of the CPU."""
        return self.aborted is None and self.violation_count == 0 and not self.failed_expectations

    @property
    def passed(self) -> bool:
        return not self.unverified and self.broke_nothing

    @property
    def unverified(self) -> list[tuple[str, str]]:
        """(UNVERIFIED verdict, its sentence) for what a capture did not verify: no bytes at
        all, a port that went away; what every report says of each."""
        return [(kind, said) for kind, said in ((NO_TRAFFIC, self.no_traffic), (CUT_SHORT, self.cut_short))
                if said is not None]

    @property
    def captured(self) -> bool:
        """A real line's traffic (`uitamr monitor`, `uitamr replay`), not a simulated run."""
        return self.platform == LINE

    @property
    def run_line(self) -> str:
        """What ran, for people: the program on its CPU and the run's virtual time, scan (with
        its jitter, which the seed draws) and seed; for a capture the line and how long its
        traffic is."""
        if self.captured:
            return f"the PLC on the line ({self.channel}), {format_seconds(self.ended_us)} of traffic"
        jitter = f" ±{self.scan_jitter_us / 1000:g} ms" if self.scan_jitter_us else ""
        return (f"program {self.program} on {self.platform} ({self.channel}), {format_seconds(self.ended_us)} of "
                f"virtual time, scan {self.scan_us / 1000:g} ms{jitter}, seed {self.seed}")

    @property
    def verdict(self) -> str:
        """"pass", "fail", or an UNVERIFIED one: a capture with nothing on it neither passes nor
        fails (NO_TRAFFIC); one cut short fails on a rule its frames broke, else is CUT_SHORT."""
        if self.no_traffic is not None:
            return NO_TRAFFIC
        if not self.broke_nothing:
            return "fail"
        return CUT_SHORT if self.cut_short is not None else "pass"

    def all_violations(self) -> list[Violation]:
        """Every violation by time; those of the same time in the rules' own order, as
        `broken_rules` and so the console and the JUnit report list them (the HTML and JSON
        lists put them in the order of the rules' names: a PACING violation came after a
        HALF-DUPLEX one of the same moment there, before it in the console)."""
        order = {rule: i for i, rule in enumerate(self.violations)}
        return sorted((v for found in self.violations.values() for v in found), key=lambda v: (v.t_us, order[v.rule]))


def run_names(results: list[ScenarioResult]) -> list[str]:
    """Each run's name where reports tell runs apart by name (JUnit test cases, `--trace`
    records, which `uitamr replay` groups by it): its own; for runs that share one (a copied
    scenario file that kept it), the name with its file (a number without one); the same
    file run twice gets a number after its file too."""
    count = Counter(result.name for result in results)
    seen: Counter = Counter()
    labels: list[str | None] = []
    for result in results:
        seen[result.name] += 1
        labels.append((result.file or str(seen[result.name])) if count[result.name] > 1 else None)
    clash = Counter(zip((result.name for result in results), labels))
    again: Counter = Counter()
    names = []
    for result, label in zip(results, labels):
        if label is None:
            names.append(result.name)
            continue
        if clash[result.name, label] > 1:
            again[result.name, label] += 1
            label = f"{label} #{again[result.name, label]}"
        names.append(f"{result.name} [{label}]")
    return names


def overall_verdict(results: list[ScenarioResult]) -> str:
    """"fail" when any result failed (or there are none), else NO_TRAFFIC when any capture
    saw nothing, else CUT_SHORT when any was cut short, else "pass"."""
    verdicts = {result.verdict for result in results}
    if not results or "fail" in verdicts:
        return "fail"
    return next((verdict for verdict in UNVERIFIED if verdict in verdicts), "pass")


def all_captured(results: list[ScenarioResult]) -> bool:
    """Every result is a capture's (`ScenarioResult.captured`): the reports speak of
    captures, not scenarios; no result at all is no capture."""
    return bool(results) and all(result.captured for result in results)


def summarize_diagnostics(diagnostics, shown=lambda location: location) -> list[str]:
    """`diagnostics` (SimDiagnostic) grouped by place and by message, numbers aside: one
    line each, in the order they first happened, e.g. "×160, first at 0.250 s: RS2 fx3:1:
    6 received byte(s) discarded because ...  at plc/MAIN.st:58:1". A program that gets
    one wrong on every reply gets one line, not thousands. `shown` turns a location into
    the text the line gives (the reports make files relative to the working folder)."""
    groups: dict[tuple, list] = {}
    for d in diagnostics:
        key = (d.location, d.code, re.sub(r"\d+", "#", d.message))
        if key in groups:
            groups[key][1] += 1
        else:
            groups[key] = [d, 1]
    lines = []
    for first, count in groups.values():
        at = format_seconds(first.t_us)
        times = f"×{count}, first at {at}" if count > 1 else f"at {at}"
        where = f"  at {shown(first.location)}" if first.location else ""
        lines.append(f"{times}: {first.message}{where}")
    return lines
