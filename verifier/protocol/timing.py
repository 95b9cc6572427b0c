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


#: More ways than this to split one frame at its pauses: not worked out (see below).
MAX_PAUSE_SPLITS = 64


def splits_at_pauses(t_start_us: int, t_end_us: int, length: int,
                     pauses_us: list[int]) -> list[tuple[tuple[int, int], ...]]:
    """How a frame of `length` characters at 9600 8N1, on the line from `t_start_us` (its
    first start bit) to `t_end_us` (its last stop bit's end), may have been sent, given
    where the pauses inside it end (`pauses_us`: the start of the character after each).
    Each way is a tuple with one (k, silence in µs) a pause: the characters sent before it
    and how long it lasted.

    Between two pauses the characters go back to back, and each pause is longer than t1.5
    (else it is no pause) and shorter than t3.5 (else the line ends the frame there). The
    characters after the last pause fix its place exactly (the frame's end is known), so
    one pause gives one way at most. Before another pause, a silence of 1.5 to 3.5
    characters leaves one character either way: two pauses may give two ways, which the
    caller tells apart from the bytes or does not split at all. (A silence of t1.5 or less
    is no pause, but it takes time: where one is, the way listed may be a character off,
    or none be listed. The caller checks what it splits.) [] when the times allow no way
    (or more than MAX_PAUSE_SPLITS ways: not listed)."""
    if not pauses_us:
        return []
    tail = round((t_end_us - pauses_us[-1]) / BYTE_TIME_EXACT_US)  # after the last pause
    if not 1 <= tail < length:
        return []
    ways: list[tuple[tuple[int, int], ...]] = [()]
    for i, end in enumerate(pauses_us):
        begin = pauses_us[i - 1] if i else t_start_us  # where this run of characters began
        longer: list[tuple[tuple[int, int], ...]] = []
        lowest = max(1, int((end - begin - T3_5_US) / BYTE_TIME_EXACT_US) - 1)  # no pause is longer
        for way in ways:
            sent = way[-1][0] if way else 0
            for count in range(lowest, length - sent):
                silence = end - (begin + frame_time_us(count))
                if silence < T1_5_US:
                    break
                if silence <= T3_5_US:  # the bounds included: never rule out the way it was
                    longer.append(way + ((sent + count, silence),))
        if len(longer) > MAX_PAUSE_SPLITS:
            return []
        ways = longer
    return [way for way in ways if way[-1][0] == length - tail]
