"""Scripted faults, and loading robot configs and faults from TOML-style tables."""
from __future__ import annotations

import tomllib

import pytest

from verifier.amr import ConfigError, Fault, Robot, RobotConfig, faults_from_list
from verifier.amr.faults import FAULT_KINDS
from verifier.protocol import (
    STOP_FRAME,
    Settings,
    ControlCode,
    ControlRequest,
    Query,
    RobotCommand,
    StatusRequest,
    crc_ok,
    encode,
    with_crc,
)

S = 1_000_000
STATUS_TASK = encode(StatusRequest(1, Query.TASK))
STATUS_VEHICLE = encode(StatusRequest(1, Query.VEHICLE))
STATUS_BATTERY = encode(StatusRequest(1, Query.BATTERY))


def control(code: int, command: int) -> bytes:
    return encode(ControlRequest(1, code, command))


def robot_with(*faults: dict, **config) -> Robot:
    return Robot(config=RobotConfig(**config), faults=faults_from_list(list(faults)))


def answers(robot: Robot, frames: list[bytes], start: int = 300_000, period: int = 300_000):
    out = []
    for i, frame in enumerate(frames):
        out.append(robot.on_request(frame, start + i * period))
    return out


def status_bytes(reply) -> tuple[int, int]:
    """(error, value) of a status reply."""
    return reply.data[4], reply.data[5]


# ---- state faults ------------------------------------------------------------------------

def test_anti_collision_stops_the_task_and_latches_until_stop():
    robot = robot_with({"kind": "anti_collision", "at_s": 3.0})
    answers(robot, [STOP_FRAME, control(ControlCode.ROBOT, 2)], start=300_000)
    robot.advance(3 * S - 1)
    assert robot.mode == "running"
    robot.advance(3 * S)
    assert robot.mode == "idle" and robot.error == 1
    task, vehicle = answers(robot, [STATUS_TASK, STATUS_VEHICLE], start=4 * S)
    assert status_bytes(task) == (1, 0)
    assert status_bytes(vehicle) == (1, 1)
    # motion is refused while the obstacle is there; stop clears the latched error
    robot.on_request(control(ControlCode.ROBOT, 2), 5 * S)
    assert robot.mode == "idle"
    robot.on_request(STOP_FRAME, 6 * S)
    assert robot.error == 0
    robot.on_request(control(ControlCode.ROBOT, 2), 7 * S)
    assert robot.mode == "running"


def test_anti_collision_with_a_duration_clears_by_itself_but_not_by_stop():
    robot = robot_with({"kind": "anti_collision", "at_s": 1.0, "duration_s": 2.0})
    robot.on_request(STOP_FRAME, 300_000)
    robot.advance(1 * S)
    assert robot.error == 1
    robot.on_request(STOP_FRAME, 2 * S)
    assert robot.error == 1
    robot.advance(3 * S)
    assert robot.error == 0


def test_anti_collision_has_no_effect_with_range_zero():
    robot = robot_with({"kind": "anti_collision", "at_s": 1.0})
    answers(robot, [STOP_FRAME, control(ControlCode.COLLISION_RANGE, 0), control(ControlCode.ROBOT, 2)])
    robot.advance(2 * S)
    assert robot.error == 0 and robot.mode == "running"
    assert any("range is 0 m" in e.message for e in robot.events)


def test_anti_collision_on_request_shows_in_that_requests_reply():
    robot = robot_with({"kind": "anti_collision", "on_request": 3})
    replies = answers(robot, [STOP_FRAME, control(ControlCode.ROBOT, 1), STATUS_TASK])
    assert status_bytes(replies[2]) == (1, 0)


def test_off_tape_stops_a_tape_task_with_error_two():
    robot = robot_with({"kind": "off_tape", "at_s": 2.0})
    answers(robot, [STOP_FRAME, control(ControlCode.ROBOT, RobotCommand.FOLLOW_FORWARD)])
    robot.advance(2 * S)
    assert robot.mode == "idle" and robot.error == 2
    robot.on_request(control(ControlCode.ROBOT, RobotCommand.SEEK_FORWARD), 3 * S)
    assert robot.mode == "idle"  # refused while off the tape
    robot.on_request(STOP_FRAME, 4 * S)
    assert robot.error == 0


def test_off_tape_has_no_effect_outside_magnetic_mode():
    robot = robot_with({"kind": "off_tape", "at_s": 1.0})
    answers(robot, [STOP_FRAME, control(ControlCode.ROBOT, 5)])
    robot.advance(2 * S)
    assert robot.error == 0 and robot.mode == "running"


def test_low_battery_fault_reports_battery_one_and_error_three():
    robot = robot_with({"kind": "low_battery", "at_s": 1.0, "duration_s": 5.0})
    before, = answers(robot, [STATUS_BATTERY], start=500_000)
    assert status_bytes(before) == (0, 0)
    during, = answers(robot, [STATUS_BATTERY], start=2 * S)
    assert status_bytes(during) == (3, 1)
    after, = answers(robot, [STATUS_BATTERY], start=7 * S)
    assert status_bytes(after) == (0, 0)


def test_anti_collision_outranks_the_battery_warning_in_the_error_byte():
    robot = robot_with({"kind": "low_battery", "at_s": 0.5}, {"kind": "anti_collision", "at_s": 0.6})
    reply, = answers(robot, [STATUS_BATTERY], start=S)
    assert status_bytes(reply) == (1, 1)


# ---- reply faults ------------------------------------------------------------------------

def test_no_reply_loses_the_request_count_times():
    robot = robot_with({"kind": "no_reply", "on_request": 2, "count": 2})
    replies = answers(robot, [STOP_FRAME, control(ControlCode.ROBOT, 1), control(ControlCode.ROBOT, 1),
                              control(ControlCode.ROBOT, 2)])
    assert [r is None for r in replies] == [False, True, True, False]
    assert robot.mode == "running" and "2" in robot.motion.title


def test_late_reply_adds_its_delay():
    robot = robot_with({"kind": "late_reply", "on_request": 1, "delay_ms": 300})
    first, second = answers(robot, [STATUS_TASK, STATUS_TASK])
    assert first.delay_us == 5_000 + 300_000
    assert second.delay_us == 5_000


def test_bad_crc_corrupts_only_the_crc():
    robot = robot_with({"kind": "bad_crc", "on_request": 1})
    reply, = answers(robot, [STOP_FRAME])
    assert reply.data[:-2] == STOP_FRAME[:-2]
    assert not crc_ok(reply.data)
    assert robot.stop_seen  # the command was carried out; only the answer is damaged


def test_exception_fault_refuses_the_command():
    robot = robot_with({"kind": "exception", "on_request": 1, "code": 6})
    reply, = answers(robot, [STOP_FRAME])
    assert reply.data == with_crc(bytes((1, 0x86, 6)))
    assert not robot.stop_seen


@pytest.mark.parametrize("position, build", [
    ("instead", lambda g, r: g),
    ("before", lambda g, r: g + r),
    ("after", lambda g, r: r + g),
])
def test_garbage_replaces_or_surrounds_the_reply(position, build):
    robot = robot_with({"kind": "garbage", "on_request": 1, "data": "DE AD", "position": position})
    reply, = answers(robot, [STOP_FRAME])
    assert reply.data == build(bytes.fromhex("DEAD"), STOP_FRAME)


def test_wrong_address_reply_has_a_valid_crc_and_another_address():
    robot = robot_with({"kind": "wrong_address", "on_request": 1},
                       {"kind": "wrong_address", "on_request": 2, "address": 9})
    first, second = answers(robot, [STATUS_TASK, STATUS_TASK])
    assert first.data[0] == 2 and crc_ok(first.data)
    assert second.data[0] == 9 and crc_ok(second.data)


def test_reply_faults_by_time_window_and_request_filter():
    robot = robot_with({"kind": "no_reply", "at_s": 1.0, "duration_s": 1.0, "requests": "status"})
    frames = [STATUS_TASK, STOP_FRAME, STATUS_TASK, STATUS_TASK, STATUS_TASK, STATUS_TASK]
    replies = answers(robot, frames, start=500_000, period=400_000)
    # times 0.5, 0.9, 1.3, 1.7, 2.1, 2.5 s: only the status requests inside [1, 2) are lost
    assert [r is None for r in replies] == [False, False, True, True, False, False]


def test_at_s_without_duration_hits_one_request():
    robot = robot_with({"kind": "bad_crc", "at_s": 1.0})
    replies = answers(robot, [STATUS_TASK] * 4, start=500_000, period=400_000)
    assert [crc_ok(r.data) for r in replies] == [True, True, False, True]


def test_requests_that_get_no_reply_anyway_are_not_counted():
    robot = robot_with({"kind": "late_reply", "on_request": 1, "delay_ms": 50})
    assert robot.on_request(STOP_FRAME[:-1] + b"\x00", 300_000) is None  # bad CRC
    reply = robot.on_request(STOP_FRAME, 600_000)
    assert reply.delay_us == 55_000


# ---- loading from dicts ------------------------------------------------------------------

def test_fault_file_in_toml_loads():
    text = """
    [[faults]]
    kind = "no_reply"
    on_request = 3

    [[faults]]
    kind = "late-reply"
    at_s = 12.5
    delay_ms = 400
    count = 2

    [[faults]]
    kind = "garbage"
    on_request = 5
    data = [0xFF, 0, 0x55]
    position = "after"
    """
    faults = faults_from_list(tomllib.loads(text)["faults"])
    assert faults[0] == Fault("no_reply", on_request=3)
    assert faults[1] == Fault("late_reply", at_s=12.5, delay_ms=400.0, count=2)
    assert faults[2].data == bytes((0xFF, 0, 0x55)) and faults[2].position == "after"


@pytest.mark.parametrize("items, message", [
    ([{"kind": "no_reply", "on_request": 1}, {"kind": "no_reply", "at_s": 1}, {"kind": "x", "at_s": 1}],
     "faults[2].kind: unknown fault 'x'; expected one of " + ", ".join(FAULT_KINDS)),
    ([{"at_s": 1}], "faults[0].kind: missing; expected one of"),
    # an array or a table as the kind was a TypeError (unhashable) and a traceback
    ([{"kind": ["no_reply"], "at_s": 1}], "faults[0].kind: expected a string, got ['no_reply']; one of"),
    ([{"kind": {"a": 1}, "at_s": 1}], "faults[0].kind: expected a string, got a table; one of"),
    ([{"kind": "no_reply"}], "faults[0]: give exactly one trigger: at_s or on_request"),
    ([{"kind": "no_reply", "at_s": 1, "on_request": 2}], "faults[0]: give exactly one trigger"),
    ([{"kind": "no_reply", "at_s": 1, "colour": "red"}], "faults[0].colour: unknown key; expected one of"),
    ([{"kind": "no_reply", "at_s": 1, "delay_ms": 5}], "faults[0].delay_ms: not used by fault 'no_reply'"),
    ([{"kind": "anti_collision", "at_s": 1, "count": 2}], "faults[0].count: not used by fault 'anti_collision'"),
    ([{"kind": "late_reply", "at_s": 1}], "faults[0].delay_ms: missing"),
    ([{"kind": "late_reply", "at_s": "soon", "delay_ms": 5}], "faults[0].at_s: expected a number, got 'soon'"),
    ([{"kind": "no_reply", "on_request": 0}], "faults[0].on_request: must be at least 1, got 0"),
    ([{"kind": "no_reply", "on_request": 1.5}], "faults[0].on_request: expected a whole number, got 1.5"),
    ([{"kind": "garbage", "on_request": 1, "data": "zz"}], "faults[0].data: expected hex bytes"),
    ([{"kind": "garbage", "on_request": 1, "position": "middle"}], "faults[0].position: unknown position 'middle'"),
    ([{"kind": "exception", "on_request": 1, "code": 0}], "faults[0].code: must be at least 1"),
    ([{"kind": "no_reply", "at_s": 1, "requests": "writes"}], "faults[0].requests: unknown request filter"),
    ("no", "faults: expected a list of fault tables"),
    (["no"], "faults[0]: expected a table of keys"),
])
def test_bad_fault_tables_name_the_key(items, message):
    with pytest.raises(ConfigError) as caught:
        faults_from_list(items)
    assert str(caught.value).startswith(message)


def test_robot_config_from_dict_converts_and_checks():
    config = RobotConfig.from_dict({
        "turnaround_ms": 8, "point_durations_s": {"3": 2.5}, "taught_points": [1, 3],
        "point_poses": {"3": [1, 2, 0]}, "pacing": "late", "trackless_speeds_mps": [0.1, 0.2, 0.3, 0.4],
    })
    assert config.turnaround_us == 8_000
    assert config.point_duration_us(3) == 2_500_000
    assert config.point_duration_us(4) == 8_000_000
    assert config.is_taught(3) and not config.is_taught(2)
    assert config.point_poses[3] == (1.0, 2.0, 0.0)
    assert RobotConfig.from_dict({"taught_points": "all"}).is_taught(21)
    assert RobotConfig() == RobotConfig.from_dict({})


@pytest.mark.parametrize("data, message", [
    ({"turnaround": 5}, "robot.turnaround: unknown key; expected one of turnaround_ms,"),
    ({"turnaround_ms": "5"}, "robot.turnaround_ms: expected a number, got '5'"),
    ({"turnaround_ms": -1}, "robot.turnaround_ms: must be at least 0.0, got -1"),
    ({"speed_stage": 4}, "robot.speed_stage: must be at most 3, got 4"),
    ({"pacing": "drop"}, "robot.pacing: unknown pacing policy 'drop'; expected one of answer, ignore, late"),
    ({"point_durations_s": {"25": 1}}, "robot.point_durations_s.25: must be at most 21, got 25"),
    ({"point_durations_s": {"a": 1}}, "robot.point_durations_s.a: key 'a' must be a whole number written with 0-9"),
    ({"point_durations_s": {" 4": 1}}, "robot.point_durations_s. 4: key ' 4' must be a whole number"),
    ({"point_durations_s": {"+4": 1}}, "robot.point_durations_s.+4: key '+4' must be a whole number"),
    ({"point_durations_s": {"4_0": 1}}, "robot.point_durations_s.4_0: key '4_0' must be a whole number"),
    ({"point_poses": {"2": [1, 2]}}, "robot.point_poses.2: expected [x_m, y_m, heading_rad]"),
    ({"taught_points": [1, 0]}, "robot.taught_points[1]: must be at least 1, got 0"),
    ({"trackless_speeds_mps": [1, 2, 3]}, "robot.trackless_speeds_mps: expected four speeds"),
    ({"magnetic_speeds_mps": [1, 2, 0, 3]}, "robot.magnetic_speeds_mps[2]: must be greater than 0"),
    ({"battery_pct": True}, "robot.battery_pct: expected a number, got true"),
    ([1, 2], "robot: expected a table of keys"),
])
def test_bad_robot_config_names_the_key(data, message):
    with pytest.raises(ConfigError) as caught:
        RobotConfig.from_dict(data)
    assert str(caught.value).startswith(message)


def test_programmatic_config_gets_the_same_checks():
    with pytest.raises(ConfigError, match="robot.before_stop: unknown policy"):
        RobotConfig(before_stop="maybe")


def test_every_fault_kind_is_exercised_here():
    import inspect
    import sys
    source = inspect.getsource(sys.modules[__name__])
    for kind in FAULT_KINDS:
        assert f'"kind": "{kind}"' in source, kind


@pytest.mark.parametrize("own, fault_address", [(1, 1), (7, 7)])
def test_a_wrong_address_fault_with_the_robots_own_address_is_a_config_error(own, fault_address):
    faults = faults_from_list([{"kind": "no_reply", "on_request": 1},
                               {"kind": "wrong_address", "on_request": 2, "address": fault_address}])
    with pytest.raises(ConfigError) as caught:
        Robot(Settings(address=own), RobotConfig(), faults)
    assert caught.value.path == "faults[1].address"
    assert f"{own} is the robot's own address" in caught.value.message


def test_a_wrong_address_fault_with_another_address_is_fine():
    faults = faults_from_list([{"kind": "wrong_address", "on_request": 1, "address": 1}])
    robot = Robot(Settings(address=2), RobotConfig(), faults)
    stop = encode(ControlRequest(2, ControlCode.ROBOT, RobotCommand.STOP))
    reply = robot.on_request(stop, 300_000)
    assert reply.data[0] == 1 and crc_ok(reply.data)


def test_a_scenario_with_a_wrong_address_fault_on_the_robots_own_address_names_the_line():
    from verifier.verify.scenario import ScenarioError, parse_scenario
    text = ('name = "x"\n\n[protocol]\naddress = 4\n\n[[faults]]\nkind = "wrong_address"\n'
            'on_request = 1\naddress = 4\n')
    with pytest.raises(ScenarioError) as caught:
        parse_scenario(text)
    assert str(caught.value).startswith("scenario:9:11: faults[0].address: 4 is the robot's own address")
