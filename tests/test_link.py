"""The virtual 9600 8N1 line: byte times, t1.5/t3.5, turnaround, collisions, the trace."""
from __future__ import annotations

from dataclasses import replace

import pytest
from hypothesis import given, settings as hsettings, strategies as st

from verifier.amr import Robot, RobotConfig, faults_from_list
from verifier.link import Line, LineConfig, TraceFrame
from verifier.protocol import STOP_FRAME, ControlRequest, Query, StatusRequest, encode, with_crc
from verifier.protocol.strategies import requests
from verifier.protocol.timing import T1_5_US, T3_5_US

STATUS = encode(StatusRequest(1, Query.TASK))
BYTE_END = [0, 1042, 2083, 3125, 4167, 5208, 6250, 7292, 8333]  # k × 3125/3 µs, rounded


def make_line(*faults: dict, **config) -> Line:
    return Line(Robot(config=RobotConfig(**config), faults=faults_from_list(list(faults))))


def test_bytes_take_one_character_time_each_without_drift():
    line = make_line()
    assert line.config.byte_time_us == 1042
    assert [line.config.offset_us(k) for k in range(9)] == BYTE_END
    assert line.config.offset_us(9600) == 10 * 1_000_000  # one second of characters, exactly
    assert line.send(STOP_FRAME, 1_000) == 1_000 + 8_333


def test_reply_starts_after_the_turnaround_and_arrives_byte_by_byte():
    line = make_line()
    line.send(STOP_FRAME, 0, origin="Main.st:12:5")
    received = line.receive_until(100_000)
    reply_start = 8_333 + 5_000
    assert bytes(b for b, _ in received) == STOP_FRAME
    assert [t for _, t in received] == [reply_start + BYTE_END[k + 1] for k in range(8)]
    assert line.trace == [
        TraceFrame(0, 8_333, "tx", STOP_FRAME, "Main.st:12:5"),
        TraceFrame(reply_start, reply_start + 8_333, "rx", STOP_FRAME, None),
    ]


def test_hand_over_trace_gives_the_trace_and_the_line_keeps_no_frames():
    line = make_line()
    line.send(STOP_FRAME, 0, origin="Main.st:12:5")
    line.receive_until(100_000)
    expected = line.trace
    assert line.hand_over_trace() == expected and len(expected) == 2
    assert line.trace == []
    line.send(STATUS, 200_000)  # the line goes on recording
    assert [f.data for f in line.trace] == [STATUS]


def test_receive_until_hands_each_byte_over_once_and_only_when_it_has_arrived():
    line = make_line()
    line.send(STOP_FRAME, 0)
    first = line.receive_until(13_333 + 2_083)  # two bytes of the reply complete
    assert [b for b, _ in first] == [0x01, 0x06]
    rest = line.receive_until(50_000)
    assert bytes(b for b, _ in first + rest) == STOP_FRAME
    assert line.receive_until(60_000) == []


def test_a_reply_never_starts_before_t3_5():
    line = make_line(turnaround_ms=1.0)
    line.send(STOP_FRAME, 0)
    received = line.receive_until(50_000)
    assert received[0][1] == 8_333 + T3_5_US + 1_042


def test_late_reply_fault_shifts_the_reply():
    line = make_line({"kind": "late_reply", "on_request": 1, "delay_ms": 40})
    line.send(STOP_FRAME, 0)
    assert line.receive_until(50_000) == []
    assert line.receive_until(100_000)[0][1] == 8_333 + 45_000 + 1_042


def test_garbage_and_no_reply_reach_the_plc_as_they_are():
    line = make_line({"kind": "garbage", "on_request": 1, "data": "FF 00"}, {"kind": "no_reply", "on_request": 2})
    line.send(STOP_FRAME, 0)
    assert [b for b, _ in line.receive_until(200_000)] == [0xFF, 0x00]
    line.send(STATUS, 400_000)
    assert line.receive_until(600_000) == []


def test_a_send_while_sending_follows_back_to_back_and_joins_the_frame():
    line = make_line()
    line.send(STATUS[:3], 0)
    end = line.send(STATUS[3:], 1_000)  # UART still busy: queued behind the first three bytes
    assert end == 8_333
    line.receive_until(100_000)
    assert [f.data for f in line.trace if f.direction == "tx"] == [STATUS]
    assert any(f.direction == "rx" for f in line.trace)


def test_two_requests_back_to_back_are_one_bad_frame_and_get_silence():
    line = make_line()
    line.send(STOP_FRAME + STATUS, 0)
    assert line.receive_until(300_000) == []
    assert [f.data for f in line.trace] == [STOP_FRAME + STATUS]
    assert any(e.kind == "robot.silent" for e in line.events)


@pytest.mark.parametrize("gap_us, answered", [
    (T1_5_US, True),            # exactly t1.5: still one frame
    (T1_5_US + 1, False),       # over t1.5: discarded
    (T3_5_US - 1, False),       # just under t3.5: still the same (broken) frame
])
def test_a_gap_over_t1_5_inside_a_frame_discards_it(gap_us, answered):
    line = make_line()
    line.send(STOP_FRAME[:4], 0)
    line.send(STOP_FRAME[4:], 4_167 + gap_us)
    received = line.receive_until(300_000)
    assert (received != []) is answered
    kinds = [e.kind for e in line.events]
    assert ("gap" in kinds) is not answered
    assert ("discarded" in kinds) is not answered
    if not answered:
        discarded = next(e for e in line.events if e.kind == "discarded")
        assert discarded.frames == (STOP_FRAME,)
        assert "t1.5" in discarded.message


def test_a_silence_of_t3_5_splits_frames():
    line = make_line()
    line.send(STOP_FRAME[:4], 0)
    line.send(STOP_FRAME[4:], 4_167 + T3_5_US)
    assert line.receive_until(300_000) == []
    assert [f.data for f in line.trace] == [STOP_FRAME[:4], STOP_FRAME[4:]]
    assert sum(e.kind == "robot.silent" for e in line.events) == 2


def test_plc_sending_into_a_reply_is_a_collision():
    line = make_line()
    line.send(STATUS, 0)
    line.advance(20_000)  # the reply (13_333..21_666) is scheduled and under way
    line.send(STOP_FRAME, 20_000, origin="Main.st:40:3")
    got = line.receive_until(400_000)
    # the reply's first six bytes ended before 20 ms; the two overlapping the send are lost
    assert [t for _, t in got] == [13_333 + BYTE_END[k + 1] for k in range(6)]
    collision = next(e for e in line.events if e.kind == "collision")
    assert collision.t_us == 20_000
    assert collision.frames[0] == STOP_FRAME
    assert collision.frames[1][:2] == b"\x01\x01"
    assert "Main.st:40:3" in collision.message
    discarded = next(e for e in line.events if e.kind == "discarded")
    assert "while the robot was transmitting" in discarded.message
    assert not line.robot.stop_seen


def test_a_reply_scheduled_into_a_plc_send_is_a_collision_too():
    line = make_line()
    line.send(STATUS, 0)
    line.send(STOP_FRAME, 12_000)  # queued before the robot even has the request
    got = line.receive_until(400_000)
    assert len(got) < 8  # the overlapping part of the reply never reached the PLC
    assert [e.kind for e in line.events].count("collision") == 1


def test_pacing_late_reply_can_collide_with_the_next_request():
    line = make_line(pacing="late")
    line.send(STATUS, 0)
    line.send(STATUS, 100_000)
    line.send(STATUS, 258_000)  # the late reply to the second request starts at 263.334 ms
    line.receive_until(600_000)
    assert any(e.kind == "collision" for e in line.events)


def test_time_only_moves_forward_and_must_be_integer():
    line = make_line()
    line.receive_until(1_000)
    with pytest.raises(ValueError, match="virtual time only moves forward"):
        line.send(STATUS, 999)
    with pytest.raises(TypeError, match="integer microseconds"):
        line.send(STATUS, 1_500.0)


def test_events_merge_line_and_robot_events_in_time_order():
    line = make_line()
    line.send(STOP_FRAME[:4], 0)
    line.send(STOP_FRAME[4:], 6_000)
    line.send(STOP_FRAME, 400_000)
    line.receive_until(900_000)
    times = [e.t_us for e in line.events]
    assert times == sorted(times)
    assert {"gap", "discarded", "robot.command"} <= {e.kind for e in line.events}


def test_other_baud_rates_use_the_modbus_fixed_silences_above_19200():
    fast = LineConfig(baud=38400)
    assert (fast.gap_limit_us, fast.frame_gap_us) == (750, 1750)
    slow = LineConfig(baud=4800)
    assert slow.byte_time_us == 2083 and slow.frame_gap_us == 7292


def test_the_robot_is_driven_by_the_line_clock():
    line = make_line()
    line.send(STOP_FRAME, 0)
    line.send(encode(ControlRequest(1, 1, 3)), 300_000)
    line.advance(300_000 + 8_333 + 8 * 1_000_000)
    assert line.robot.mode == "idle"
    assert line.robot.now_us == line.now_us


@hsettings(max_examples=150, deadline=None)
@given(st.lists(st.tuples(st.binary(min_size=1, max_size=12), st.integers(0, 400_000)), max_size=10))
def test_random_traffic_never_crashes_and_the_trace_keeps_every_plc_byte(sends):
    line = make_line(before_stop="obey")
    t = 0
    sent = b""
    received = []
    for data, gap in sends:
        t += gap
        line.send(data, t)
        sent += data
        received += line.receive_until(t)
    received += line.receive_until(t + 2_000_000)
    assert b"".join(f.data for f in line.trace if f.direction == "tx") == sent
    frames = line.trace
    assert all(a.t_start_us <= b.t_start_us for a, b in zip(frames, frames[1:]))
    assert [t for _, t in received] == sorted(t for _, t in received)


def _plc_sees(line: Line, frames: list[bytes], period_us: int = 300_000) -> list[bytes]:
    """Send each frame one period apart; what reached the PLC after each."""
    seen = []
    for i, frame in enumerate(frames):
        line.send(frame, i * period_us)
        seen.append(bytes(b for b, _ in line.receive_until((i + 1) * period_us - 1)))
    return seen


VEHICLE = encode(StatusRequest(1, Query.VEHICLE))
FOLLOW = bytes.fromhex("01 06 01 17 00 00")


@pytest.mark.parametrize("fault, expected_second", [
    ({"kind": "bad_crc", "on_request": 2}, lambda ok: ok[:-2] + bytes(b ^ 0xFF for b in ok[-2:])),
    ({"kind": "exception", "on_request": 2, "code": 4}, lambda ok: with_crc(bytes.fromhex("01 81 04"))),
    ({"kind": "wrong_address", "on_request": 2, "address": 7}, lambda ok: with_crc(b"\x07" + ok[1:-2])),
    ({"kind": "anti_collision", "at_s": 0.1}, lambda ok: with_crc(bytes.fromhex("01 01 03 00 01 01"))),
    ({"kind": "low_battery", "at_s": 0.1}, lambda ok: with_crc(bytes.fromhex("01 01 03 00 03 03"))),
    ({"kind": "no_reply", "on_request": 2}, lambda ok: b""),
    ({"kind": "late_reply", "on_request": 2, "delay_ms": 400}, lambda ok: b""),
])
def test_each_fault_as_the_plc_sees_it_on_the_line(fault, expected_second):
    healthy = _plc_sees(make_line(), [STOP_FRAME, VEHICLE])
    faulty = _plc_sees(make_line(fault), [STOP_FRAME, VEHICLE])
    assert faulty[0] == STOP_FRAME
    assert faulty[1] == expected_second(healthy[1])


def test_off_tape_on_the_line_during_a_tape_follow():
    line = make_line({"kind": "off_tape", "at_s": 0.5})
    seen = _plc_sees(line, [STOP_FRAME, with_crc(FOLLOW), VEHICLE])
    assert seen[2] == with_crc(bytes.fromhex("01 01 03 00 02 02"))


_SCRIPTED_FAULTS = st.lists(st.one_of(
    st.fixed_dictionaries({"kind": st.sampled_from(["no_reply", "bad_crc", "garbage", "wrong_address"]),
                           "on_request": st.integers(1, 12)}),
    st.fixed_dictionaries({"kind": st.just("exception"), "on_request": st.integers(1, 12),
                           "code": st.integers(1, 11)}),
    st.fixed_dictionaries({"kind": st.just("late_reply"), "on_request": st.integers(1, 12),
                           "delay_ms": st.integers(1, 150)}),
    st.fixed_dictionaries({"kind": st.sampled_from(["anti_collision", "off_tape", "low_battery"]),
                           "at_s": st.floats(0, 6, allow_nan=False)}),
), max_size=4)


@hsettings(max_examples=60, deadline=None)
@given(st.lists(st.tuples(requests, st.integers(260_000, 900_000)), min_size=1, max_size=12), _SCRIPTED_FAULTS)
def test_well_spaced_requests_get_exactly_what_the_robot_answers_directly(script, faults):
    """The line adds time, never content: requests more than 250 ms apart reach the robot
    whole, and the PLC receives, byte for byte, what the same robot model (same faults)
    answers when it is fed the same frames at the same times without a line."""
    line = Line(Robot(config=RobotConfig(before_stop="obey"), faults=faults_from_list(faults)))
    direct = Robot(config=RobotConfig(before_stop="obey"), faults=faults_from_list(faults))
    t, expected, received = 0, [], []
    for request, gap in script:
        t += gap
        frame = encode(replace(request, address=1))
        end = line.send(frame, t)
        reply = direct.on_request(frame, end, start_us=t)
        if reply is not None:
            first_arrival = end + max(reply.delay_us, T3_5_US) + BYTE_END[1]
            expected.append((reply.data, first_arrival))
        got = line.receive_until(t + 200_000)  # every reply is in long before the next send
        if got:
            received.append((bytes(b for b, _ in got), got[0][1]))
    tail = line.receive_until(t + 2_000_000)
    if tail:
        received.append((bytes(b for b, _ in tail), tail[0][1]))
    assert received == expected
    assert not [e for e in line.events if e.kind in ("collision", "gap", "discarded")]


@hsettings(max_examples=100, deadline=None)
@given(st.lists(st.tuples(requests, st.integers(0, 30_000)), min_size=1, max_size=15))
def test_crowded_traffic_keeps_the_half_duplex_rules(script):
    """Requests sent too close together (collisions, merged frames): whatever happens, the
    robot never answers before t3.5 of silence after the PLC's last byte, never talks over
    itself, and the trace stays in time order."""
    line = Line(Robot(config=RobotConfig(before_stop="obey", turnaround_ms=0)))
    t = 0
    for request, gap in script:
        t += gap
        line.send(encode(replace(request, address=1)), t)
        line.receive_until(t)
    line.receive_until(t + 2_000_000)
    frames = line.trace
    assert all(a.t_start_us <= b.t_start_us for a, b in zip(frames, frames[1:]))
    replies = [f for f in frames if f.direction == "rx"]
    assert all(a.t_end_us <= b.t_start_us for a, b in zip(replies, replies[1:]))
    sends = [f for f in frames if f.direction == "tx"]
    for reply in replies:
        before = [f for f in sends if f.t_end_us <= reply.t_start_us]
        assert before, "a reply with no request before it"
        assert reply.t_start_us - before[-1].t_end_us >= T3_5_US


@hsettings(max_examples=150, deadline=None)
@given(st.lists(st.tuples(st.one_of(requests.map(lambda r: encode(replace(r, address=1))),
                                    st.binary(min_size=1, max_size=12)),
                          st.integers(0, 400_000), st.booleans()), min_size=1, max_size=15),
       _SCRIPTED_FAULTS)
def test_frames_taken_as_they_settle_are_the_trace_in_order(script, faults):
    """`take_settled` along the way (as `uitamr verify` streams a run) hands over exactly
    the frames of the whole trace, in its order, none twice, none changed afterwards: the
    same traffic on a line nobody drains gives the same list."""
    drained = Line(Robot(config=RobotConfig(before_stop="obey"), faults=faults_from_list(faults)))
    whole = Line(Robot(config=RobotConfig(before_stop="obey"), faults=faults_from_list(faults)))
    taken: list[TraceFrame] = []
    frontiers: list[int] = []
    t = 0
    for data, gap, take in script:
        t += gap
        for line in (drained, whole):
            line.receive_until(t)
        if take:  # just before a send that may join the last frame, or collide with a reply
            taken += drained.take_settled()
            assert all(f.t_end_us + T3_5_US <= drained.now_us for f in taken)
            frontiers.append((len(taken), drained.settled_until_us))
        for line in (drained, whole):
            line.send(data, t)
    for line in (drained, whole):
        line.receive_until(t + 2_000_000)
    taken += drained.take_settled()
    taken += drained.hand_over_trace()
    assert taken == whole.trace
    # no frame handed over later starts before the frontier said at the time
    for handed, frontier in frontiers:
        assert all(f.t_start_us >= frontier for f in taken[handed:])


def test_a_frame_the_robot_cannot_read_is_on_the_line_but_discarded():
    """send(..., unreadable=why): the PLC's port runs at another line format; the bytes are
    traced as sent, the robot discards the frame with that reason and stays silent."""
    line = make_line()
    line.send(STOP_FRAME, 0, origin="Main.st:3:1", unreadable="sent at 19200 8N1")
    assert line.receive_until(300_000) == []
    assert [(f.direction, f.data) for f in line.trace] == [("tx", STOP_FRAME)]
    discarded = next(e for e in line.events if e.kind == "discarded")
    assert discarded.message.endswith("discarded by the robot: sent at 19200 8N1")
    assert not line.robot.stop_seen
    line.send(STOP_FRAME, 400_000)                      # the same bytes readable: answered
    assert bytes(b for b, _ in line.receive_until(800_000)) == STOP_FRAME
