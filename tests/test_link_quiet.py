"""The quiet-line shortcut changes speed, never behaviour: the PLC's endpoint
(`send`, `receive_until`) no longer runs the robot's clock on every call, and
`receive_until` on a quiet line returns at once.  Compared here with the line as it was
(every call first brought the line and the robot up to its time, which `Line.advance`
still does): the same bytes at the same times on the line, the same events, the same
robot."""
from __future__ import annotations

from dataclasses import replace
from pathlib import Path

from hypothesis import given, settings as hsettings, strategies as st

import verifier
from test_link import _SCRIPTED_FAULTS
from verifier.amr import Robot, RobotConfig, faults_from_list
from verifier.link import Line
from verifier.protocol.strategies import requests

PLC = Path(__file__).resolve().parents[1] / "plc"


class EagerLine(Line):
    """The line before the shortcuts: every PLC call runs everything up to its time, the
    line never promises a quiet time (so the PLC's port calls it on every scan) and it
    keeps every transmission it ever had for its overlap tests."""

    def _forget_past(self):
        pass

    @property
    def quiet_until_us(self):
        return 0

    @quiet_until_us.setter
    def quiet_until_us(self, value):
        pass

    def send(self, data, t_us, origin=None):
        self.advance(t_us)
        return super().send(data, t_us, origin)

    def receive_until(self, t_us):
        self.advance(t_us)
        return super().receive_until(t_us)


def observed(line: Line, end_us: int):
    line.advance(end_us)
    trace = [(f.t_start_us, f.t_end_us, f.direction, f.data, f.origin) for f in line.trace]
    events = [(e.t_us, e.kind, e.message) for e in line.events]
    return trace, events, line.robot.snapshot()


def robot_pair(faults, **config):
    config = {"before_stop": "obey", "battery_pct": 20.2, "battery_drain_idle_pct_per_min": 3.0,
              "battery_drain_running_pct_per_min": 9.0, **config}
    return [Robot(config=RobotConfig(**config), faults=faults_from_list(faults)) for _ in range(2)]


@hsettings(max_examples=80, deadline=None)
@given(st.lists(st.tuples(requests, st.integers(0, 700_000)), min_size=1, max_size=14),
       _SCRIPTED_FAULTS, st.integers(1_000, 20_000), st.integers(0, 2**16))
def test_same_traffic_events_and_robot_as_the_eager_line(script, faults, scan_us, seed):
    """Requests (tasks that run and end, crowded sends, faults, a battery crossing its
    threshold) polled every scan: both lines hand the PLC the same bytes at the same calls."""
    robots = robot_pair(faults)
    lazy, eager = Line(robots[0]), EagerLine(robots[1])
    t = 0
    for k, (request, gap) in enumerate(script):
        frame = bytes(__import__("verifier.protocol", fromlist=["encode"]).encode(replace(request, address=1)))
        t += gap
        assert lazy.send(frame, t) == eager.send(frame, t)
        polls = (gap + seed + k) % 40 + 1
        for _ in range(polls):
            t += scan_us
            assert lazy.receive_until(t) == eager.receive_until(t)
    assert observed(lazy, t + 3_000_000) == observed(eager, t + 3_000_000)


def test_the_fx3_example_makes_the_same_trace_on_both_lines():
    """A fixed scenario (seeded scan jitter, a point cycle started by X0, scripted faults):
    the simulated PLC talking to the lazy line and to the eager one, byte for byte."""
    sources = sorted((PLC / "core").glob("*.st")) + [
        next(PLC.rglob(f"{pou}.st")) for pou in ("UITAMR_PortFx3", "UITAMR_PointCycle", "UITAMR_ExampleFx3")]
    faults = [{"kind": "late_reply", "on_request": 9, "delay_ms": 120},
              {"kind": "bad_crc", "on_request": 14},
              {"kind": "anti_collision", "at_s": 9.0, "duration_s": 2.0},
              {"kind": "low_battery", "at_s": 20.0, "duration_s": 3.0}]
    results, clocks = [], []
    for make_line in (Line, CalledEveryScan, EagerLine):
        project = verifier.load(*sources, target="gxworks2", scan_ms=10, jitter_ms=2, seed=7)
        line = make_line(robot_pair(faults, point_duration_s=4.0)[0])
        project.attach_serial("fx3:1", line)
        project.run_programs(["UITAMR_ExampleFx3"], ms=2000)
        project.devices["X0"] = True
        project.run_programs(["UITAMR_ExampleFx3"], ms=500)
        project.devices["X0"] = False
        project.run_programs(["UITAMR_ExampleFx3"], ms=27_500)
        line = getattr(line, "line", line)
        clocks.append(line.now_us)
        results.append(observed(line, project.now_us))
    lazy, called, eager = results
    assert len([f for f in lazy[0] if f[2] == "rx"]) > 50
    assert any(kind == "robot.task" for _, kind, _ in lazy[1])
    assert lazy == called == eager
    assert clocks[0] == clocks[1]  # the port's skipped calls moved the line's clock as a call would


class CalledEveryScan:
    """A Line behind an endpoint that promises no quiet time: the PLC's port calls
    receive_until on every scan instead of skipping the calls on a quiet line."""

    def __init__(self, robot):
        self.line = Line(robot)

    def send(self, data, t_us, origin=None):
        return self.line.send(data, t_us, origin)

    def receive_until(self, t_us):
        return self.line.receive_until(t_us)


@hsettings(max_examples=60, deadline=None)
@given(st.lists(st.tuples(requests, st.integers(0, 40_000), st.integers(1, 3)), min_size=2, max_size=30),
       st.integers(1_000, 12_000))
def test_crowded_sends_collide_the_same_on_a_line_that_forgets_the_past(script, poll_us):
    """Sends crowded into the robot's replies (collisions, lost bytes, broken frames),
    some as several back-to-back pieces: the line that lets old transmissions go gives
    the same trace, events and bytes as the one that keeps them all."""
    from verifier.protocol import encode
    robots = robot_pair([])
    lazy, eager = Line(robots[0]), EagerLine(robots[1])
    t = 0
    for request, gap, pieces in script:
        frame = encode(replace(request, address=1))
        t += gap
        cut = len(frame) // pieces
        for k in range(pieces):
            piece = frame[k * cut:] if k == pieces - 1 else frame[k * cut:(k + 1) * cut]
            assert lazy.send(piece, t) == eager.send(piece, t)
        for _ in range(gap // poll_us):
            t += poll_us
            assert lazy.receive_until(t) == eager.receive_until(t)
    assert observed(lazy, t + 3_000_000) == observed(eager, t + 3_000_000)


def test_crowded_sends_do_collide():
    """The crowded-send test above reaches collisions (a fixed example of its kind)."""
    from verifier.protocol import StatusRequest, encode
    robots = robot_pair([])
    lines = [Line(robots[0]), EagerLine(robots[1])]
    frame = encode(StatusRequest(1, 1))
    for line in lines:
        t = 0
        for _ in range(40):
            line.send(frame, t)
            t += 12_000
            line.receive_until(t)
    results = [observed(line, t + 3_000_000) for line in lines]
    assert any(kind == "collision" for _, kind, _ in results[0][1])
    assert results[0] == results[1]
    assert len(lines[0]._replies) < 5 < len(lines[1]._replies)  # the past was let go
