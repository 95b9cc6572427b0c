"""The robot model in virtual time: commands, tasks, status replies, Modbus rules, pacing."""
from __future__ import annotations

import math

import pytest
from hypothesis import given, settings as hsettings, strategies as st

from verifier.amr import Reply, Robot, RobotConfig
from verifier.protocol import (
    STOP_FRAME,
    ControlCode,
    ControlRequest,
    ExceptionReply,
    ManualMove,
    Query,
    RobotCommand,
    Settings,
    StatusReply,
    StatusRequest,
    crc_ok,
    decode_reply,
    encode,
    with_crc,
)

S = 1_000_000  # µs per second
GAP = 300_000  # a well-paced request period


def control(code: int, command: int, settings: Settings = Settings()) -> bytes:
    return encode(ControlRequest(settings.address, code, command), settings)


def status(query: Query, settings: Settings = Settings()) -> bytes:
    return encode(StatusRequest(settings.address, query), settings)


class Bench:
    """Drives a robot with well-paced requests and decodes its replies."""

    def __init__(self, robot: Robot | None = None, t_us: int = GAP) -> None:
        self.robot = robot or Robot()
        self.t = t_us

    def request(self, frame: bytes, at_us: int | None = None) -> Reply | None:
        if at_us is not None:
            self.t = at_us
        self.t = max(self.t, self.robot.now_us)
        reply = self.robot.on_request(frame, self.t)
        self.t += GAP
        return reply

    def ask(self, query: Query) -> StatusReply:
        request = StatusRequest(self.robot.settings.address, query)
        reply = self.request(encode(request, self.robot.settings))
        assert reply is not None
        decoded = decode_reply(reply.data, self.robot.settings, request)
        assert isinstance(decoded, StatusReply)
        return decoded

    def command(self, code: int, command: int) -> Reply:
        reply = self.request(control(code, command, self.robot.settings))
        assert reply is not None
        return reply

    def stop(self) -> Reply:
        return self.command(ControlCode.ROBOT, RobotCommand.STOP)

    def runs_for(self, code: int, command: int, seconds: float) -> None:
        """Send a task command and check it runs exactly ``seconds``."""
        start = self.t
        self.command(code, command)
        self.robot.advance(start + round(seconds * S) - 1)
        assert self.robot.task_running
        self.robot.advance(start + round(seconds * S))
        assert not self.robot.task_running

    def skip(self, seconds: float) -> None:
        self.t += round(seconds * S)
        self.robot.advance(self.t)


def test_power_on_state_reports_idle_normal_stage_one_battery_ok():
    bench = Bench()
    assert [bench.ask(q).value for q in Query] == [0, 0, 0, 0]
    assert bench.ask(Query.TASK).error == 0
    assert bench.robot.mode == "idle" and not bench.robot.stop_seen


def test_stop_is_echoed_byte_for_byte_after_the_turnaround():
    reply = Robot().on_request(STOP_FRAME, 10_000)
    assert reply.data == bytes.fromhex("01 06 01 A0 00 00 88 14")
    assert reply.delay_us == 5_000


def test_motion_before_the_power_on_stop_is_echoed_but_ignored():
    bench = Bench()
    reply = bench.command(ControlCode.ROBOT, 3)
    assert reply.data == control(ControlCode.ROBOT, 3)
    assert bench.ask(Query.TASK).value == 0
    assert any(e.kind == "ignored" and "no stop command" in e.message for e in bench.robot.events)
    bench.stop()
    bench.command(ControlCode.ROBOT, 3)
    assert bench.ask(Query.TASK).value == 1


def test_before_stop_obey_runs_motion_at_once():
    bench = Bench(Robot(config=RobotConfig(before_stop="obey")))
    bench.command(ControlCode.ROBOT, 3)
    assert bench.ask(Query.TASK).value == 1


def test_point_run_takes_its_configured_duration_then_reports_idle():
    config = RobotConfig(point_duration_s=8.0, point_durations_s={5: 2.0},
                         point_poses={5: (3.0, 4.0, 1.5)})
    bench = Bench(Robot(config=config))
    bench.stop()
    bench.runs_for(ControlCode.ROBOT, 5, 2.0)
    assert bench.robot.pose == pytest.approx((3.0, 4.0, 1.5))
    assert bench.ask(Query.TASK).value == 0
    bench.runs_for(ControlCode.ROBOT, 6, 8.0)


def test_untaught_point_is_accepted_and_does_nothing():
    bench = Bench(Robot(config=RobotConfig(taught_points=(1, 2))))
    bench.stop()
    reply = bench.command(ControlCode.ROBOT, 7)
    assert reply.data == control(ControlCode.ROBOT, 7)
    assert bench.ask(Query.TASK).value == 0
    assert bench.robot.pose == (0.0, 0.0, 0.0)
    assert any("not taught" in e.message for e in bench.robot.events)
    bench.command(ControlCode.ROBOT, 2)
    assert bench.ask(Query.TASK).value == 1


def test_pause_keeps_the_remaining_time_and_the_same_point_resumes():
    bench = Bench()
    bench.stop()
    start = bench.t
    bench.command(ControlCode.ROBOT, 4)  # 8 s
    bench.request(control(ControlCode.ROBOT, RobotCommand.PAUSE), start + 3 * S)
    assert bench.robot.mode == "paused"
    bench.skip(60)
    assert bench.robot.mode == "paused"
    assert bench.ask(Query.TASK).value == 1  # a paused task is not finished
    resume_at = bench.t
    bench.command(ControlCode.ROBOT, 4)
    assert bench.robot.mode == "running"
    bench.robot.advance(resume_at + 5 * S - 1)
    assert bench.robot.mode == "running"
    bench.robot.advance(resume_at + 5 * S)
    assert bench.robot.mode == "idle"


def test_pause_with_nothing_running_is_logged_and_harmless():
    bench = Bench()
    bench.stop()
    bench.command(ControlCode.ROBOT, RobotCommand.PAUSE)
    assert bench.robot.mode == "idle"
    assert bench.robot.events[-1].kind == "ignored"


def test_stop_abandons_a_running_task_where_it_is():
    bench = Bench()
    bench.stop()
    start = bench.t
    bench.command(ControlCode.MOVE_FRONT_POS, 20)  # 2.0 m at 0.2 m/s = 10 s
    bench.request(control(ControlCode.ROBOT, RobotCommand.STOP), start + 5 * S)
    assert bench.robot.mode == "idle"
    assert bench.robot.pose[0] == pytest.approx(1.0)
    bench.skip(30)
    assert bench.robot.pose[0] == pytest.approx(1.0)


@pytest.mark.parametrize("code, units, stage, expected, seconds", [
    (ControlCode.MOVE_FRONT_POS, 10, 0, (1.0, 0.0, 0.0), 5.0),
    (ControlCode.MOVE_FRONT_NEG, 10, 3, (-1.0, 0.0, 0.0), 1.25),
    (ControlCode.MOVE_REAR_POS, 4, 1, (0.4, 0.0, 0.0), 1.0),
    (ControlCode.MOVE_REAR_NEG, 6, 2, (-0.6, 0.0, 0.0), 1.0),
    (ControlCode.MOVE_Y_POS, 8, 1, (0.0, 0.8, 0.0), 2.0),
    (ControlCode.MOVE_Y_NEG, 8, 1, (0.0, -0.8, 0.0), 2.0),
    (ControlCode.ROTATE_POS, 150, 0, (0.0, 0.0, 1.5), 5.0),
    (ControlCode.ROTATE_NEG, 90, 0, (0.0, 0.0, -0.9), 3.0),
])
def test_relative_moves_take_distance_over_stage_speed(code, units, stage, expected, seconds):
    bench = Bench()
    bench.stop()
    bench.command(ControlCode.SPEED_TRACKLESS, stage)
    bench.runs_for(code, units, seconds)
    assert bench.robot.pose == pytest.approx(expected)
    assert bench.ask(Query.SPEED).value == stage


def test_rotation_unit_can_be_degrees():
    bench = Bench(Robot(config=RobotConfig(rotation_unit="deg")))
    bench.stop()
    bench.command(ControlCode.ROTATE_POS, 255)  # 2.55 degrees
    bench.skip(10)
    assert bench.robot.pose[2] == pytest.approx(math.radians(2.55))


def test_codes_10_to_13_follow_the_wire_setting():
    hexy = Settings(codes_10_13="hex")
    bench = Bench(Robot(settings=hexy))
    bench.stop()
    frame = control(ControlCode.MOVE_Y_POS, 5, hexy)
    assert frame[2] == 0x10
    assert bench.request(frame).data == frame
    bench.skip(10)
    assert bench.robot.pose[1] == pytest.approx(0.5)
    # the decimal wire code 0x0A is an illegal value under the hex setting
    reply = bench.request(with_crc(bytes((1, 6, 0x0A, 5, 0, 0))))
    assert decode_reply(reply.data, hexy) == ExceptionReply(1, 6, 3)


def test_field_order_code_low_reads_the_command_from_the_high_byte():
    low = Settings(field_order="code-low")
    bench = Bench(Robot(settings=low))
    stop = control(ControlCode.ROBOT, RobotCommand.STOP, low)
    assert stop[2:4] == bytes((0xA0, 0x01))
    assert bench.request(stop).data == stop
    assert bench.robot.stop_seen


def test_status_order_return_numbers_the_queries_differently():
    ret = Settings(status_order="return")
    bench = Bench(Robot(settings=ret, config=RobotConfig(speed_stage=2, battery_pct=10)))
    raw = with_crc(bytes((1, 1, 0, 0, 0, 0x16)))  # parameter 0 = speed in "return" order
    reply = bench.request(raw)
    assert reply.data[5] == 2
    assert bench.ask(Query.BATTERY).value == 1
    assert bench.ask(Query.BATTERY).error == 3


def test_tape_commands_use_magnetic_speed_and_durations():
    config = RobotConfig(tape_seek_s=2, tape_follow_s=10, tape_rotate_s=4,
                         magnetic_speeds_mps=(0.1, 0.2, 0.3, 0.4))
    bench = Bench(Robot(config=config))
    bench.stop()
    bench.command(ControlCode.SPEED_MAGNETIC, 1)
    start = bench.t
    bench.command(ControlCode.ROBOT, RobotCommand.SEEK_FORWARD)
    assert bench.ask(Query.SPEED).value == 1
    bench.robot.advance(start + 2 * S)
    assert bench.robot.mode == "idle"
    bench.t = start + 2 * S + GAP
    bench.command(ControlCode.ROBOT, RobotCommand.ROTATE_LEFT)
    bench.skip(4)
    assert bench.robot.pose[2] == pytest.approx(math.pi / 2)
    bench.command(ControlCode.ROBOT, RobotCommand.FOLLOW_FORWARD)  # along the heading (+y now)
    bench.skip(10)
    assert bench.robot.pose == pytest.approx((0.0, 2.0, math.pi / 2), abs=1e-9)
    bench.command(ControlCode.ROBOT, RobotCommand.FOLLOW_RIGHT)  # across: towards +x
    bench.skip(10)
    assert bench.robot.pose == pytest.approx((2.0, 2.0, math.pi / 2), abs=1e-9)


def test_manual_moves_need_manual_mode_and_run_until_manual_stop():
    bench = Bench()
    bench.stop()
    bench.command(ControlCode.MANUAL, ManualMove.FORWARD)
    assert bench.robot.events[-1].kind == "ignored"
    bench.command(ControlCode.ROBOT, RobotCommand.MANUAL_MODE)
    assert bench.robot.mode == "manual"
    assert bench.ask(Query.TASK).value == 0
    start = bench.t
    bench.command(ControlCode.MANUAL, ManualMove.FORWARD)
    assert bench.ask(Query.TASK).value == 1
    bench.request(control(ControlCode.MANUAL, ManualMove.STOP), start + 10 * S)
    assert bench.robot.pose[0] == pytest.approx(3.0)  # 0.3 m/s for 10 s
    assert bench.ask(Query.TASK).value == 0
    assert bench.robot.mode == "manual"
    bench.stop()
    assert bench.robot.mode == "idle"


def test_coordinate_reset_zeroes_the_pose_even_mid_move():
    bench = Bench()
    bench.stop()
    start = bench.t
    bench.command(ControlCode.MOVE_FRONT_POS, 20)  # 10 s
    bench.request(control(ControlCode.ROBOT, RobotCommand.RESET), start + 5 * S)
    assert bench.robot.pose == pytest.approx((0.0, 0.0, 0.0))
    bench.robot.advance(start + 10 * S)
    assert bench.robot.pose == pytest.approx((1.0, 0.0, 0.0))


def test_a_new_task_replaces_the_running_one():
    bench = Bench()
    bench.stop()
    bench.command(ControlCode.ROBOT, 1)
    bench.command(ControlCode.MOVE_Y_POS, 2)
    assert "move y" in bench.robot.motion.title
    assert "replaces" in bench.robot.events[-1].message


def test_battery_drains_and_warns_at_the_threshold():
    config = RobotConfig(battery_pct=21.0, battery_low_pct=20.0,
                         battery_drain_running_pct_per_min=6.0, battery_drain_idle_pct_per_min=0.0)
    bench = Bench(Robot(config=config))
    bench.stop()
    assert bench.ask(Query.BATTERY).value == 0
    start = bench.t
    bench.command(ControlCode.ROBOT, 1)  # 8 s running at 0.1 %/s
    bench.skip(60)
    assert bench.robot.battery_pct == pytest.approx(21.0 - 0.8)
    bench.command(ControlCode.MOVE_FRONT_POS, 50)  # 25 s
    bench.skip(60)
    reply = bench.ask(Query.BATTERY)
    assert (reply.value, reply.error) == (1, 3)
    assert bench.ask(Query.VEHICLE).value == 3
    warning = [e for e in bench.robot.events if e.kind == "battery"]
    assert len(warning) == 1
    assert warning[0].t_us > start


# ---- Modbus serial-line rules ---------------------------------------------------------------

def test_bad_crc_and_other_addresses_get_silence():
    robot = Robot()
    broken = STOP_FRAME[:-1] + bytes((STOP_FRAME[-1] ^ 1,))
    assert robot.on_request(broken, 1000) is None
    assert robot.on_request(with_crc(bytes((2, 6, 1, 0xA0, 0, 0))), 400_000) is None
    assert robot.on_request(b"\x01", 800_000) is None
    assert robot.requests == 0
    assert not robot.stop_seen


def test_broadcast_control_is_carried_out_without_a_reply():
    robot = Robot()
    assert robot.on_request(with_crc(bytes((0, 6, 1, 0xA0, 0, 0))), 1000) is None
    assert robot.stop_seen
    assert robot.on_request(with_crc(bytes((0, 1, 0, 0, 0, 0x16))), 400_000) is None


@pytest.mark.parametrize("body, exception", [
    (bytes((1, 3, 0, 0, 0, 1)), (3, 1)),  # FC03: illegal function
    (bytes((1, 0x10, 0, 0, 0, 1, 2, 0, 0)), (0x10, 1)),  # FC16, longer frame
    (bytes((1, 1, 0, 7, 0, 0x16)), (1, 2)),  # query parameter 7: illegal data address
    (bytes((1, 1, 0, 0, 0, 8)), (1, 3)),  # quantity 8: illegal data value
    (bytes((1, 6, 0x0E, 0, 0, 0)), (6, 3)),  # control code 14
    (bytes((1, 6, 1, 0x99, 0, 0)), (6, 3)),  # robot command 0x99
    (bytes((1, 6, 2, 4, 0, 0)), (6, 3)),  # speed stage 5
    (bytes((1, 6, 1, 0xA0, 0, 1)), (6, 3)),  # value field not zero
])
def test_bad_requests_get_the_modbus_exception(body, exception):
    reply = Robot().on_request(with_crc(body), 10_000)
    function, code = exception
    assert reply.data == with_crc(bytes((1, function | 0x80, code)))


def test_an_exception_request_does_nothing():
    robot = Robot()
    robot.on_request(with_crc(bytes((1, 6, 1, 0xA0, 0, 1))), 10_000)
    assert not robot.stop_seen


# ---- pacing ----------------------------------------------------------------------------------

def test_pacing_violation_answered_normally_by_default_and_logged():
    robot = Robot()
    frame = status(Query.TASK)
    robot.on_request(frame, 100_000)
    reply = robot.on_request(frame, 200_000)
    assert reply is not None and reply.delay_us == 5_000
    assert robot.events[-1].kind == "pacing"
    assert "100.0 ms" in robot.events[-1].message


def test_exactly_250_ms_breaks_the_rule_and_251_does_not():
    robot = Robot()
    frame = status(Query.TASK)
    robot.on_request(frame, 100_000)
    robot.on_request(frame, 350_000)
    assert robot.events[-1].kind == "pacing"
    robot.on_request(frame, 600_001)
    assert not robot.events or robot.events[-1].t_us != 600_001


def test_pacing_ignore_drops_the_fast_request():
    robot = Robot(config=RobotConfig(pacing="ignore"))
    robot.on_request(STOP_FRAME, 100_000)
    assert robot.on_request(control(ControlCode.ROBOT, 1), 150_000) is None
    assert robot.mode == "idle"


def test_pacing_ignore_still_marks_a_request_answered_after_dropped_ones():
    """A master at 100 ms with pacing "ignore": the second and third requests were dropped
    and logged, the fourth (300 ms after the first, the last one answered) was answered
    with no `pacing` line, though it too came 100 ms after the one before."""
    robot = Robot(config=RobotConfig(pacing="ignore"))
    frame = status(Query.TASK)
    replies = [robot.on_request(frame, t_us) for t_us in (100_000, 200_000, 300_000, 400_000)]
    assert [reply is not None for reply in replies] == [True, False, False, True]
    messages = [e.message for e in robot.events if e.kind == "pacing"]
    assert len(messages) == 3, messages
    assert messages[-1] == ("request 4 came 100.0 ms after the previous one (must be > 250 ms): answered, as more "
                            "than 250 ms after the last one answered")


def test_pacing_late_answers_when_the_period_is_over():
    robot = Robot(config=RobotConfig(pacing="late"))
    frame = status(Query.TASK)
    robot.on_request(frame, 100_000)
    reply = robot.on_request(frame, 200_000)
    # starts: 100_000 - 8333 and 200_000 - 8333; the period ends 250_001 µs after the first
    assert reply.delay_us == 5_000 + 150_001


def test_pacing_late_says_how_far_apart_the_requests_really_came():
    """Three requests 100 ms apart: the third was logged as coming -49.7 ms after the second
    (measured from the second's delayed answer, not from when it came)."""
    robot = Robot(config=RobotConfig(pacing="late"))
    frame = status(Query.TASK)
    for t_us in (100_000, 200_000, 300_000):
        last = robot.on_request(frame, t_us)
    messages = [e.message for e in robot.events if e.kind == "pacing"]
    assert [m.split(" came ")[1].split(" after")[0] for m in messages] == ["100.0 ms", "100.0 ms"]
    assert last.delay_us == 5_000 + 300_002  # still queued behind the second's late answer


# ---- robustness and determinism --------------------------------------------------------------

@hsettings(max_examples=200, deadline=None)
@given(st.lists(st.tuples(st.binary(min_size=0, max_size=20), st.integers(0, 2_000_000)), max_size=12))
def test_any_bytes_never_crash_and_replies_are_well_formed(script):
    robot = Robot(config=RobotConfig(before_stop="obey"))
    t = 0
    for data, gap in script:
        t += gap
        reply = robot.on_request(data, t)
        if reply is not None:
            assert crc_ok(reply.data)
            assert reply.data[0] == 1


def _run_script(frames):
    robot = Robot(config=RobotConfig(before_stop="obey"))
    out = []
    for i, frame in enumerate(frames):
        reply = robot.on_request(frame, (i + 1) * GAP)
        out.append(None if reply is None else (reply.data, reply.delay_us))
    robot.advance(len(frames) * GAP + 60 * S)
    return out, robot.events, robot.snapshot()


_robot_commands = [int(c) for c in RobotCommand] + list(range(1, 22))
_requests = st.one_of(
    st.builds(lambda v: control(ControlCode.ROBOT, v), st.sampled_from(_robot_commands)),
    st.builds(lambda c, v: control(c, v), st.sampled_from([2, 3, 4]), st.integers(0, 3)),
    st.builds(lambda v: control(ControlCode.MANUAL, v), st.integers(0, 6)),
    st.builds(lambda c, v: control(c, v), st.sampled_from(list(range(6, 14))), st.integers(0, 255)),
    st.builds(status, st.sampled_from(list(Query))),
)


@hsettings(max_examples=50, deadline=None)
@given(st.lists(_requests, max_size=15))
def test_the_same_requests_give_the_same_answers(frames):
    assert _run_script(frames) == _run_script(frames)


def test_time_cannot_go_back():
    robot = Robot()
    robot.advance(1000)
    with pytest.raises(ValueError, match="cannot go back"):
        robot.advance(999)


def test_every_robot_setting_is_in_the_emulator_docs_with_its_default():
    """docs/emulator.md's `[robot]` table is where integrators look up a key: every field
    of RobotConfig is a row, and its default column says what the code does."""
    import re
    from collections.abc import Mapping
    from dataclasses import fields
    from pathlib import Path

    page = (Path(__file__).resolve().parents[1] / "docs" / "emulator.md").read_text(encoding="utf-8")
    rows = {}
    for keys, default in re.findall(r"^\| ((?:`\w+`(?:, )?)+) \| ([^|]+) \|", page, re.M):
        names = re.findall(r"`(\w+)`", keys)
        values = [v.strip() for v in re.split(r",\s(?![^\[]*\])", default)] if len(names) > 1 else [default.strip()]
        rows.update(zip(names, values))
    config = RobotConfig()
    for f in fields(RobotConfig):
        assert f.name in rows, f"docs/emulator.md has no row for [robot] {f.name}"
        shown = rows[f.name].strip("`")
        value = getattr(config, f.name)
        if f.name == "taught_points":
            assert value is None and shown == "all of 1–21"
        elif isinstance(value, str):
            assert shown == f'"{value}"', f.name
        elif isinstance(value, tuple):
            assert shown == str(list(value)), f.name
        elif isinstance(value, Mapping):
            assert shown == "{}" and not value, f.name
        else:
            assert float(shown) == value, f.name
