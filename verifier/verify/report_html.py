"""`--html FILE`: one self-contained page (inline CSS/JS, no external resources) per run.

Per scenario: the verdict, counts per rule, an overview strip of the whole run, and a
zoomable, scrollable SVG timing diagram — requests (PLC→robot), replies (robot→PLC), each
request's 250 ms pacing window (red when the next request starts inside it), line events,
and a red marker at every violation — followed by the violations, expectations and frames.
The geometry is computed here at the default zoom; the page's script only rescales it.
"""
from __future__ import annotations

from pathlib import Path
from typing import Iterator

import jinja2

from verifier import __version__
from verifier.textfile import UNENCODABLE, whole_file

from .durations import format_seconds
from .events_shown import EVENTS_AT_MOST, event_class
from .report_trace import LineTimes, blamed_frames, frame_count, records
from .result import ScenarioResult, all_captured, overall_verdict
from .rules import RULES, RULES_BY_ID

DEFAULT_PX_PER_MS = 0.5
MINOR_TICKS_UP_TO_MS = 120_000
#: a page a browser opens at once, however long the run (an hour of fx3u-healthy is 23,000
#: frames): the diagram and the frame table draw at most this many frames - those around
#: each violation's frames, then the run's first ones; `--trace` has every frame
FRAMES_AT_MOST = 4000
#: a page of many runs (--matrix of soak tests) shares this many frames between them, each
#: run keeping at least FRAMES_EACH_AT_LEAST; a page under it draws every run as above
PAGE_FRAMES_AT_MOST = 20_000
FRAMES_EACH_AT_LEAST = 500
CONTEXT_FRAMES = 4  # frames drawn on each side of a frame that is evidence of a violation
VIOLATIONS_AT_MOST = 1000  # violations marked and listed (every one is in --json)


def _environment() -> jinja2.Environment:
    return jinja2.Environment(
        loader=jinja2.PackageLoader("verifier.verify", "templates"),
        autoescape=jinja2.select_autoescape(["html", "j2"]),
        trim_blocks=True,
        lstrip_blocks=True,
    )


def _ms(t_us: int) -> float:
    return round(t_us / 1000, 3)


def _seconds(t_us: int) -> float:
    """A frame's time as its trace line has it (`t`, `t_end`): the page computes from that."""
    return t_us / 1_000_000


# a 10 h run has 3,600 ten-second ticks; a capture with a gap of years would have millions
MAJOR_TICKS_AT_MOST = 5000


def frames_each(results: list[ScenarioResult]) -> int:
    """How many frames each run of the page may draw: FRAMES_AT_MOST, or a share of
    PAGE_FRAMES_AT_MOST when the runs have more frames than that between them."""
    if sum(frame_count(result) for result in results) <= PAGE_FRAMES_AT_MOST:
        return FRAMES_AT_MOST
    return min(FRAMES_AT_MOST, max(FRAMES_EACH_AT_LEAST, PAGE_FRAMES_AT_MOST // len(results)))


def shown_frames(line: LineTimes, blamed: dict, at_most: int = FRAMES_AT_MOST) -> list[int]:
    """The positions (in trace order) of the frames the page draws: all of them, or for a
    longer run `at_most`: those within CONTEXT_FRAMES of a blamed frame, in time order,
    then the first frames of the run. `line`: each frame's (start µs, end µs, direction),
    in trace order, and how many there are (`len`); read once, in order."""
    count = len(line)
    if count <= at_most:
        return list(range(count))
    shown: set[int] = set()
    for k, (t_us, _, direction) in enumerate(line):
        if (t_us, direction) in blamed:
            shown.update(range(max(0, k - CONTEXT_FRAMES), min(count, k + CONTEXT_FRAMES + 1)))
            if len(shown) >= at_most:
                break
    k = 0
    while len(shown) < at_most:
        shown.add(k)
        k += 1
    return sorted(shown)[:at_most]


def _overview(line: LineTimes, end_ms: float, long: bool) -> list[dict]:
    """The overview strip's marks (x in 0..1000): one per position and direction; for a long
    run the positions are half units (a strip is about 1000 px wide), so the page draws at
    most 4002 marks, not a mark per frame."""
    def x(t_us: int) -> float:
        at = round(round(_seconds(t_us) * 1000, 3) / end_ms * 1000, 2)
        return round(at * 2) / 2 if long else at

    marks = {(x(t_us), direction) for t_us, _, direction in line}
    return [{"x": x, "dir": direction} for x, direction in sorted(marks, key=lambda m: (m[0], m[1] != "tx"))]


def _windows(line: LineTimes, drawn: set[int], period_ms: float) -> tuple[list[dict], int]:
    """The pacing window of each drawn request (broken when the next request, drawn or not,
    started inside it), and how many requests the run sent."""
    windows: list[dict] = []
    requests = 0
    waiting = None  # the start (ms) of the last request, when drawn: its window waits for the next one

    def window(t0: float, following: float | None) -> dict:
        return {"t0": round(t0, 3), "t1": round(t0 + period_ms, 3),
                "broken": following is not None and following - t0 <= period_ms}

    for k, (t_us, _, direction) in enumerate(line):
        if direction != "tx":
            continue
        requests += 1
        t0 = _seconds(t_us) * 1000
        if waiting is not None:
            windows.append(window(waiting, t0))
        waiting = t0 if k in drawn else None
    if waiting is not None:
        windows.append(window(waiting, None))
    return windows, requests


def _skipped_before(shown: list[int]) -> list[int]:
    """For each shown frame, how many frames the table leaves out just before it."""
    gaps, previous = [], -1
    for k in shown:
        gaps.append(k - previous - 1)
        previous = k
    return gaps


def scenario_view(index: int, result: ScenarioResult, frames_at_most: int = FRAMES_AT_MOST) -> dict:
    """What the page shows of one run. A run whose frames went to a spool file as it went
    (`ScenarioResult.trace_file`) is read from it pass by pass: only the frames drawn are
    held at once, and the page is the same as from the frames held."""
    line = LineTimes(result)
    shown = shown_frames(line, blamed_frames(result), frames_at_most)
    frames = list(records(result, only=shown))
    last_end_us = max((t_end_us for _, t_end_us, _ in line), default=None)
    # the largest of the frames' ends in ms is the end of the last-ending frame in ms
    end_ms = max([_ms(result.ended_us)] + ([] if last_end_us is None else [_seconds(last_end_us) * 1000])) or 1.0
    period_ms = result.min_period_us / 1000
    windows, requests = _windows(line, set(shown), period_ms)
    for frame, skipped in zip(frames, _skipped_before(shown)):
        frame["t0"] = round(frame["t"] * 1000, 3)
        frame["t1"] = round(frame["t_end"] * 1000, 3)
        frame["time"] = f"{frame['t']:.6f} s"
        frame["skipped"] = skipped
    violations = result.all_violations()
    markers = [
        {"t": _ms(v.t_us), "rule": v.rule, "message": v.message, "time": format_seconds(v.t_us),
         "origin": v.origin, "frames": v.frames}
        for v in violations[:VIOLATIONS_AT_MOST]
    ]
    events = result.events
    if len(events) > EVENTS_AT_MOST:  # the faults first, then the others, in the run's order
        kept = {id(e) for e in sorted(events, key=lambda e: event_class(e.kind) != "fault")[:EVENTS_AT_MOST]}
        events = [e for e in events if id(e) in kept]
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
        "overview": _overview(line, end_ms, long=len(line) > frames_at_most),
        "frames_left_out": len(line) - len(frames),
        "frames_after_last": len(line) - 1 - shown[-1] if shown else 0,
        "windows": windows,
        "markers": markers,
        "violations": len(violations),
        "events": [
            {"t": _ms(e.t_us), "message": e.message, "kind": e.kind, "class": event_class(e.kind),
             "time": format_seconds(e.t_us)}
            for e in events
        ],
        "events_left_out": len(result.events) + result.events_dropped - len(events),
        "ticks": ticks,
        "minor_ticks": minor,
        "end_ms": round(end_ms, 3),
        "period_ms": period_ms,
        # the broken rules first, in the order of their first violation as the console and
        # the JUnit list them, then the others in the rules' own order
        "rules": [
            {"id": rule.id, "title": rule.title, "explanation": rule.explanation,
             "count": len(result.violations.get(rule.id, []))}
            for rule in _rules_in_order(result)
        ],
        "first_finding": result.first_finding,
        "tx": requests,
        "rx": len(line) - requests,
        "ended": format_seconds(result.ended_us),
    }


def _rules_in_order(result: ScenarioResult) -> list:
    """Every rule, the broken ones first as ScenarioResult.broken_rules lists them."""
    broken = [found[0].rule for found in result.broken_rules()]
    return [RULES_BY_ID[rule] for rule in broken] + [rule for rule in RULES if rule.id not in broken]


def _pieces(results: list[ScenarioResult], command: str) -> Iterator[str]:
    """The page, piece by piece as the template gives it; `command`: the one that made it."""
    template = _environment().get_template("report.html.j2")
    each = frames_each(results)
    return template.generate(
        verdict=overall_verdict(results),
        command=command,
        version=__version__,
        scenarios=[scenario_view(i, r, each) for i, r in enumerate(results)],
        px_per_ms=DEFAULT_PX_PER_MS,
        failed=sum(not r.passed for r in results),
        total=len(results),
        captured=all_captured(results),
    )


def render(results: list[ScenarioResult], command: str = "uitamr verify") -> str:
    return "".join(_pieces(results, command))


def write(results: list[ScenarioResult], path: Path, command: str = "uitamr verify") -> None:
    # written as the template goes: the page of a --matrix of soak tests is tens of MB, and
    # the whole text at once (with its pieces) was the largest thing the command held
    with whole_file(path, encoding="utf-8", errors=UNENCODABLE) as out:
        out.writelines(_pieces(results, command))
