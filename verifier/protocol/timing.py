"""Timing of the serial line and of the robot's command pacing, in integer microseconds.

9600 bit/s, 8N1: each character is 10 bits (start, 8 data, stop) = 1041.67 µs. Modbus RTU
(Modbus over Serial Line V1.02, §2.5.1.1) ends a frame after a silence of 3.5 characters
and rejects a frame with a gap of more than 1.5 characters inside it.
"""
from __future__ import annotations

from fractions import Fraction

BAUD = 9600
BITS_PER_CHAR = 10  # start + 8 data + stop (8N1)

#: Exact character time: 3125/3 µs = 1041.666… µs.
BYTE_TIME_EXACT_US = Fraction(1_000_000 * BITS_PER_CHAR, BAUD)
#: Character time rounded to whole microseconds (1042).
BYTE_TIME_US = round(BYTE_TIME_EXACT_US)
#: Longest gap allowed inside a frame: 1.5 characters (1563 µs).
T1_5_US = round(BYTE_TIME_EXACT_US * Fraction(3, 2))
#: Silence that ends a frame: 3.5 characters (3646 µs).
T3_5_US = round(BYTE_TIME_EXACT_US * Fraction(7, 2))

#: The manual: fewer than four commands a second, the period must exceed 250 ms.
MIN_PERIOD_US = 250_000
#: Period the PLC library uses by default (a margin above the minimum).
RECOMMENDED_PERIOD_US = 300_000
#: The manual gives no reply timeout or retry policy; these are our suggested defaults.
DEFAULT_REPLY_TIMEOUT_US = 500_000
DEFAULT_ATTEMPTS = 3


def silence_us(baud: int = BAUD, bits_per_char: int = BITS_PER_CHAR) -> int:
    """t3.5, the silence that ends a frame, at any line speed: 3.5 characters, but fixed at
    1750 µs above 19200 bit/s (Modbus over Serial Line V1.02 §2.5.1.1)."""
    if baud == BAUD and bits_per_char == BITS_PER_CHAR:
        return T3_5_US
    return 1750 if baud > 19200 else round(3.5 * bits_per_char * 1_000_000 / baud)


def gap_limit_us(baud: int = BAUD, bits_per_char: int = BITS_PER_CHAR) -> int:
    """t1.5, the longest silence inside a frame: 1.5 characters, 750 µs above 19200 bit/s."""
    if baud == BAUD and bits_per_char == BITS_PER_CHAR:
        return T1_5_US
    return 750 if baud > 19200 else round(1.5 * bits_per_char * 1_000_000 / baud)


def frame_time_us(length: int, baud: int = BAUD, bits_per_char: int = BITS_PER_CHAR) -> int:
    """Time to send ``length`` characters back to back, rounded to whole µs (halves to
    even, as `round` of the exact Fraction) in whole numbers: the monitor asks it once per
    byte, and a Fraction per byte cost more than all the rest of a replay."""
    whole, part = divmod(1_000_000 * bits_per_char * length, baud)
    return whole + (2 * part > baud or (2 * part == baud and whole % 2 == 1))
