"""Data instructions called from ST: MOV, BMOV, FMOV, SET, RST, CRC.

Each function takes the execution condition first, then the operands in the ST order of
docs/st-dialect.md (inputs, then outputs), then the call's location id, and returns ENO.
"""
from __future__ import annotations

from verifier.protocol import crc16


def mov(rt, en, s, d, loc_id):
    if en:
        d.set(0, s)
    return bool(en)


def _bad_count(rt, name, n, loc_id) -> bool:
    if n < 0:
        rt.operation_error(loc_id, f"{name}: n={n} is negative")
        return True
    return False


def bmov(rt, en, s, n, d, loc_id):
    if en and not _bad_count(rt, "BMOV", n, loc_id):
        values = [s.get(k) for k in range(n)]
        for k, v in enumerate(values):
            d.set(k, v)
    return bool(en)


def fmov(rt, en, s, n, d, loc_id):
    if en and not _bad_count(rt, "FMOV", n, loc_id):
        for k in range(n):
            d.set(k, s)
    return bool(en)


def set_(rt, en, d, loc_id):
    """SET d: a bit device/label goes ON (a word bit `D0.3` too)."""
    if en:
        d.set(0, True)
    return bool(en)


def rst(rt, en, d, loc_id):
    """RST d: a bit goes OFF, a word becomes 0."""
    if en:
        cur = d.get(0)
        d.set(0, False if isinstance(cur, bool) else 0)
    return bool(en)


def crc(rt, en, s, n, d, loc_id, eight_bit_device: str):
    """CRC(EN, s, n, d): CRC-16 (x16+x15+x2+1, initial FFFFH — CRC-16/MODBUS) of n bytes.

    16-bit mode (M8161/SM8161 OFF): bytes are taken two per word, low byte first, and the
    result is one word.  8-bit mode (ON): the low byte of each of n words; the result's
    low byte goes to d, its high byte to d+1.  n outside 1..256 is an operation error.
    Manual: FX3U programming manual FNC 188 (manualsbrain 1307693 p.594/596)."""
    if not en:
        return False
    if not 1 <= n <= 256:
        rt.operation_error(loc_id, f"CRC: n={n} is outside 1..256", code=rt.cpu.div_zero_code)
        return True
    a = rt.dev.address(eight_bit_device)
    eight_bit = bool(rt.dev.areas[a.area][a.index])
    if eight_bit:
        value = crc16(s.get_low_bytes(n))
        d.set(0, value & 0xFF)
        d.set(1, value >> 8)
    else:
        d.set(0, crc16(s.get_bytes(n)))
    return True
