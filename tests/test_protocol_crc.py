"""CRC-16/MODBUS against an independent bit-by-bit reference, known vectors and pymodbus."""
from __future__ import annotations

from hypothesis import given
from hypothesis import strategies as st
from pymodbus.framer import FramerRTU

from verifier.protocol import crc16, crc_ok, with_crc
from verifier.protocol.crc import crc_bytes, frame_crc


def reference_crc(data: bytes) -> int:
    """Textbook shift-register CRC: 16-bit register, reflected poly 0xA001, init 0xFFFF."""
    register = 0xFFFF
    for byte in data:
        register ^= byte
        for _ in range(8):
            carry = register & 0x0001
            register >>= 1
            if carry:
                register ^= 0xA001
    return register


KNOWN = [
    # CRC-16/MODBUS catalogue check value (reveng): "123456789" -> 0x4B37
    (b"123456789", 0x4B37),
    # Mitsubishi FX3U user's manual, MODBUS serial communication edition, CRC example:
    # 01 03 03 02 00 14 -> CRC E4 41 on the wire (0x41E4)
    (bytes.fromhex("010303020014"), 0x41E4),
    # The robot's stop command, as in the team reference: 01 06 01 A0 00 00 -> 88 14
    (bytes.fromhex("010601A00000"), 0x1488),
    # Empty input leaves the initial value.
    (b"", 0xFFFF),
]


def test_known_vectors():
    for data, expected in KNOWN:
        assert crc16(data) == expected, data.hex()
        assert reference_crc(data) == expected, data.hex()


def test_stop_frame_bytes_low_first():
    assert with_crc(bytes.fromhex("010601A00000")) == bytes.fromhex("010601A000008814")
    assert crc_bytes(0x1488) == b"\x88\x14"


@given(st.binary(max_size=300))
def test_table_crc_equals_bitwise_reference(data):
    assert crc16(data) == reference_crc(data)


@given(st.binary(max_size=300))
def test_matches_pymodbus_rtu_framer(data):
    # pymodbus returns the CRC byte-swapped, ready to pack big-endian.
    assert crc16(data).to_bytes(2, "little") == FramerRTU.compute_CRC(data).to_bytes(2, "big")


@given(st.binary(min_size=1, max_size=100))
def test_with_crc_verifies_and_residue_is_zero(body):
    frame = with_crc(body)
    assert len(frame) == len(body) + 2
    assert crc_ok(frame)
    assert frame_crc(frame) == crc16(body)
    # CRC over a frame with its own CRC appended is 0 for CRC-16/MODBUS.
    assert crc16(frame) == 0


@given(st.binary(min_size=1, max_size=40), st.data())
def test_every_single_bit_error_is_detected(body, data):
    frame = bytearray(with_crc(body))
    bit = data.draw(st.integers(0, len(frame) * 8 - 1))
    frame[bit // 8] ^= 1 << (bit % 8)
    assert not crc_ok(bytes(frame))


@given(st.binary(min_size=1, max_size=40), st.data())
def test_every_burst_up_to_16_bits_is_detected(body, data):
    frame = bytearray(with_crc(body))
    total = len(frame) * 8
    length = data.draw(st.integers(1, min(16, total)))
    start = data.draw(st.integers(0, total - length))
    # A burst: first and last bit flipped, anything in between.
    pattern = (1 << (length - 1)) | 1 | (data.draw(st.integers(0, (1 << length) - 1)) & ((1 << length) - 1))
    as_int = int.from_bytes(frame, "little") ^ (pattern << start)
    assert not crc_ok(as_int.to_bytes(len(frame), "little"))


def test_crc_ok_rejects_too_short():
    assert not crc_ok(b"")
    assert not crc_ok(b"\xff\xff")  # two bytes cannot carry a body and a CRC


def test_manual_printed_crcs_are_placeholders():
    """Errata: the CRCs printed in the manual's tables do not verify for the frames shown."""
    printed = [
        ("010600010000", "68AA"),
        ("010600020000", "240A"),
        ("010100000016", "100B"),
        ("010103000000", "D1CB"),
    ]
    for body, crc_text in printed:
        body = bytes.fromhex(body)
        as_printed = bytes.fromhex(crc_text)
        assert not crc_ok(body + as_printed)
        assert not crc_ok(body + as_printed[::-1])
