"""CRC-16/MODBUS: the check that ends every Modbus RTU frame.

Polynomial 0x8005 reflected (0xA001), initial value 0xFFFF, no final XOR; the two CRC
bytes travel low byte first. The 256-entry table is the same one pymodbus's RTU framer
uses (``pymodbus.framer.FramerRTU.crc16_table``); we build it here so this module stays
import-light, and the tests check both against a bit-by-bit reference.
"""
from __future__ import annotations

CRC_INIT = 0xFFFF
CRC_POLY_REFLECTED = 0xA001


def _table_entry(index: int) -> int:
    crc = index
    for _ in range(8):
        crc = (crc >> 1) ^ CRC_POLY_REFLECTED if crc & 1 else crc >> 1
    return crc


_TABLE = tuple(_table_entry(i) for i in range(256))


def crc16(data: bytes) -> int:
    """CRC-16/MODBUS of ``data`` as an int (0x1488 for the stop frame's first six bytes)."""
    crc = CRC_INIT
    for byte in data:
        crc = (crc >> 8) ^ _TABLE[(crc ^ byte) & 0xFF]
    return crc


def crc_bytes(crc: int) -> bytes:
    """The two bytes that carry ``crc`` on the wire: low byte first."""
    return bytes((crc & 0xFF, crc >> 8))


def with_crc(body: bytes) -> bytes:
    """``body`` followed by its CRC, low byte first: a complete RTU frame."""
    body = bytes(body)
    return body + crc_bytes(crc16(body))


def frame_crc(frame: bytes) -> int:
    """The CRC carried in the last two bytes of ``frame`` (as an int)."""
    return frame[-2] | (frame[-1] << 8)


def crc_ok(frame: bytes) -> bool:
    """True when the last two bytes of ``frame`` are the CRC of the bytes before them."""
    return len(frame) >= 3 and crc16(frame[:-2]) == frame_crc(frame)
