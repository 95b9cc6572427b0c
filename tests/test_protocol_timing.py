"""Line timing constants: 9600 bit/s, 8N1, Modbus RTU silences, the manual's pacing."""
from __future__ import annotations

from fractions import Fraction

from hypothesis import given
from hypothesis import strategies as st

from verifier.protocol import (
    BYTE_TIME_EXACT_US,
    BYTE_TIME_US,
    MIN_PERIOD_US,
    RECOMMENDED_PERIOD_US,
    T1_5_US,
    T3_5_US,
    frame_time_us,
)
from verifier.protocol.timing import BAUD, BITS_PER_CHAR


def test_character_time():
    assert BAUD == 9600 and BITS_PER_CHAR == 10
    assert BYTE_TIME_EXACT_US == Fraction(3125, 3)  # 1041.666... µs
    assert BYTE_TIME_US == 1042


def test_silent_intervals():
    assert T1_5_US in (1562, 1563)  # 1562.5 µs rounded
    assert T3_5_US == 3646  # 3645.83 µs rounded
    assert T1_5_US < T3_5_US


def test_pacing():
    assert MIN_PERIOD_US == 250_000
    assert RECOMMENDED_PERIOD_US > MIN_PERIOD_US
    # an 8-byte request and an 8-byte reply fit many times into one period
    assert 2 * frame_time_us(8) + T3_5_US < MIN_PERIOD_US


def test_frame_times():
    assert frame_time_us(8) == 8333
    assert frame_time_us(5) == 5208
    assert frame_time_us(0) == 0


@given(st.integers(0, 10_000))
def test_frame_time_is_exact_to_the_microsecond(length):
    assert abs(frame_time_us(length) - BYTE_TIME_EXACT_US * length) <= Fraction(1, 2)


def test_a_frame_is_split_at_each_pause_where_its_times_allow_one_way():
    from verifier.protocol import splits_at_pauses, frame_time_us, T1_5_US, T3_5_US

    # three 8-byte requests, 1.667 ms apart (what tests/test_verify_cli.py's program sends)
    start, pause = 10_000, 1_667
    ends = [start + frame_time_us(8) + pause, start + 2 * (frame_time_us(8) + pause)]
    end = ends[1] + frame_time_us(8)
    assert splits_at_pauses(start, end, 24, ends) == [((8, pause), (16, pause))]
    # one pause: the characters after it fix where it was
    assert splits_at_pauses(start, ends[0] + frame_time_us(8), 16, ends[:1]) == [((8, pause),)]
    # a pause of 1.5 to 3.5 characters leaves one character either way before another pause:
    # 7 + 9 and 8 + 8 bytes both fit these times, and both are listed (the caller tells them apart)
    long = 2_700
    ends = [start + frame_time_us(8) + 1_600]
    ends.append(ends[0] + frame_time_us(8) + long)
    ways = splits_at_pauses(start, ends[1] + frame_time_us(8), 24, ends)
    seven_then_nine = ((7, 1_600 + frame_time_us(8) - frame_time_us(7)),
                       (16, long + frame_time_us(8) - frame_time_us(9)))
    assert sorted(ways) == [seven_then_nine, ((8, 1_600), (16, long))]
    assert all(T1_5_US <= silence <= T3_5_US for way in ways for _, silence in way)
    # times no way of sending fits (the last pause nearer the start than a character)
    assert splits_at_pauses(start, start + 30_000, 24, [start + 500]) == []
    assert splits_at_pauses(start, start + 10_000, 8, []) == []
