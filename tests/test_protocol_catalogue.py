"""The catalogue agrees with the manual (Modbus 通訊手冊 V2.05) and with the reference page."""
from __future__ import annotations

import pytest
from hypothesis import given
from hypothesis import strategies as st

from verifier.protocol import (
    ControlCode,
    ExceptionCode,
    ManualMove,
    Query,
    RobotCommand,
    RobotError,
    Settings,
    command_problem,
    command_title,
    logical_code,
    logical_query,
    value_problem,
    wire_code,
    wire_query,
)
from verifier.protocol.catalogue import POINT_NUMBERS, QUERY_VALUES
from verifier.protocol.strategies import settings as any_settings


def test_decimal_summary_of_the_manual():
    """[整理] 控制指令簡易說明(十進位)."""
    assert RobotCommand.SEEK_FORWARD == 22
    assert RobotCommand.SEEK_BACKWARD == 22 + 32
    assert RobotCommand.FOLLOW_FORWARD == 23
    assert RobotCommand.FOLLOW_BACKWARD == 23 + 32
    assert RobotCommand.FOLLOW_LEFT == 23 + 64
    assert RobotCommand.FOLLOW_RIGHT == 23 + 96
    assert RobotCommand.ROTATE_LEFT == 24
    assert RobotCommand.ROTATE_RIGHT == 25
    assert RobotCommand.PAUSE == 128
    assert RobotCommand.STOP == 160
    assert RobotCommand.RESET == 192
    assert RobotCommand.MANUAL_MODE == 224
    assert len(RobotCommand) == 12


def test_table_two_bit_patterns():
    """Table 2 prints each value as bits 1.0 (LSB) .. 1.7; the hex column must match them."""
    rows = {
        "01101000": RobotCommand.SEEK_FORWARD,
        "01101100": RobotCommand.SEEK_BACKWARD,
        "11101000": RobotCommand.FOLLOW_FORWARD,
        "11101100": RobotCommand.FOLLOW_BACKWARD,
        "11101010": RobotCommand.FOLLOW_LEFT,
        "11101110": RobotCommand.FOLLOW_RIGHT,
        "00011000": RobotCommand.ROTATE_LEFT,
        "10011000": RobotCommand.ROTATE_RIGHT,
        "00000001": RobotCommand.PAUSE,
        "00000101": RobotCommand.STOP,
        "00000011": RobotCommand.RESET,
        "00000111": RobotCommand.MANUAL_MODE,
    }
    for bits_lsb_first, command in rows.items():
        assert int(bits_lsb_first[::-1], 2) == command, command.name


def test_control_codes_one_to_thirteen():
    assert [int(c) for c in ControlCode] == list(range(1, 14))
    assert ControlCode.ROBOT == 1 and ControlCode.MANUAL == 5
    assert ControlCode.MOVE_FRONT_POS == 6 and ControlCode.ROTATE_NEG == 13


def test_queries_errors_and_manual_moves():
    assert [int(q) for q in (Query.TASK, Query.VEHICLE, Query.SPEED, Query.BATTERY)] == [0, 1, 2, 3]
    assert [int(e) for e in (RobotError.NONE, RobotError.ANTI_COLLISION, RobotError.OFF_TAPE, RobotError.BATTERY_LOW)] == [0, 1, 2, 3]
    assert [int(m) for m in ManualMove] == list(range(7))
    assert ExceptionCode.ILLEGAL_FUNCTION == 1 and ExceptionCode.ILLEGAL_DATA_VALUE == 3
    assert QUERY_VALUES[Query.TASK] == {0: "idle", 1: "running"}
    assert sorted(QUERY_VALUES[Query.SPEED]) == [0, 1, 2, 3]
    assert sorted(QUERY_VALUES[Query.BATTERY]) == [0, 1]
    assert sorted(QUERY_VALUES[Query.VEHICLE]) == [0, 1, 2, 3]


def test_wire_codes_for_codes_10_to_13():
    decimal, hexa = Settings(codes_10_13="decimal"), Settings(codes_10_13="hex")
    assert [wire_code(c, decimal) for c in range(10, 14)] == [0x0A, 0x0B, 0x0C, 0x0D]
    assert [wire_code(c, hexa) for c in range(10, 14)] == [0x10, 0x11, 0x12, 0x13]
    for code in range(1, 10):  # codes 1-9 read the same either way
        assert wire_code(code, decimal) == wire_code(code, hexa) == code


@given(any_settings)
def test_logical_code_inverts_wire_code(settings):
    for code in ControlCode:
        assert logical_code(wire_code(code, settings), settings) is code
    wires = {wire_code(c, settings) for c in ControlCode}
    for byte in set(range(256)) - wires:
        with pytest.raises(ValueError):
            logical_code(byte, settings)


def test_logical_code_explains_the_other_numbering():
    with pytest.raises(ValueError, match="0x10-0x13 with codes_10_13=hex"):
        logical_code(0x0A, Settings(codes_10_13="hex"))
    with pytest.raises(ValueError, match="0x0A-0x0D with codes_10_13=decimal"):
        logical_code(0x12, Settings(codes_10_13="decimal"))


def test_status_orders():
    query, returned = Settings(status_order="query"), Settings(status_order="return")
    assert [wire_query(q, query) for q in Query] == [0, 1, 2, 3]
    # return-parameter list: 0 speed, 1 battery, 2 task, 3 vehicle
    assert wire_query(Query.SPEED, returned) == 0
    assert wire_query(Query.BATTERY, returned) == 1
    assert wire_query(Query.TASK, returned) == 2
    assert wire_query(Query.VEHICLE, returned) == 3
    for settings in (query, returned):
        for q in Query:
            assert logical_query(wire_query(q, settings), settings) is q
        with pytest.raises(ValueError):
            logical_query(4, settings)


@pytest.mark.parametrize("code", [ControlCode.SPEED_TRACKLESS, ControlCode.SPEED_MAGNETIC, ControlCode.COLLISION_RANGE])
def test_stage_codes_take_zero_to_three(code):
    accepted = [v for v in range(256) if command_problem(code, v) is None]
    assert accepted == [0, 1, 2, 3]


def test_manual_move_takes_zero_to_six():
    assert [v for v in range(256) if command_problem(ControlCode.MANUAL, v) is None] == list(range(7))


def test_robot_code_takes_table_two_and_points():
    accepted = {v for v in range(256) if command_problem(ControlCode.ROBOT, v) is None}
    assert accepted == {int(c) for c in RobotCommand} | set(POINT_NUMBERS)
    assert "unknown robot command 0x20" in command_problem(ControlCode.ROBOT, 0x20)
    assert command_problem(ControlCode.ROBOT, 0) is not None


def test_move_and_rotate_codes_take_any_byte():
    for code in range(6, 14):
        assert all(command_problem(code, v) is None for v in range(256))
        assert command_problem(code, 256) is not None


def test_unknown_code_is_a_problem():
    assert command_problem(0, 0) == "unknown control code 0"
    assert command_problem(14, 0) == "unknown control code 14"


def test_value_problem_per_query():
    assert value_problem(Query.TASK, 1) is None
    assert "out of range for task status" in value_problem(Query.TASK, 2)
    assert value_problem(Query.BATTERY, 1) is None and value_problem(Query.BATTERY, 2)
    assert value_problem(Query.SPEED, 3) is None and value_problem(Query.SPEED, 4)


@given(st.sampled_from(list(ControlCode)), st.integers(0, 255))
def test_every_valid_pair_has_a_title(code, command):
    if command_problem(code, command) is None:
        assert command_title(code, command)


def test_titles():
    assert command_title(1, 0xA0) == "stop"
    assert command_title(1, 5) == "run point/script 5"
    assert command_title(4, 3) == "anti-collision range 0.6 m"
    assert command_title(7, 25) == "move front -2.5 m"
    assert command_title(8, 10) == "move rear +1.0 m"
    assert command_title(11, 3) == "move y -0.3 m"
    assert command_title(12, 157) == "rotate +1.57"
    assert command_title(5, 6) == "manual move shift right (D300)"


def test_settings_validate():
    with pytest.raises(ValueError, match="address"):
        Settings(address=0)
    with pytest.raises(ValueError, match="address"):
        Settings(address=248)
    with pytest.raises(ValueError, match="field_order"):
        Settings(field_order="high")
    with pytest.raises(ValueError, match="codes_10_13"):
        Settings(codes_10_13="octal")
    with pytest.raises(ValueError, match="status_order"):
        Settings(status_order="other")
    defaults = Settings()
    assert (defaults.address, defaults.field_order, defaults.codes_10_13, defaults.status_order,
            defaults.manual_stop_counts_as_stop) == (1, "code-high", "decimal", "query", False)
