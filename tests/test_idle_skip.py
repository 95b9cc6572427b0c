"""Idle-scan skipping (verifier.sim.idle, issue 12) must not change a single byte of what a
run produces: the fast path (skipping) and the plain scan-by-scan path give the same
result on every bundled scenario, on random scenarios of the robot examples with random
faults, scan times, jitter and inputs, and on random timer/clock-relay programs.

Each comparison also checks that the fast path did skip (so none of them can pass by
running scan by scan), and a control shows the comparison catches a skip that ends late.
"""
from __future__ import annotations

import json
import re
from pathlib import Path

import pytest
from hypothesis import HealthCheck, example, given, settings
from hypothesis import strategies as st

from sim_helpers import comparable
from verifier.sim import idle as idle_module
from verifier.verify.report_json import to_dict
from verifier.verify.runner import run_scenario
from verifier.verify.scenario import load_scenario, parse_scenario

ROOT = Path(__file__).resolve().parent.parent
SCENARIOS = sorted((ROOT / "plc" / "scenarios").glob("*.toml"))
PLC = ROOT / "plc"


def _fast_and_plain(scenario, idle_runs):
    idle_runs.clear()
    fast = run_scenario(scenario)
    skipper = idle_runs[-1]
    plain = run_scenario(scenario, plain=True)
    return fast, plain, skipper


# ---- the bundled scenarios ------------------------------------------------------------

@pytest.mark.parametrize("path", SCENARIOS, ids=lambda p: p.stem)
def test_bundled_scenario_same_result_and_report_bytes(path, idle_runs):
    fast, plain, skipper = _fast_and_plain(load_scenario(path), idle_runs)
    assert comparable(fast) == comparable(plain)
    fast.wall_s = plain.wall_s = 0.0
    assert json.dumps(to_dict([fast]), sort_keys=True) == json.dumps(to_dict([plain]), sort_keys=True)
    if skipper.reason is None and all(hasattr(p, "idle_deadline") for p in skipper.rt.pollers):
        assert skipper.skipped_scans > 0, "nothing skipped: the comparison proves nothing"


def test_the_serial_examples_skip_most_scans(idle_runs):
    """The FX3U example waits for its pace timer most of the time: most scans are idle."""
    fast, plain, skipper = _fast_and_plain(load_scenario(PLC / "scenarios" / "fx3u-healthy.toml"), idle_runs)
    assert skipper.reason is None
    assert skipper.skipped_scans > skipper.rt.scan_count // 2
    assert comparable(fast) == comparable(plain)


# ---- the first quiet scan's state (verifier.sim.idle, "The first quiet scan") ---------------

@pytest.mark.parametrize("path", SCENARIOS, ids=lambda p: p.stem)
def test_leaving_out_every_first_quiet_state_changes_no_result(path, idle_runs, monkeypatch):
    """The policy at its extreme: every first quiet scan's state left out (never probed),
    and every state of a quiet scan a jump landed on ("The scan a jump lands on", the same
    constants). Each bundled scenario gives the plain run's result, byte for byte."""
    monkeypatch.setattr(idle_module, "FIRST_SKIP_SCORE", 0)
    monkeypatch.setattr(idle_module, "FIRST_PROBE_EVERY", 10**9)
    fast, plain, skipper = _fast_and_plain(load_scenario(path), idle_runs)
    assert comparable(fast) == comparable(plain)
    fast.wall_s = plain.wall_s = 0.0
    assert json.dumps(to_dict([fast]), sort_keys=True) == json.dumps(to_dict([plain]), sort_keys=True)
    if skipper.reason is None and skipper.skipped_scans:
        assert skipper.first_states_skipped > 0, "none left out: the comparison proves nothing"


def test_the_first_quiet_state_is_left_out_on_the_tcp_route_only(idle_runs):
    """On the TCP route the first quiet scan's state is of no use (the engine's re-arm
    pulse follows it): most are left out, and the run jumps as often as it did. On the
    FX3U example it is of use (the next scan is idle): almost all are taken."""
    fast, plain, skipper = _fast_and_plain(load_scenario(PLC / "scenarios" / "q-tcp-healthy.toml"), idle_runs)
    assert comparable(fast) == comparable(plain)
    assert skipper.first_states_skipped > skipper.jumps // 2
    fast, plain, skipper = _fast_and_plain(load_scenario(PLC / "scenarios" / "fx3u-healthy.toml"), idle_runs)
    assert comparable(fast) == comparable(plain)
    assert skipper.first_states_skipped < skipper.jumps // 20


# ---- the scan a jump lands on (verifier.sim.idle, "The scan a jump lands on") -------------

def _counting_states(monkeypatch) -> list[int]:
    """A list whose one item counts the states the idle check takes from now on."""
    taken = [0]
    make = idle_module.IdleScans._state_reader

    def reader(self):
        state = make(self)

        def counted():
            taken[0] += 1
            return state()
        return counted

    monkeypatch.setattr(idle_module.IdleScans, "_state_reader", reader)
    return taken


@pytest.mark.parametrize("name", ["q-tcp-no-reply", "fx5u-tcp-split"])
def test_the_landing_state_is_left_out_where_it_is_of_no_use(name, idle_runs, monkeypatch):
    """On the TCP route the scan a jump lands on (the pace timer's end: the engine builds
    the next request) changes the program while it counts as quiet, so its state differs
    from the next one. Left out, the run takes about two states a jump (it took 2.8 and
    2.9 on these two with every such state taken), for the same result."""
    taken = _counting_states(monkeypatch)
    fast, plain, skipper = _fast_and_plain(load_scenario(PLC / "scenarios" / f"{name}.toml"), idle_runs)
    assert comparable(fast) == comparable(plain)
    assert skipper.jumps > 100
    assert taken[0] < 2.3 * skipper.jumps


def test_every_landing_state_left_out_changes_no_result(idle_runs, monkeypatch):
    """With every landing state left out (never probed), a run where they are (the TCP
    route, late replies) gives the plain run's result."""
    monkeypatch.setattr(idle_module, "FIRST_SKIP_SCORE", 0)
    monkeypatch.setattr(idle_module, "FIRST_PROBE_EVERY", 10**9)
    for name in ("q-tcp-no-reply", "fx3u-late-reply"):
        fast, plain, skipper = _fast_and_plain(load_scenario(PLC / "scenarios" / f"{name}.toml"), idle_runs)
        assert comparable(fast) == comparable(plain)
        assert skipper.landing_states_skipped > 0, name


# ---- random scenarios of the robot examples --------------------------------------------

def _example(name: str) -> tuple[str, str, str, str, bool]:
    """(sources, PROGRAM, start input, CPU, behind a converter) of a bundled healthy scenario:
    the random scenarios run the examples exactly as the bundled ones load them."""
    text = (PLC / "scenarios" / f"{name}.toml").read_text(encoding="utf-8")
    value = lambda key: re.search(rf"^{key} = (.*)$", text, re.M).group(1)  # noqa: E731
    start = re.search(r"set = \{ (\w+) = true", text).group(1)
    return value("sources"), json.loads(value("program")), start, json.loads(value("platform")), "-tcp-" in name


EXAMPLES = {name: _example(name) for name in ("fx3u-healthy", "fx3u-adprw-healthy", "fx5u-healthy", "q-healthy",
                                               "fx5u-tcp-healthy", "q-tcp-healthy")}


@st.composite
def converters(draw, seconds: int) -> str:
    """A [converter] section: its delays, packing, refusals, drops and split replies."""
    lines = ["[converter]", f'delay = "{draw(st.integers(0, 40))}ms"', f'connect = "{draw(st.integers(0, 80))}ms"',
             f'packing = "{draw(st.integers(1, 20))}ms"']
    if draw(st.booleans()):
        lines.append(f'refuse_until = "{draw(st.integers(1, 4000))}ms"')
    drops = draw(st.lists(st.integers(1, seconds * 1000 - 1), max_size=2))
    if drops:
        lines.append("drops = [" + ", ".join(f'"{ms}ms"' for ms in sorted(drops)) + "]")
    if draw(st.booleans()):
        lines += ["split_reply = true", f'split_gap = "{draw(st.integers(1, 60))}ms"']
    return "\n".join(lines)

FAULTS = st.one_of(
    st.builds(lambda at, d: f'kind = "no_reply"\nat_s = {at}\nduration_s = {d}',
              st.integers(1, 4), st.integers(1, 5)),
    st.builds(lambda n: f'kind = "bad_crc"\non_request = {n}', st.integers(2, 40)),
    st.builds(lambda n, ms: f'kind = "late_reply"\non_request = {n}\ndelay_ms = {ms}',
              st.integers(2, 40), st.integers(50, 1500)),
    st.builds(lambda n, pos: f'kind = "garbage"\non_request = {n}\nposition = "{pos}"',
              st.integers(2, 40), st.sampled_from(["instead", "after"])),
    st.builds(lambda at, d: f'kind = "exception"\nat_s = {at}\nduration_s = {d}\nrequests = "control"\ncode = 4',
              st.integers(1, 4), st.integers(1, 3)),
)


@st.composite
def robot_scenarios(draw):
    example_name = draw(st.sampled_from(sorted(EXAMPLES)))
    sources, program, start, platform, tcp = EXAMPLES[example_name]
    scan_ms = draw(st.integers(2, 20))
    jitter_ms = draw(st.integers(0, scan_ms - 1))
    seconds = draw(st.integers(5, 30))
    lines = [
        'name = "random"', f"sources = {sources}", f'program = "{program}"', f'platform = "{platform}"',
        f'duration = "{seconds}s"', f'scan = "{scan_ms}ms"',
        f'scan_jitter = "{jitter_ms}ms"', f"seed = {draw(st.integers(0, 2**16))}",
        'watch = ["fbEngine.o_wTxCount", "fbCycle.o_wPoint", "fbEngine.o_uErrId"]',
        "[robot]", f"point_duration_s = {draw(st.sampled_from([1.0, 2.5, 6.0]))}",
    ]
    if tcp:
        lines.append(draw(converters(seconds)))
    for fault in draw(st.lists(FAULTS, max_size=3)):
        lines += ["[[faults]]", fault]
    for at_ms in draw(st.lists(st.integers(0, seconds * 1000 - 1), max_size=3)):
        lines += ["[[inputs]]", f'at = "{at_ms}ms"', f"set = {{ {start} = true }}",
                  f'pulse = "{draw(st.integers(1, 800))}ms"']
    lines += ["[[expect]]", 'never = "fbEngine.o_bErr"']
    return "\n".join(lines) + "\n"


@settings(max_examples=16, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(text=robot_scenarios())
@example(text="\n".join([
    'name = "late reply after a pulse"', f"sources = {EXAMPLES['fx3u-healthy'][0]}", 'program = "UITAMR_ExampleFx3"',
    'platform = "fx3u"', 'duration = "12s"', 'scan = "7ms"', 'scan_jitter = "3ms"', "seed = 5",
    "[[faults]]", 'kind = "late_reply"', "on_request = 3", "delay_ms = 700",
    "[[inputs]]", 'at = "1500ms"', "set = { X0 = true }", 'pulse = "300ms"']) + "\n")
def test_random_robot_scenarios_same_result(text, idle_runs):
    scenario = parse_scenario(text, PLC / "scenarios" / "random.toml")
    fast, plain, skipper = _fast_and_plain(scenario, idle_runs)
    assert comparable(fast) == comparable(plain)
    assert skipper.reason is None and skipper.skipped_scans > 0


# ---- random timer and clock-relay programs -----------------------------------------------

def _timer_program(pts: list[int], clock: str, read_et: bool) -> str:
    """Three timers chained in a loop, each Q edge counted and its scan-time trace kept,
    and the edges of one clock relay counted."""
    body = f"""PROGRAM P
VAR
    tmrOn : TON; tmrOff : TOF; tmrPulse : TP;
    nOn : INT; nOff : INT; nPulse : INT; nClock : INT;
    bOnQ : BOOL; bOff : BOOL; bPulse : BOOL; bClock : BOOL;
    wLate : INT;
END_VAR
tmrOn(IN := NOT tmrOn.Q, PT := T#{pts[0]}ms);
IF tmrOn.Q AND NOT bOnQ THEN nOn := nOn + 1; END_IF;
bOnQ := tmrOn.Q;
tmrOff(IN := tmrOn.Q, PT := T#{pts[1]}ms);
IF bOff AND NOT tmrOff.Q THEN nOff := nOff + 1; END_IF;
bOff := tmrOff.Q;
tmrPulse(IN := tmrOff.Q, PT := T#{pts[2]}ms);
IF tmrPulse.Q AND NOT bPulse THEN nPulse := nPulse + 1; END_IF;
bPulse := tmrPulse.Q;
IF {clock} <> bClock THEN nClock := nClock + 1; END_IF;
bClock := {clock};
"""
    if read_et:
        body += "IF tmrOn.ET > T#5ms THEN wLate := wLate + 1; END_IF;\n"
    return body + "END_PROGRAM\n"


def _timer_scenario(tmp_path: Path, source: str, scan_ms: int, jitter_ms: int, seed: int, platform: str,
                    watch_clock: str | None = None) -> object:
    st_file = tmp_path / "timers.st"
    st_file.write_text(source, encoding="utf-8")
    watch = ["nOn", "nOff", "nPulse", "nClock", "wLate", "bOnQ", "bOff", "bPulse"]
    if watch_clock:
        watch.append(watch_clock)
    text = "\n".join([
        'name = "timers"', f"sources = [{json.dumps(st_file.as_posix())}]", 'program = "P"',
        f'platform = "{platform}"', 'duration = "20s"', f'scan = "{scan_ms}ms"', f'scan_jitter = "{jitter_ms}ms"',
        f"seed = {seed}", f"watch = {json.dumps(watch)}",
    ]) + "\n"
    return parse_scenario(text, tmp_path / "timers.toml")


CLOCKS = {"fx3u": ["M8012", "M8013", "M8014"], "fx5u": ["SM410", "SM412", "SM8013"]}


@settings(max_examples=20, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(pts=st.lists(st.integers(1, 2000), min_size=3, max_size=3), scan_ms=st.integers(1, 25),
       jitter=st.integers(0, 100), seed=st.integers(0, 1000), platform=st.sampled_from(["fx3u", "fx5u"]),
       clock_pick=st.integers(0, 2), watch_clock=st.booleans())
@example(pts=[370, 55, 125], scan_ms=10, jitter=0, seed=0, platform="fx3u", clock_pick=1, watch_clock=False)
def test_random_timer_programs_same_result(tmp_path_factory, idle_runs, pts, scan_ms, jitter, seed, platform,
                                           clock_pick, watch_clock):
    clock = CLOCKS[platform][clock_pick]
    # a watched clock the program does not read: the watch alone must stop the jumps
    source = _timer_program(pts, clock if not watch_clock else "FALSE", read_et=False)
    scenario = _timer_scenario(tmp_path_factory.mktemp("t"), source, scan_ms, scan_ms * jitter // 101, seed,
                               platform, watch_clock=clock if watch_clock else None)
    fast, plain, skipper = _fast_and_plain(scenario, idle_runs)
    assert comparable(fast) == comparable(plain)
    assert skipper.reason is None  # (whether a given draw leaves two quiet scans in a row varies)


@pytest.mark.parametrize("clock", ["M8013", "M8014", "FALSE"])
def test_timer_programs_do_skip(tmp_path, idle_runs, clock):
    scenario = _timer_scenario(tmp_path, _timer_program([370, 55, 125], clock, read_et=False), 10, 0, 0, "fx3u")
    fast, plain, skipper = _fast_and_plain(scenario, idle_runs)
    assert comparable(fast) == comparable(plain)
    assert skipper.skipped_scans > skipper.rt.scan_count // 4
    assert fast.watched["nOn"][-1][1] > 40


def test_a_program_reading_et_runs_scan_by_scan(tmp_path, idle_runs):
    scenario = _timer_scenario(tmp_path, _timer_program([300, 50, 100], "M8013", read_et=True), 10, 0, 0, "fx3u")
    fast, plain, skipper = _fast_and_plain(scenario, idle_runs)
    assert skipper.reason == "the program reads a timer's ET"
    assert skipper.skipped_scans == 0
    assert comparable(fast) == comparable(plain)
    assert fast.watched["wLate"][-1][1] > 0


def test_a_skip_that_ends_late_is_caught(tmp_path, idle_runs, monkeypatch):
    """The control: with the timers' deadline moved one scan late, the comparison fails."""
    late = idle_module.IdleScans._timer_deadline_us
    monkeypatch.setattr(idle_module.IdleScans, "_timer_deadline_us", lambda self: late(self) + 10_000)
    scenario = _timer_scenario(tmp_path, _timer_program([370, 55, 125], "FALSE", read_et=False), 10, 0, 0, "fx3u")
    fast, plain, _ = _fast_and_plain(scenario, idle_runs)
    assert comparable(fast) != comparable(plain)
