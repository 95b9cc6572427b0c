"""Standard function blocks (IEC 61131-3 as GX Works provides them): timers, edges,
counters, bistables.

Each instance keeps its memory in attributes named as GX Works names the FB's inputs and
outputs (IN, PT, Q, ET, CLK, CU, ...).  Generated code assigns the inputs given in a call
and then calls `_body()`; inputs not given keep their last value, as in IEC.

Timers read the virtual clock *when the FB is called* (a MELSEC CPU evaluates a timer FB at
the point of the program where it is executed; time advances between scans).  PT and ET
are TIME values in ms.  Resolution: ET advances in whole ms of virtual time (ASSUMPTION,
see docs/instructions.md: GX Works' TON/TOF/TP are built on 1 ms or 100 ms timers depending
on CPU; a scan clock in ms is the finest either can show).
"""
from __future__ import annotations


class StdFB:
    __slots__ = ("_rt",)
    TYPE_NAME = ""
    BODY: str | None = None  # Python template ({o} instance, {rt} runtime, {t} a temporary)
    INPUTS: tuple[str, ...] = ()
    OUTPUTS: tuple[str, ...] = ()
    _STATE: dict = {}  # internal memory and its initial value

    def __init__(self, rt):
        self._rt = rt
        types = FB_PARAM_TYPES[self.TYPE_NAME]
        for name in self.INPUTS + self.OUTPUTS:
            setattr(self, name, False if types[name] == "BOOL" else 0)
        for name, value in self._STATE.items():
            setattr(self, name, value)


class TON(StdFB):
    """On-delay: Q rises PT after IN rose and stays while IN stays TRUE."""

    __slots__ = ("IN", "PT", "Q", "ET", "_start")
    TYPE_NAME = "TON"
    _STATE = {"_start": None}
    INPUTS = ("IN", "PT")
    OUTPUTS = ("Q", "ET")
    BODY = """
if {o}.IN:
    if {o}._start is None:
        {o}._start = {rt}.now_ms
    {t} = {rt}.now_ms - {o}._start
    if {t} >= {o}.PT:
        {o}.ET = {o}.PT if {o}.PT > 0 else 0
        {o}.Q = True
    else:
        {o}.ET = {t}
        {o}.Q = False
else:
    {o}._start = None
    {o}.Q = False
    {o}.ET = 0
"""


class TOF(StdFB):
    """Off-delay: Q follows IN up at once and falls PT after IN fell."""

    __slots__ = ("IN", "PT", "Q", "ET", "_start")
    TYPE_NAME = "TOF"
    _STATE = {"_start": None}
    INPUTS = ("IN", "PT")
    OUTPUTS = ("Q", "ET")
    BODY = """
if {o}.IN:
    {o}._start = None
    {o}.Q = True
    {o}.ET = 0
elif {o}.Q:
    if {o}._start is None:
        {o}._start = {rt}.now_ms
    {t} = {rt}.now_ms - {o}._start
    if {t} >= {o}.PT:
        {o}.ET = {o}.PT if {o}.PT > 0 else 0
        {o}.Q = False
        {o}._start = None
    else:
        {o}.ET = {t}
"""


class TP(StdFB):
    """Pulse: a rising edge of IN gives a Q pulse of exactly PT, not retriggerable."""

    __slots__ = ("IN", "PT", "Q", "ET", "_start", "_prev")
    TYPE_NAME = "TP"
    _STATE = {"_start": None, "_prev": False}
    INPUTS = ("IN", "PT")
    OUTPUTS = ("Q", "ET")

    def _body(self):
        now = self._rt.now_ms
        if self._start is None:
            if self.IN and not self._prev:
                self._start = now
        if self._start is not None:
            et = now - self._start
            if et >= self.PT:
                self.ET = max(self.PT, 0)
                self.Q = False
                if not self.IN:
                    self._start = None
                    self.ET = 0
            else:
                self.ET = et
                self.Q = True
        elif not self.IN:
            self.ET = 0
        self._prev = self.IN


class R_TRIG(StdFB):
    __slots__ = ("CLK", "Q", "_m")
    TYPE_NAME = "R_TRIG"
    _STATE = {"_m": False}
    INPUTS = ("CLK",)
    OUTPUTS = ("Q",)
    BODY = """
{o}.Q = {o}.CLK and not {o}._m
{o}._m = {o}.CLK
"""


class F_TRIG(StdFB):
    """Falling edge.  The previous CLK starts FALSE, so a CLK that is FALSE from the first
    scan gives no pulse (MELSEC falling-edge semantics; ASSUMPTION, documented)."""

    __slots__ = ("CLK", "Q", "_m")
    TYPE_NAME = "F_TRIG"
    _STATE = {"_m": False}
    INPUTS = ("CLK",)
    OUTPUTS = ("Q",)
    BODY = """
{o}.Q = {o}._m and not {o}.CLK
{o}._m = {o}.CLK
"""


class CTU(StdFB):
    __slots__ = ("CU", "R", "PV", "Q", "CV", "_m")
    TYPE_NAME = "CTU"
    _STATE = {"_m": False}
    INPUTS = ("CU", "R", "PV")
    OUTPUTS = ("Q", "CV")

    def _body(self):
        edge = self.CU and not self._m
        self._m = self.CU
        if self.R:
            self.CV = 0
        elif edge and self.CV < 32767:
            self.CV += 1
        self.Q = self.CV >= self.PV


class CTD(StdFB):
    __slots__ = ("CD", "LD", "PV", "Q", "CV", "_m")
    TYPE_NAME = "CTD"
    _STATE = {"_m": False}
    INPUTS = ("CD", "LD", "PV")
    OUTPUTS = ("Q", "CV")

    def _body(self):
        edge = self.CD and not self._m
        self._m = self.CD
        if self.LD:
            self.CV = self.PV
        elif edge and self.CV > -32768:
            self.CV -= 1
        self.Q = self.CV <= 0


class CTUD(StdFB):
    __slots__ = ("CU", "CD", "R", "LD", "PV", "QU", "QD", "CV", "_mu", "_md")
    TYPE_NAME = "CTUD"
    _STATE = {"_mu": False, "_md": False}
    INPUTS = ("CU", "CD", "R", "LD", "PV")
    OUTPUTS = ("QU", "QD", "CV")

    def _body(self):
        up = self.CU and not self._mu
        down = self.CD and not self._md
        self._mu = self.CU
        self._md = self.CD
        if self.R:
            self.CV = 0
        elif self.LD:
            self.CV = self.PV
        elif not (up and down):
            if up and self.CV < 32767:
                self.CV += 1
            elif down and self.CV > -32768:
                self.CV -= 1
        self.QU = self.CV >= self.PV
        self.QD = self.CV <= 0


class SR(StdFB):
    """Set-dominant bistable."""

    __slots__ = ("S1", "R", "Q1")
    TYPE_NAME = "SR"
    INPUTS = ("S1", "R")
    OUTPUTS = ("Q1",)

    def _body(self):
        self.Q1 = self.S1 or (not self.R and self.Q1)


class RS(StdFB):
    """Reset-dominant bistable."""

    __slots__ = ("S", "R1", "Q1")
    TYPE_NAME = "RS"
    INPUTS = ("S", "R1")
    OUTPUTS = ("Q1",)

    def _body(self):
        self.Q1 = not self.R1 and (self.S or self.Q1)


def body_code(cls: type[StdFB], receiver: str, rt: str, temp: str) -> str:
    """The FB's body as Python lines for `receiver` (generated code inlines these)."""
    return cls.BODY.strip("\n").format(o=receiver, rt=rt, t=temp)


def _install_bodies() -> None:
    """`_body` methods of the FBs described by a BODY template: one text serves both the
    method and the code the compiler inlines."""
    for cls in (TON, TOF, R_TRIG, F_TRIG):
        lines = body_code(cls, "self", "self._rt", "et").split("\n")
        src = "def _body(self):\n" + "\n".join("    " + ln for ln in lines)
        env: dict = {}
        exec(src, env)
        cls._body = env["_body"]


STANDARD_FBS: dict[str, type[StdFB]] = {
    cls.TYPE_NAME: cls for cls in (TON, TOF, TP, R_TRIG, F_TRIG, CTU, CTD, CTUD, SR, RS)
}

# Input/output types, so the compiler can normalise what is assigned to them.
FB_PARAM_TYPES: dict[str, dict[str, str]] = {
    "TON": {"IN": "BOOL", "PT": "TIME", "Q": "BOOL", "ET": "TIME"},
    "TOF": {"IN": "BOOL", "PT": "TIME", "Q": "BOOL", "ET": "TIME"},
    "TP": {"IN": "BOOL", "PT": "TIME", "Q": "BOOL", "ET": "TIME"},
    "R_TRIG": {"CLK": "BOOL", "Q": "BOOL"},
    "F_TRIG": {"CLK": "BOOL", "Q": "BOOL"},
    "CTU": {"CU": "BOOL", "R": "BOOL", "PV": "INT", "Q": "BOOL", "CV": "INT"},
    "CTD": {"CD": "BOOL", "LD": "BOOL", "PV": "INT", "Q": "BOOL", "CV": "INT"},
    "CTUD": {"CU": "BOOL", "CD": "BOOL", "R": "BOOL", "LD": "BOOL", "PV": "INT",
             "QU": "BOOL", "QD": "BOOL", "CV": "INT"},
    "SR": {"S1": "BOOL", "R": "BOOL", "Q1": "BOOL"},
    "RS": {"S": "BOOL", "R1": "BOOL", "Q1": "BOOL"},
}

_install_bodies()
