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
