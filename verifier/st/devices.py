"""MELSEC device names: which identifiers are devices, and how to read them.

GX Works forbids labels that look like devices, so the reader can decide from the
spelling alone that `D100`, `M0`, `X1F`, `SM400`, `K4M0` are devices, not labels.
Device letters and radixes: MELSEC-Q/L Programming Manual (Common Instructions),
device list; X/Y/B/W/SB/SW are hexadecimal on Q/L/iQ-R (on FX they are octal for X/Y
— the address is kept as written so both readings stay possible).
"""
from __future__ import annotations

import re

#: bit devices (one bit per address)
BIT_DEVICES = frozenset(
    {"X", "Y", "M", "L", "B", "F", "SB", "V", "S", "SM", "DX", "DY", "TS", "TC", "CS",
     "CC", "STS", "STC"}
)
#: word devices (16 bits per address)
WORD_DEVICES = frozenset(
    {"D", "W", "R", "ZR", "SD", "SW", "TN", "CN", "STN", "Z", "V", "G", "T", "C", "ST"}
) - {"V"}
#: devices addressed in hexadecimal on Q/L/iQ-R CPUs
HEX_DEVICES = frozenset({"X", "Y", "B", "W", "SB", "SW", "DX", "DY"})
#: bit devices that can be grouped with a digit specification (K4M0)
DIGIT_DEVICES = frozenset({"X", "Y", "M", "L", "B", "F", "SB", "V", "S", "SM"})

# Longest letter groups first so "SM400" is SM, not S + M.
_KINDS = sorted(BIT_DEVICES | WORD_DEVICES | {"V"}, key=len, reverse=True)
_HEX_KINDS = "|".join(k for k in _KINDS if k in HEX_DEVICES)
_DEC_KINDS = "|".join(k for k in _KINDS if k not in HEX_DEVICES)

DEVICE_RE = re.compile(
    rf"(?:K(?P<digits>[1-8]))?"
    rf"(?:(?P<hkind>{_HEX_KINDS})(?P<haddr>[0-9][0-9A-F]*)|(?P<dkind>{_DEC_KINDS})(?P<daddr>[0-9]+))"
    rf"(?:Z(?P<index>[0-9]+))?",
    re.IGNORECASE,
)
BUFFER_RE = re.compile(r"U(?P<module>[0-9A-F]+)\\G(?P<addr>[0-9]+)", re.IGNORECASE)
K_CONST_RE = re.compile(r"K(?P<value>[0-9]+)", re.IGNORECASE)
H_CONST_RE = re.compile(r"H(?P<value>[0-9][0-9A-F]*)", re.IGNORECASE)


def is_bit_device(kind: str) -> bool:
    return kind.upper() in BIT_DEVICES


def parse_device(text: str) -> dict | None:
    """Read a device name; None when `text` is not a device. Returns the fields of
    `ast.Device` (kind, address, number, digits, index, module)."""
    m = DEVICE_RE.fullmatch(text)
    if m is None:
        b = BUFFER_RE.fullmatch(text)
        if b is None:
            return None
        return {"kind": "G", "address": b["addr"], "number": int(b["addr"]),
                "digits": None, "index": None, "module": b["module"].upper()}
    if m["hkind"]:
        kind, address, radix = m["hkind"].upper(), m["haddr"].upper(), 16
    else:
        kind, address, radix = m["dkind"].upper(), m["daddr"], 10
    digits = int(m["digits"]) if m["digits"] else None
    if digits is not None and kind not in DIGIT_DEVICES:
        return None
    return {"kind": kind, "address": address, "number": int(address, radix),
            "digits": digits, "index": int(m["index"]) if m["index"] else None,
            "module": None}


def looks_like_device(name: str) -> bool:
    """True when a label name would be read as a device (GX Works rejects such labels)."""
    return parse_device(name) is not None
