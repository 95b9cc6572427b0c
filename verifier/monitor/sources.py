"""Where live bytes come from: a serial port (a pyserial URL too) or a TCP stream; each
read becomes a Chunk stamped with the host's monotonic clock (µs).

The monitor only listens. It opens a serial port for reading and never writes to it: on
an RS-485 line use an adapter whose transmitter stays off (receive-only), or one that
only drives while it is sent data — the monitor sends none. On the TCP route it connects
to a server that streams the line's bytes (a serial-to-Ethernet converter port set to
"TCP server" on a second RS-485 tap, or ser2net): one client among others, it reads.
"""
from __future__ import annotations

import errno
import socket
import time
from typing import Protocol

from verifier.serialports import why_it_failed, why_not_connected, why_not_opened

from .capture import Chunk

#: how long one read waits for bytes before the monitor looks at the clock (silence)
POLL_S = 0.002


def now_us() -> int:
    return time.monotonic_ns() // 1000


class ByteSource(Protocol):
    description: str

    def read(self) -> Chunk | None:
        """The next chunk, or None when nothing came within POLL_S."""

    def close(self) -> None: ...


class SourceError(Exception):
    """A port or server that cannot be opened or read; the message names it and why."""


class SerialSource:
    def __init__(self, port: str, baud: int, bytesize: int, parity: str, stopbits: float):
        import serial

        try:
            # exclusive (Linux/macOS: flock; Windows ports always are): a second reader of the
            # same port - `uitamr emulate`, another monitor - takes every byte it reads away
            # from this one, and both would judge a line with holes in it
            self.port = serial.serial_for_url(port, baudrate=baud, bytesize=bytesize, parity=parity,
                                              stopbits=stopbits, timeout=POLL_S, do_not_open=False,
                                              exclusive=True)
        except (serial.SerialException, ValueError, OSError) as exc:
            if getattr(exc, "errno", None) in (errno.EAGAIN, errno.EWOULDBLOCK):
                raise SourceError(f"cannot open {port}: another program has it open and locked (uitamr "
                                  "emulate, or another uitamr monitor?); each would read only part of the "
                                  "line's bytes: stop that one first, or tap the line with a second "
                                  "adapter") from None
            raise SourceError(f"cannot open {port}: {why_not_opened(exc)}") from None
        self.description = port
        self._error = serial.SerialException

    def read(self) -> Chunk | None:
        """The bytes that came: the first one waited for, then all that are already there
        with it, in one chunk. Bytes that were waiting together are never two chunks: were
        the host to stall this process between two reads of one frame (a loaded machine,
        a slow terminal), the second read's later time would look like a silence inside
        the frame, and the frame would be judged as two."""
        try:
            data = self.port.read(self.port.in_waiting or 1)
            if data and self.port.in_waiting:
                data += self.port.read(self.port.in_waiting)
        except (self._error, OSError) as exc:  # in_waiting's ioctl on a port gone: OSError (EIO)
            raise SourceError(f"{self.description}: {why_it_failed(exc)}") from None
        if not data:
            return None
        return Chunk(now_us(), bytes(data))

    def close(self) -> None:
        self.port.close()


class TcpSource:
    def __init__(self, host: str, port: int, connect_timeout_s: float = 5.0):
        try:
            self.sock = socket.create_connection((host, port), timeout=connect_timeout_s)
        except OSError as exc:
            raise SourceError(f"cannot connect to {host}:{port}: {why_not_connected(exc)}") from None
        except UnicodeError:  # from the idna codec, before any lookup
            raise SourceError(f"cannot connect to {host}:{port}: not a host name (a part between dots is "
                              "empty or longer than 63 characters)") from None
        self.sock.settimeout(POLL_S)
        self.description = f"tcp {host}:{port}"

    def read(self) -> Chunk | None:
        try:
            data = self.sock.recv(4096)
        except (TimeoutError, socket.timeout):
            return None
        except OSError as exc:  # "Connection reset by peer": said with what to check
            raise SourceError(f"{self.description}: {why_it_failed(exc)}") from None
        if not data:
            raise SourceError(f"{self.description}: the server closed the connection")
        return Chunk(now_us(), data)

    def close(self) -> None:
        self.sock.close()
