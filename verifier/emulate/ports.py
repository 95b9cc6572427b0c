"""The emulator on real ports: a serial port (any pyserial URL) or a TCP listener carrying
raw RTU frames (as a transparent serial-to-TCP converter does).

Why not pymodbus's ModbusSerialServer / ModbusTcpServer: reading pymodbus 3.16
(``framer/rtu.py``, ``server/requesthandler.py``) shows that its RTU framer has no
inter-frame timing (a noise byte before a request loses the request; on a CRC failure it
drops the whole buffer; an unknown function code is hunted byte by byte and swallows the
next request), that the server answers an undecodable request with exception 01 and a
request for an unknown slave with exception 0B unless told to ignore it, and that replies
are always built by its framer from a PDU, at once. The robot needs its reply bytes sent
exactly as the model made them (garbage, corrupted CRC, another slave's address, late
replies) and the Modbus silence rules; so the framing is ours (``assembler``) over pyserial
and plain sockets, and pymodbus serves as an independent client in the tests.
"""
from __future__ import annotations

import errno
import selectors
import socket
from dataclasses import dataclass, field

import serial

from verifier.emulate.assembler import RequestAssembler
from verifier.emulate.core import Emulator, Outgoing, counted
from verifier.link.line import LineConfig
from verifier.protocol.codec import hex_bytes
from verifier.serialports import why_it_failed, why_not_listening, why_not_opened
from verifier.stopflag import StopFlag

POLL_S = 0.005  # longest wait between looks at the clock (reply and silence deadlines)


# how long replies still owed to a peer that shut its sending side are waited for
END_GRACE_US = 2_000_000
# how long after a reply has left the line its echo may still come back through a USB
# adapter (latency timers: 16 ms by default on FTDI chips) or a busy pty. Kept short: an FC06
# reply is its request byte for byte, so a master that sends the same command again this
# soon after the reply (a retry after a reply that came late) would be taken for the echo
ECHO_GRACE_US = 60_000


class PortError(RuntimeError):
    """A port that cannot be opened or failed while in use (message for the user);
    `in_use`: it failed after the emulator had begun to serve on it."""

    def __init__(self, message: str, in_use: bool = False):
        super().__init__(message)
        self.in_use = in_use


@dataclass
class _Channel:
    """One conversation: its own assembler and its replies waiting for their time."""

    assembler: RequestAssembler
    peer: str = ""
    outgoing: list[Outgoing] = field(default_factory=list)
    line: LineConfig = field(default_factory=LineConfig)  # the robot's line (TCP: behind the converter)
    line_free_us: int = 0  # t3.5 after the last reply left the line: the next may start
    ended_us: int | None = None  # when the peer closed its sending side (replies still owed)
    unread_at_end: bytes = b""  # a request it had not finished when it did

    @property
    def ended(self) -> bool:
        return self.ended_us is not None

    def end(self, now_us: int) -> None:
        """The peer shut its sending side: no more bytes come, so a part of a request is
        dropped now; the replies already owed are still sent (`finished` says when done)."""
        self.ended_us = now_us
        self.unread_at_end = self.assembler.discard()

    def finished(self, now_us: int) -> bool:
        """Ended, and every reply sent - or the grace for them over (a peer that closed
        altogether looks the same as one that only shut its sending side)."""
        return self.ended_us is not None and (not self.outgoing or now_us - self.ended_us >= END_GRACE_US)

    def take(self, emulator: Emulator, items) -> None:
        for item in items:
            reply = emulator.handle(item, self.peer)
            if reply is not None:
                self.outgoing.append(reply)
        self.outgoing.sort(key=lambda o: o.due_us)

    def close(self, emulator: Emulator) -> str:
        """Forget what is still in flight (counting replies not sent); the words for the
        log, '' when nothing was."""
        emulator.not_sent(len(self.outgoing))
        unread = self.unread_at_end + self.assembler.discard()
        lost = []
        if unread:
            lost.append(f"{counted(len(unread), 'received byte', 'received bytes')} that were not yet "
                        f"a whole request dropped ({hex_bytes(unread)})")
        if self.outgoing:
            lost.append(f"{counted(len(self.outgoing), 'reply', 'replies')} not sent")
            self.outgoing = []
        return "; " + ", ".join(lost) if lost else ""

    def due(self, now_us: int) -> list[Outgoing]:
        """The reply to send now, if one is due and the line is free: at most one, and
        marked as sent. Two replies owed at once (a master that sent two requests together)
        went out back to back, which a master reads as one frame with a bad CRC; Modbus
        needs t3.5 of silence between frames (Modbus over Serial Line V1.02 §2.5.1.1)."""
        if not self.outgoing or self.outgoing[0].due_us > now_us or now_us < self.line_free_us:
            return []
        reply = self.outgoing.pop(0)
        self.line_free_us = now_us + self.line.offset_us(len(reply.data)) + self.line.frame_gap_us
        return [reply]


class _EchoFilter:
    """Drops the bytes a 2-wire adapter with local echo hands back of what the emulator
    sent: the robot's transceiver does not hear itself, and an FC06 reply heard back is
    the request again, which the emulator then answered, and so on for ever."""

    def __init__(self) -> None:
        self._expected = b""
        self._until_us = 0
        self._held = b""  # bytes that match the echo's start, until it is whole
        self.seen = False  # an echo has come back at least once

    def sent(self, data: bytes, until_us: int) -> None:
        self._expected, self._until_us, self._held = bytes(data), until_us, b""

    def strip(self, data: bytes, t_us: int) -> bytes:
        """``data`` without the echo at its start, if it begins with the bytes expected.
        Bytes that match only the echo's start are held: a master's next request begins
        like the reply (address, function) and comes a byte at a time; they are given back
        with the first byte that is not the echo's. An echo cut short is dropped."""
        if not self._expected or t_us > self._until_us:
            self._expected, self._held = b"", b""
            return data
        n = min(len(data), len(self._expected))
        if data[:n] != self._expected[:n]:
            held, self._expected, self._held = self._held, b"", b""  # not an echo: a master's bytes
            return held + data
        self._expected, self._held = self._expected[n:], self._held + data[:n]
        if self._expected:
            return b""
        self._held, self.seen = b"", True
        return data[n:]


try:  # pyserial's flush() is termios.tcdrain on POSIX, whose error is no OSError
    from termios import error as _DrainError
except ImportError:  # Windows: no termios, pyserial raises SerialException
    _DrainError = OSError


def send_reply(port: serial.SerialBase, url: str, data: bytes) -> None:
    """Write a reply and wait until it has left. A port that goes away (the adapter
    unplugged) between the write and the drain made the drain raise termios.error, which
    ended the emulator in a traceback without its summary, 1 time in 3 on a loaded bench PC."""
    try:
        port.write(data)
        port.flush()
    except (serial.SerialException, OSError, _DrainError) as err:
        raise PortError(f"serial port {url} failed while writing: {why_it_failed(err)}", in_use=True) from None


def t3_5_at(baudrate: int) -> int:
    """t3.5, the silence that ends a frame, on a line at ``baudrate`` (µs)."""
    return LineConfig(baud=baudrate).frame_gap_us


def serial_assembler(baudrate: int, silence_us: int) -> RequestAssembler:
    """The assembler for a serial port at ``baudrate``. Modbus ends a frame after 3.5
    character times: 3.65 ms at 9600 bit/s, but 117 ms at 300 bit/s, where one byte alone
    takes longer than the default wall-clock gap - so the gap is never shorter than t3.5."""
    t3_5_us = t3_5_at(baudrate)
    return RequestAssembler(max(silence_us, t3_5_us), t3_5_us=t3_5_us)


def serve_serial(url: str, emulator: Emulator, stop: StopFlag, silence_us: int,
                 baudrate: int = 9600) -> None:
    """Run until ``stop`` is set: read requests from ``url``, write replies when due."""
    try:
        # exclusive: a second emulator (or a monitor, or another locking program) on the same
        # port would take every other request, and each would answer what it read
        port = serial.serial_for_url(url, baudrate=baudrate, bytesize=serial.EIGHTBITS,
                                     parity=serial.PARITY_NONE, stopbits=serial.STOPBITS_ONE,
                                     timeout=POLL_S, exclusive=True)
    except (serial.SerialException, ValueError, OSError) as err:
        if getattr(err, "errno", None) in (errno.EAGAIN, errno.EWOULDBLOCK):
            raise PortError(f"cannot open serial port {url}: another program has it locked (another "
                            "uitamr emulate, or a uitamr monitor?); stop that one first") from None
        raise PortError(f"cannot open serial port {url}: {why_not_opened(err)}") from None
    channel = _Channel(serial_assembler(baudrate, silence_us), line=LineConfig(baud=baudrate))
    gap_us = channel.assembler.silence_us
    longer = f", frame gap {gap_us / 1000:g} ms (t3.5 at {baudrate} bit/s)" if gap_us > silence_us else ""
    emulator.note(f"listening on serial {url} at {baudrate} 8N1{longer}, "
                  f"robot address {emulator.robot.settings.address}")
    echo = _EchoFilter()
    try:
        while not stop.is_set():
            try:
                data = port.read(1)
                if data and port.in_waiting:
                    data += port.read(port.in_waiting)
            except (serial.SerialException, OSError) as err:
                raise PortError(f"serial port {url} failed: {why_it_failed(err)}", in_use=True) from None
            now = emulator.now_us()
            if data:
                heard_before = echo.seen
                data = echo.strip(data, now)
                if echo.seen and not heard_before:
                    emulator.note(f"serial {url} echoes what the emulator sends (a 2-wire adapter with local "
                                  "echo): the echo is dropped, as the robot does not hear its own replies")
            channel.take(emulator, channel.assembler.feed(data, now) if data else channel.assembler.poll(now))
            emulator.tick()
            now = emulator.now_us()
            for reply in channel.due(now):
                try:
                    send_reply(port, url, reply.data)
                except PortError:
                    # not seen to leave: the closing line names it and the summary counts it as
                    # not sent (it was counted nowhere: frames in were more than the sum)
                    channel.outgoing.insert(0, reply)
                    raise
                echo.sent(reply.data, emulator.now_us() + channel.line.offset_us(len(reply.data)) + ECHO_GRACE_US)
                emulator.sent(reply, now)
    finally:
        port.close()
        if left_behind := channel.close(emulator):
            emulator.note(f"serial {url} closed{left_behind}")


#: the most one read of a client takes (a flood beyond it is read on the next round)
READ_AT_ONCE = 1 << 20


def _read_waiting(sock: socket.socket) -> bytes:
    """Every byte a client's socket holds now (up to READ_AT_ONCE), in one piece; b"" when
    the peer shut its side. Read 4096 bytes at a time, a flood that had already come was
    framed in pieces, and a host that stalled the emulator between two of them for longer
    than the frame gap made it take the stall for a silence: the flood was cut, its tail
    taken for a new frame, and a request sent after the first "!!" line was glued to it
    (no reply). Bytes that arrive while the emulator is stalled still get the later time."""
    data = sock.recv(65536)
    while data and len(data) < READ_AT_ONCE:
        try:
            more = sock.recv(65536)
        except OSError:  # nothing more waits (or the connection failed: said on the next read)
            break
        if not more:  # the peer shut its side: said on the next read
            break
        data += more
    return data


def serve_tcp(host: str, port: int, emulator: Emulator, stop: StopFlag, silence_us: int,
              on_listening=None) -> None:
    """Run until ``stop`` is set: accept clients on host:port; each has its own framing,
    all share the one robot."""
    try:
        family = socket.AF_INET6 if ":" in host else socket.AF_INET
        server = socket.create_server((host, port), family=family)
    except OSError as err:
        raise PortError(f"cannot listen on {f'[{host}]' if ':' in host else host}:{port}: "
                        f"{why_not_listening(err, host, port)}") from None
    server.setblocking(False)
    bound_host, bound_port = server.getsockname()[:2]
    if ":" in bound_host:
        bound_host = f"[{bound_host}]"  # as --tcp takes it back: [::1]:4001
    selector = selectors.DefaultSelector()
    selector.register(server, selectors.EVENT_READ, None)
    clients: dict[socket.socket, _Channel] = {}
    emulator.note(f"listening on tcp {bound_host}:{bound_port} (raw RTU frames), "
                  f"robot address {emulator.robot.settings.address}")
    if on_listening is not None:
        on_listening(bound_host, bound_port)

    def drop(sock: socket.socket, why: str) -> None:
        channel = clients.pop(sock)
        if not channel.ended:  # an ended one is no longer watched for reading
            selector.unregister(sock)
        sock.close()
        emulator.note(f"client {channel.peer} {why}{channel.close(emulator)}")

    try:
        while not stop.is_set():
            for key, _ in selector.select(POLL_S):
                if key.fileobj is server:
                    try:
                        sock, address = server.accept()
                    except OSError:
                        continue
                    sock.setblocking(False)
                    sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
                    peer = f"{address[0]}:{address[1]}"
                    clients[sock] = _Channel(RequestAssembler(silence_us), peer)
                    selector.register(sock, selectors.EVENT_READ, None)
                    emulator.note(f"client {peer} connected")
                    continue
                sock = key.fileobj
                try:
                    data = _read_waiting(sock)
                except (BlockingIOError, InterruptedError):
                    continue
                except OSError as err:
                    drop(sock, f"lost: {err}")
                    continue
                if not data:  # the peer shut its side: what it sent is still answered
                    channel = clients[sock]
                    channel.end(emulator.now_us())
                    selector.unregister(sock)
                    if not channel.outgoing:
                        drop(sock, "disconnected")
                    continue
                channel = clients[sock]
                channel.take(emulator, channel.assembler.feed(data, emulator.now_us()))
            now = emulator.now_us()
            for sock, channel in list(clients.items()):
                channel.take(emulator, channel.assembler.poll(now))
            emulator.tick()
            for sock, channel in list(clients.items()):
                now = emulator.now_us()
                for reply in channel.due(now):
                    try:
                        sock.sendall(reply.data)
                    except OSError as err:
                        drop(sock, f"lost while writing: {err}")
                        break
                    emulator.sent(reply, now, channel.peer)
            for sock, channel in list(clients.items()):
                if channel.finished(emulator.now_us()):
                    drop(sock, "disconnected")
    finally:
        for sock in list(clients):
            drop(sock, "closed: the emulator stops")
        selector.close()
        server.close()
