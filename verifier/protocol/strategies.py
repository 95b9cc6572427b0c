"""Hypothesis strategies for property tests of anything that speaks the robot's protocol.

Needs the test extra (hypothesis); import it from tests only. Other lanes use it to fuzz
the emulated robot or the checks with every valid frame under every setting.
"""
from __future__ import annotations

from hypothesis import strategies as st

from verifier.protocol.catalogue import (
    POINT_NUMBERS,
    QUERY_VALUES,
    ControlCode,
    ExceptionCode,
    ManualMove,
    Query,
    RobotCommand,
    RobotError,
)
from verifier.protocol.frames import ControlReply, ControlRequest, ExceptionReply, StatusReply, StatusRequest
from verifier.protocol.settings import CODES_10_13_STYLES, FIELD_ORDERS, STATUS_ORDERS, Settings

addresses = st.integers(1, 247)

settings = st.builds(
    Settings,
    address=addresses,
    field_order=st.sampled_from(FIELD_ORDERS),
    codes_10_13=st.sampled_from(CODES_10_13_STYLES),
    status_order=st.sampled_from(STATUS_ORDERS),
    manual_stop_counts_as_stop=st.booleans(),
)


@st.composite
def code_and_command(draw) -> tuple[ControlCode, int]:
    """Any catalogued (logical) control code with a command it accepts."""
    code = draw(st.sampled_from(list(ControlCode)))
    if code is ControlCode.ROBOT:
        command = draw(st.one_of(st.sampled_from([int(c) for c in RobotCommand]), st.sampled_from(list(POINT_NUMBERS))))
    elif code in (ControlCode.SPEED_TRACKLESS, ControlCode.SPEED_MAGNETIC, ControlCode.COLLISION_RANGE):
        command = draw(st.integers(0, 3))
    elif code is ControlCode.MANUAL:
        command = draw(st.sampled_from([int(m) for m in ManualMove]))
    else:
        command = draw(st.integers(0, 255))
    return code, command


@st.composite
def control_requests(draw, address=addresses) -> ControlRequest:
    code, command = draw(code_and_command())
    return ControlRequest(draw(address), code, command)


@st.composite
def status_requests(draw, address=addresses) -> StatusRequest:
    return StatusRequest(draw(address), draw(st.sampled_from(list(Query))))


requests = st.one_of(control_requests(), status_requests())


@st.composite
def status_replies(draw, address=addresses, with_query: bool = True) -> StatusReply:
    query = draw(st.sampled_from(list(Query)))
    value = draw(st.sampled_from(sorted(QUERY_VALUES[query])))
    return StatusReply(draw(address), draw(st.sampled_from(list(RobotError))), value, query if with_query else None)


@st.composite
def control_replies(draw, address=addresses) -> ControlReply:
    return ControlReply.echo(draw(control_requests(address)))


@st.composite
def exception_replies(draw, address=addresses) -> ExceptionReply:
    return ExceptionReply(draw(address), draw(st.sampled_from([1, 6])), draw(st.sampled_from(list(ExceptionCode))))


replies = st.one_of(control_replies(), status_replies(), exception_replies())
