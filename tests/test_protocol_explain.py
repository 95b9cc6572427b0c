"""explain() and describe() take any bytes without failing, and cover every byte."""
from __future__ import annotations

from hypothesis import given
from hypothesis import strategies as st

from verifier.protocol import (
    FrameError,
    decode_frame,
    decode_reply,
    describe,
    encode,
    explain,
    explain_table,
    with_crc,
)
from verifier.protocol.strategies import replies, requests, settings as any_settings

directions = st.sampled_from(["request", "reply"])


@given(any_settings, st.binary(max_size=12), directions)
def test_explain_covers_every_byte_once_in_order(settings, data, direction):
    fields = explain(data, settings, direction)
    joined = b"".join(f.data for f in fields)
    assert joined == data
    position = 0
    for field in fields:
        if field.data:
            assert field.start == position
            position += len(field.data)
    assert explain_table(fields).splitlines()[0].startswith("byte")


@given(any_settings, requests)
def test_explain_of_a_valid_request_has_no_complaint(settings, request):
    fields = explain(encode(request, settings), settings, "request")
    text = " ".join(f.meaning for f in fields)
    for word in ("must", "unknown", "wrong", "missing", "out of range"):
        assert word not in text
    assert fields[-1].meaning.endswith(": ok")


@given(any_settings, replies)
def test_explain_of_a_valid_reply_has_a_good_crc(settings, reply):
    fields = explain(encode(reply, settings), settings, "reply")
    assert fields[-1].meaning.endswith(": ok")


@given(any_settings, st.binary(max_size=12), st.sampled_from([None, "request", "reply"]))
def test_describe_any_bytes(settings, data, direction):
    text = describe(data, settings, direction)
    assert isinstance(text, str) and text
    try:
        decode_frame(data, settings, direction)
    except FrameError as err:
        assert text == f"invalid frame: {err}"


@given(any_settings, st.binary(min_size=1, max_size=6))
def test_any_reply_body_with_good_crc_decodes_or_names_a_byte(settings, body):
    data = with_crc(body)
    try:
        decode_reply(data, settings)
    except FrameError as err:
        assert 0 <= err.offset <= len(data)
        assert err.kind in {"length", "function", "byte-count", "data", "error-code", "value",
                            "exception-code", "code", "command", "value-field"}
