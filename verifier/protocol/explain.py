"""Field-by-field layout of a frame, for ``uitamr frame --explain`` and the docs.

Works on any bytes, valid or not: each field is named from its position (given the
function code and the direction) and its value is interpreted where it can be.
"""
from __future__ import annotations

import unicodedata
from dataclasses import dataclass

from verifier.protocol.catalogue import (
    ERROR_TITLES,
    EXCEPTION_FLAG,
    EXCEPTION_TITLES,
    FC_READ_COILS,
    FC_WRITE_SINGLE_REGISTER,
    QUERY_TITLES,
    CODE_TITLES,
    command_problem,
    command_title,
    logical_code,
    logical_query,
)
from verifier.protocol.codec import hex_bytes
from verifier.protocol.crc import crc16, crc_bytes
from verifier.protocol.settings import Settings
from verifier.protocol.stream import Direction


@dataclass(frozen=True)
class Field:
    start: int  # first byte offset
    data: bytes  # the bytes of the field (fewer than its size when the frame is short)
    name: str  # the manual's term, English (Chinese)
    meaning: str  # what the value says, or what is wrong with it

    @property
    def offsets(self) -> str:
        end = self.start + max(len(self.data), 1) - 1
        return str(self.start) if end == self.start else f"{self.start}-{end}"


_FUNCTION_TEXT = {
    FC_READ_COILS: "01 read coils: status read",
    FC_WRITE_SINGLE_REGISTER: "06 write single register: control",
}


def explain(data: bytes, settings: Settings, direction: Direction) -> list[Field]:
    """The fields of ``data`` read as a ``direction`` frame."""
    data = bytes(data)
    function = data[1] if len(data) > 1 else None
    if function is not None and direction == "reply" and function & EXCEPTION_FLAG:
        layout = _exception_layout(data)
    elif function == FC_WRITE_SINGLE_REGISTER:
        layout = _control_layout(data, settings)
    elif function == FC_READ_COILS and direction == "request":
        layout = _status_request_layout(data, settings)
    elif function == FC_READ_COILS:
        layout = _status_reply_layout(data)
    else:
        layout = [(2, len(data) - 4, "data", "unknown layout for this function code")] if len(data) > 4 else []
    fields = [
        _field(data, 0, 1, "address (模塊地址)", _address_text(data, settings)),
        _field(data, 1, 1, "function code (功能碼)", _function_text(function)),
    ]
    fields += [_field(data, start, size, name, meaning) for start, size, name, meaning in layout]
    crc_at = max(len(data) - 2, 2) if not layout else layout[-1][0] + layout[-1][1]
    fields.append(_field(data, crc_at, 2, "CRC (CRC 校驗碼), low byte first", _crc_text(data, crc_at)))
    extra = data[crc_at + 2:]
    if extra:
        fields.append(Field(crc_at + 2, extra, "extra bytes", "beyond the end of this frame kind"))
    return fields


def _field(data: bytes, start: int, size: int, name: str, meaning: str) -> Field:
    chunk = data[start:start + size]
    if len(chunk) < size:
        meaning = f"missing ({len(chunk)} of {size} bytes)"
    return Field(start, chunk, name, meaning)


def _address_text(data: bytes, settings: Settings) -> str:
    if not data:
        return ""
    if data[0] == 0:
        return "0: broadcast"
    mine = "this robot" if data[0] == settings.address else f"not this robot ({settings.address})"
    return f"{data[0]}: {mine}"


def _function_text(function: int | None) -> str:
    if function is None:
        return ""
    if function & EXCEPTION_FLAG:
        return f"{function:02X}: exception reply to function {function & 0x7F:02X}"
    return _FUNCTION_TEXT.get(function, f"{function:02X}: unknown to the robot")


def _control_layout(data: bytes, settings: Settings) -> list[tuple[int, int, str, str]]:
    code_at, command_at = (2, 3) if settings.field_order == "code-high" else (3, 2)
    code_text = command_text = ""
    if len(data) > max(code_at, command_at):
        try:
            code = logical_code(data[code_at], settings)
        except ValueError as exc:
            code_text, command_text = str(exc), ""
        else:
            code_text = f"{int(code):02d}: {CODE_TITLES[code]}"
            problem = command_problem(code, data[command_at])
            command_text = problem or command_title(code, data[command_at])
    value = data[4:6]
    fields = [
        (code_at, 1, "control code (控制代號)", code_text),
        (command_at, 1, "control command (控制指令)", command_text),
    ]
    fields.sort()
    fields.append((4, 2, "value (always 0)", "ok" if value == b"\x00\x00" else "must be 00 00"))
    return fields


def _status_request_layout(data: bytes, settings: Settings) -> list[tuple[int, int, str, str]]:
    query_text = ""
    if len(data) >= 4:
        parameter = int.from_bytes(data[2:4], "big")
        try:
            query_text = f"{parameter}: {QUERY_TITLES[logical_query(parameter, settings)]}"
        except ValueError as exc:
            query_text = str(exc)
    quantity = int.from_bytes(data[4:6], "big") if len(data) >= 6 else None
    quantity_text = "22 coils: ok" if quantity == 22 else f"{quantity}: must be 22 (00 16)"
    return [(2, 2, "query parameter (查詢參數)", query_text), (4, 2, "quantity (位元)", quantity_text)]


def _status_reply_layout(data: bytes) -> list[tuple[int, int, str, str]]:
    count_text = "3: ok" if data[2:3] == b"\x03" else "must be 03"
    first_text = "0: ok" if data[3:4] == b"\x00" else "must be 00"
    error_text = ""
    if len(data) > 4:
        error_text = f"{data[4]:02X}: {ERROR_TITLES.get(data[4], 'unknown error code')}"
    value_text = f"{data[5]}: meaning depends on the query asked" if len(data) > 5 else ""
    return [
        (2, 1, "byte count (固定值 03)", count_text),
        (3, 1, "first data byte (固定值 00)", first_text),
        (4, 1, "error code (錯誤代碼, table 3)", error_text),
        (5, 1, "value (回傳參數)", value_text),
    ]


def _exception_layout(data: bytes) -> list[tuple[int, int, str, str]]:
    text = ""
    if len(data) > 2:
        text = f"{data[2]:02X}: {EXCEPTION_TITLES.get(data[2], 'unknown exception code')}"
    return [(2, 1, "exception code", text)]


def _crc_text(data: bytes, crc_at: int) -> str:
    got = data[crc_at:crc_at + 2]
    if len(got) < 2:
        return ""
    expected = crc16(data[:crc_at])
    carried = got[0] | got[1] << 8
    if carried == expected:
        return f"0x{expected:04X}: ok"
    return f"0x{carried:04X}: wrong, expected 0x{expected:04X} ({hex_bytes(crc_bytes(expected))})"


def _width(text: str) -> int:
    """Columns ``text`` takes in a terminal (CJK characters take two)."""
    return sum(2 if unicodedata.east_asian_width(ch) in "WF" else 1 for ch in text)


def _pad(text: str, width: int) -> str:
    return text + " " * (width - _width(text))


def explain_table(fields: list[Field]) -> str:
    """Fixed-width text table of the fields."""
    rows = [("byte", "hex", "field", "meaning")]
    rows += [(f.offsets, hex_bytes(f.data), f.name, f.meaning) for f in fields]
    widths = [max(_width(row[i]) for row in rows) for i in range(3)]
    return "\n".join(
        "  ".join(_pad(cell, width) for cell, width in zip(row, widths)) + "  " + row[3]
        for row in rows
    ).replace("  \n", "\n").rstrip()
