"""The five frame kinds on the robot's line, as plain dataclasses (logical values, no CRC).

Codes and queries are held in their logical numbering (``ControlCode``, ``Query``); the
wire numbering is applied by ``codec.encode`` from the ``Settings``.
"""
from __future__ import annotations

from dataclasses import dataclass

from verifier.protocol.catalogue import (
    STATUS_QUANTITY,
    ControlCode,
    ExceptionCode,
    Query,
    RobotError,
)


def _as_enum(enum, value):
    """``value`` as a member of ``enum`` when it is one, else the plain int."""
    try:
        return enum(value)
    except ValueError:
        return value


@dataclass(frozen=True)
class _ControlFields:
    """Address, logical control code and command byte: the content of both FC06 frames."""

    address: int
    code: ControlCode
    command: int

    def __post_init__(self) -> None:
        object.__setattr__(self, "code", _as_enum(ControlCode, self.code))


@dataclass(frozen=True)
class ControlRequest(_ControlFields):
    """FC06 request: ``addr 06 CODE CMD 00 00 CRC``."""


@dataclass(frozen=True)
class ControlReply(_ControlFields):
    """FC06 normal reply: the echo of the request."""

    @classmethod
    def echo(cls, request: ControlRequest) -> "ControlReply":
        return cls(request.address, request.code, request.command)


@dataclass(frozen=True)
class StatusRequest:
    """FC01 request: ``addr 01 00 P 00 16 CRC`` (P = query parameter)."""

    address: int
    query: Query
    quantity: int = STATUS_QUANTITY

    def __post_init__(self) -> None:
        object.__setattr__(self, "query", _as_enum(Query, self.query))


@dataclass(frozen=True)
class StatusReply:
    """FC01 reply: ``addr 01 03 00 ERR VAL CRC``.

    ``query`` is known only when the reply was decoded against its request (or set by
    whoever builds the reply); it does not travel on the wire.
    """

    address: int
    error: RobotError
    value: int
    query: Query | None = None

    def __post_init__(self) -> None:
        object.__setattr__(self, "error", _as_enum(RobotError, self.error))
        if self.query is not None:
            object.__setattr__(self, "query", _as_enum(Query, self.query))


@dataclass(frozen=True)
class ExceptionReply:
    """Modbus exception reply: ``addr (FC|80) EXC CRC``; ``function`` is the plain FC."""

    address: int
    function: int
    exception_code: ExceptionCode

    def __post_init__(self) -> None:
        object.__setattr__(self, "exception_code", _as_enum(ExceptionCode, self.exception_code))


Request = ControlRequest | StatusRequest
Reply = ControlReply | StatusReply | ExceptionReply
Frame = Request | Reply


class FrameError(ValueError):
    """A frame that is not a valid UITAMR frame, with the byte where it goes wrong.

    ``offset`` is the 0-based byte index (== len(data) when bytes are missing).
    ``kind`` is a short tag ("length", "crc", "function", "address", "quantity",
    "value-field", "code", "command", "query", "byte-count", "data", "error-code",
    "value", "exception-code", "echo").
    ``exception`` is the Modbus exception a slave would answer with for this request
    (None = the slave stays silent: bad CRC, bad length), following the Modbus serial-line
    rules; it is meaningful for requests only.
    ``address``/``function`` are the frame's first two bytes when present, so a slave can
    build its exception reply without parsing again.
    ``silence`` says why no slave answers this request whatever its address, as the decoder
    found it: "broken" (a bad length or CRC: the frame is discarded), "function" (a
    function code no exception reply can answer, 00 or 80-FF); None when ``exception`` and
    the address decide (requests only, as ``exception``).
    """

    def __init__(
        self,
        message: str,
        offset: int,
        *,
        kind: str = "format",
        exception: ExceptionCode | None = None,
        address: int | None = None,
        function: int | None = None,
        silence: str | None = None,
    ) -> None:
        super().__init__(message, offset)
        self.message = message
        self.offset = offset
        self.kind = kind
        self.exception = exception
        self.address = address
        self.function = function
        self.silence = silence

    def __str__(self) -> str:
        return f"byte {self.offset}: {self.message}"
