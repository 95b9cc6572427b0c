"""What a run leaves behind, and what a check says about it.

The rules never see the simulator: they read a `RunEvidence` — the frames on the line
(objects shaped like `verifier.link.TraceFrame`), the line's events, the PLC variables
sampled every scan — and return `Violation`s. Tests build evidence by hand.
"""
from __future__ import annotations

from bisect import bisect_right
from dataclasses import dataclass, field
from typing import Any, Iterator, Protocol, Sequence

from verifier import protocol

from .conditions import Condition

DEFAULT_REPLY_TIMEOUT_US = protocol.DEFAULT_REPLY_TIMEOUT_US
DEFAULT_RESPONSE_WITHIN_US = 5_000_000


class TraceFrameLike(Protocol):
    t_start_us: int
    t_end_us: int
    direction: str  # "tx" PLC→robot, "rx" robot→PLC
    data: bytes
    origin: str | None


@dataclass(frozen=True)
class RuleOptions:
    """The knobs of the rules; scenario files set them under [rules]."""

    min_period_us: int = protocol.MIN_PERIOD_US
    reply_timeout_us: int = DEFAULT_REPLY_TIMEOUT_US
    # RESPONSE-HANDLING: the output that shows the program noticed a failed exchange.
    response_signal: Condition | None = None
    response_within_us: int = DEFAULT_RESPONSE_WITHIN_US
    # with no signal: the program's FB outputs that could be it ("fbEngine.o_bErr, ..."), for the message
    response_signal_hint: str = ""
    # Captures (`uitamr monitor`, `uitamr replay`): how far host timestamps may be off, so
    # that timing rules do not fire on the adapter's latency; 0 for the simulator's exact times.
    timing_tolerance_us: int = 0
    # False for captures: the PLC's outputs are not on the line to judge RESPONSE-HANDLING by.
    outputs_visible: bool = True


@dataclass(frozen=True, slots=True)
class FrameRef:
    """A frame as a report shows it."""

    t_us: int
    t_end_us: int
    direction: str
    hex: str
    meaning: str
    origin: str | None = None


@dataclass(frozen=True, slots=True)
class Violation:
    rule: str
    t_us: int
    message: str
    frames: tuple[FrameRef, ...] = ()
    origin: str | None = None


class Samples:
    """PLC variables over virtual time, stored as changes: name → [(t_us, value), ...]."""

    def __init__(self, names: Sequence[str] = ()):
        self.names = list(dict.fromkeys(names))
        self.changes: dict[str, list[tuple[int, Any]]] = {name: [] for name in self.names}
        self._times: dict[str, list[int]] = {name: [] for name in self.names}
        self._spans: dict[Condition, Spans] = {}

    def record(self, t_us: int, values: dict[str, Any]) -> None:
        changed = []
        for name, value in values.items():
            if name not in self.changes:
                self.names.append(name)
                self.changes[name], self._times[name] = [], []
            history = self.changes[name]
            if not history or history[-1][1] != value:
                history.append((t_us, value))
                self._times[name].append(t_us)
                changed.append(name)
        for spans in self._spans.values():
            if not spans.names.isdisjoint(changed):
                spans.moment(t_us, {name: self.value_at(name, t_us) for name in spans.names})

    def spans(self, condition: Condition) -> "Spans":
        """When `condition` held, as `intervals` says, kept up to date as samples come in
        (a run judged as it goes asks before its first sample; a finished run, at the end)."""
        spans = self._spans.get(condition)
        if spans is None:
            spans = self._spans[condition] = Spans(condition)
            for t_us, values in self.states(condition.names):
                spans.moment(t_us, values)
        return spans

    def given(self, condition: Condition, stretches: Sequence[tuple[int, int | None]]) -> None:
        """When `condition` held, known without its labels' values (a verify trace's end
        record, `Spans.stretches`): `spans(condition)` answers from these."""
        spans = self._spans[condition] = Spans(condition)
        for began, stopped in stretches:
            spans.began.append(began)
            if stopped is not None:
                spans.stopped.append(stopped)

    def value_at(self, name: str, t_us: int) -> Any:
        index = bisect_right(self._times.get(name, []), t_us) - 1
        return self.changes[name][index][1] if index >= 0 else None

    def states(self, names: Sequence[str] | frozenset[str]) -> Iterator[tuple[int, dict[str, Any]]]:
        """Every moment one of `names` changed, with the values of all of them then.

        Starts at the first moment all of them are known."""
        names = list(names)
        moments = sorted({t for name in names for t in self._times.get(name, [])})
        positions = {name: 0 for name in names}
        current: dict[str, Any] = {}
        for t_us in moments:
            for name in names:
                history = self.changes.get(name, [])
                position = positions[name]
                while position < len(history) and history[position][0] <= t_us:
                    current[name] = history[position][1]
                    position += 1
                positions[name] = position
            if len(current) == len(names):
                yield t_us, dict(current)

    def first_time(self, condition: Condition, start_us: int, end_us: int) -> int | None:
        """The first moment in [start_us, end_us] at which `condition` holds, or None."""
        at_start = {name: self.value_at(name, start_us) for name in condition.names}
        if all(value is not None for value in at_start.values()) and condition.holds(at_start):
            return start_us
        for t_us, values in self.states(condition.names):
            if t_us <= start_us:
                continue
            if t_us > end_us:
                return None
            if condition.holds(values):
                return t_us
        return None

    def intervals(self, condition: Condition, end_us: int) -> list[tuple[int, int]]:
        """The [start, end) stretches of virtual time during which `condition` holds."""
        spans: list[tuple[int, int]] = []
        began: int | None = None
        for t_us, values in self.states(condition.names):
            if condition.holds(values):
                if began is None:
                    began = t_us
            elif began is not None:
                spans.append((began, t_us))
                began = None
        if began is not None:
            spans.append((began, end_us))
        return spans


class Spans:
    """The [began, stopped) stretches during which a condition held, built moment by moment
    (`Samples.states`); a stretch still running has no stop yet."""

    def __init__(self, condition: Condition):
        self.condition = condition
        self.names = condition.names
        self.began: list[int] = []
        self.stopped: list[int] = []  # one fewer than `began` while a stretch runs

    def moment(self, t_us: int, values: dict[str, Any]) -> None:
        if any(value is None for value in values.values()):
            return  # not every name known yet (Samples.states starts when all are)
        holds = self.condition.holds(values)
        running = len(self.began) > len(self.stopped)
        if holds and not running:
            self.began.append(t_us)
        elif not holds and running:
            self.stopped.append(t_us)

    def stretches(self) -> list[tuple[int, int | None]]:
        """(began, stopped) of each stretch, stopped None for one still running."""
        return [(began, self.stopped[k] if k < len(self.stopped) else None) for k, began in enumerate(self.began)]

    def first_running_after(self, t_us: int) -> int | None:
        """When the first stretch still running after `t_us` began (it may have begun
        before), or None."""
        index = bisect_right(self.stopped, t_us)
        return self.began[index] if index < len(self.began) else None


@dataclass
class RunEvidence:
    settings: protocol.Settings
    trace: Sequence[TraceFrameLike]
    end_us: int
    events: Sequence[Any] = ()
    samples: Samples = field(default_factory=Samples)
    options: RuleOptions = field(default_factory=RuleOptions)
    stopped_early: bool = False  # the program stopped the simulated CPU at end_us
    duration_from_option: bool = False  # --duration set end_us, not the scenario file
