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

from dataclasses import dataclass

from verifier import protocol

from .conditions import Condition
from .durations import format_seconds
from .evidence import FrameRef, RunEvidence
from .traffic import Traffic

KINDS = ("that", "always", "never", "sent", "reached_point")
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
    start, end = expectation.window(evidence.end_us)
    short = expectation.within_us is not None and expectation.after_us + expectation.within_us > evidence.end_us
    if short:
        closes = format_seconds(expectation.after_us + expectation.within_us)
        if evidence.stopped_early:
            why = f"the simulation stopped at {format_seconds(evidence.end_us)}, before the window closed at {closes}"
        else:
            why = (f"the run ended at {format_seconds(evidence.end_us)}, before the window closed at {closes}: "
                   "make the scenario's duration longer")
        return ExpectationResult(expectation, False, why)
    judge_kind = {
        "that": _judge_that,
        "always": _judge_always,
        "never": _judge_never,
        "sent": _judge_sent,
        "reached_point": _judge_reached_point,
    }[expectation.kind]
    return judge_kind(expectation, evidence, traffic, start, end)


def _span(start: int, end: int) -> str:
    return f"between {format_seconds(start)} and {format_seconds(end)}"


def _values_at(evidence: RunEvidence, condition: Condition, t_us: int) -> str:
    return ", ".join(
        f"{name} = {evidence.samples.value_at(name, t_us)!r}" for name in sorted(condition.names)
    )


def _judge_that(expectation, evidence, traffic, start, end) -> ExpectationResult:
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


def _judge_always(expectation, evidence, traffic, start, end) -> ExpectationResult:
    condition = expectation.condition
    at = _first_in_window(Condition(f"NOT ({condition.text})", ("not", condition.tree)), evidence, start, end)
    if at is None:
        return ExpectationResult(expectation, True, f"held {_span(start, end)}")
    return ExpectationResult(
        expectation, False, f"'{condition}' was false at {format_seconds(at)} ({_values_at(evidence, condition, at)})", at
    )


def _judge_never(expectation, evidence, traffic, start, end) -> ExpectationResult:
    condition = expectation.condition
    at = _first_in_window(condition, evidence, start, end)
    if at is None:
        return ExpectationResult(expectation, True, f"never true {_span(start, end)}")
    return ExpectationResult(
        expectation, False, f"'{condition}' became true at {format_seconds(at)} ({_values_at(evidence, condition, at)})", at
    )


def _judge_sent(expectation, evidence, traffic, start, end) -> ExpectationResult:
    wanted = protocol.encode(expectation.request, evidence.settings)
    sent_unanswered = None
    for exchange in traffic.exchanges:
        t = exchange.request.t_start_us
        if t < start or t > end or bytes(exchange.request.data) != wanted:
            continue
        if exchange.answered:
            return ExpectationResult(
                expectation, True, f"sent and answered at {format_seconds(t)}", t, exchange.refs()
            )
        sent_unanswered = sent_unanswered or exchange
    meaning = protocol.describe(expectation.request, evidence.settings)
    if sent_unanswered is not None:
        return ExpectationResult(
            expectation, False,
            f"{meaning} was sent at {format_seconds(sent_unanswered.request.t_start_us)} but never "
            f"answered {_span(start, end)}",
            sent_unanswered.request.t_start_us, sent_unanswered.refs(),
        )
    return ExpectationResult(
        expectation, False,
        f"{meaning} ({protocol.hex_bytes(wanted)}) was not sent {_span(start, end)}",
    )


def _judge_reached_point(expectation, evidence, traffic, start, end) -> ExpectationResult:
    point = expectation.point
    accepted_at = None
    running_seen = False
    progress = f"run-point {point} was not sent and answered {_span(start, end)}"
    for exchange in traffic.exchanges:
        t = exchange.request.t_start_us
        if t < start or t > end or not exchange.answered:
            continue
        request = exchange.decoded_request
        if isinstance(request, protocol.ControlRequest):
            if request.code == protocol.ControlCode.ROBOT and request.command == point:
                accepted_at, running_seen = t, False
                progress = f"run-point {point} accepted at {format_seconds(t)}, but the robot never reported the task running"
            elif accepted_at is not None:
                accepted_at = None
                progress = f"run-point {point} was superseded by {protocol.describe(request, evidence.settings)} at {format_seconds(t)}"
            continue
        if accepted_at is None or request.query != protocol.Query.TASK:
            continue
        reply = protocol.decode_reply(exchange.reply.data, evidence.settings, request)
        if reply.value == 1:
            running_seen = True
            progress = f"run-point {point} was running (since {format_seconds(accepted_at)}) but did not finish {_span(start, end)}"
        elif running_seen and reply.error not in TASK_STOPPING_ERRORS:
            return ExpectationResult(
                expectation, True, f"point {point} reached: task idle at {format_seconds(t)}", t, exchange.refs()
            )
        elif running_seen:
            progress = f"the task of run-point {point} ended with error {int(reply.error):02d} at {format_seconds(t)}"
    return ExpectationResult(expectation, False, progress)
