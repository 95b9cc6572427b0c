"""The emulator's parts without ports: frame assembly on arrival times, the fault file,
and the wall-clock core driven by a fake clock."""
from __future__ import annotations

from pathlib import Path

import pytest
from hypothesis import given, settings as hsettings, strategies as st

from verifier.amr import Robot, RobotConfig
from verifier.emulate import (
    Dropped,
    Emulator,
    FaultFileError,
    ReceivedFrame,
    RequestAssembler,
    load_fault_file,
)
from verifier.emulate.ports import _EchoFilter, serial_assembler
from verifier.protocol import STOP_FRAME, T3_5_US, Query, StatusRequest, encode, with_crc

STATUS = encode(StatusRequest(1, Query.TASK))


def frames_of(items):
    return [i.data for i in items if isinstance(i, ReceivedFrame)]


def test_a_whole_request_completes_at_once_even_in_pieces():
    asm = RequestAssembler(silence_us=20_000)
    assert asm.feed(STOP_FRAME[:3], 0) == []
    done = asm.feed(STOP_FRAME[3:], 9_000)  # a USB chunk 9 ms later: still one frame
    assert done == [ReceivedFrame(STOP_FRAME, 0, 9_000, "length")]
    assert asm.deadline_us() is None


def test_back_to_back_requests_are_cut_apart_by_length():
    asm = RequestAssembler()
    assert frames_of(asm.feed(STOP_FRAME + STATUS, 0)) == [STOP_FRAME, STATUS]


def test_noise_glued_to_a_request_makes_one_bad_frame_at_the_silence():
    asm = RequestAssembler(silence_us=20_000)
    assert asm.feed(b"\xff" + STOP_FRAME, 0) == []
    assert asm.deadline_us() == 20_000
    assert asm.poll(19_999) == []
    assert frames_of(asm.poll(20_000)) == [b"\xff" + STOP_FRAME]


def test_a_request_after_t3_5_of_quiet_is_cut_off_the_noise_before_it():
    asm = RequestAssembler(silence_us=20_000)
    asm.feed(b"\xff\x00", 0)
    done = asm.feed(STOP_FRAME, 3_700)
    assert [(i.data, i.ended_by) for i in done] == [(b"\xff\x00", "silence"), (STOP_FRAME, "length")]


def test_less_than_t3_5_of_quiet_keeps_noise_and_request_together():
    asm = RequestAssembler(silence_us=20_000)
    asm.feed(b"\xff", 0)
    assert asm.feed(STOP_FRAME, 3_000) == []
    assert frames_of(asm.poll(30_000)) == [b"\xff" + STOP_FRAME]


def test_unknown_function_codes_end_by_silence_and_do_not_swallow_the_next_request():
    asm = RequestAssembler(silence_us=20_000)
    fc100 = with_crc(bytes((1, 0x64, 0, 0)))  # no standard length: only a silence ends it
    assert asm.feed(fc100, 0) == []
    assert frames_of(asm.feed(STATUS, 25_000)) == [fc100, STATUS]
    fc3 = with_crc(bytes((1, 3, 0, 0, 0, 1)))  # a standard request: complete at once
    assert frames_of(asm.feed(fc3 + STATUS, 50_000)) == [fc3, STATUS]


def test_a_flood_is_dropped_until_the_line_goes_quiet():
    asm = RequestAssembler(silence_us=20_000)
    assert asm.feed(bytes(200), 0) == []
    assert asm.feed(bytes(200), 1_000) == []
    assert asm.feed(STOP_FRAME, 2_000) == []  # still inside the flood: lost with it
    dropped = asm.poll(22_000)
    assert dropped == [Dropped(408, 0, dropped[0].reason)]
    assert "more than 256" in dropped[0].reason
    assert frames_of(asm.feed(STOP_FRAME, 30_000)) == [STOP_FRAME]


def test_a_request_after_t3_5_of_quiet_ends_a_flood():
    """t3.5 of silence ends any frame, a flood too: the request after it was lost with the
    flood unless the quiet lasted the whole --frame-gap-ms."""
    asm = RequestAssembler(silence_us=20_000)
    assert asm.feed(bytes(300), 0) == []
    assert asm.feed(STOP_FRAME[:3], 5_000) == []  # 5 ms of quiet, then a request in pieces
    done = asm.feed(STOP_FRAME[3:] + STATUS, 6_000)
    assert done[0] == Dropped(300, 0, done[0].reason) and "more than 256" in done[0].reason
    assert done[1:] == [ReceivedFrame(STOP_FRAME, 5_000, 6_000, "length"),
                        ReceivedFrame(STATUS, 6_000, 6_000, "length")]
    assert asm.deadline_us() is None


@hsettings(max_examples=200, deadline=None)
@given(st.lists(st.tuples(st.binary(min_size=1, max_size=300), st.integers(0, T3_5_US - 1)), min_size=1),
       st.integers(T3_5_US, 19_999))
def test_a_flood_then_t3_5_of_quiet_then_a_request_is_always_answered(chunks, quiet_us):
    asm = RequestAssembler(silence_us=20_000)
    t, items = 0, asm.feed(bytes(257), 0)  # a flood from the first chunk on
    for data, gap in chunks:  # never t3.5 of quiet: all of it the flood
        t += gap
        items += asm.feed(data, t)
    items += asm.feed(STOP_FRAME, t + quiet_us)
    assert frames_of(items) == [STOP_FRAME]
    assert [i.data_len for i in items if isinstance(i, Dropped)] == [257 + sum(len(d) for d, _ in chunks)]


@hsettings(max_examples=200, deadline=None)
@given(st.lists(st.tuples(st.binary(max_size=40), st.integers(0, 30_000)), max_size=20))
def test_noise_then_silence_then_a_request_is_always_recovered(chunks):
    asm = RequestAssembler(silence_us=20_000)
    t = 0
    for data, gap in chunks:
        t += gap
        asm.feed(data, t)
    t += 20_000
    asm.poll(t)
    assert frames_of(asm.feed(STOP_FRAME, t + 1)) == [STOP_FRAME]


def test_a_line_on_which_no_frame_has_a_good_crc_is_said_to_be_at_another_speed():
    """A PLC at 19200 into the emulator at 9600 (or A and B swapped): every frame is garbled,
    no reply goes out, and the summary said only "2 frames in, 0 replies out, 2 unanswered".
    The bytes are what a 9600 8N1 receiver reads of the stop and a status read sent at 19200,
    as emulator.md's troubleshooting table quotes the first."""
    emulator = Emulator(Robot(), [].append, FakeClock())
    for data in (bytes.fromhex("28 08 08 68"), bytes.fromhex("18 08 68 AB")):
        assert emulator.handle(ReceivedFrame(data, 0, 0, "silence")) is None
    said = emulator.summary()
    # the words of `uitamr monitor`'s note (commissioning.md quotes it), from one place
    assert said.endswith("; not one of the 2 frame(s) has a good CRC: the line is probably at another speed or "
                         "parity than the 9600 8N1 it was read at, or A and B are swapped; check those before the "
                         "PLC's CRC routine and frame builder"), said
    fast = Emulator(Robot(), [].append, FakeClock(), read_at="19200 8N1")  # `uitamr emulate --baud 19200`
    fast.handle(ReceivedFrame(bytes.fromhex("28 08 08 68"), 0, 0, "silence"))
    assert fast.summary().endswith("; not one of the 1 frame(s) has a good CRC: the line is probably at another "
                                   "speed or parity than the 19200 8N1 it was read at (the robot's is 9600 8N1), or "
                                   "A and B are swapped; check those before the PLC's CRC routine and frame builder")
    page = " ".join((Path(__file__).resolve().parents[1] / "docs" / "emulator.md").read_text(encoding="utf-8").split())
    assert "the summary line ends `not one of the N frame(s) has a good CRC: ...`" in page
    assert "as `28 08 08 68`: half its bytes" in page
    emulator.handle(ReceivedFrame(STOP_FRAME, 0, 0, "length"))  # one good frame: the PLC's own mistakes
    assert "has a good CRC" not in emulator.summary()
    swapped = Emulator(Robot(), [].append, FakeClock())  # its CRC high byte first: the PLC's CRC, not the line
    swapped.handle(ReceivedFrame(STOP_FRAME[:6] + STOP_FRAME[:5:-1], 0, 0, "silence"))
    assert "has a good CRC" not in swapped.summary()

# ---- the fault file ------------------------------------------------------------------------

def test_fault_file_with_robot_table(tmp_path):
    path = tmp_path / "bench.toml"
    path.write_text('[robot]\nturnaround_ms = 8\n\n[[faults]]\nkind = "no_reply"\non_request = 3\n')
    loaded = load_fault_file(path)
    assert loaded.robot == {"turnaround_ms": 8}
    assert [f.kind for f in loaded.faults] == ["no_reply"]


@pytest.mark.parametrize("text, where", [
    ("[[faults]\n", ":1:9: not valid TOML"),
    ("[scenario]\nname = 'x'\n", ":1:1: scenario: unknown key; expected one of robot, faults"),
    ("robot = 3\n", ":1:9: robot: expected a table"),
    ("[[faults]]\nkind = 'late_reply'\non_request = 2\n", ":1:1: faults[0].delay_ms: missing"),
    ('[[faults]]\nkind = "no_reply"\non_request = 1\n\n[[faults]]\nkind = "x"\nat_s = 1\n',
     ":6:8: faults[1].kind: unknown fault 'x'"),
    ("# bench\n[robot]\nturnaround_ms = 8\npacing = 'sometimes'\n", ":4:10: robot.pacing: unknown pacing policy"),
    # a key of a sub-table: its own line, not the first line (was :1:1)
    ("[robot]\nturnaround_ms = 8\n[robot.point_durations_s]\n3 = 2.0\n4 = 'x'\n",
     ":5:5: robot.point_durations_s.4: expected a number"),
    ("[[faults]]\nkind = 'late_reply'\non_request = 2\n\n[[faults]]\nkind = 'late_reply'\n"
     "on_request = 3\ndelay_ms = 5\n", ":1:1: faults[0].delay_ms: missing"),
    ("[[faults]]\nkind = 'no_reply'\non_request = 1\n[[faults]\n", ":4:9: not valid TOML: "),
    # tomllib let int()'s ValueError (more than 4300 digits) through: a traceback
    ("[[faults]]\nkind = 'no_reply'\non_request = " + "9" * 5000 + "\n", ":3:14: not valid TOML: a whole number of 5000 digits"),
])
def test_bad_fault_files_name_the_file_the_line_and_the_key(tmp_path, text, where):
    path = tmp_path / "bad.toml"
    path.write_text(text)
    with pytest.raises(FaultFileError) as caught:
        load_fault_file(path)
    assert str(caught.value).startswith(f"{path}{where}")


CAPTURE = Path(__file__).resolve().parent / "captures" / "bad-master.txt"


@pytest.mark.parametrize("name, text, says", [
    ("site.txt", CAPTURE.read_text(encoding="utf-8"),
     "this is a capture of `uitamr monitor --capture` (times and bytes on the line): `uitamr replay {path}` judges"),
    ("site.jsonl", '{"t": 0.0, "dir": "tx", "hex": "01 06 01 A0 00 00 88 14"}\n',
     "this is a trace (JSON Lines) of `uitamr verify` or `uitamr monitor`: `uitamr replay {path}` judges"),
])
def test_a_capture_given_as_a_fault_file_or_a_scenario_is_named_as_one(tmp_path, name, text, says):
    """`--faults site.txt` or `--scenario site.txt`, the capture from site in place of the
    fault script, said only "site.txt:5:10: not valid TOML: Expected '=' after a key"."""
    from verifier.verify.scenario import ScenarioError, load_scenario

    path = tmp_path / name
    path.write_text(text, encoding="utf-8")
    with pytest.raises(FaultFileError) as caught:
        load_fault_file(path)
    assert "not valid TOML" in str(caught.value) and says.format(path=path) in str(caught.value)
    with pytest.raises(ScenarioError) as caught:
        load_scenario(path)
    assert "not valid TOML" in str(caught.value) and says.format(path=path) in str(caught.value)
    path.write_text("[[faults]\n", encoding="utf-8")  # TOML gone wrong stays just that
    with pytest.raises(FaultFileError) as caught:
        load_fault_file(path)
    assert "this is" not in str(caught.value)


def test_fault_file_refuses_a_wrong_address_fault_with_the_robots_own_address(tmp_path):
    path = tmp_path / "bench.toml"
    path.write_text("[[faults]]\nkind = 'wrong_address'\non_request = 1\naddress = 3\n")
    with pytest.raises(FaultFileError) as caught:
        load_fault_file(path, own_address=3)
    assert str(caught.value).startswith(f"{path}:4:11: faults[0].address: 3 is the robot's own address")
    assert load_fault_file(path, own_address=1).faults[0].address == 3


def test_discard_returns_the_unfinished_bytes_and_forgets_them():
    asm = RequestAssembler(silence_us=20_000)
    assert asm.feed(STOP_FRAME[:5], 1_000) == []
    assert asm.discard() == STOP_FRAME[:5]
    assert asm.poll(1_000_000) == []
    assert frames_of(asm.feed(STOP_FRAME, 2_000_000)) == [STOP_FRAME]


@pytest.mark.parametrize("baud, gap_us, t3_5_us", [
    (9600, 20_000, 3_646), (19200, 20_000, 1_823), (115200, 20_000, 1_750),
    (1200, 29_167, 29_167), (300, 116_667, 116_667),
])
def test_serial_framing_follows_the_speed(baud, gap_us, t3_5_us):
    asm = serial_assembler(baud, 20_000)
    assert (asm.silence_us, asm.t3_5_us) == (gap_us, t3_5_us)
    # a byte every 40 ms: one frame at 300 bit/s (a byte takes 33 ms there), one frame per
    # byte at 9600 (20 ms of silence ends it)
    noise = bytes.fromhex("01 03 00 00 00 01 00 00")
    items = []
    for k, byte in enumerate(noise):
        items += asm.feed(bytes((byte,)), k * 40_000)
    items += asm.poll(len(noise) * 40_000 + gap_us)
    assert frames_of(items) == ([noise] if baud == 300 else [bytes((b,)) for b in noise])


def test_the_echo_filter_drops_only_an_echo_that_comes_in_time():
    echo = _EchoFilter()
    echo.sent(STOP_FRAME, 100)
    assert echo.strip(STOP_FRAME[:3], 10) == b""  # the echo, in two chunks
    assert echo.strip(STOP_FRAME[3:] + STATUS, 20) == STATUS  # a master's request right after it
    assert echo.seen
    assert echo.strip(STOP_FRAME, 30) == STOP_FRAME  # the same bytes again: no echo owed
    echo.sent(STOP_FRAME, 100)
    assert echo.strip(STATUS, 40) == STATUS  # other bytes: not an echo, and none expected now
    assert echo.strip(STOP_FRAME, 50) == STOP_FRAME
    echo.sent(STOP_FRAME, 100)
    assert echo.strip(STOP_FRAME, 101) == STOP_FRAME  # too late to be the echo


def test_the_echo_filter_gives_back_a_masters_bytes_that_only_began_like_the_echo():
    """The port is read a byte as it comes, so a master's next request arrives in pieces;
    its address and function (01 06 ...) are the first bytes of the reply just sent. The
    filter dropped those pieces as the echo's start, then passed the rest on: the request
    lost its head, got a bad CRC and no answer. Bytes that match the echo are held until it
    is whole, and given back with what follows when it turns out not to be the echo."""
    request = with_crc(bytes.fromhex("010601a00001"))  # the same register again, another value
    for first in (1, 2, 5):
        echo = _EchoFilter()
        echo.sent(STOP_FRAME, 100)
        passed = echo.strip(request[:first], 10) + echo.strip(request[first:], 20)
        assert passed == request and not echo.seen
    echo.sent(STOP_FRAME, 100)
    assert echo.strip(STOP_FRAME[:7], 10) == b""  # an echo that loses its last byte is still dropped
    assert echo.strip(STATUS, 200) == STATUS


def test_missing_fault_file(tmp_path):
    with pytest.raises(FaultFileError, match="cannot read"):
        load_fault_file(tmp_path / "nope.toml")


# ---- the core on a fake clock ----------------------------------------------------------------

class FakeClock:
    def __init__(self) -> None:
        self.ns = 1_000_000_000

    def __call__(self) -> int:
        return self.ns


def test_core_schedules_the_reply_after_the_turnaround_and_logs_both_ways():
    clock, lines = FakeClock(), []
    emulator = Emulator(Robot(), lines.append, clock)
    clock.ns += 2_000_000_000
    reply = emulator.handle(ReceivedFrame(STOP_FRAME, 1_990_000, 2_000_000, "length"))
    assert reply.due_us == 2_005_000 and reply.data == STOP_FRAME
    emulator.sent(reply, 2_005_000)
    assert lines[0] == "     2.000 s  <- 01 06 01 A0 00 00 88 14  stop (01/A0)"
    assert lines[1].startswith("     2.000 s  ** command: stop")
    assert lines[2] == "     2.005 s  -> 01 06 01 A0 00 00 88 14  echo: stop (01/A0)"
    assert "1 frame in, 1 reply out" in emulator.summary()


@pytest.mark.parametrize("turnaround_ms, t3_5_us, delay_us", [
    (0, T3_5_US, T3_5_US),  # 9600 bit/s: was sent 0 µs after the request
    (2, T3_5_US, T3_5_US),
    (5, 29_167, 29_167),  # 1200 bit/s: was 5 ms, inside the request's own t3.5
    (40, 29_167, 40_000),  # a longer turnaround stands
])
def test_core_never_schedules_a_reply_before_t3_5_has_ended_the_request(turnaround_ms, t3_5_us, delay_us):
    emulator = Emulator(Robot(config=RobotConfig(turnaround_ms=turnaround_ms)), [].append, FakeClock(),
                        t3_5_us=t3_5_us)
    reply = emulator.handle(ReceivedFrame(STOP_FRAME, 0, 1_000_000, "length"))
    assert reply.due_us == 1_000_000 + delay_us


def test_core_describes_a_status_reply_with_its_query():
    clock, lines = FakeClock(), []
    emulator = Emulator(Robot(), lines.append, clock)
    reply = emulator.handle(ReceivedFrame(STATUS, 0, 0, "length"))
    emulator.sent(reply, 5_000)
    assert "task status" in lines[-1] and "idle" in lines[-1]


def test_core_counts_silence_and_floods():
    clock, lines = FakeClock(), []
    emulator = Emulator(Robot(), lines.append, clock)
    assert emulator.handle(ReceivedFrame(b"\xff", 0, 0, "silence")) is None
    assert emulator.handle(Dropped(999, 10, "999 bytes without a silence")) is None
    assert "1 unanswered" in emulator.summary() and "999 flood bytes" in emulator.summary()
    assert lines[-1].endswith("!! 999 bytes without a silence")


def test_standard_requests_of_other_function_codes_complete_by_length_too():
    asm = RequestAssembler(silence_us=20_000)
    fc16 = with_crc(bytes((1, 0x10, 0, 0, 0, 1, 2, 0, 0)))
    assert asm.feed(fc16[:7], 0) == []
    assert frames_of(asm.feed(fc16[7:], 1_000)) == [fc16]


@hsettings(max_examples=300, deadline=None)
@given(st.binary(max_size=300))
def test_any_noise_fed_byte_by_byte_never_raises(noise):
    asm = RequestAssembler(silence_us=20_000)
    for i, byte in enumerate(noise):
        asm.feed(bytes((byte,)), i * 100)
    asm.poll(10_000_000)
