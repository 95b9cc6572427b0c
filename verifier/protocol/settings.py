"""The manual's ambiguities, each a named setting with the project's default.

Every field is one **[choice]** of docs/protocol.md: an integrator flips it after checking
a real robot; the emulator, the checks and the PLC library constants all read it from here.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

FieldOrder = Literal["code-high", "code-low"]
Codes10To13 = Literal["decimal", "hex"]
StatusOrder = Literal["query", "return"]

FIELD_ORDERS: tuple[str, ...] = ("code-high", "code-low")
CODES_10_13_STYLES: tuple[str, ...] = ("decimal", "hex")
STATUS_ORDERS: tuple[str, ...] = ("query", "return")

#: Modbus serial line: 0 is broadcast, 1-247 are slave addresses.
SLAVE_ADDRESSES = range(1, 248)


@dataclass(frozen=True)
class Settings:
    """How to read the manual where it can be read two ways.

    address
        The robot's Modbus slave address (manual: "默認 01", default 1).
    field_order
        FC06 register-address field: ``"code-high"`` (the manual's text: high byte =
        control code, low byte = command) or ``"code-low"`` (its printed examples 0001/0002).
    codes_10_13
        Control codes printed "10".."13": ``"decimal"`` (wire 0x0A-0x0D) or ``"hex"``
        (wire 0x10-0x13).
    status_order
        FC01 query parameter numbering: ``"query"`` (0 task, 1 vehicle, 2 speed,
        3 battery) or ``"return"`` (0 speed, 1 battery, 2 task, 3 vehicle).
    manual_stop_counts_as_stop
        Whether manual move 05/00 ("停止移動") is also accepted as the stop command
        that must come first after power-on (default: only 01/A0).
    """

    address: int = 1
    field_order: FieldOrder = "code-high"
    codes_10_13: Codes10To13 = "decimal"
    status_order: StatusOrder = "query"
    manual_stop_counts_as_stop: bool = False

    def __post_init__(self) -> None:
        if not isinstance(self.address, int) or self.address not in SLAVE_ADDRESSES:
            raise ValueError(f"robot address must be 1-247, got {self.address!r}")
        _check_choice("field_order", self.field_order, FIELD_ORDERS)
        _check_choice("codes_10_13", self.codes_10_13, CODES_10_13_STYLES)
        _check_choice("status_order", self.status_order, STATUS_ORDERS)
        if not isinstance(self.manual_stop_counts_as_stop, bool):
            raise ValueError("manual_stop_counts_as_stop must be true or false")


def _check_choice(name: str, value: object, allowed: tuple[str, ...]) -> None:
    if value not in allowed:
        raise ValueError(f"{name} must be one of {', '.join(allowed)}; got {value!r}")


DEFAULT_SETTINGS = Settings()
