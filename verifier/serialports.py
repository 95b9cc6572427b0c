"""What is wrong with a serial port a user named, in words to act on: for the two commands
that open one, `uitamr emulate` (the robot's end) and `uitamr monitor` (a tap on the line).
"""
from __future__ import annotations

import errno


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


def why_not_opened(err: Exception) -> str:
    """Why pyserial could not open a port, and what to do, for the mistakes made on site: a
    wrong name (or the adapter unplugged), a port the user may not open, one another program
    holds. Anything else in pyserial's words ("[Errno 2] could not open port /dev/ttyUSB9:
    [Errno 2] No such file or directory: '/dev/ttyUSB9'" said the first twice, and no more)."""
    number = getattr(err, "errno", None)
    if number == errno.ENOENT:
        return ("no such port: check its name and that the adapter is plugged in (Linux: `ls /dev/ttyUSB* "
                "/dev/ttyACM* /dev/serial/by-id/` lists the USB adapters; Windows: Device Manager, Ports (COM & LPT))")
    if number in (errno.EACCES, errno.EPERM):
        return ("permission denied: your user may not open it; add it to the port's group (`ls -l` names "
                "the group, dialout on Debian and Ubuntu: `sudo usermod -aG dialout $USER`, then log in again)")
    if number == errno.EBUSY:
        return "the port is busy: another program has it open (a terminal program, ModemManager); close that first"
    return str(err)
