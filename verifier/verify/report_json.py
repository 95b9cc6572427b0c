"""`--json FILE`: the whole verdict for machines, with a top-level "verdict": "pass"|"fail"
("no-traffic" for a monitor or replay capture that saw no bytes, "cut-short" for one whose
port went away and whose frames broke no rule)."""
from __future__ import annotations

import json
from dataclasses import asdict
from pathlib import Path
from typing import Any

from verifier import __version__
from verifier.place import Place
from verifier.textfile import UNENCODABLE, whole_file

from .evidence import Violation
from .expectations import ExpectationResult
from .result import UNVERIFIED, ScenarioResult, overall_verdict
from .rules import RULES

#: the report's "schema": raised when a field's place or meaning changes (docs/verifier.md).
#: 2: the TCP route's converter is a scenario's "converter", no longer one of its "faults".
SCHEMA_VERSION = 2


def _seconds(t_us: int | None) -> float | None:
    return None if t_us is None else t_us / 1_000_000


def violation_dict(violation: Violation) -> dict[str, Any]:
    return {
        "rule": violation.rule,
        "t": _seconds(violation.t_us),
        "message": violation.message,
        "origin": violation.origin,
        "frames": [
            {
                "t": _seconds(frame.t_us),
                "t_end": _seconds(frame.t_end_us),
                "dir": frame.direction,
                "hex": frame.hex,
                "meaning": frame.meaning,
                "origin": frame.origin,
            }
            for frame in violation.frames
        ],
    }


def expectation_dict(outcome: ExpectationResult, place: Place | None = None) -> dict[str, Any]:
    """`place`: where the scenario file states it (ScenarioResult.place_of)."""
    return {
        "expectation": outcome.expectation.label,
        "kind": outcome.expectation.kind,
        "passed": outcome.passed,
        "detail": outcome.detail,
        "t": _seconds(outcome.t_us),
        "place": None if place is None else str(place),
    }


def scenario_dict(result: ScenarioResult) -> dict[str, Any]:
    return {
        "name": result.name,
        "file": result.file,
        "description": result.description,
        "verdict": result.verdict,
        # where a CI annotation belongs, as the JUnit test case's file and line (first_place)
        "place": None if (place := result.first_place) is None else str(place),
        "program": result.program,
        "platform": result.platform,
        "channel": result.channel,
        "sources": result.sources,
        "duration": _seconds(result.duration_us),
        "ended": _seconds(result.ended_us),
        "scan": _seconds(result.scan_us),
        "scan_jitter": _seconds(result.scan_jitter_us),
        "seed": result.seed,
        "protocol": asdict(result.settings),
        "faults": result.faults,
        "converter": result.converter,
        "frames": {
            "tx": result.tx_count,
            "rx": result.rx_count,
        },
        "rules": {
            rule.id: {
                "status": "fail" if result.violations.get(rule.id) else "pass",
                "violations": len(result.violations.get(rule.id, [])),
            }
            for rule in RULES
        },
        "violations": [violation_dict(v) for v in result.all_violations()],
        "expectations": [expectation_dict(e, result.place_of(e.expectation)) for e in result.expectations],
        "watched": {
            name: [[_seconds(t), value] for t, value in changes] for name, changes in result.watched.items()
        },
        "aborted": result.aborted,
        "no_traffic": result.no_traffic,
        "cut_short": result.cut_short,
        "notes": list(result.notes),
        "simulator_diagnostics": result.diagnostics,
        "line_events": [{"t": _seconds(e.t_us), "kind": e.kind, "message": e.message} for e in result.events],
    }


def to_dict(results: list[ScenarioResult], command: str = "uitamr verify") -> dict[str, Any]:
    """The report; `command`: the one that made it (a capture's is `uitamr monitor` or `uitamr replay`)."""
    return {
        "verdict": overall_verdict(results),
        "schema": SCHEMA_VERSION,
        "tool": {"name": command, "version": __version__},
        "summary": {
            "scenarios": len(results),
            "passed": sum(r.passed for r in results),
            # passed + failed + no_traffic + cut_short = scenarios
            "failed": sum(r.verdict == "fail" for r in results),
            **{verdict.replace("-", "_"): sum(r.verdict == verdict for r in results) for verdict in UNVERIFIED},
            "violations": {
                rule.id: sum(len(r.violations.get(rule.id, [])) for r in results) for rule in RULES
            },
            "failed_expectations": sum(len(r.failed_expectations) for r in results),
        },
        "rules": [{"id": r.id, "title": r.title, "explanation": r.explanation} for r in RULES],
        "scenarios": [scenario_dict(r) for r in results],
    }


def write(results: list[ScenarioResult], path: Path, command: str = "uitamr verify") -> None:
    # streamed to the file: an indented dumps() of a long capture's findings (a 1 MB burst on
    # the monitor: 60,000 violations) holds every piece of the text in one list at once
    with whole_file(path, encoding="utf-8", errors=UNENCODABLE) as out:
        json.dump(to_dict(results, command), out, indent=2, ensure_ascii=False)
        out.write("\n")
