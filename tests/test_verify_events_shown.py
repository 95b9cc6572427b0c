"""A run whose only report of events is the HTML page keeps no more of them than the page
can show (verifier/verify/events_shown.py): the page draws at most EVENTS_AT_MOST, the
faults first, so in each list of events one with that many of its class before it can
never be drawn. Tests: on random lists growing in any order and thinned at any moments,
the page's choice and its count of events left out are those of the lists kept whole; on
long runs, the page is the same bytes with and without thinning, and what the run holds
does not grow."""
from __future__ import annotations

import bisect
import re
from dataclasses import dataclass
from pathlib import Path

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from verifier.verify import report_html
from verifier.verify import runner as runner_module
from verifier.verify.events_shown import event_class, keep_first
from verifier.verify.result import Keep
from verifier.verify.runner import run_scenario
from verifier.verify.scenario import load_scenario

ROOT = Path(__file__).resolve().parent.parent
SCENARIOS = ROOT / "plc" / "scenarios"


@dataclass(eq=False)
class Event:
    t_us: int
    kind: str


def _page_choice(line_events: list, robot_events: list, at_most: int) -> tuple[list, int]:
    """What the page draws of a run's events, and how many it leaves out (as runner and
    report_html put them together: line's, then robot's, merged in time order)."""
    merged = [(e, e.kind) for e in line_events] + [(e, f"robot.{e.kind}") for e in robot_events]
    merged.sort(key=lambda pair: pair[0].t_us)
    if len(merged) <= at_most:
        return [e for e, _ in merged], 0
    kept = {id(e) for e, kind in sorted(merged, key=lambda pair: event_class(pair[1]) != "fault")[:at_most]}
    shown = [e for e, _ in merged if id(e) in kept]
    return shown, len(merged) - len(shown)


_events = st.lists(st.tuples(st.integers(0, 50), st.booleans(), st.sampled_from(["gap", "collision", "task", "fault"]),
                             st.booleans()), max_size=60)


@settings(max_examples=300, deadline=None, derandomize=True)
@given(arrivals=_events, at_most=st.integers(0, 8), every=st.integers(1, 10), lag=st.integers(-5, 20),
       beyond=st.integers(0, 10))
def test_thinning_as_the_run_goes_keeps_what_the_page_shows(arrivals, at_most, every, lag, beyond):
    """Events arrive in any time order (the line's by insort, the robot's appended) and the
    lists are thinned every few arrivals up to a moment that may lie before or after them;
    the run ends at or after the last such moment, and the result holds the events up to
    its end (events after it are not counted)."""
    whole_line, whole_robot, line, robot = [], [], [], []
    dropped = 0
    untils = [0]
    for k, (t, on_line, kind, _) in enumerate(arrivals):
        event = Event(t, kind if on_line else kind)
        if on_line:
            bisect.insort(whole_line, event, key=lambda e: e.t_us)
            bisect.insort(line, event, key=lambda e: e.t_us)
        else:
            whole_robot.append(event)
            robot.append(event)
        if k % every == every - 1:
            until = t + lag
            untils.append(until)
            dropped += keep_first(line, at_most, until, lambda e: event_class(e.kind) == "fault")
            dropped += keep_first(robot, at_most, until, lambda e: event_class(f"robot.{e.kind}") == "fault")
    if at_most == 0:
        return  # the page always shows some events; 0 only checks that nothing breaks
    end = max(untils) + beyond  # the runner thins up to min(now, end): never past the end

    def until_end(events: list) -> list:
        return [e for e in events if e.t_us <= end]

    shown, left_out = _page_choice(until_end(whole_line), until_end(whole_robot), at_most)
    shown_thin, left_out_thin = _page_choice(until_end(line), until_end(robot), at_most)
    assert [id(e) for e in shown_thin] == [id(e) for e in shown]
    assert left_out_thin + dropped == left_out


def _stretched(name: str, seconds: int, folder: Path):
    text = (SCENARIOS / f"{name}.toml").read_text(encoding="utf-8").replace('"../', f'"{SCENARIOS.parent.as_posix()}/')
    text = re.sub(r'^duration = "[^"]*"', f'duration = "{seconds}s"', text, count=1, flags=re.M)
    path = folder / f"{name}.toml"
    path.write_text(text, encoding="utf-8")
    return load_scenario(path)


@pytest.mark.parametrize("name, at_most", [("fx3u-bad-crc-persistent", 3), ("fx3u-bad-crc-persistent", 8),
                                           ("fx3u-garbage", 20)])
def test_a_long_run_gives_the_same_page_and_holds_few_events(tmp_path, monkeypatch, name, at_most):
    """Ten minutes: a robot answering with a bad CRC for five seconds (17 fault events, a few
    others: with a cap of 3 or 8 the faults overflow it), and one with garbage on the line
    (14 faults: two single ones and 4 s of every reply; about 175 task events: the others
    overflow it). The page is the same as from every event, and the run holds each class's
    first ones and the last second's."""
    monkeypatch.setattr(runner_module, "STREAM_EVERY_US", 1_000_000)
    monkeypatch.setattr(report_html, "EVENTS_AT_MOST", at_most)
    scenario = _stretched(name, 600, tmp_path)
    whole = run_scenario(scenario, keep=Keep(watched=False, frames_to_file=str(tmp_path)))
    thin = run_scenario(scenario, keep=Keep(watched=False, frames_to_file=str(tmp_path), events_at_most=at_most))
    whole.wall_s = thin.wall_s = 0.0
    assert thin.events_dropped > 0 and whole.events_dropped == 0
    assert len(thin.events) + thin.events_dropped == len(whole.events)
    assert len(thin.events) <= 2 * at_most + 10
    page = report_html.render([whole])
    assert report_html.render([thin]) == page
    assert f"{at_most} of its {len(whole.events)} events (the faults first)" in page


def test_verify_html_keeps_no_more_events_than_the_page_shows(tmp_path, monkeypatch):
    """`uitamr verify --html` asks for the page's events only; with --json, every event."""
    from click.testing import CliRunner

    from verifier.commands import verify as verify_command

    kept = []
    real = verify_command._run_all
    monkeypatch.setattr(verify_command, "_run_all", lambda *a: kept.append(a[4]) or real(*a))
    scenario = SCENARIOS / "fx3u-healthy.toml"
    for extra in ([], ["--json", str(tmp_path / "r.json")]):
        result = CliRunner().invoke(verify_command.command, ["--scenario", str(scenario), "--html",
                                                             str(tmp_path / "r.html"), *extra])
        assert result.exit_code == 0, result.output
    assert [k.events_at_most for k in kept] == [report_html.EVENTS_AT_MOST, None]
