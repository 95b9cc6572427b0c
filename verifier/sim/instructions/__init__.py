"""MELSEC instructions the simulator runs, with the operand kinds the compiler needs.

Operand kinds (after EN): "val" an input value; "src" the head of a block the instruction
reads; "dst" the head of a block it writes; "blk" a block it reads and writes (control
data).  Block operands reach the instruction as `verifier.sim.refs.Ref` objects.
"""
from __future__ import annotations

from dataclasses import dataclass

from ..rs2_devices import FX3_CHANNELS, FX5_CHANNELS
from . import basic
from .rs2 import Rs2Port


@dataclass(frozen=True)
class InstructionSpec:
    name: str
    operands: tuple[str, ...]
    families: frozenset[str]
    pulse_form: bool = True  # has a P variant (MOVP ...)
    always: bool = False  # executed whatever EN is (OUT writes EN; PLS/PLF watch its edges)
    edge: str | None = None  # PLS: "rise", PLF: "fall" (compiled with a memory of EN)
    wide: bool = False  # 32-bit operands: a word device operand spans two words


_ALL = frozenset({"fx3", "fx5", "q"})
SPECS = {s.name: s for s in (
    InstructionSpec("MOV", ("val", "dst"), _ALL),
    InstructionSpec("BMOV", ("src", "val", "dst"), _ALL),
    InstructionSpec("FMOV", ("val", "val", "dst"), _ALL),
    InstructionSpec("SET", ("dst",), _ALL, pulse_form=False),
    InstructionSpec("RST", ("dst",), _ALL, pulse_form=False),
    InstructionSpec("OUT", ("dst",), _ALL, pulse_form=False, always=True),
    InstructionSpec("PLS", ("dst",), _ALL, pulse_form=False, always=True, edge="rise"),
    InstructionSpec("PLF", ("dst",), _ALL, pulse_form=False, always=True, edge="fall"),
    InstructionSpec("DMOV", ("val", "dst"), _ALL, wide=True),
    InstructionSpec("CML", ("val", "dst"), _ALL),
    InstructionSpec("XCH", ("blk", "blk"), _ALL),
    InstructionSpec("SWAP", ("blk",), _ALL),
    InstructionSpec("INC", ("blk",), _ALL),
    InstructionSpec("DEC", ("blk",), _ALL),
    InstructionSpec("WAND", ("val", "val", "dst"), _ALL),
    InstructionSpec("WOR", ("val", "val", "dst"), _ALL),
    InstructionSpec("WXOR", ("val", "val", "dst"), _ALL),
    InstructionSpec("BCD", ("val", "dst"), _ALL),
    InstructionSpec("BIN", ("val", "dst"), _ALL),
    InstructionSpec("ZRST", ("dst", "dst"), _ALL),
    InstructionSpec("CRC", ("src", "val", "dst"), frozenset({"fx3", "fx5"})),
    InstructionSpec("RS2", ("src", "val", "val", "val", "dst"), frozenset({"fx3", "fx5"}), False),
    InstructionSpec("ADPRW", ("val", "val", "val", "val", "blk"), frozenset({"fx3"}), False),
    InstructionSpec("G_OUTPUT", ("val", "blk", "src", "dst"), frozenset({"q"})),
    InstructionSpec("G_INPUT", ("val", "blk", "dst", "dst"), frozenset({"q"})),
    # Ethernet (tcp.py): run once on the rising edge of EN, so called on every scan
    InstructionSpec("SP_SOCOPEN", ("val", "val", "blk", "dst"), frozenset({"fx5"}), False, always=True),
    InstructionSpec("SP_SOCSND", ("val", "val", "blk", "src", "dst"), frozenset({"fx5"}), False, always=True),
    InstructionSpec("SP_SOCRCV", ("val", "val", "blk", "dst", "dst"), frozenset({"fx5"}), False, always=True),
    InstructionSpec("SP_SOCCLOSE", ("val", "val", "blk", "dst"), frozenset({"fx5"}), False, always=True),
    InstructionSpec("ZP_OPEN", ("val", "val", "blk", "dst"), frozenset({"q"}), False, always=True),
    InstructionSpec("ZP_BUFSND", ("val", "val", "blk", "src", "dst"), frozenset({"q"}), False, always=True),
    InstructionSpec("ZP_BUFRCV", ("val", "val", "blk", "dst", "dst"), frozenset({"q"}), False, always=True),
    InstructionSpec("ZP_CLOSE", ("val", "val", "blk", "dst"), frozenset({"q"}), False, always=True),
)}
#: the Ethernet instructions (tcp.py): a program that calls one reaches the robot over TCP
ETHERNET = frozenset(name for name in SPECS if name.startswith(("SP_SOC", "ZP_")))
# FX5's ADPRW has a completion-bits operand after the data block.
FX5_ADPRW = InstructionSpec("ADPRW", ("val", "val", "val", "val", "blk", "dst"), frozenset({"fx5"}), False)


def lookup(name: str, family: str) -> tuple[InstructionSpec, bool] | None:
    """(spec, is_pulse_variant) for an instruction name as called from ST, or None."""
    key = name.upper()
    if key == "ADPRW" and family == "fx5":
        return FX5_ADPRW, False
    if key in SPECS:
        return SPECS[key], False
    if key.startswith("GP_") and "G_" + key[3:] in SPECS:
        return SPECS["G_" + key[3:]], True
    if key.endswith("P") and key[:-1] in SPECS and SPECS[key[:-1]].pulse_form:
        return SPECS[key[:-1]], True
    return None


def not_on_cpu(name: str, cpu) -> str | None:
    """Why the instruction called `name` (as written) does not run on the CPU profile
    `cpu`, or None: when it does, and for names that are no instruction the simulator
    knows. The simulator's compiler and `uitamr check --platform` both ask this."""
    found = lookup(name, cpu.family)
    if found is None or cpu.family in found[0].families:
        return None
    return (f"{name} does not exist on the {cpu.name} "
            f"(it is a {'/'.join(sorted(found[0].families))} instruction)")


class InstructionSet:
    """The instruction implementations bound to one runtime (generated code calls
    `_I.RS2(en, ..., loc_id)`)."""

    def __init__(self, rt):
        self.rt = rt
        self._rs2: dict[int, Rs2Port] = {}
        self._c24 = {}
        self._adprw = {}
        self._socket = None
        self._e71 = {}
        fam = rt.cpu.family
        self._eight_bit = "M8161" if fam == "fx3" else "SM8161"

    def MOV(self, en, s, d, loc_id):
        return basic.mov(self.rt, en, s, d, loc_id)

    def BMOV(self, en, s, n, d, loc_id):
        return basic.bmov(self.rt, en, s, n, d, loc_id)

    def FMOV(self, en, s, n, d, loc_id):
        return basic.fmov(self.rt, en, s, n, d, loc_id)

    def SET(self, en, d, loc_id):
        return basic.set_(self.rt, en, d, loc_id)

    def RST(self, en, d, loc_id):
        return basic.rst(self.rt, en, d, loc_id)

    def OUT(self, en, d, loc_id):
        return basic.out(self.rt, en, d, loc_id)

    PLS = PLF = OUT  # the compiler turns EN into the one-scan pulse

    def DMOV(self, en, s, d, loc_id):
        return basic.dmov(self.rt, en, s, d, loc_id)

    def CML(self, en, s, d, loc_id):
        return basic.cml(self.rt, en, s, d, loc_id)

    def XCH(self, en, d1, d2, loc_id):
        return basic.xch(self.rt, en, d1, d2, loc_id)

    def SWAP(self, en, d, loc_id):
        return basic.swap(self.rt, en, d, loc_id)

    def INC(self, en, d, loc_id):
        return basic.inc(self.rt, en, d, loc_id, 1)

    def DEC(self, en, d, loc_id):
        return basic.inc(self.rt, en, d, loc_id, -1)

    def WAND(self, en, s1, s2, d, loc_id):
        return basic.logic(self.rt, en, s1, s2, d, loc_id, "AND")

    def WOR(self, en, s1, s2, d, loc_id):
        return basic.logic(self.rt, en, s1, s2, d, loc_id, "OR")

    def WXOR(self, en, s1, s2, d, loc_id):
        return basic.logic(self.rt, en, s1, s2, d, loc_id, "XOR")

    def BCD(self, en, s, d, loc_id):
        return basic.bcd(self.rt, en, s, d, loc_id)

    def BIN(self, en, s, d, loc_id):
        return basic.bin_(self.rt, en, s, d, loc_id)

    def ZRST(self, en, d1, d2, loc_id):
        return basic.zrst(self.rt, en, d1, d2, loc_id)

    def CRC(self, en, s, n, d, loc_id):
        return basic.crc(self.rt, en, s, n, d, loc_id, self._eight_bit)

    # -- serial ----------------------------------------------------------------------
    def rs2_port(self, channel: int, loc_id: int | None = None) -> Rs2Port:
        port = self._rs2.get(channel)
        if port is None:
            fam = self.rt.cpu.family
            table = FX3_CHANNELS if fam == "fx3" else FX5_CHANNELS
            if channel not in table:
                self.rt.fail(loc_id, f"RS2: channel n1={channel} does not exist on the "
                                     f"{self.rt.cpu.name} (use {' or '.join(map(str, table))})")
            name = f"{fam}:{channel}"
            port = Rs2Port(self.rt, self.rt.channel(name), table[channel], fam)
            self._rs2[channel] = port
        return port

    def RS2(self, en, s, m, n, n1, d, loc_id):
        port = self._rs2.get(n1)
        if port is None:
            if not en:
                return False
            port = self.rs2_port(n1, loc_id)
        return port.call(en, s, m, n, d, loc_id)

    def c24(self, un: int):
        mod = self._c24.get(un)
        if mod is None:  # imported on first use only (each G.INPUT/G.OUTPUT call comes here)
            from .c24 import C24Module

            mod = self._c24[un] = C24Module(self.rt, un)
        return mod

    def G_OUTPUT(self, en, un, s1, s2, d, loc_id):
        if not en:
            return False
        return self.c24(un).output(s1, s2, d, loc_id)

    def G_INPUT(self, en, un, s, d1, d2, loc_id):
        if not en:
            return False
        return self.c24(un).input(s, d1, d2, loc_id)

    def adprw_port(self, channel: int = 1):
        port = self._adprw.get(channel)
        if port is None:  # imported on first use only (every ADPRW call comes here)
            from .adprw import AdprwMaster

            port = self._adprw[channel] = AdprwMaster(self.rt, channel)
        return port

    def ADPRW(self, en, s, s1, s2, s3, s4d, *rest):
        if self.rt.cpu.family == "fx5":
            d2, loc_id = rest
        else:
            d2, (loc_id,) = None, rest
        return self.adprw_port(1).call(bool(en), s, s1, s2, s3, s4d, d2, loc_id)

    # -- Ethernet ------------------------------------------------------------------------
    def socket_port(self):
        socket = self._socket
        if socket is None:  # imported on first use only: this runs four times a scan
            from .tcp import SocketPort

            socket = self._socket = SocketPort(self.rt)
        return socket

    def e71(self, un):
        """The QJ71E71 of a Un operand; the operand as written is remembered too (four
        instruction calls a scan would otherwise parse 'U0' each time)."""
        port = self._e71.get(un)
        if port is None:
            from .tcp import FixedBufferPort

            number = _module_number(un)
            port = self._e71.get(number)
            if port is None:
                port = self._e71[number] = FixedBufferPort(self.rt, number)
            self._e71[un] = port
        return port

    # Each of these runs on every scan and acts only on the rising edge of EN; a scan
    # with EN FALSE, as on the scan before, changes nothing (`TcpPort.rising` would store
    # FALSE again), so it returns here without a call into the port.

    def SP_SOCOPEN(self, en, u, s1, s2, d, loc_id):
        port = self._socket or self.socket_port()
        if en or port._last_en.get(loc_id) is not False:
            port.sp_socopen(en, u, s1, s2, d, loc_id)

    def SP_SOCSND(self, en, u, s1, s2, s3, d, loc_id):
        port = self._socket or self.socket_port()
        if en or port._last_en.get(loc_id) is not False:
            port.sp_socsnd(en, u, s1, s2, s3, d, loc_id)

    def SP_SOCRCV(self, en, u, s1, s2, d1, d2, loc_id):
        port = self._socket or self.socket_port()
        if en or port._last_en.get(loc_id) is not False:
            port.sp_socrcv(en, u, s1, s2, d1, d2, loc_id)

    def SP_SOCCLOSE(self, en, u, s1, s2, d, loc_id):
        port = self._socket or self.socket_port()
        if en or port._last_en.get(loc_id) is not False:
            port.sp_socclose(en, u, s1, s2, d, loc_id)

    def ZP_OPEN(self, en, un, s1, s2, d, loc_id):
        port = self._e71.get(un) or self.e71(un)
        if en or port._last_en.get(loc_id) is not False:
            port.zp_open(en, s1, s2, d, loc_id)

    def ZP_BUFSND(self, en, un, s1, s2, s3, d, loc_id):
        port = self._e71.get(un) or self.e71(un)
        if en or port._last_en.get(loc_id) is not False:
            port.zp_bufsnd(en, s1, s2, s3, d, loc_id)

    def ZP_BUFRCV(self, en, un, s1, s2, d1, d2, loc_id):
        port = self._e71.get(un) or self.e71(un)
        if en or port._last_en.get(loc_id) is not False:
            port.zp_bufrcv(en, s1, s2, d1, d2, loc_id)

    def ZP_CLOSE(self, en, un, s1, s2, d, loc_id):
        port = self._e71.get(un) or self.e71(un)
        if en or port._last_en.get(loc_id) is not False:
            port.zp_close(en, s1, s2, d, loc_id)


def _module_number(un) -> int:
    """The module's start I/O number / 16 from a Un operand: a number (16#2) or a string
    'U2' / '02' as the ladder form "Un" writes it."""
    if isinstance(un, str):
        text = un.strip().upper()
        return int(text[1:] if text.startswith("U") else text or "0", 16)
    return int(un) & 0xFFFF
