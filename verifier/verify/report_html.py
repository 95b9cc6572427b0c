"""`--html FILE`: one self-contained page (inline CSS/JS, no external resources) per run.

Per scenario: the verdict, counts per rule, an overview strip of the whole run, and a
zoomable, scrollable SVG timing diagram — requests (PLC→robot), replies (robot→PLC), each
request's 250 ms pacing window (red when the next request starts inside it), line events,
and a red marker at every violation — followed by the violations, expectations and frames.
The geometry is computed here at the default zoom; the page's script only rescales it.
"""
from __future__ import annotations

from pathlib import Path

import jinja2

from verifier import __version__

from .durations import format_seconds
from .report_trace import records
from .result import ScenarioResult, overall_verdict
from .rules import RULES

DEFAULT_PX_PER_MS = 0.5
MINOR_TICKS_UP_TO_MS = 120_000


def _environment() -> jinja2.Environment:
    return jinja2.Environment(
        loader=jinja2.PackageLoader("verifier.verify", "templates"),
        autoescape=jinja2.select_autoescape(["html", "j2"]),
        trim_blocks=True,
        lstrip_blocks=True,
    )


def _ms(t_us: int) -> float:
    return round(t_us / 1000, 3)


def _event_class(kind: str) -> str:
    """Faults the scenario injected, trouble on the line, or the robot's ordinary doings."""
    if kind == "robot.fault":
        return "fault"
    if not kind.startswith("robot."):
        return "line"
    return "info"


# a 10 h run has 3,600 ten-second ticks; a capture with a gap of years would have millions
MAJOR_TICKS_AT_MOST = 5000


def scenario_view(index: int, result: ScenarioResult) -> dict:
    frames = list(records(result))
    end_ms = max(
        [_ms(result.ended_us)] + [f["t_end"] * 1000 for f in frames]
    ) or 1.0
    requests = [f for f in frames if f["dir"] == "tx"]
    windows = []
    period_ms = result.min_period_us / 1000
    for position, request in enumerate(requests):
        t0 = request["t"] * 1000
        following = requests[position + 1]["t"] * 1000 if position + 1 < len(requests) else None
        windows.append({
            "t0": round(t0, 3),
            "t1": round(t0 + period_ms, 3),
            "broken": following is not None and following - t0 <= period_ms,
        })
    for frame in frames:
        frame["t0"] = round(frame["t"] * 1000, 3)
        frame["t1"] = round(frame["t_end"] * 1000, 3)
        frame["time"] = f"{frame['t']:.6f} s"
    markers = [
        {"t": _ms(v.t_us), "rule": v.rule, "message": v.message, "time": format_seconds(v.t_us),
         "origin": v.origin, "frames": v.frames}
        for v in result.all_violations()
    ]
    major_ms = 1000 if end_ms <= 300_000 else 10_000
    while end_ms / major_ms > MAJOR_TICKS_AT_MOST:  # a capture spanning days or years
        major_ms *= 10
    ticks = [{"t": t, "label": f"{t / 1000:g} s"} for t in range(0, int(end_ms) + 1, major_ms)]
    minor = []
    if end_ms <= MINOR_TICKS_UP_TO_MS:
        minor = [t for t in range(0, int(end_ms) + 1, 100) if t % major_ms]
    return {
        "id": f"s{index}",
        "result": result,
        "frames": frames,
        "windows": windows,
        "markers": markers,
        "events": [
            {"t": _ms(e.t_us), "message": e.message, "kind": e.kind, "class": _event_class(e.kind),
             "time": format_seconds(e.t_us)}
            for e in result.events
        ],
        "ticks": ticks,
        "minor_ticks": minor,
        "end_ms": round(end_ms, 3),
        "period_ms": period_ms,
        "rules": [
            {"id": rule.id, "title": rule.title, "explanation": rule.explanation,
             "count": len(result.violations.get(rule.id, []))}
            for rule in RULES
        ],
        "tx": len(requests),
        "rx": len(frames) - len(requests),
        "ended": format_seconds(result.ended_us),
    }


def render(results: list[ScenarioResult]) -> str:
    template = _environment().get_template("report.html.j2")
    return template.render(
        verdict=overall_verdict(results),
        version=__version__,
        scenarios=[scenario_view(i, r) for i, r in enumerate(results)],
        px_per_ms=DEFAULT_PX_PER_MS,
        failed=sum(not r.passed for r in results),
        total=len(results),
    )


def write(results: list[ScenarioResult], path: Path) -> None:
    Path(path).write_text(render(results), encoding="utf-8")
