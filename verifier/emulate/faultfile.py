"""``--faults FILE.toml``: scripted faults (``[[faults]]``) and robot settings (``[robot]``).

The same tables a verifier scenario uses, so a fault script written for CI runs on the
bench unchanged::

    [robot]
    turnaround_ms = 8
    point_duration_s = 12

    [[faults]]
    kind = "no_reply"
    on_request = 3
"""
from __future__ import annotations

import tomllib
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from verifier.amr import ConfigError, Fault, RobotConfig, check_fault_addresses, faults_from_list
from verifier.amr.schema import reject_unknown_keys
from verifier.place import Place
from verifier.textfile import UnreadableText, read_utf8, text_lines
from verifier.tomlpos import decode_error_position, place_of_key

FILE_KEYS = ("robot", "faults")


class FaultFileError(ValueError):
    """A fault file that cannot be used; the message names the file and the key."""


@dataclass(frozen=True)
class FaultFile:
    robot: dict[str, Any]
    faults: list[Fault]


def load_fault_file(path: str | Path, own_address: int | None = None) -> FaultFile:
    """Read and check a fault file. Every error names the file, the line and the key
    (``bench.toml:7:8: faults[0].kind: unknown fault 'x'; …``), as a scenario's do.

    ``own_address`` is the robot's address, when known: a ``wrong_address`` fault may not
    use it. The ``[robot]`` table is checked here, key by key, and returned as a table so
    that command-line options can still override single keys.
    """
    path = Path(path)
    try:
        text = read_utf8(path)
    except UnreadableText as err:  # file:line:col at bytes that are not text, as a scenario's
        raise FaultFileError(f"{_where(path, err.place)}: {err.after_place()}") from None
    try:
        data = tomllib.loads(text)
    except (ValueError, RecursionError) as err:
        # TOMLDecodeError, int()'s limit of 4300 digits, or arrays nested too deep for tomllib
        from verifier.monitor.capture import capture_instead

        message, line = decode_error_position(err, text)
        raise FaultFileError(f"{_where(path, line)}: not valid TOML: {message}{capture_instead(text, path)}") from None
    try:
        reject_unknown_keys(data, FILE_KEYS, "")
        robot = data.get("robot", {})
        if not isinstance(robot, dict):
            raise ConfigError("robot", "expected a table ([robot])")
        RobotConfig.from_dict(robot, "robot")
        faults = faults_from_list(data.get("faults", []))
        if own_address is not None:
            check_fault_addresses(faults, own_address)
    except ConfigError as err:
        place = place_of_key(text_lines(text), err.path, err.at_name)
        raise FaultFileError(f"{_where(path, place)}: {err}") from None
    return FaultFile(robot, faults)


def _where(path: Path, place: Place | None) -> str:
    return str(place.in_file(str(path))) if place is not None else str(path)
