"""Operand references: how an instruction model reaches the block of words or bits an ST
call names by its head (`wSend[0]`, `wSend`, `D100`, `M10`, a scalar label).

A reference knows the cells (a Python list: an array label or a device area), where the
block starts, how to normalise what it stores (INT wraps, WORD masks...), and the ST
location of the operand so that a block running past the end of its array is reported
where it was written.
"""
from __future__ import annotations

from .datatypes import NORMALIZERS


class Ref:
    __slots__ = ("cells", "base", "norm", "rt", "loc_id", "label")

    def __init__(self, cells: list, base: int, type_name: str, rt, loc_id: int | None, label: str):
        self.cells = cells
        self.base = base
        self.norm = NORMALIZERS.get(type_name, lambda v: v)
        self.rt = rt
        self.loc_id = loc_id
        self.label = label

    def _index(self, k: int) -> int:
        i = self.base + k
        if i < 0 or i >= len(self.cells):
            self.rt.fail(self.loc_id, f"operand {self.label}: word {k} of the block is past the end "
                                      f"({len(self.cells) - self.base} available); on the real CPU "
                                      "this reads or overwrites whatever memory follows")
        return i

    def available(self) -> int:
        return len(self.cells) - self.base

    def get(self, k: int = 0):
        return self.cells[self._index(k)]

    def set(self, k: int, value) -> None:
        i = self._index(k)
        self.cells[i] = self.norm(value)
        if self.rt.dirty_log is not None:
            self.rt.dirty_log.append((self.cells, i))

    def get_u16(self, k: int = 0) -> int:
        return int(self.cells[self._index(k)]) & 0xFFFF

    def get_bytes(self, count: int) -> bytes:
        """`count` bytes packed two per word, low byte first (RS2, CRC 16-bit mode, C24)."""
        out = bytearray()
        for k in range((count + 1) // 2):
            w = self.get_u16(k)
            out.append(w & 0xFF)
            out.append(w >> 8)
        return bytes(out[:count])

    def get_low_bytes(self, count: int) -> bytes:
        """`count` bytes from the low byte of each word (8-bit mode)."""
        return bytes(self.get_u16(k) & 0xFF for k in range(count))

    def put_bytes(self, data: bytes) -> None:
        """Store bytes two per word, low byte first; an odd count leaves 00H in the last
        word's high byte."""
        for k in range((len(data) + 1) // 2):
            lo = data[2 * k]
            hi = data[2 * k + 1] if 2 * k + 1 < len(data) else 0
            self.set(k, lo | (hi << 8))

    def put_low_bytes(self, data: bytes) -> None:
        for k, b in enumerate(data):
            self.set(k, b)


class AttrRef(Ref):
    """A scalar label used as an operand: a block of exactly one cell."""

    __slots__ = ("obj", "attr")

    def __init__(self, obj, attr: str, type_name: str, rt, loc_id: int | None, label: str):
        super().__init__([], 0, type_name, rt, loc_id, label)
        self.obj = obj
        self.attr = attr

    def available(self) -> int:
        return 1

    def _check(self, k: int) -> None:
        if k != 0:
            self.rt.fail(self.loc_id, f"operand {self.label} is a single label but the instruction "
                                      f"needs word {k} of a block; use an array")

    def get(self, k: int = 0):
        self._check(k)
        return getattr(self.obj, self.attr)

    def set(self, k: int, value) -> None:
        self._check(k)
        setattr(self.obj, self.attr, self.norm(value))

    def get_u16(self, k: int = 0) -> int:
        return int(self.get(k)) & 0xFFFF


class DwordRef(Ref):
    """A 32-bit value held by two consecutive word devices (DMOV K100000 D0: D0 low word,
    D1 high word)."""

    def get(self, k: int = 0):
        lo = self.cells[self._index(2 * k)] & 0xFFFF
        hi = self.cells[self._index(2 * k + 1)] & 0xFFFF
        return self.norm(lo | (hi << 16))

    def set(self, k: int, value) -> None:
        v = int(value) & 0xFFFFFFFF
        lo, hi = self._index(2 * k), self._index(2 * k + 1)
        self.cells[lo] = ((v & 0xFFFF) + 0x8000 & 0xFFFF) - 0x8000
        self.cells[hi] = ((v >> 16) + 0x8000 & 0xFFFF) - 0x8000
        if self.rt.dirty_log is not None:
            self.rt.dirty_log.extend(((self.cells, lo), (self.cells, hi)))


class BitRef(Ref):
    """One bit of a word used as an instruction operand (`SET(EN, D0.3)`, `RST(EN, wData.15)`):
    a block of exactly one BOOL."""

    __slots__ = ("obj", "attr", "bit", "word_norm")

    def __init__(self, holder, key, bit: int, word_type: str, rt, loc_id: int | None, label: str):
        super().__init__([], 0, "BOOL", rt, loc_id, label)
        self.obj = holder  # a list (device cells) or an object (label owner)
        self.attr = key  # index into the list, or attribute name
        self.bit = bit
        self.word_norm = NORMALIZERS[word_type]

    def _word(self) -> int:
        return self.obj[self.attr] if isinstance(self.obj, list) else getattr(self.obj, self.attr)

    def available(self) -> int:
        return 1

    def get(self, k: int = 0):
        if k != 0:
            self.rt.fail(self.loc_id, f"operand {self.label} is a single bit")
        return bool((self._word() >> self.bit) & 1)

    def set(self, k: int, value) -> None:
        if k != 0:
            self.rt.fail(self.loc_id, f"operand {self.label} is a single bit")
        word = self._word() & 0xFFFFFFFF
        word = word | (1 << self.bit) if value else word & ~(1 << self.bit)
        word = self.word_norm(word)
        if isinstance(self.obj, list):
            self.obj[self.attr] = word
            if self.rt.dirty_log is not None:
                self.rt.dirty_log.append((self.obj, self.attr))
        else:
            setattr(self.obj, self.attr, word)


def operand_key(ref):
    """A comparable stand-in for an instruction operand in an `idle_state` tuple (verifier.sim.idle):
    the memory it names, not the handle (a handle built on every call is a new object)."""
    if isinstance(ref, BitRef):
        return ("bit", id(ref.obj), ref.attr, ref.bit)
    if isinstance(ref, Ref):
        attr = getattr(ref, "attr", None)  # AttrRef: a scalar label
        return (id(ref.cells), ref.base) if attr is None else ("attr", id(ref.obj), attr)
    return None if ref is None else ("object", id(ref))


def pulse_keys(flags) -> tuple:
    """`operand_key` of each (operand, bit) of a pulse list."""
    return tuple((operand_key(ref), bit) for ref, bit in flags)
