"""The command catalogue of the UITAMR manual (Modbus 通訊手冊 V2.05): every control code,
every table-2 robot command, the four status queries, the error codes, and which values
each accepts. Names follow the manual; the Chinese term is in each docstring.
"""
from __future__ import annotations

from enum import IntEnum

from verifier.protocol.settings import Settings

FC_READ_COILS = 0x01
FC_WRITE_SINGLE_REGISTER = 0x06
FUNCTION_CODES = (FC_READ_COILS, FC_WRITE_SINGLE_REGISTER)
EXCEPTION_FLAG = 0x80

#: FC01 quantity field: always 22 coils (0x0016).
STATUS_QUANTITY = 22
#: the most coils one FC01 request may ask for (Modbus Application Protocol V1.1b3 §6.1)
MAX_COILS = 2000
#: FC01 reply byte count: 22 coils fill 3 bytes.
STATUS_BYTE_COUNT = 3


class ControlCode(IntEnum):
    """Table 1, 控制代號: the high byte of the FC06 register-address field (logical numbers)."""

    ROBOT = 1  # 機器人控制: table-2 command or taught point / script
    SPEED_TRACKLESS = 2  # 無軌速度設定
    SPEED_MAGNETIC = 3  # 磁移動速度設定
    COLLISION_RANGE = 4  # 超聲波防撞段數設定
    MANUAL = 5  # 手動移動
    MOVE_FRONT_POS = 6  # 無軌式車前 正座標
    MOVE_FRONT_NEG = 7  # 無軌式車前 負座標
    MOVE_REAR_POS = 8  # 無軌式車後 正座標
    MOVE_REAR_NEG = 9  # 無軌式車後 負座標
    MOVE_Y_POS = 10  # 無軌式 y 座標 正座標
    MOVE_Y_NEG = 11  # 無軌式 y 座標 負座標
    ROTATE_POS = 12  # 無軌式旋轉 正座標
    ROTATE_NEG = 13  # 無軌式旋轉 負座標


class RobotCommand(IntEnum):
    """Table 2, 控制指令 for control code 01 (UITAMR-D300 I/O definition)."""

    SEEK_FORWARD = 0x16  # 尋磁(前)  22
    SEEK_BACKWARD = 0x36  # 尋磁(後)  22+32
    FOLLOW_FORWARD = 0x17  # 磁追蹤(前)  23
    FOLLOW_BACKWARD = 0x37  # 磁追蹤(後)  23+32
    FOLLOW_LEFT = 0x57  # 磁追蹤(左)  23+64
    FOLLOW_RIGHT = 0x77  # 磁追蹤(右)  23+96
    ROTATE_LEFT = 0x18  # 左磁旋轉  24
    ROTATE_RIGHT = 0x19  # 右磁旋轉  25
    PAUSE = 0x80  # 劇本暫停  128
    STOP = 0xA0  # 停止動作  160
    RESET = 0xC0  # 座標重置  192
    MANUAL_MODE = 0xE0  # 手動模式  224


class ManualMove(IntEnum):
    """Control code 05 commands, 手動移動 (note 2 of the manual)."""

    STOP = 0  # 停止移動
    FORWARD = 1  # 前進
    BACKWARD = 2  # 後退
    ROTATE_LEFT = 3  # 左旋轉
    ROTATE_RIGHT = 4  # 右旋轉
    SHIFT_LEFT = 5  # 左橫移 (D300 only)
    SHIFT_RIGHT = 6  # 右橫移 (D300 only)


class Query(IntEnum):
    """FC01 query parameter (查詢參數), logical numbering = the manual's query list."""

    TASK = 0  # 任務狀態
    VEHICLE = 1  # 車輛狀態
    SPEED = 2  # 車速
    BATTERY = 3  # 電池電量


class RobotError(IntEnum):
    """Table 3, 錯誤代碼: the error byte of every FC01 reply."""

    NONE = 0  # 正常
    ANTI_COLLISION = 1  # 防撞啟動
    OFF_TAPE = 2  # 磁走行模式下出軌
    BATTERY_LOW = 3  # 電量警訊


class ExceptionCode(IntEnum):
    """Modbus exception codes (Modbus Application Protocol V1.1b3, §7)."""

    ILLEGAL_FUNCTION = 1
    ILLEGAL_DATA_ADDRESS = 2
    ILLEGAL_DATA_VALUE = 3
    SLAVE_DEVICE_FAILURE = 4
    ACKNOWLEDGE = 5
    SLAVE_DEVICE_BUSY = 6
    NEGATIVE_ACKNOWLEDGE = 7
    MEMORY_PARITY_ERROR = 8
    GATEWAY_PATH_UNAVAILABLE = 0x0A
    GATEWAY_TARGET_FAILED = 0x0B


def is_member(enum: type[IntEnum], value: object) -> bool:
    """Whether ``value`` is the number of one of ``enum``'s members (bools are not numbers here)."""
    return isinstance(value, int) and not isinstance(value, bool) and value in enum._value2member_map_


# --- what each code accepts -------------------------------------------------------------

#: [choice] Code 01 low bytes 1-21 run a taught point / script (0x16 is the first table-2 value).
POINT_NUMBERS = range(1, 22)
#: Codes 02/03/04: four stages, 0-3.
STAGES = range(0, 4)
#: Codes 06-13: low byte × 0.1 m (or × 0.01 for rotation), any byte value.
DISTANCE_UNITS = range(0, 256)
METRES_PER_UNIT = 0.1
ROTATION_PER_UNIT = 0.01  # unit not stated by the manual; [choice] radians

SPEED_STAGE_NAMES = {0: "stage 1", 1: "stage 2", 2: "stage 3", 3: "stage 4"}
COLLISION_RANGE_METRES = {0: 0.0, 1: 0.2, 2: 0.4, 3: 0.6}

MOVE_CODES = frozenset(range(ControlCode.MOVE_FRONT_POS, ControlCode.ROTATE_NEG + 1))
ROTATE_CODES = frozenset({ControlCode.ROTATE_POS, ControlCode.ROTATE_NEG})
NEGATIVE_CODES = frozenset(
    {ControlCode.MOVE_FRONT_NEG, ControlCode.MOVE_REAR_NEG, ControlCode.MOVE_Y_NEG, ControlCode.ROTATE_NEG}
)


def command_problem(code: int, command: int) -> str | None:
    """Why (logical) ``code``/``command`` is not in the catalogue, or None when it is."""
    if not 0 <= command <= 0xFF:
        return f"command {command} does not fit in one byte"
    if not is_member(ControlCode, code):
        return f"unknown control code {code}"
    code = ControlCode(code)
    if code is ControlCode.ROBOT:
        if is_member(RobotCommand, command) or command in POINT_NUMBERS:
            return None
        return (
            f"unknown robot command 0x{command:02X} for control code 01 "
            "(table 2 values, or a point/script number 1-21)"
        )
    if code in (ControlCode.SPEED_TRACKLESS, ControlCode.SPEED_MAGNETIC, ControlCode.COLLISION_RANGE):
        if command in STAGES:
            return None
        return f"value {command} out of range 0-3 for control code {code:02d} ({CODE_TITLES[code]})"
    if code is ControlCode.MANUAL:
        if is_member(ManualMove, command):
            return None
        return f"value {command} out of range 0-6 for control code 05 (manual move)"
    return None  # moves and rotations take any byte


# --- settings-dependent numbering -------------------------------------------------------

def wire_code(code: int, settings: Settings) -> int:
    """The byte that carries logical control ``code`` on the wire (codes 10-13 depend on settings)."""
    code = ControlCode(code)
    if code >= ControlCode.MOVE_Y_POS and settings.codes_10_13 == "hex":
        return int(str(int(code)), 16)  # 10 -> 0x10 ... 13 -> 0x13
    return int(code)


def logical_code(wire: int, settings: Settings) -> ControlCode:
    """The control code a wire byte stands for; ValueError when it stands for none."""
    for code in ControlCode:
        if wire_code(code, settings) == wire:
            return code
    if settings.codes_10_13 == "hex" and 0x0A <= wire <= 0x0D:
        raise ValueError(
            f"unknown control code 0x{wire:02X} (codes 10-13 are sent as 0x10-0x13 "
            "with codes_10_13=hex)"
        )
    if settings.codes_10_13 == "decimal" and 0x10 <= wire <= 0x13:
        raise ValueError(
            f"unknown control code 0x{wire:02X} (codes 10-13 are sent as 0x0A-0x0D "
            "with codes_10_13=decimal)"
        )
    raise ValueError(f"unknown control code 0x{wire:02X}")


_RETURN_ORDER = (Query.SPEED, Query.BATTERY, Query.TASK, Query.VEHICLE)


def wire_query(query: int, settings: Settings) -> int:
    """The FC01 start-address value (query parameter) asking for ``query``."""
    query = Query(query)
    if settings.status_order == "return":
        return _RETURN_ORDER.index(query)
    return int(query)


def logical_query(wire: int, settings: Settings) -> Query:
    """The status a wire query parameter asks for; ValueError when it asks for none."""
    if not 0 <= wire <= 3:
        raise ValueError(f"unknown query parameter {wire} (0-3)")
    if settings.status_order == "return":
        return _RETURN_ORDER[wire]
    return Query(wire)


# --- value meanings ---------------------------------------------------------------------

CODE_TITLES = {
    ControlCode.ROBOT: "robot control",
    ControlCode.SPEED_TRACKLESS: "trackless speed",
    ControlCode.SPEED_MAGNETIC: "magnetic-tape speed",
    ControlCode.COLLISION_RANGE: "anti-collision range",
    ControlCode.MANUAL: "manual move",
    ControlCode.MOVE_FRONT_POS: "move front, positive",
    ControlCode.MOVE_FRONT_NEG: "move front, negative",
    ControlCode.MOVE_REAR_POS: "move rear, positive",
    ControlCode.MOVE_REAR_NEG: "move rear, negative",
    ControlCode.MOVE_Y_POS: "move y, positive",
    ControlCode.MOVE_Y_NEG: "move y, negative",
    ControlCode.ROTATE_POS: "rotate, positive",
    ControlCode.ROTATE_NEG: "rotate, negative",
}

ROBOT_COMMAND_TITLES = {
    RobotCommand.SEEK_FORWARD: "seek tape forward",
    RobotCommand.SEEK_BACKWARD: "seek tape backward",
    RobotCommand.FOLLOW_FORWARD: "follow tape forward",
    RobotCommand.FOLLOW_BACKWARD: "follow tape backward",
    RobotCommand.FOLLOW_LEFT: "follow tape left",
    RobotCommand.FOLLOW_RIGHT: "follow tape right",
    RobotCommand.ROTATE_LEFT: "rotate left on tape",
    RobotCommand.ROTATE_RIGHT: "rotate right on tape",
    RobotCommand.PAUSE: "pause script",
    RobotCommand.STOP: "stop",
    RobotCommand.RESET: "coordinate reset",
    RobotCommand.MANUAL_MODE: "manual mode",
}

MANUAL_MOVE_TITLES = {
    ManualMove.STOP: "stop moving",
    ManualMove.FORWARD: "forward",
    ManualMove.BACKWARD: "backward",
    ManualMove.ROTATE_LEFT: "rotate left",
    ManualMove.ROTATE_RIGHT: "rotate right",
    ManualMove.SHIFT_LEFT: "shift left (D300)",
    ManualMove.SHIFT_RIGHT: "shift right (D300)",
}

QUERY_TITLES = {
    Query.TASK: "task status",
    Query.VEHICLE: "vehicle status",
    Query.SPEED: "speed",
    Query.BATTERY: "battery",
}

ERROR_TITLES = {
    RobotError.NONE: "normal",
    RobotError.ANTI_COLLISION: "anti-collision triggered",
    RobotError.OFF_TAPE: "off the tape",
    RobotError.BATTERY_LOW: "battery warning",
}

#: Values each status query can return, with their meaning.
QUERY_VALUES: dict[Query, dict[int, str]] = {
    Query.TASK: {0: "idle", 1: "running"},
    Query.VEHICLE: {int(e): ERROR_TITLES[e] for e in RobotError},
    Query.SPEED: dict(SPEED_STAGE_NAMES),
    Query.BATTERY: {0: "normal", 1: "low"},
}

EXCEPTION_TITLES = {
    ExceptionCode.ILLEGAL_FUNCTION: "illegal function",
    ExceptionCode.ILLEGAL_DATA_ADDRESS: "illegal data address",
    ExceptionCode.ILLEGAL_DATA_VALUE: "illegal data value",
    ExceptionCode.SLAVE_DEVICE_FAILURE: "slave device failure",
    ExceptionCode.ACKNOWLEDGE: "acknowledge",
    ExceptionCode.SLAVE_DEVICE_BUSY: "slave device busy",
    ExceptionCode.NEGATIVE_ACKNOWLEDGE: "negative acknowledge",
    ExceptionCode.MEMORY_PARITY_ERROR: "memory parity error",
    ExceptionCode.GATEWAY_PATH_UNAVAILABLE: "gateway path unavailable",
    ExceptionCode.GATEWAY_TARGET_FAILED: "gateway target failed to respond",
}


def value_problem(query: int, value: int) -> str | None:
    """Why ``value`` cannot be the answer to ``query``, or None when it can."""
    query = Query(query)
    allowed = QUERY_VALUES[query]
    if value in allowed:
        return None
    listing = ", ".join(f"{k} {v}" for k, v in allowed.items())
    return f"value {value} out of range for {QUERY_TITLES[query]} ({listing})"


def command_title(code: int, command: int) -> str:
    """Plain-English meaning of a catalogued (logical) code/command pair."""
    code = ControlCode(code)
    if code is ControlCode.ROBOT:
        if is_member(RobotCommand, command):
            return ROBOT_COMMAND_TITLES[RobotCommand(command)]
        return f"run point/script {command}"
    if code in (ControlCode.SPEED_TRACKLESS, ControlCode.SPEED_MAGNETIC):
        return f"{CODE_TITLES[code]} {SPEED_STAGE_NAMES.get(command, f'value {command}')}"
    if code is ControlCode.COLLISION_RANGE:
        metres = COLLISION_RANGE_METRES.get(command)
        return f"anti-collision range {metres} m" if metres is not None else f"anti-collision value {command}"
    if code is ControlCode.MANUAL:
        move = MANUAL_MOVE_TITLES[ManualMove(command)] if is_member(ManualMove, command) else f"value {command}"
        return f"manual move {move}"
    sign = "-" if code in NEGATIVE_CODES else "+"
    if code in ROTATE_CODES:
        return f"rotate {sign}{command * ROTATION_PER_UNIT:.2f}"
    axis = {6: "front", 7: "front", 8: "rear", 9: "rear", 10: "y", 11: "y"}[int(code)]
    return f"move {axis} {sign}{command * METRES_PER_UNIT:.1f} m"
