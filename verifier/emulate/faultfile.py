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

from verifier.amr import ConfigError, Fault, faults_from_list
from verifier.amr.schema import reject_unknown_keys

FILE_KEYS = ("robot", "faults")


class FaultFileError(ValueError):
    """A fault file that cannot be used; the message names the file and the key."""


@dataclass(frozen=True)
class FaultFile:
    robot: dict[str, Any]
    faults: list[Fault]


def load_fault_file(path: str | Path) -> FaultFile:
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8")
    except OSError as err:
        raise FaultFileError(f"{path}: cannot read: {err.strerror or err}") from None
    except UnicodeDecodeError as err:
        raise FaultFileError(f"{path}: byte {err.start}: not UTF-8 text") from None
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as err:
        raise FaultFileError(f"{path}: not valid TOML: {err}") from None
    try:
        reject_unknown_keys(data, FILE_KEYS, "")
        robot = data.get("robot", {})
        if not isinstance(robot, dict):
            raise ConfigError("robot", "expected a table ([robot])")
        faults = faults_from_list(data.get("faults", []))
    except ConfigError as err:
        raise FaultFileError(f"{path}: {err}") from None
    return FaultFile(robot, faults)
