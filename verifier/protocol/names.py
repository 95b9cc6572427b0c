"""Commands by name, for people: the words of ``uitamr frame`` and of scenario files.

``command_from_words(["move", "x", "+1.5"])`` -> ``ControlRequest(1, MOVE_FRONT_POS, 15)``;
``words_for`` turns a request back into its words.
"""
from __future__ import annotations

import re
from decimal import Decimal, InvalidOperation

from verifier.digits import digit_problem

from verifier.protocol.catalogue import (
    is_member,
    POINT_NUMBERS,
    ControlCode,
    ManualMove,
    Query,
    RobotCommand,
    command_problem,
)
from verifier.protocol.frames import ControlRequest, StatusRequest


class CommandError(ValueError):
    """Words that do not name a command; the message says what would."""


_SIMPLE = {
    "stop": RobotCommand.STOP,
    "pause": RobotCommand.PAUSE,
    "coordinate-reset": RobotCommand.RESET,
    "manual-mode": RobotCommand.MANUAL_MODE,
}
_SEEK = {"forward": RobotCommand.SEEK_FORWARD, "backward": RobotCommand.SEEK_BACKWARD}
_FOLLOW = {
    "forward": RobotCommand.FOLLOW_FORWARD,
    "backward": RobotCommand.FOLLOW_BACKWARD,
    "left": RobotCommand.FOLLOW_LEFT,
    "right": RobotCommand.FOLLOW_RIGHT,
}
_ROTATE_ON_TAPE = {"left": RobotCommand.ROTATE_LEFT, "right": RobotCommand.ROTATE_RIGHT}
_SPEED = {"trackless": ControlCode.SPEED_TRACKLESS, "magnetic": ControlCode.SPEED_MAGNETIC}
_JOG = {
    "stop": ManualMove.STOP,
    "forward": ManualMove.FORWARD,
    "backward": ManualMove.BACKWARD,
    "left": ManualMove.ROTATE_LEFT,
    "right": ManualMove.ROTATE_RIGHT,
    "shift-left": ManualMove.SHIFT_LEFT,
    "shift-right": ManualMove.SHIFT_RIGHT,
}
#: axis word -> (code for +, code for -); "x" and "front" are the same axis.
_MOVE_AXES = {
    "x": (ControlCode.MOVE_FRONT_POS, ControlCode.MOVE_FRONT_NEG),
    "front": (ControlCode.MOVE_FRONT_POS, ControlCode.MOVE_FRONT_NEG),
    "rear": (ControlCode.MOVE_REAR_POS, ControlCode.MOVE_REAR_NEG),
    "y": (ControlCode.MOVE_Y_POS, ControlCode.MOVE_Y_NEG),
}
_READ = {"task": Query.TASK, "vehicle": Query.VEHICLE, "speed": Query.SPEED, "battery": Query.BATTERY}

METRE_STEP = Decimal("0.1")
ROTATION_STEP = Decimal("0.01")

#: One line per command form, for help texts and error messages.
USAGE = (
    "stop",
    "pause",
    "run-point N                      (N = 1-21, a taught point / script)",
    "seek-tape forward|backward",
    "follow-tape forward|backward|left|right",
    "rotate-on-tape left|right",
    "coordinate-reset",
    "manual-mode",
    "speed trackless|magnetic 0-3",
    "collision-range 0-3              (0 m, 0.2 m, 0.4 m, 0.6 m)",
    "jog stop|forward|backward|left|right|shift-left|shift-right",
    "move x|front|rear|y ±METRES      (0-25.5 m in 0.1 m steps)",
    "rotate ±VALUE                    (0-2.55 in 0.01 steps)",
    "read task|vehicle|speed|battery",
    "raw CODE CMD                     (control code 1-13, command byte; decimal, 0x.. for hex: stop is raw 1 0xA0)",
)


def command_from_words(words: list[str] | str, address: int = 1) -> ControlRequest | StatusRequest:
    """The request named by ``words`` (see ``USAGE``); CommandError says what is wrong.

    ``words`` is a list (``["move", "x", "-2.5"]``) or one string (``"move x -2.5"``).
    """
    if isinstance(words, str):
        words = [words]
    # "run-point 3" given as one argument (quoted, as a scenario's `sent` writes it) is two words
    words = [part for w in words for part in w.split()]
    if not words:
        raise CommandError("no command given; one of: " + _forms())
    name, args = words[0].lower(), words[1:]

    def control(code: ControlCode, command: int) -> ControlRequest:
        return ControlRequest(address, code, int(command))

    if name in _SIMPLE:
        _arity(name, args, 0)
        return control(ControlCode.ROBOT, _SIMPLE[name])
    if name == "run-point":
        _arity(name, args, 1, "N")
        point = _integer(args[0], "point number")
        if point not in POINT_NUMBERS:
            raise CommandError(f"point number must be 1-21, got {point}")
        return control(ControlCode.ROBOT, point)
    if name == "seek-tape":
        return control(ControlCode.ROBOT, _choice(name, args, _SEEK))
    if name == "follow-tape":
        return control(ControlCode.ROBOT, _choice(name, args, _FOLLOW))
    if name == "rotate-on-tape":
        return control(ControlCode.ROBOT, _choice(name, args, _ROTATE_ON_TAPE))
    if name == "speed":
        _arity(name, args, 2, "trackless|magnetic 0-3")
        code = _choice(name, args[:1], _SPEED)
        return control(code, _stage(args[1], "speed stage"))
    if name == "collision-range":
        _arity(name, args, 1, "0-3")
        return control(ControlCode.COLLISION_RANGE, _stage(args[0], "anti-collision range"))
    if name == "jog":
        return control(ControlCode.MANUAL, _choice(name, args, _JOG))
    if name == "move":
        _arity(name, args, 2, "x|front|rear|y ±METRES")
        positive, negative = _choice(name, args[:1], _MOVE_AXES)
        sign, units = _scaled(args[1], METRE_STEP, "distance", "m")
        return control(negative if sign < 0 else positive, units)
    if name == "rotate":
        _arity(name, args, 1, "±VALUE")
        sign, units = _scaled(args[0], ROTATION_STEP, "rotation", "")
        return control(ControlCode.ROTATE_NEG if sign < 0 else ControlCode.ROTATE_POS, units)
    if name == "read":
        return StatusRequest(address, _choice(name, args, _READ))
    if name == "raw":
        _arity(name, args, 2, "CODE CMD")
        code_number = _integer(args[0], "control code")
        command = _integer(args[1], "command")
        if not is_member(ControlCode, code_number):
            raise CommandError(f"control code must be 1-13, got {code_number}")
        if problem := command_problem(code_number, command):
            raise CommandError(problem)
        return control(ControlCode(code_number), command)
    raise CommandError(f"unknown command {words[0]!r}; one of: " + _forms())


def _forms() -> str:
    return ", ".join(line.split("  ")[0].strip() for line in USAGE)


def _arity(name: str, args: list[str], count: int, shape: str = "") -> None:
    if len(args) != count:
        expected = f"{name} {shape}".strip()
        raise CommandError(f"{name} takes {count} argument(s): {expected}; got {len(args)}: {' '.join(args) or '(none)'}")


def _choice(name: str, args: list[str], options: dict):
    if len(args) != 1 or args[0].lower() not in options:
        given = " ".join(args) or "(nothing)"
        raise CommandError(f"{name} takes one of {'|'.join(options)}; got {given}")
    return options[args[0].lower()]


def _integer(text: str, what: str) -> int:
    if problem := digit_problem(text):  # int() reads '１２' as 12
        raise CommandError(f"{what} {text!r}: {problem}")
    if len(text) > 20:  # every value here fits a byte; 5000 digits are more than int() reads or prints
        raise CommandError(f"{what} must be a small whole number (decimal, or hex as 0x..), got "
                           f"{len(text)} characters: {text[:20]}...")
    try:
        return int(text, 16) if text.lower().startswith("0x") else int(text, 10)
    except ValueError:
        pass
    # hex as the decoder prints it ("stop (01/A0)"), as GX Works writes it (HA0, 16#A0), or A0h
    written = re.fullmatch(r"(?:16#|[hH])?([0-9a-fA-F]+)[hH]?", text)
    if written is not None and int(written.group(1), 16) <= 0xFF:  # `1e3` is no byte in hex either
        digits = written.group(1).upper()
        raise CommandError(f"{what} {text!r} is hex: write it 0x{digits} (or {int(digits, 16)} in decimal); a "
                           f"number without 0x is read as decimal")
    raise CommandError(f"{what} must be a whole number (decimal, or hex as 0x..), got {text!r}")


def _stage(text: str, what: str) -> int:
    stage = _integer(text, what)
    if not 0 <= stage <= 3:
        raise CommandError(f"{what} must be 0-3, got {stage}")
    return stage


def _scaled(text: str, step: Decimal, what: str, unit: str) -> tuple[int, int]:
    """(sign, units) for a signed decimal that must be a whole number of ``step``s ≤ 255."""
    if problem := digit_problem(text):  # Decimal() reads '٢.٥' as 2.5
        raise CommandError(f"{what} {text!r}: {problem}")
    try:
        value = Decimal(text)
    except InvalidOperation:
        value = None
    if value is None or not value.is_finite():
        raise CommandError(f"{what} must be a number like +1.5 or -0.3, got {text!r}")
    if value.copy_abs() >= step * 1_000_000:  # 1e999999 overflows abs() and the division; 9 x 5000 the digits of int()
        raise CommandError(f"{what} {text}{unit and ' ' + unit} is far more than 255 units of {step}; one byte "
                           f"holds at most 255 ({step * 255}{unit and ' ' + unit})")
    units = abs(value) / step
    if units != units.to_integral_value():
        raise CommandError(f"{what} {text} is not a whole number of {step}{unit and ' ' + unit} steps")
    if units > 255:
        limit = step * 255
        raise CommandError(
            f"{what} {text}{unit and ' ' + unit} is {int(units)} units of {step}; one byte holds at most "
            f"255 ({limit}{unit and ' ' + unit})"
        )
    return (-1 if value.is_signed() else 1), int(units)  # "-0" keeps its sign: code 07 with 0


# --- the other way round ----------------------------------------------------------------

def _reverse(table: dict) -> dict:
    out = {}
    for word, value in table.items():
        out.setdefault(value, word)
    return out


def words_for(request: ControlRequest | StatusRequest) -> list[str]:
    """The words that ``command_from_words`` turns into ``request`` (address aside)."""
    if isinstance(request, StatusRequest):
        return ["read", _reverse(_READ)[Query(request.query)]]
    code, command = ControlCode(request.code), request.command
    if problem := command_problem(code, command):
        raise CommandError(problem)
    if code is ControlCode.ROBOT:
        for table, name in ((_SEEK, "seek-tape"), (_FOLLOW, "follow-tape"), (_ROTATE_ON_TAPE, "rotate-on-tape")):
            if command in table.values():
                return [name, _reverse(table)[command]]
        if command in _SIMPLE.values():
            return [_reverse(_SIMPLE)[command]]
        return ["run-point", str(command)]
    if code in _SPEED.values():
        return ["speed", _reverse(_SPEED)[code], str(command)]
    if code is ControlCode.COLLISION_RANGE:
        return ["collision-range", str(command)]
    if code is ControlCode.MANUAL:
        return ["jog", _reverse(_JOG)[command]]
    if code in (ControlCode.ROTATE_POS, ControlCode.ROTATE_NEG):
        sign = "-" if code is ControlCode.ROTATE_NEG else "+"
        return ["rotate", f"{sign}{command * ROTATION_STEP}"]
    for axis, (positive, negative) in _MOVE_AXES.items():
        if code in (positive, negative):
            sign = "-" if code is negative else "+"
            return ["move", axis, f"{sign}{command * METRE_STEP}"]
    raise CommandError(f"no words for {request!r}")  # unreachable: every code is covered
