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
        rt.operation_error(loc_id, f"CRC: n={n} is outside 1..256")
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


# ----------------------------------------------------------------------------- more data instructions
def dmov(rt, en, s, d, loc_id):
    """DMOV s d: 32-bit move (a word device destination takes d and d+1, low word first)."""
    if en:
        d.set(0, s)
    return bool(en)


def cml(rt, en, s, d, loc_id):
    """CML s d: bit inversion of a 16-bit value."""
    if en:
        d.set(0, ~int(s) & 0xFFFF)
    return bool(en)


def xch(rt, en, d1, d2, loc_id):
    if en:
        a, b = d1.get(0), d2.get(0)
        d1.set(0, b)
        d2.set(0, a)
    return bool(en)


def swap(rt, en, d, loc_id):
    """SWAP d: exchange the high and low bytes of a word."""
    if en:
        w = d.get_u16(0)
        d.set(0, ((w & 0xFF) << 8) | (w >> 8))
    return bool(en)


def inc(rt, en, d, loc_id, step: int = 1):
    """INC/DEC d: +1 / -1 with 16-bit wrap (K32767 + 1 = K-32768, as the manual states)."""
    if en:
        d.set(0, int(d.get(0)) + step)
    return bool(en)


def logic(rt, en, s1, s2, d, loc_id, op: str):
    """WAND/WOR/WXOR s1 s2 d: 16-bit logical operations."""
    if en:
        a, b = int(s1) & 0xFFFF, int(s2) & 0xFFFF
        d.set(0, {"AND": a & b, "OR": a | b, "XOR": a ^ b}[op])
    return bool(en)


def bcd(rt, en, s, d, loc_id):
    """BCD s d: binary 0..9999 to BCD; anything else is an operation error."""
    if en:
        v = int(s)
        if not 0 <= v <= 9999:
            rt.operation_error(loc_id, f"BCD: {v} is outside 0..9999")
            return True
        d.set(0, int(str(v), 16))
    return bool(en)


def bin_(rt, en, s, d, loc_id):
    """BIN s d: BCD to binary; a nibble above 9 is an operation error."""
    if en:
        text = f"{int(s) & 0xFFFF:04X}"
        if not text.isdigit():
            rt.operation_error(loc_id, f"BIN: H{text} is not a BCD value")
            return True
        d.set(0, int(text))
    return bool(en)


def zrst(rt, en, d1, d2, loc_id):
    """ZRST d1 d2: reset every device from d1 to d2 (same device type)."""
    if en:
        if d1.cells is not d2.cells or not d1.cells:
            rt.operation_error(loc_id, "ZRST: d1 and d2 must be devices of the same type")
            return True
        lo, hi = sorted((d1.base, d2.base))
        zero = False if isinstance(d1.cells[lo], bool) else 0
        for i in range(lo, hi + 1):
            d1.cells[i] = zero
        if rt.dirty_log is not None:
            rt.dirty_log.extend((d1.cells, i) for i in range(lo, hi + 1))
    return bool(en)


def out(rt, en, d, loc_id):
    """OUT d: the coil follows the execution condition (executed even when EN is FALSE)."""
    d.set(0, bool(en))
    return bool(en)
