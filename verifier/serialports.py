"""What is wrong with a serial port a user named, in words to act on: for the two commands
that open one, `uitamr emulate` (the robot's end) and `uitamr monitor` (a tap on the line);
with the TCP server either dials (a pyserial socket:// URL, `monitor --tcp`); and with the
TCP port `uitamr emulate --tcp` listens on.
"""
from __future__ import annotations

import errno
import socket


def serial_url_problem(url: str) -> str | None:
    """What is wrong with a pyserial network URL (socket://, rfc2217://) before pyserial
    says it less clearly: it needs HOST:PORT with a port 1-65535. None for other ports.
    An empty name (`--serial "$PORT"` with PORT unset) is named as such, not as no file ''."""
    if not url.strip():
        return "the port name is empty: give the serial port, e.g. /dev/ttyUSB0 or COM3"
    scheme, sep, rest = url.partition("://")
    if not sep or scheme.lower() not in ("socket", "rfc2217"):
        return None
    host, colon, port = rest.split("/", 1)[0].split("?", 1)[0].rpartition(":")
    if not colon or not host:
        return f"{url} needs a host and a port: {scheme}://HOST:PORT"
    if not (port.isascii() and port.isdigit()) or len(port) > 5 or not 1 <= int(port) <= 65535:  # not '²'
        return f"{url}: the port {port!r} is not a number from 1 to 65535"
    return None


def _cause(err: BaseException) -> BaseException:
    """The error pyserial wrapped: for socket:// and rfc2217:// URLs it raises a
    SerialException without an errno, "Could not open port socket://...: [Errno 111]
    Connection refused", the socket's OSError only as the context."""
    if getattr(err, "errno", None) is None and isinstance(err.__context__, (OSError, socket.gaierror)):
        return err.__context__
    return err


def why_not_opened(err: Exception) -> str:
    """Why pyserial could not open a port, and what to do, for the mistakes made on site: a
    wrong name (or the adapter unplugged), a port the user may not open, one another program
    holds, a file that is no serial port, a serial server (socket://) that cannot be reached.
    Anything else in pyserial's words ("[Errno 2] could not open port /dev/ttyUSB9:
    [Errno 2] No such file or directory: '/dev/ttyUSB9'" said the first twice, and no more)."""
    cause = _cause(err)
    if cause is not err and isinstance(cause, OSError):
        return why_not_connected(cause)
    number = getattr(err, "errno", None)
    if number is None and getattr(err.__context__, "args", ())[:1] == (errno.ENOTTY,):  # termios.error
        return ("not a serial port (a file or another kind of device): give the adapter's port, e.g. "
                "/dev/ttyUSB0 or COM3")
    if "does not seem to support RFC2217" in str(err):  # pyserial's rfc2217:// after its negotiation failed
        return ("the server does not speak RFC 2217 (telnet COM port control): for a converter or ser2net that "
                "passes the bytes as they are (raw TCP), give socket://HOST:PORT")
    if number == errno.ENOENT:
        return ("no such port: check its name and that the adapter is plugged in (Linux: `ls /dev/ttyUSB* "
                "/dev/ttyACM* /dev/serial/by-id/` lists the USB adapters; Windows: Device Manager, Ports (COM & LPT))")
    if number == errno.EISDIR:  # Tab completion stops at /dev/serial/by-id/
        return ("a folder, not a serial port: give the adapter's port, e.g. /dev/ttyUSB0 or a name in "
                "/dev/serial/by-id/ (Linux: `ls /dev/ttyUSB* /dev/ttyACM* /dev/serial/by-id/` lists the USB adapters)")
    if number in (errno.EACCES, errno.EPERM):
        return ("permission denied: your user may not open it; add it to the port's group (`ls -l` names "
                "the group, dialout on Debian and Ubuntu: `sudo usermod -aG dialout $USER`, then log in again)")
    if number == errno.EBUSY:
        return "the port is busy: another program has it open (a terminal program, ModemManager); close that first"
    return str(err)


def why_not_connected(err: OSError) -> str:
    """Why a TCP server (a converter streaming the line, a serial device server) could not be
    reached, and what to check: it refused, it did not answer, this PC has no route to it,
    its name is unknown. Anything else in the socket's words."""
    if isinstance(err, socket.gaierror):
        return "not an address, nor a name this PC can look up: give the converter's IP address"
    number = err.errno
    if number == errno.ECONNREFUSED:
        return ("refused: nothing accepts connections on that port; check the address and port (the converter's "
                "web page), that it is set to TCP server and is on, and that no other client holds its one "
                "connection")
    if isinstance(err, TimeoutError) or number == errno.ETIMEDOUT:
        return ("no answer: check the address, that the converter is on and on this PC's network "
                "(`ping` it), and any firewall between them")
    if number in (errno.EHOSTUNREACH, errno.ENETUNREACH):
        return ("no route to it: this PC is not on the converter's network; give the PC an address in the "
                "converter's subnet, or check the address")
    return err.strerror or str(err)


def why_not_listening(err: OSError, host: str, port: int) -> str:
    """Why --tcp cannot listen, and what to do: Python said "[Errno 98] Address already in
    use (while attempting to bind on address ('0.0.0.0', 4001))" for the usual one, an
    emulator started earlier still running."""
    if isinstance(err, socket.gaierror) or (err.errno or 0) < 0:  # bind() says getaddrinfo's EAI_* as errno
        return f"{host} is not an address, nor a name this PC can look up: give one of its own IP addresses"
    if err.errno == errno.EADDRINUSE:
        return (f"the port is in use: another program listens on {port} (an emulator started earlier?); stop "
                "it, or give another port (--tcp 0 picks a free one)")
    if err.errno == errno.EADDRNOTAVAIL:
        return (f"{host} is not an address of this PC: give one of its own (Linux: `ip -brief address`, "
                "Windows: `ipconfig`), 0.0.0.0 for all of them, or the port alone for 127.0.0.1")
    if err.errno in (errno.EACCES, errno.EPERM) and 0 < port < 1024:
        return "permission denied: ports below 1024 need root; give a port from 1024 up, e.g. 4001"
    return err.strerror or str(err)


#: pyserial 3.5's words when a port it reads from has gone (select says readable, read gives
#: nothing): a USB adapter unplugged, or the socat that made a pty ended
_GONE = "device reports readiness to read but returned no data"


def why_it_failed(err: Exception) -> str:
    """Why a serial port that was open failed while in use, and what to do: an unplugged
    adapter gave pyserial's "device reports readiness to read but returned no data (device
    disconnected or multiple access on port?)" - the port is locked, so it is the first -
    or "[Errno 5] Input/output error"; a TCP stream (monitor --tcp) that the converter reset
    gave "Connection reset by peer". Anything else in pyserial's or the socket's words."""
    number = getattr(_cause(err), "errno", None)
    if number is None and err.args and isinstance(err.args[0], int):  # termios.error(5, 'Input/output error')
        number = err.args[0]
    if _GONE in str(err) or number in (errno.EIO, errno.ENXIO, errno.ENODEV):
        return ("the port went away: the USB adapter was unplugged or lost power (or the program that made the "
                "pty ended); plug it back in and start again")
    if number in (errno.ECONNRESET, errno.ECONNABORTED):  # the converter's RST: "Connection reset by peer"
        return ("the server reset the connection: the converter restarted, lost power or dropped this client; "
                "check it and start again")
    if str(err).endswith("socket disconnected"):  # pyserial's socket:// URL: "read failed: socket disconnected"
        return "the serial server closed the connection"
    return str(err)
