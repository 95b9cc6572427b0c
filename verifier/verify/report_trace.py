"""`--trace FILE`: every frame on the line as JSON Lines, one frame per line.

Fields: `t`, `t_end` (seconds of virtual time), `dir` ("tx" PLC→robot, "rx" robot→PLC),
`hex` (space-separated bytes), `meaning` (decoded), `origin` (the ST location that sent a
tx frame, when known), `scenario`, and `rules` (ids of the rules this frame is evidence for);
a trace of host times (`uitamr monitor`, `uitamr replay`) also has `tolerance` (seconds), which
a replay of it allows again.

A run of `uitamr verify --trace` without `--html` does not hold its frames: it writes each
one as a spool line while it goes (`spool_line`: everything but `rules`, which only the
judgement at the end knows) and `write` completes the lines. Both ways give the same bytes
(tests/test_verify_trace_spool.py).
"""
from __future__ import annotations

import json
from pathlib import Path
from typing import Iterator

from verifier import protocol

from .evidence import RuleOptions
from .result import ScenarioResult
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


def _blamed(result: ScenarioResult) -> dict[tuple[int, str], set[str]]:
    blamed: dict[tuple[int, str], set[str]] = {}
    for violation in result.all_violations():
        for frame in violation.frames:
            blamed.setdefault((frame.t_us, frame.direction), set()).add(violation.rule)
    return blamed


def records(result: ScenarioResult) -> Iterator[dict]:
    blamed = _blamed(result)
    traffic = analyse(result.trace, result.settings, RuleOptions(reply_timeout_us=result.reply_timeout_us))
    for frame in sorted(result.trace, key=_line_order):
        request = traffic.request_of(frame) if frame.direction == "rx" else None
        record = _frame_fields(result.name, frame, result.settings, request)
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
        yield f"{frame.t_start_us} {frame.direction} {head[:-1]}\n"


def _spooled(result: ScenarioResult) -> Iterator[str]:
    blamed = _blamed(result)
    with open(result.trace_file, encoding="utf-8") as spool:
        for line in spool:
            t_us, direction, head = line.rstrip("\n").split(" ", 2)
            rules = sorted(blamed.get((int(t_us), direction), ()))
            yield f'{head}, "rules": {json.dumps(rules)}}}\n'


def write(results: list[ScenarioResult], path: Path) -> None:
    with open(path, "w", encoding="utf-8") as out:
        for result in results:
            if result.trace_file is not None:
                out.writelines(_spooled(result))
                continue
            for record in records(result):
                out.write(json.dumps(record, ensure_ascii=False) + "\n")
