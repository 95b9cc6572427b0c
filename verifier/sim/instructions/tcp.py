"""TCP connections of the PLC's Ethernet port to a serial-to-TCP converter.

Two families of instructions, one model of a connection underneath:

* FX5U/FX5UC built-in Ethernet, socket communication: ``SP_SOCOPEN``, ``SP_SOCSND``,
  ``SP_SOCRCV``, ``SP_SOCCLOSE`` (ladder SP.SOCOPEN ...); status in SD10680 (open
  completion signal) and SD10682 (receive state signal), bit n-1 for connection n.
* QJ71E71-100 on a Q CPU, fixed buffer communication without procedure: ``ZP_OPEN``,
  ``ZP_BUFSND``, ``ZP_BUFRCV``, ``ZP_CLOSE``; status in the module's buffer memory:
  5000H (open completion signal) and 5005H (fixed buffer reception status signal).

ST calls, operand layouts, what is cited and what is an ASSUMPTION: docs/instructions.md
("Ethernet: FX5U socket communication", "Ethernet: QJ71E71-100 fixed buffer").

The other end is the object attached with `Project.attach_tcp` (a
`verifier.link.converter.Converter`: ``open``, ``send``, ``receive_until``,
``peer_closed``, ``close``); with nothing attached every open fails as unreachable.
"""
from __future__ import annotations

from collections import deque

from verifier.plcfacts import E71_OPEN_SIGNAL, E71_RECEIVE_SIGNAL

from ..refs import operand_key, pulse_keys

# completion status codes the simulator writes (ASSUMPTION: the modules' own codes are
# not modelled; these sit in a range the modules do not document, like the C24 model's)
ERR_REFUSED = 0x7FE1  # the converter answered the open with a reset
ERR_UNREACHABLE = 0x7FE2  # nothing answered the open
ERR_NOT_OPEN = 0x7FE3  # send/receive/close on a connection that is not open
ERR_CONNECTION = 0x7FE4  # connection number out of range, or the wrong direction (E71)
ERR_ALREADY_OPEN = 0x7FE5  # open of a connection that is open or opening
ERR_PARAMETER_OPEN = 0x7FE6  # execution type 0 (open settings from parameters): not modelled
ERR_LENGTH = 0x7FE7  # send length 0 or longer than the data block
ERR_NOT_TCP_ACTIVE = 0x7FE8  # application setting other than TCP, active open

EXECUTE_WITH_CONTROL_DATA = 0x8000
CONNECTIONS = range(1, 9)

CLOSED, OPENING, OPEN, PEER_CLOSED = "closed", "opening", "open", "closed by the converter"


def _ip_text(low: int, high: int) -> str:
    value = (high & 0xFFFF) << 16 | (low & 0xFFFF)
    return ".".join(str(value >> s & 0xFF) for s in (24, 16, 8, 0))


class _Connection:
    __slots__ = ("number", "state", "remote", "open_done_us", "open_ok", "open_status", "open_refs", "received",
                 "receiver", "partner", "pair")

    def __init__(self, number: int):
        self.number = number
        self.state = CLOSED
        self.remote = 0  # the converter's connection number
        self.open_done_us = 0
        self.open_ok = False
        self.open_status = 0
        self.open_refs = None  # (control data, completion) of the running open
        self.received: deque[bytes] = deque()  # segments not yet read
        self.receiver = None  # the connection that reads what this one's TCP connection gets
        self.partner = None  # the other connection of an E71 pairing open
        self.pair = None  # the partner while the pairing open runs


class TcpPort:
    """The connections of one Ethernet port (the FX5's built-in port or one QJ71E71)."""

    coalesce = True  # a receive reads every byte waiting (socket); False: one message (E71)

    def __init__(self, rt, name: str):
        self.rt = rt
        self.name = name
        self.connections = {n: _Connection(n) for n in CONNECTIONS}
        self._last_en: dict[int, bool] = {}
        self.pulses: list[tuple] = []  # (ref, bit) ON for one scan
        self.pending: list[tuple] = []  # (ref, bit) to turn ON from the next scan
        self._active = False
        self.open_count = 0  # opens the program ran (a silent run's note says so)
        self.sends = 0  # frames handed to the converter
        self.closes_while_open = 0  # closes the program ran on a connection that was open
        rt.pollers.append(self)

    # ---- the status words (the platform names them) ---------------------------------------
    OPEN_SIGNAL = RECEIVE_SIGNAL = 0  # word addresses in `status_cells`
    status_cells: list = []

    def show_status(self, conn: _Connection) -> None:
        """Bit n-1 of the open completion and receive status words for connection n."""
        bit, cells = 1 << (conn.number - 1), self.status_cells
        for address, on in ((self.OPEN_SIGNAL, conn.state == OPEN), (self.RECEIVE_SIGNAL, bool(conn.received))):
            word = cells[address] & 0xFFFF
            word = word | bit if on else word & ~bit
            cells[address] = word - 0x10000 if word > 0x7FFF else word

    # ---- helpers -----------------------------------------------------------------------------
    @property
    def endpoint(self):
        """The Ethernet port's peer (`Runtime.tcp_endpoint`, None until one is attached);
        `poll`, `idle_deadline` and `idle_state` read it there directly (once per scan)."""
        return self.rt.tcp_endpoint

    def rising(self, en: bool, loc_id: int) -> bool:
        """SP./ZP. instructions run once on the rising edge of their execution command."""
        last = self._last_en.get(loc_id, False)
        self._last_en[loc_id] = bool(en)
        return bool(en) and not last

    def connection(self, number, control, done, loc_id) -> _Connection | None:
        conn = self.connections.get(number)
        if conn is None:
            self.rt.warn(self.rt.locations[loc_id], f"{self.name}: connection {number} does not exist "
                                                    f"(use {CONNECTIONS.start}..{CONNECTIONS.stop - 1})")
            self.finish(control, done, ERR_CONNECTION)
        return conn

    def finish(self, control, done, status: int) -> None:
        """Completion status into control data word 1; the completion bit d (and d+1 on an
        error) ON from the next scan, for one scan."""
        control.set(1, status)
        self.pending.append((done, 0))
        if status:
            self.pending.append((done, 1))

    # ---- instructions --------------------------------------------------------------------------
    def open(self, number, control, done, loc_id) -> None:
        self.open_count += 1
        conn = self.connection(number, control, done, loc_id)
        if conn is None:
            return
        if conn.state in (OPEN, OPENING):
            self.finish(control, done, ERR_ALREADY_OPEN)
            return
        if control.get_u16(0) != EXECUTE_WITH_CONTROL_DATA:
            self.rt.warn(self.rt.locations[loc_id],
                         f"{self.name}: open of connection {number} with execution type "
                         f"{control.get_u16(0):04X}H: opening with the parameter settings is not modelled; "
                         "set control data word 0 to 8000H and give the destination in the control data")
            self.finish(control, done, ERR_PARAMETER_OPEN)
            return
        setting = control.get_u16(2)
        if setting & 0x0100 or setting & 0xC000:
            self.finish(control, done, ERR_NOT_TCP_ACTIVE)
            return
        ip = _ip_text(control.get_u16(4), control.get_u16(5))
        port = control.get_u16(6)
        conn.state = OPENING
        endpoint = self.endpoint
        if endpoint is None:
            conn.open_ok, conn.open_done_us, conn.remote = False, self.rt.now_us, 0
            conn.open_status = ERR_UNREACHABLE
        else:
            result = endpoint.open(self.rt.now_us, ip, port)
            conn.open_ok, conn.open_done_us, conn.remote = result.ok, result.done_us, result.connection
            conn.open_status = 0 if result.ok else (ERR_UNREACHABLE if result.reason == "unreachable"
                                                    else ERR_REFUSED)
        conn.open_refs = (control, done)
        self._active = True

    def send(self, number, control, data, done, loc_id, byte_count: int) -> None:
        conn = self.connection(number, control, done, loc_id)
        if conn is None:
            return
        if conn.state != OPEN:
            self.finish(control, done, ERR_NOT_OPEN)
            return
        if byte_count <= 0 or (byte_count + 1) // 2 > data.available() - 1:
            self.finish(control, done, ERR_LENGTH)
            return
        payload = bytearray()
        for k in range((byte_count + 1) // 2):
            word = data.get_u16(1 + k)
            payload += bytes((word & 0xFF, word >> 8))
        ok = self.endpoint.send(self.rt.now_us, conn.remote, bytes(payload[:byte_count]),
                                self.rt.locations[loc_id])
        self.sends += ok
        self.finish(control, done, 0 if ok else ERR_NOT_OPEN)

    def receive(self, conn: _Connection, control, data, done) -> None:
        if not conn.received:
            self.finish(control, done, ERR_NOT_OPEN if conn.state != OPEN else 0)
            data.set(0, 0)
            return
        room = 2 * (data.available() - 1)
        if self.coalesce:
            chunk = b"".join(conn.received)
            conn.received.clear()
        else:
            chunk = conn.received.popleft()
        if len(chunk) > room:  # what does not fit stays for the next receive (ASSUMPTION)
            conn.received.appendleft(chunk[room:])
            chunk = chunk[:room]
        data.set(0, len(chunk))
        for k in range((len(chunk) + 1) // 2):
            lo = chunk[2 * k]
            hi = chunk[2 * k + 1] if 2 * k + 1 < len(chunk) else 0
            data.set(1 + k, lo | hi << 8)
        self.finish(control, done, 0)
        self.show_status(conn)

    def close(self, number, control, done, loc_id) -> None:
        conn = self.connection(number, control, done, loc_id)
        if conn is None:
            return
        if conn.state == CLOSED:
            self.finish(control, done, ERR_NOT_OPEN)
            return
        self.closes_while_open += conn.state == OPEN  # the program's own close of a live connection
        if self.endpoint is not None and conn.remote:
            self.endpoint.close(self.rt.now_us, conn.remote)
        self._reset(conn)
        self.finish(control, done, 0)

    def _reset(self, conn: _Connection) -> None:
        partner = conn.partner
        conn.state, conn.remote, conn.open_refs = CLOSED, 0, None
        conn.receiver = conn.partner = conn.pair = None
        conn.received.clear()
        self.show_status(conn)
        if partner is not None:
            self._reset(partner)

    # ---- between scans -----------------------------------------------------------------------------
    def poll(self, now: int) -> None:
        if self.pulses or self.pending:  # (both empty on most scans: nothing to swap)
            for ref, bit in self.pulses:
                ref.set(bit, False)
            self.pulses, self.pending = self.pending, []
            for ref, bit in self.pulses:
                ref.set(bit, True)
        if not self._active:
            return
        endpoint = self.rt.tcp_endpoint
        active = False
        for conn in self.connections.values():
            if conn.state == CLOSED:
                continue
            if conn.state == OPENING:
                active = True
                if now >= conn.open_done_us:
                    control, done = conn.open_refs
                    conn.open_refs = None
                    conn.state = OPEN if conn.open_ok else CLOSED
                    control.set(1, conn.open_status)
                    done.set(0, True)
                    self.pulses.append((done, 0))
                    if not conn.open_ok:
                        done.set(1, True)
                        self.pulses.append((done, 1))
                    self.opened(conn)
                    self.show_status(conn)
            elif conn.state == OPEN and endpoint is not None:
                active = True
                reader = conn.receiver or conn
                for _, segment in endpoint.receive_until(now, conn.remote):
                    reader.received.append(segment)
                if reader.received:
                    self.show_status(reader)
                if endpoint.peer_closed(now, conn.remote):
                    conn.state = PEER_CLOSED
                    self.show_status(conn)
            elif conn.state == PEER_CLOSED:
                active = True
        self._active = active

    # ---- idle-scan skipping (verifier.sim.idle) -------------------------------------------
    def idle_deadline(self, now: int) -> float | None:
        """The first instant `poll` can change anything, or None when it may at `now` (a
        completion bit to turn ON or OFF, a segment or a close under way, an endpoint that
        cannot say when it is quiet)."""
        if self.pulses or self.pending:
            return None
        if not self._active:
            return float("inf")  # poll returns at once
        deadline, active = float("inf"), False
        endpoint = self.rt.tcp_endpoint
        quiet = getattr(endpoint, "quiet_until", None)
        for conn in self.connections.values():
            state = conn.state
            if state == CLOSED:
                continue
            if state == OPENING:
                active = True
                deadline = min(deadline, conn.open_done_us)
            elif state == OPEN and endpoint is not None:
                active = True
                until = quiet(conn.remote) if quiet is not None else None
                if until is None or until <= now:
                    return None
                deadline = min(deadline, until)
            elif state == PEER_CLOSED:
                active = True
        return deadline if active else None  # not active: poll clears `_active`

    def idle_state(self) -> tuple:
        """Everything the instructions and `poll` change (nothing counts scans). Taken
        about four times per request, so it is a plain loop over the connections."""
        conns = []
        for c in self.connections.values():
            refs, receiver, partner, pair = c.open_refs, c.receiver, c.partner, c.pair
            conns.append((c.state, c.remote, c.open_done_us, c.open_ok, c.open_status,
                           None if refs is None else tuple(map(operand_key, refs)),
                           tuple(c.received) if c.received else (),
                           None if receiver is None else receiver.number,
                           None if partner is None else partner.number,
                           None if pair is None else pair.number))
        endpoint = self.rt.tcp_endpoint
        peer = endpoint.idle_state() if hasattr(endpoint, "idle_state") else None
        return (conns, tuple(self._last_en.items()), pulse_keys(self.pulses) if self.pulses else (),
                pulse_keys(self.pending) if self.pending else (), self._active,
                tuple(self.direction.items()) if hasattr(self, "direction") else (), peer)

    def skipped(self, scan_count: int, scans: int) -> None:
        """Nothing here depends on the scan count."""

    def opened(self, conn: _Connection) -> None:
        """After an open completed (the E71 opens the paired connection too)."""


class SocketPort(TcpPort):
    """FX5U/FX5UC built-in Ethernet port, socket communication (SP.SOCxxx)."""

    OPEN_SIGNAL = 10680  # SD10680: open completion signal, bit n-1 (ASSUMPTION, docs/instructions.md)
    RECEIVE_SIGNAL = 10682  # SD10682: receive state signal, bit n-1 (ASSUMPTION)

    def __init__(self, rt):
        super().__init__(rt, "FX5 built-in Ethernet")
        self.status_cells = rt.dev.areas["SD"]

    def sp_socopen(self, en, u, s1, s2, d, loc_id) -> None:
        if self.rising(en, loc_id):
            self.open(s1, s2, d, loc_id)

    def sp_socsnd(self, en, u, s1, s2, s3, d, loc_id) -> None:
        if self.rising(en, loc_id):
            self.send(s1, s2, s3, d, loc_id, s3.get_u16(0))

    def sp_socrcv(self, en, u, s1, s2, d1, d2, loc_id) -> None:
        if self.rising(en, loc_id):
            conn = self.connection(s1, s2, d2, loc_id)
            if conn is not None:
                self.receive(conn, s2, d1, d2)

    def sp_socclose(self, en, u, s1, s2, d, loc_id) -> None:
        if self.rising(en, loc_id):
            self.close(s1, s2, d, loc_id)


class FixedBufferPort(TcpPort):
    """QJ71E71-100 fixed buffer communication, no procedure (ZP.OPEN/BUFSND/BUFRCV/CLOSE)."""

    coalesce = False
    OPEN_SIGNAL = E71_OPEN_SIGNAL  # open completion signal, bit n-1 (ASSUMPTION, docs/instructions.md)
    RECEIVE_SIGNAL = E71_RECEIVE_SIGNAL  # fixed buffer reception status signal, bit n-1 (ASSUMPTION)
    FOR_RECEIVING = 0x0001  # application setting b0: fixed buffer for receiving
    PAIRING = 0x0080  # application setting b7: pairing open (n receives, n+1 sends)
    NO_PROCEDURE = 0x0200  # application setting b9: fixed buffer without procedure

    def __init__(self, rt, un: int):
        super().__init__(rt, f"QJ71E71 at U{un:X}")
        self.un = un
        self.status_cells = rt.buffer(un)
        self.direction: dict[int, str] = {}  # connection -> "send" | "receive"

    def zp_open(self, en, s1, s2, d, loc_id) -> None:
        if not self.rising(en, loc_id):
            return
        setting = s2.get_u16(2) if s2.get_u16(0) == EXECUTE_WITH_CONTROL_DATA else 0
        if s2.get_u16(0) == EXECUTE_WITH_CONTROL_DATA and not setting & self.NO_PROCEDURE:
            self.rt.warn(self.rt.locations[loc_id],
                         f"{self.name}: connection {s1} opened for fixed buffer communication with procedure; "
                         "only 'no procedure' (application setting b9 = 1) is modelled: the data pass unchanged")
        pair = self.connections.get(s1 + 1) if setting & self.PAIRING else None
        if setting & self.PAIRING and (pair is None or pair.state != CLOSED):
            self.finish(s2, d, ERR_CONNECTION)
            return
        self.open(s1, s2, d, loc_id)
        conn = self.connections.get(s1)
        if conn is not None and conn.state == OPENING:
            self.direction[s1] = "receive" if setting & self.FOR_RECEIVING else "send"
            if pair is not None:
                self.direction[s1 + 1] = "send"
                conn.pair = pair

    def opened(self, conn: _Connection) -> None:
        pair = conn.pair
        if pair is None:
            return
        conn.pair = None
        if conn.state == OPEN:  # the paired connection sends on the same TCP connection
            pair.state, pair.remote, pair.receiver = OPEN, conn.remote, conn
            pair.partner, conn.partner = conn, pair
            self.show_status(pair)

    def _reset(self, conn: _Connection) -> None:
        self.direction.pop(conn.number, None)
        super()._reset(conn)

    def zp_bufsnd(self, en, s1, s2, s3, d, loc_id) -> None:
        if not self.rising(en, loc_id):
            return
        if self.direction.get(s1) == "receive":
            self.rt.warn(self.rt.locations[loc_id], f"{self.name}: BUFSND on connection {s1}, which is open "
                                                    "for receiving (send on the paired connection n+1)")
            self.finish(s2, d, ERR_CONNECTION)
            return
        self.send(s1, s2, s3, d, loc_id, s3.get_u16(0))

    def zp_bufrcv(self, en, s1, s2, d1, d2, loc_id) -> None:
        if not self.rising(en, loc_id):
            return
        conn = self.connection(s1, s2, d2, loc_id)
        if conn is None:
            return
        if self.direction.get(s1) == "send":
            self.rt.warn(self.rt.locations[loc_id], f"{self.name}: BUFRCV on connection {s1}, which is open "
                                                    "for sending (receive on the connection opened for receiving)")
            self.finish(s2, d2, ERR_CONNECTION)
            return
        self.receive(conn, s2, d1, d2)

    def zp_close(self, en, s1, s2, d, loc_id) -> None:
        if self.rising(en, loc_id):
            self.close(s1, s2, d, loc_id)
