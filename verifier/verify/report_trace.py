"""`--trace FILE`: every frame on the line as JSON Lines, one frame per line, and after each
run's frames what the rules read besides them.

Fields: `t`, `t_end` (seconds of virtual time), `dir` ("tx" PLC→robot, "rx" robot→PLC),
`hex` (space-separated bytes), `meaning` (decoded), `origin` (the ST location that sent a
tx frame, when known), `scenario`, and `rules` (ids of the rules this frame is evidence for);
a trace of host times (`uitamr monitor`, `uitamr replay`) also has `tolerance` (seconds), which
a replay of it allows again. After a run's frames come its event records (`event_record`:
the line's events the rules read that the frames do not show, RULE_EVENTS: a pause inside a
PLC frame, a TCP converter that dropped the connection after forwarding a request), then its
end record (`end_record`): when the run ended - until when the line was listened to, a
simulated run's end in virtual time - so that a replay judges the silence after the last
frame as the run did (a reply still due, the run's length), as a plain capture's `end` line
does; the rules' and the protocol's settings the run was judged with; for a monitor whose
port went away, its `cut_short` sentence; and, for a run that saw the program's outputs
(`uitamr verify`), its response signal and when it held. With them
`uitamr replay` of the trace reaches the run's own rule findings
(tests/test_replay_verify_trace.py).

A run of `uitamr verify --trace` or `--html` does not hold its frames: it writes each
one as a spool line while it goes (`spool_lines`: everything but `rules`, which only the
judgement at the end knows) and `write` completes the lines; the HTML page reads the
frames it draws from the same lines (`LineTimes`, `records`). Both ways give the same
bytes (tests/test_verify_trace_spool.py, tests/test_verify_html_spool.py).
"""
from __future__ import annotations

import json
from dataclasses import asdict
from pathlib import Path
from typing import Collection, Iterator

from verifier import protocol
from verifier.textfile import UNENCODABLE, whole_file

from .evidence import RuleOptions
from .result import ScenarioResult, run_names
from .traffic import analyse, describe_bytes


def _line_order(frame) -> tuple:
    return frame.t_start_us, frame.direction != "tx"


def _frame_fields(name: str, frame, settings: protocol.Settings, request) -> dict:
    """A frame's trace line, all but its `rules` (the last field)."""
    return {
        "scenario": name,
        "t": frame.t_start_us / 1_000_000,
        "t_end": frame.t_end_us / 1_000_000,
        "dir": frame.direction,
        "hex": protocol.hex_bytes(frame.data),
        "meaning": describe_bytes(frame.data, settings, frame.direction, request=request),
        "origin": frame.origin,
    }


def blamed_frames(result: ScenarioResult) -> dict[tuple[int, str], set[str]]:
    """(start µs, direction) of each frame that is evidence of a violation -> those rules."""
    blamed: dict[tuple[int, str], set[str]] = {}
    for violation in result.all_violations():
        for frame in violation.frames:
            blamed.setdefault((frame.t_us, frame.direction), set()).add(violation.rule)
    return blamed


def in_line_order(result: ScenarioResult) -> list:
    """The frames of a run that kept them, in trace order."""
    return sorted(result.trace, key=_line_order)


def frame_count(result: ScenarioResult) -> int:
    """How many frames a run that kept them has, held or spooled."""
    return len(result.trace) if result.trace_file is None else result.tx_count + result.rx_count


class LineTimes:
    """(start µs, end µs, direction) of each frame of a run that kept its frames, in trace
    order, read afresh on each pass: from the frames it holds, or from its spool file
    (a long run's frames are never all in memory at once). `len` is the number of frames."""

    def __init__(self, result: ScenarioResult):
        self._result = result
        self._held = in_line_order(result) if result.trace_file is None else None
        self._count = frame_count(result)

    def __len__(self) -> int:
        return self._count

    def __iter__(self) -> Iterator[tuple[int, int, str]]:
        if self._held is not None:
            return ((frame.t_start_us, frame.t_end_us, frame.direction) for frame in self._held)
        return ((t_us, t_end_us, direction) for t_us, t_end_us, direction, _ in _spool(self._result.trace_file))


def records(result: ScenarioResult, name: str | None = None, only: Collection[int] | None = None) -> Iterator[dict]:
    """The trace lines of a run that kept its frames (held or spooled); `name` (default:
    the run's) goes in each line's `scenario`; `only`: the positions (in trace order) of
    the frames wanted."""
    if result.trace_file is not None:
        for line in _spooled(result, name or result.name, only):
            yield json.loads(line)
        return
    blamed = blamed_frames(result)
    traffic = analyse(result.trace, result.settings, RuleOptions(reply_timeout_us=result.reply_timeout_us))
    frames = in_line_order(result)
    if only is not None:
        frames = [frames[k] for k in only]
    for frame in frames:
        request = traffic.request_of(frame) if frame.direction == "rx" else None
        record = _frame_fields(name or result.name, frame, result.settings, request)
        if result.timing_tolerance_us:  # host times (monitor): a replay allows what the monitor did
            record["tolerance"] = result.timing_tolerance_us / 1_000_000
        record["rules"] = sorted(blamed.get((frame.t_start_us, frame.direction), ()))
        yield record


def spool_lines(name: str, frames, settings: protocol.Settings, request_of) -> Iterator[str]:
    """Spool lines of frames handed over together while a run goes, in trace order:
    the frame's start and direction, then its trace line without the closing `rules`.
    `request_of(frame)` is the request a robot frame was paired with."""
    for frame in sorted(frames, key=_line_order):
        request = request_of(frame) if frame.direction == "rx" else None
        head = json.dumps(_frame_fields(name, frame, settings, request), ensure_ascii=False)
        yield f"{frame.t_start_us} {frame.t_end_us} {frame.direction} {head[:-1]}\n"


def _spool(path: str) -> Iterator[tuple[int, int, str, str]]:
    """A spool file's lines: start and end (µs), direction, and the trace line's head."""
    with open(path, encoding="utf-8") as spool:
        for line in spool:
            t_us, t_end_us, direction, head = line.rstrip("\n").split(" ", 3)
            yield int(t_us), int(t_end_us), direction, head


def _spooled(result: ScenarioResult, name: str, only: Collection[int] | None = None) -> Iterator[str]:
    """The run's spool lines completed; `name` in place of the run's own (`scenario` is the
    first field, written as `_frame_fields` writes it); `only`: the positions wanted."""
    blamed = blamed_frames(result)
    spooled_name = _scenario_field(result.name)
    renamed = _scenario_field(name)
    wanted = None if only is None else set(only)
    last = max(wanted, default=-1) if wanted is not None else None
    for k, (t_us, _, direction, head) in enumerate(_spool(result.trace_file)):
        if wanted is not None:
            if k > last:
                break
            if k not in wanted:
                continue
        if renamed != spooled_name:
            head = renamed + head[len(spooled_name):]
        rules = sorted(blamed.get((t_us, direction), ()))
        yield f'{head}, "rules": {json.dumps(rules)}}}\n'


def _scenario_field(name: str) -> str:
    """How a trace line starts: its `scenario` field."""
    return json.dumps({"scenario": name}, ensure_ascii=False)[:-1]


def write(results: list[ScenarioResult], path: Path) -> None:
    """The trace of `results`, run after run; runs that share a name are told apart as the
    JUnit report tells them (`run_names`), so that `uitamr replay` reads them as two."""
    with whole_file(path, encoding="utf-8", errors=UNENCODABLE) as out:
        for result, name in zip(results, run_names(results)):
            if result.trace_file is not None:
                out.writelines(_spooled(result, name))
            else:
                for record in records(result, name):
                    out.write(json.dumps(record, ensure_ascii=False) + "\n")
            end = end_record(result, name)
            if end is not None:
                for event in result.rule_events:
                    out.write(json.dumps(event_record(event, name), ensure_ascii=False) + "\n")
                out.write(json.dumps(end, ensure_ascii=False) + "\n")


def event_record(event, name: str) -> dict:
    """A line event the rules read that the frames do not show (`RULE_EVENTS`: a pause inside
    a PLC frame, a converter's drop), as a record after the run's frames."""
    return {"scenario": name, "t": event.t_us / 1_000_000, "event": event.kind, "message": event.message}


#: the rules' settings a run's end record carries: its key in the record -> the field (µs) of
#: ScenarioResult and RuleOptions it is
RUN_SETTINGS = {"reply_timeout": "reply_timeout_us", "min_period": "min_period_us",
                "response_within": "response_within_us"}


def end_record(result: ScenarioResult, name: str) -> dict | None:
    """The record after a run's frames (a run that has any): when the run ended - until when
    the line was listened to; a simulated run's end in virtual time, which may be well after
    its last frame (a reply time-out still running, a silence) - and the rules' settings it
    was judged with (`RUN_SETTINGS`, and the protocol settings: the address, the manual's
    choices), and a monitor's `cut_short` (its port went away), so that `uitamr replay`
    judges the trace as the run was.
    A run that saw the program's outputs (`uitamr verify`) adds its response signal and when
    it held: UITAMR-RESPONSE-HANDLING judges by them, and a line does not show them."""
    if not frame_count(result):
        return None
    record = {"scenario": name, "end": result.ended_us / 1_000_000,
              **{key: getattr(result, field) / 1_000_000 for key, field in RUN_SETTINGS.items()},
              "protocol": asdict(result.settings)}
    if result.cut_short is not None:  # the port went away: a replay is not the whole session either
        record["cut_short"] = result.cut_short
    if result.signal_held is not None:
        record["response_signal"] = result.response_signal
        if result.response_signal is None:
            record["response_signal_hint"] = result.response_signal_hint
        else:
            record["response_signal_held"] = [[began / 1_000_000, None if stopped is None else stopped / 1_000_000]
                                              for began, stopped in result.signal_held]
    return record
