"""`--trace FILE`: every frame on the line as JSON Lines, one frame per line.

Fields: `t`, `t_end` (seconds of virtual time), `dir` ("tx" PLC→robot, "rx" robot→PLC),
`hex` (space-separated bytes), `meaning` (decoded), `origin` (the ST location that sent a
tx frame, when known), `scenario`, and `rules` (ids of the rules this frame is evidence for).
"""
from __future__ import annotations

import json
from pathlib import Path
from typing import Iterator

from verifier import protocol

from .evidence import RuleOptions
from .result import ScenarioResult
from .traffic import analyse, describe_bytes


def records(result: ScenarioResult) -> Iterator[dict]:
    blamed: dict[tuple[int, str], set[str]] = {}
    for violation in result.all_violations():
        for frame in violation.frames:
            blamed.setdefault((frame.t_us, frame.direction), set()).add(violation.rule)
    traffic = analyse(result.trace, result.settings, RuleOptions(reply_timeout_us=result.reply_timeout_us))
    for frame in sorted(result.trace, key=lambda f: (f.t_start_us, f.direction != "tx")):
        request = traffic.request_of(frame) if frame.direction == "rx" else None
        yield {
            "scenario": result.name,
            "t": frame.t_start_us / 1_000_000,
            "t_end": frame.t_end_us / 1_000_000,
            "dir": frame.direction,
            "hex": protocol.hex_bytes(frame.data),
            "meaning": describe_bytes(frame.data, result.settings, frame.direction, request=request),
            "origin": frame.origin,
            "rules": sorted(blamed.get((frame.t_start_us, frame.direction), ())),
        }


def write(results: list[ScenarioResult], path: Path) -> None:
    with open(path, "w", encoding="utf-8") as out:
        for result in results:
            for record in records(result):
                out.write(json.dumps(record, ensure_ascii=False) + "\n")
