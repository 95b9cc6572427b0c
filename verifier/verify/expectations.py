"""What a scenario expects to happen, and the judgement of each expectation after a run.

Kinds (one per `[[expect]]` table in a scenario):

- `that`   — a condition on PLC variables becomes true inside the window;
- `always` — it holds during the whole window;
- `never`  — it never holds inside the window;
- `sent`   — the PLC sends this request (words of `uitamr frame`, e.g. "run-point 3") and
             the robot answers it, inside the window;
- `reached_point` — the robot accepted "run point N", reported its task running and then
             finished (idle, with no error that stops a task: a battery warning may be on)
             inside the window.

The window is [after, after + within] (`after` defaults to 0, `within` to the end of the run).
"""
from __future__ import annotations

from abc import ABC, abstractmethod
from dataclasses import dataclass, field

from verifier import protocol
from verifier.place import Place

from .conditions import Condition
from .durations import format_seconds
from .evidence import FrameRef, RunEvidence
from .traffic import ReplyStatus, Traffic

KINDS = ("that", "always", "never", "sent", "reached_point")
#: Kinds met once their moment has come: one that came before the program stopped the CPU
#: is met, though the window would have closed later (`sent = "stop"` within 5 s, the stop
#: answered at 0.23 s, the CPU stopped at 3 s). `always` and `never` need the whole window.
EVENTUALLY = ("that", "sent", "reached_point")
SENT_INSTEAD = 3  # other control commands a failed `sent` names
#: Robot errors that stop a running task (a battery warning does not; docs/emulator.md).
TASK_STOPPING_ERRORS = (protocol.RobotError.ANTI_COLLISION, protocol.RobotError.OFF_TAPE)


@dataclass(frozen=True)
class Expectation:
    kind: str
    label: str  # how reports name it, e.g. "o_bOK within 20 s"
    after_us: int = 0
    within_us: int | None = None
    condition: Condition | None = None
    request: protocol.ControlRequest | protocol.StatusRequest | None = None
    point: int | None = None
    key: str = ""  # where the scenario states it, e.g. "expect[2]"
    # the line and column of its kind's key in the scenario file (`that = ...`), for the
    # reports of a failed expectation (ScenarioResult.place_of); None: no file states it
    place: Place | None = field(default=None, compare=False)

    def window(self, end_us: int) -> tuple[int, int]:
        if self.within_us is None:
            return self.after_us, end_us
        return self.after_us, min(end_us, self.after_us + self.within_us)


@dataclass(frozen=True)
class ExpectationResult:
    expectation: Expectation
    passed: bool
    detail: str
    t_us: int | None = None
    frames: tuple[FrameRef, ...] = ()


def describe_window(expectation: Expectation) -> str:
    parts = []
    if expectation.within_us is not None:
        parts.append(f"within {expectation.within_us / 1_000_000:g} s")
    if expectation.after_us:
        parts.append(f"after {expectation.after_us / 1_000_000:g} s")
    return " ".join(parts)


def judge(expectation: Expectation, evidence: RunEvidence, traffic: Traffic) -> ExpectationResult:
    """`expectation` judged over a whole run."""
    watch = watch_exchanges(expectation, evidence.settings)
    if watch is not None:
        for exchange in traffic.exchanges:
            watch.exchange(exchange)
    return verdict(expectation, evidence, watch)


def watch_exchanges(expectation: Expectation, settings) -> "ExchangeWatch | None":
    """What judges a `sent` or `reached_point` expectation as the exchanges settle, one at
    a time and in order (None for the kinds judged on PLC labels)."""
    kind = {"sent": _Sent, "reached_point": _ReachedPoint}.get(expectation.kind)
    return None if kind is None else kind(expectation, settings)


def verdict(expectation: Expectation, evidence: RunEvidence, watch: "ExchangeWatch | None") -> ExpectationResult:
    """The result of `expectation` once the run has ended: from `watch` (every exchange of
    the run given to it) for the kinds about exchanges, from the samples for the others."""
    start, end = expectation.window(evidence.end_us)
    if expectation.after_us >= evidence.end_us:
        # the window would be empty (or end before it begins): nothing could be judged
        return ExpectationResult(expectation, False, _too_short(evidence, "opened", expectation.after_us))
    short = expectation.within_us is not None and expectation.after_us + expectation.within_us > evidence.end_us
    if short and not (evidence.stopped_early and expectation.kind in EVENTUALLY):
        return ExpectationResult(expectation, False,
                                 _too_short(evidence, "closed", expectation.after_us + expectation.within_us))
    if watch is not None:
        outcome = watch.result(start, end)
    else:
        judge_kind = {
            "that": _judge_that,
            "always": _judge_always,
            "never": _judge_never,
        }[expectation.kind]
        outcome = judge_kind(expectation, evidence, start, end)
    if short and not outcome.passed:
        # the program stopped the CPU before the window closed, and it had not happened yet
        return ExpectationResult(expectation, False,
                                 _too_short(evidence, "closed", expectation.after_us + expectation.within_us))
    return outcome


def _too_short(evidence: RunEvidence, moment: str, at_us: int) -> str:
    """Why a window the run ended before it `moment` ("opened", "closed") at `at_us` was not
    judged, with the remedy."""
    when = (f"the moment the window {moment}, leaving nothing to judge" if at_us == evidence.end_us
            else f"before the window {moment} at {format_seconds(at_us)}")  # not "at 20 s, before ... at 20 s"
    if evidence.stopped_early:
        return f"the simulation stopped at {format_seconds(evidence.end_us)}, {when}"
    return f"the run ended at {format_seconds(evidence.end_us)}, {when}: {_longer(evidence)}"


def _longer(evidence: RunEvidence) -> str:
    """The remedy for a window the run ended too early for: the length is the file's, or
    the --duration that cut it short."""
    return "give a longer --duration" if evidence.duration_from_option else "make the scenario's duration longer"


def _span(start: int, end: int) -> str:
    return f"between {format_seconds(start)} and {format_seconds(end)}"


def _st_value(value) -> str:
    """A label's value as the condition writes it: TRUE/FALSE, not Python's True/False."""
    if isinstance(value, bool):
        return "TRUE" if value else "FALSE"
    return repr(value)


def _values_at(evidence: RunEvidence, condition: Condition, t_us: int) -> str:
    return ", ".join(
        f"{name} = {_st_value(evidence.samples.value_at(name, t_us))}" for name in sorted(condition.names)
    )


def _judge_that(expectation, evidence, start, end) -> ExpectationResult:
    seen = evidence.samples.first_time(expectation.condition, start, end)
    if seen is None:
        return ExpectationResult(
            expectation, False,
            f"'{expectation.condition}' never became true {_span(start, end)} "
            f"(at the end: {_values_at(evidence, expectation.condition, end)})",
        )
    return ExpectationResult(expectation, True, f"true at {format_seconds(seen)}", seen)


def _first_in_window(condition: Condition, evidence: RunEvidence, start: int, end: int) -> int | None:
    """The first moment in [start, end] at which `condition` holds, or None."""
    for began, stopped in evidence.samples.intervals(condition, evidence.end_us):
        if began <= end and stopped > start:
            return max(began, start)
    return None


def _judge_always(expectation, evidence, start, end) -> ExpectationResult:
    condition = expectation.condition
    at = _first_in_window(Condition(f"NOT ({condition.text})", ("not", condition.tree)), evidence, start, end)
    if at is None:
        return ExpectationResult(expectation, True, f"held {_span(start, end)}")
    return ExpectationResult(
        expectation, False, f"'{condition}' was false at {format_seconds(at)} ({_values_at(evidence, condition, at)})", at
    )


def _judge_never(expectation, evidence, start, end) -> ExpectationResult:
    condition = expectation.condition
    at = _first_in_window(condition, evidence, start, end)
    if at is None:
        return ExpectationResult(expectation, True, f"never true {_span(start, end)}")
    return ExpectationResult(
        expectation, False, f"'{condition}' became true at {format_seconds(at)} ({_values_at(evidence, condition, at)})", at
    )


class ExchangeWatch(ABC):
    """An expectation about exchanges, given each settled exchange in order.

    Exchanges after the window are left out as they come: the window's end is
    `after + within` (the run's end when `within` is not given, and every request of the
    run starts before it); a window the run ended inside fails in `verdict` before this
    is asked."""

    def __init__(self, expectation: Expectation, settings):
        self.expectation = expectation
        self.settings = settings
        self.first_us = expectation.after_us
        self.last_us = (float("inf") if expectation.within_us is None
                        else expectation.after_us + expectation.within_us)

    def exchange(self, exchange) -> None:
        t = exchange.request.t_start_us
        if self.first_us <= t <= self.last_us:
            self.in_window(exchange, t)
        else:
            self.outside(exchange, t)

    def outside(self, exchange, t: int) -> None:
        """Take `exchange`, whose request started at `t`, before or after the window (for the
        words of a failure; nothing by default)."""

    @abstractmethod
    def in_window(self, exchange, t: int) -> None:
        """Take `exchange`, whose request started at `t`, inside the window."""

    @abstractmethod
    def result(self, start: int, end: int) -> ExpectationResult:
        """The verdict once every exchange of the run was given; the window is [start, end]."""


class _Sent(ExchangeWatch):
    """`sent`: the request went out and was answered inside the window."""

    def __init__(self, expectation: Expectation, settings):
        super().__init__(expectation, settings)
        self.wanted = protocol.encode(expectation.request, settings)
        self.answered = None  # the first exchange of the request that was answered
        self.unanswered = None  # else the first one sent
        # other control commands sent in the window, for a control command that was not:
        # those with its control code first ("speed trackless 2" expected, stage 2 = 02/01
        # sent), the first few distinct ones (meaning, time)
        self.instead: dict[str, int] = {}
        self.instead_other: dict[str, int] = {}
        # the request itself outside the window: the last time before it, the first after
        # it (a command that waited behind another one goes out late: say when it did)
        self.before: int | None = None
        self.later: int | None = None

    def outside(self, exchange, t: int) -> None:
        if bytes(exchange.request.data) != self.wanted:
            return
        if t < self.first_us:
            self.before = t
        elif self.later is None:
            self.later = t

    def in_window(self, exchange, t: int) -> None:
        if self.answered is not None:
            return
        if bytes(exchange.request.data) != self.wanted:
            self._other(exchange, t)
            return
        if exchange.answered:
            self.answered = exchange
        elif self.unanswered is None:
            self.unanswered = exchange

    def result(self, start: int, end: int) -> ExpectationResult:
        expectation = self.expectation
        if self.answered is not None:
            t = self.answered.request.t_start_us
            return ExpectationResult(
                expectation, True, f"sent and answered at {format_seconds(t)}", t, self.answered.refs()
            )
        meaning = protocol.describe(expectation.request, self.settings)
        if self.unanswered is not None:
            t = self.unanswered.request.t_start_us
            status, why = self.unanswered.reply_status
            got = "" if status is ReplyStatus.NONE else f" (the first time: {why})"
            return ExpectationResult(
                expectation, False,
                f"{meaning} was sent at {format_seconds(t)} but never answered {_span(start, end)}{got}",
                t, self.unanswered.refs(),
            )
        instead = self.instead or self.instead_other
        sent = ""
        if instead:
            sent = "; sent instead: " + ", ".join(
                f"{other} at {format_seconds(t)}" for other, t in list(instead.items())[:SENT_INSTEAD])
            if len(instead) > SENT_INSTEAD:
                sent += ", ..."
        if self.later is not None:
            sent += (f"; it went out later, at {format_seconds(self.later)} "
                     f"({format_seconds(self.later - start)} after the window opened)")
        elif self.before is not None:
            sent += f"; it went out before the window, last at {format_seconds(self.before)}"
        return ExpectationResult(
            expectation, False,
            f"{meaning} ({protocol.hex_bytes(self.wanted)}) was not sent {_span(start, end)}{sent}",
        )

    def _other(self, exchange, t: int) -> None:
        wanted = self.expectation.request
        request = exchange.decoded_request
        if not (isinstance(wanted, protocol.ControlRequest) and isinstance(request, protocol.ControlRequest)):
            return  # a status read expected: the polls of every other query would only be noise
        found = self.instead if request.code == wanted.code else self.instead_other
        if len(found) <= SENT_INSTEAD:
            found.setdefault(protocol.describe(request, self.settings), t)


class _ReachedPoint(ExchangeWatch):
    """`reached_point`: run point N accepted, its task seen running, then finished (idle,
    with no error that stops a task) inside the window."""

    def __init__(self, expectation: Expectation, settings):
        super().__init__(expectation, settings)
        self.accepted_at: int | None = None
        self.running_seen = False
        # how far it got, worded once the window is known: (start, end) -> text
        self.progress = lambda start, end: f"run-point {self.expectation.point} was not sent and answered {_span(start, end)}"
        self.reached = None  # (t, exchange) of the task reported finished

    def in_window(self, exchange, t: int) -> None:
        if self.reached is not None or not exchange.answered:
            return
        point, request = self.expectation.point, exchange.decoded_request
        if request is None:
            return  # a request the robot would ignore (what answered it was a late reply)
        if isinstance(request, protocol.ControlRequest):
            if request.code == protocol.ControlCode.ROBOT and request.command == point:
                self.accepted_at, self.running_seen = t, False
                self.progress = lambda start, end: (
                    f"run-point {point} accepted at {format_seconds(t)}, but the robot never reported the task running")
            elif self.accepted_at is not None:
                self.accepted_at = None
                other = protocol.describe(request, self.settings)
                self.progress = lambda start, end: (
                    f"run-point {point} was superseded by {other} at {format_seconds(t)}")
            return
        if self.accepted_at is None or request.query != protocol.Query.TASK:
            return
        reply = protocol.decode_reply(exchange.reply.data, self.settings, request)
        if not self.running_seen and reply.value != 1 and reply.error in TASK_STOPPING_ERRORS:
            # the robot still holds an anti-collision / off-tape state: it accepts the point and
            # does nothing until the stop command clears it (plc-library.md, error codes)
            error, accepted = reply.error, self.accepted_at
            self.progress = lambda start, end: (
                f"run-point {point} accepted at {format_seconds(accepted)}, but the robot never reported the task "
                f"running: its task status at {format_seconds(t)} carried error {int(error):02d} "
                f"({protocol.catalogue.ERROR_TITLES[error]}), which the robot keeps until the stop command "
                "(01/A0): send the stop (acknowledge the fault) before the next point")
            self.accepted_at = None
            return
        if reply.value == 1:
            self.running_seen = True
            since = self.accepted_at
            self.progress = lambda start, end: (
                f"run-point {point} was running (since {format_seconds(since)}) but did not finish {_span(start, end)}")
        elif self.running_seen and reply.error not in TASK_STOPPING_ERRORS:
            self.reached = (t, exchange)
        elif self.running_seen:
            error = int(reply.error)
            self.progress = lambda start, end: (
                f"the task of run-point {point} ended with error {error:02d} at {format_seconds(t)}")
            # the task is over: later polls that still show the error do not move its end
            self.accepted_at, self.running_seen = None, False

    def result(self, start: int, end: int) -> ExpectationResult:
        point = self.expectation.point
        if self.reached is not None:
            t, exchange = self.reached
            return ExpectationResult(
                self.expectation, True, f"point {point} reached: task idle at {format_seconds(t)}", t, exchange.refs()
            )
        return ExpectationResult(self.expectation, False, self.progress(start, end))
