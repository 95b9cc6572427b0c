"""The console summary: one line per scenario, counts per rule, the first violations with
their frames and ST locations, then the verdict. Plain text when not on a terminal (CI logs)."""
from __future__ import annotations

from rich.console import Console
from rich.markup import escape
from rich.table import Table

from verifier.textfile import escape_chars, shown_name

from .durations import format_seconds
from .result import CUT_SHORT, NO_TRAFFIC, UNVERIFIED, ScenarioResult, all_captured, overall_verdict
from .rules import RULES

FIRST_VIOLATIONS = 3  # times listed per broken rule and scenario
SIMULATOR_NOTES = 5  # kinds of simulator note listed per scenario (the JSON and HTML list every one)
#: how the last line counts the captures of each UNVERIFIED verdict: after FAIL, and after the
#: first one's sentence
_COUNTED = {NO_TRAFFIC: ("saw no traffic", "capture(s) with no bytes"), CUT_SHORT: ("cut short", "cut short")}


def verdict_mark(verdict: str) -> str:
    """A verdict as the console and the page show it: PASS, FAIL, NO TRAFFIC, CUT SHORT."""
    return verdict.replace("-", " ").upper()


def render(results: list[ScenarioResult], console: Console, *, first: int = FIRST_VIOLATIONS) -> None:
    for result in results:
        _scenario(result, console, first)
    verdict = overall_verdict(results)
    if len(results) > 1 or verdict == "fail":
        console.print(_rule_table(results))
    # captures (`uitamr monitor`, `uitamr replay`) are no scenarios and hold no expectations
    runs = "capture(s)" if all_captured(results) else "scenario(s)"
    if verdict == "pass":
        met = ", every expectation met" if any(r.expectations for r in results) or runs == "scenario(s)" else ""
        console.print(f"[bold green]PASS[/]: {len(results)} {runs} compliant{met}")
    elif verdict in UNVERIFIED:
        said = [dict(r.unverified)[verdict] for r in results if r.verdict == verdict]
        more = f" (and {len(said) - 1} more {_COUNTED[verdict][1]})" if len(said) > 1 else ""
        # the kinds it outranks (a capture cut short beside one with no bytes): counted here too
        more += "".join(f"; {count} {_COUNTED[kind][0]}" for kind in UNVERIFIED[UNVERIFIED.index(verdict) + 1:]
                        if (count := sum(r.verdict == kind for r in results)))
        console.print(f"[bold yellow]{verdict_mark(verdict)}[/]: {escape(said[0])}{more}")
    else:
        failed = sum(r.verdict == "fail" for r in results)
        also = "".join(f", {count} {_COUNTED[kind][0]}" for kind in UNVERIFIED
                       if (count := sum(r.verdict == kind for r in results)))
        console.print(f"[bold red]FAIL[/]: {failed} of {len(results)} {runs} failed{also}")


def _scenario(result: ScenarioResult, console: Console, first: int) -> None:
    color = {"pass": "green", "fail": "red"}.get(result.verdict, "yellow")  # yellow: UNVERIFIED
    mark = f"[{color}]{verdict_mark(result.verdict)}[/]"
    # a monitored port is a word of the run's name already ("monitor /dev/ttyUSB0"): not
    # twice (a word, not any part: a file "h" is not in the name "fx3u healthy")
    where = f" ({escape(shown_name(result.file))})" if result.file and result.file not in result.name.split() else ""
    tx = result.tx_count
    failed = len(result.failed_expectations)
    expectations = (
        f", {failed} of {len(result.expectations)} expectation(s) failed" if failed
        else "" if result.captured and not result.expectations  # a capture has none to meet
        else f", {len(result.expectations)} expectation(s) met"
    )
    # a capture's PLC is on the line ("the PLC on line" read as "online")
    ran = "the PLC on the line" if result.captured else f"{escape(result.program or 'the PLC')} on {result.platform}"
    console.print(
        f"{mark} [bold]{escape(escape_chars(result.name, str.isprintable))}[/]{where}: {ran}, {tx} request{'' if tx == 1 else 's'} in "
        f"{format_seconds(result.ended_us)}, {result.violation_count} violation(s){expectations}"
    )
    for note in result.notes:
        console.print(f"    [dim]note: {escape(note)}[/]")
    if result.aborted:
        console.print(f"    [red]simulation stopped[/]: {escape(result.aborted)}")
    shown = result.diagnostic_summary[:SIMULATOR_NOTES]
    for line in shown:
        console.print(f"    [yellow]simulator[/] {escape(line)}")
    if len(result.diagnostic_summary) > len(shown):
        console.print(f"    [yellow]simulator[/] and {len(result.diagnostic_summary) - len(shown)} more kind(s) of note "
                      "(see --json or --html)")
    for found in result.broken_rules():
        _rule_block(found, console, first)
    for outcome in result.failed_expectations:
        place = result.place_of(outcome.expectation)
        at = f"  [dim]at {escape(str(place))}[/]" if place is not None else ""
        console.print(f"    [red]expected[/] {escape(outcome.expectation.label)}: {escape(outcome.detail)}{at}")


def _rule_block(found: list, console: Console, first: int) -> None:
    """A broken rule: its count, its first violation with the frames, when the next ones were."""
    if first == 0:
        return
    violation = found[0]
    origin = f"  [dim]sent by {escape(violation.origin)}[/]" if violation.origin else ""
    count = f" ×{len(found)}" if len(found) > 1 else ""
    console.print(
        f"    [red]{violation.rule}[/]{count}, first at {format_seconds(violation.t_us)}: "
        f"{escape(violation.message)}{origin}"
    )
    for frame in violation.frames:
        arrow = "PLC→robot" if frame.direction == "tx" else "robot→PLC"
        console.print(f"      {format_seconds(frame.t_us)} {arrow} {_head(frame.hex)}  [dim]{escape(frame.meaning)}[/]")
    more = [format_seconds(v.t_us) for v in found[1:first]]
    if more:
        rest = len(found) - 1 - len(more)
        tail = f" and {rest} more (see --json or --html)" if rest else ""
        console.print(f"      [dim]also at {', '.join(more)}{tail}[/]")


#: bytes of a frame the console shows; a longer one (frames sent back to back with no gap,
#: 400 of them from a G_OUTPUT held on) is cut there, the reports files keep every byte
HEAD_BYTES = 32


def _head(hex_text: str) -> str:
    """`hex_text` ("01 06 ...") as the console shows it: whole up to HEAD_BYTES bytes, else
    its first HEAD_BYTES bytes, the count and where the rest is."""
    count = len(hex_text.split())
    if count <= HEAD_BYTES:
        return hex_text
    return f"{hex_text[:HEAD_BYTES * 3 - 1]} … ({count} bytes: every one in --json, --trace or --html)"


def _rule_table(results: list[ScenarioResult]) -> Table:
    table = Table(title="violations per rule", title_justify="left")
    table.add_column("rule")
    table.add_column("violations", justify="right")
    table.add_column("scenarios", justify="right")
    for rule in RULES:
        count = sum(len(r.violations.get(rule.id, [])) for r in results)
        scenarios = sum(1 for r in results if r.violations.get(rule.id))
        style = "red" if count else "green"
        table.add_row(rule.id, f"[{style}]{count}[/]", str(scenarios))
    expectations = sum(len(r.failed_expectations) for r in results)
    table.add_row("expectations", f"[{'red' if expectations else 'green'}]{expectations}[/]",
                  str(sum(1 for r in results if r.failed_expectations)))
    return table
