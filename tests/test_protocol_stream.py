"""Cutting byte streams into frames by function code."""
from __future__ import annotations

import pytest
from hypothesis import given
from hypothesis import strategies as st

from verifier.protocol import FrameSplitter, encode, frame_length, split_frames
from verifier.protocol.strategies import replies, requests, settings as any_settings


def test_fixed_lengths():
    assert frame_length(b"\x01\x06", "request") == 8
    assert frame_length(b"\x01\x01", "request") == 8
    assert frame_length(b"\x01\x06", "reply") == 8
    assert frame_length(b"\x01\x01", "reply") == 8
    assert frame_length(b"\x01\x86", "reply") == 5
    assert frame_length(b"\x01\x83", "reply") == 5
    assert frame_length(b"\x01", "reply") is None
    assert frame_length(b"\x01\x03", "request") is None
    assert frame_length(b"\x01\x86", "request") is None  # a master never sends 0x86
    with pytest.raises(ValueError):
        frame_length(b"\x01\x06", "sideways")


@given(any_settings, st.lists(requests, max_size=6), st.data())
def test_requests_split_back_whatever_the_chunking(settings, frames, data):
    wire = [encode(f, settings) for f in frames]
    stream = b"".join(wire)
    splitter = FrameSplitter("request")
    got: list[bytes] = []
    position = 0
    while position < len(stream):
        step = data.draw(st.integers(1, len(stream) - position))
        got += splitter.feed(stream[position:position + step])
        position += step
    assert got == wire
    assert splitter.pending == b""


@given(any_settings, st.lists(replies, max_size=6))
def test_replies_split_including_exceptions(settings, frames):
    wire = [encode(f, settings) for f in frames]
    assert split_frames(b"".join(wire), "reply") == (wire, b"")


def test_partial_frame_stays_pending_until_flush():
    splitter = FrameSplitter("request")
    assert splitter.feed(bytes.fromhex("01 06 01 A0 00")) == []
    assert splitter.pending == bytes.fromhex("01 06 01 A0 00")
    assert splitter.flush() == bytes.fromhex("01 06 01 A0 00")
    assert splitter.pending == b""


def test_unknown_function_holds_everything_after_it():
    stop = bytes.fromhex("01 06 01 A0 00 00 88 14")
    frames, rest = split_frames(stop + b"\x01\x03\x00\x00" + stop, "request")
    assert frames == [stop]
    assert rest == b"\x01\x03\x00\x00" + stop


def test_length_without_knowing_the_side():
    """A receive-only tap does not know who sent a frame: the length holds when both sides
    agree on it (FC01/FC06 requests and replies are 8 bytes) and for exception replies."""
    from verifier.protocol.stream import frame_length_either_side

    assert frame_length_either_side(bytes([1, 0x06])) == 8
    assert frame_length_either_side(bytes([1, 0x01])) == 8
    assert frame_length_either_side(bytes([1, 0x86])) == 5
    assert frame_length_either_side(bytes([1, 0x83])) is None  # exception of a function not on this line
    assert frame_length_either_side(bytes([1, 0x03])) is None
    assert frame_length_either_side(bytes([1])) is None
