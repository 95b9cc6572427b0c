"""Device memory shared by all programs of one simulated CPU (X, Y, M, L, B, SM, D, R, W, SD...).

Bit devices hold Python bools, word devices hold signed 16-bit ints (-32768..32767: a D
register read as INT).  Device names are parsed the way GX Works writes them: X/Y are
octal on FX CPUs and hexadecimal on Q, B and W are hexadecimal everywhere.  Also
understood: bit of a word device (`D100.3`, bit in hex `D100.F`) and digit specification
of bit devices (`K4M0`: 16 consecutive bits as one word; K1..K4 -> 16-bit, K5..K8 -> 32-bit).
"""
from __future__ import annotations

import operator
import re
from dataclasses import dataclass

from verifier.plcfacts import BUFFER_WORDS  # words modelled per module (0..5FFFH); scenarios read it too

from .cpu import FX3_SPECIAL, FX3_SPECIAL_RANGE, Area, CpuProfile, fx3_serial_equivalent, special_equivalent
from .datatypes import wrap16, wrap32

_DEVICE_RE = re.compile(r"^(?:K([1-8]))?([A-Z]{1,2})([0-9A-F]+)(?:\.([0-9A-F]))?$")


class DeviceError(KeyError):
    def __str__(self) -> str:  # KeyError quotes its message; keep it readable
        return str(self.args[0])


@dataclass(frozen=True)
class DeviceAddress:
    area: str
    index: int
    kind: str  # "bit" | "word"
    bit: int | None = None  # bit of a word device
    digits: int | None = None  # K-digit specification of a bit device


def parse_device(name: str, cpu: CpuProfile) -> DeviceAddress:
    text = name.strip().upper()
    m = _DEVICE_RE.match(text)
    if not m:
        raise DeviceError(f"{name!r} is not a device name")
    digits, area_name, number, bit = m.groups()
    area, index = _area_and_index(area_name, number, text, cpu)
    if bit is not None:
        if area.kind != "word" or digits:
            raise DeviceError(f"{name!r}: only word devices have addressable bits")
        return DeviceAddress(area_name, index, "word", bit=int(bit, 16))
    if digits:
        if area.kind != "bit":
            raise DeviceError(f"{name!r}: digit specification applies to bit devices")
        n = int(digits) * 4
        if index + n > area.size:
            raise DeviceError(f"{name!r}: runs past the end of {area_name}")
        return DeviceAddress(area_name, index, "bit", digits=int(digits))
    return DeviceAddress(area_name, index, area.kind)


def device_problem(name: str, cpu: CpuProfile) -> str | None:
    """Why `name` (a device as a scenario writes it: `D300`, `SM400`) is not a device of
    `cpu`, in the words `uitamr check --platform` uses for ST; None when it is."""
    try:
        parse_device(name, cpu)
    except DeviceError as exc:
        return str(exc)
    return None


def device_warning(name: str, cpu: CpuProfile) -> str | None:
    """For a device as a scenario writes it (`M8002`): the warning `uitamr check --platform`
    gives the same device in ST when it is an FX3 special number that is an ordinary device
    on `cpu` (setting M8402 on an FX5U sends nothing); None otherwise."""
    m = _DEVICE_RE.match(name.strip().upper())
    if not m:
        return None
    digits, area_name, number, bit = m.groups()
    if digits or bit is not None:
        return None
    return _fx3_special_warning(area_name, number, name.strip(), cpu)


def locate_buffer(d, cpu: CpuProfile) -> tuple[int, int]:
    """(module, word) of buffer memory written in ST (`U2\\G164`: module 2, word 164) on
    `cpu`, or DeviceError: a module number past the CPU's I/O range, or a word past what
    the simulator models per module (G0..G24575). Asked by the compiler and by `uitamr
    check --platform`, as `locate` is for devices."""
    label = d.text or d.key
    module = int(d.module, 16)
    xs = cpu.areas.get("X")
    if xs is not None and module * 16 >= xs.size:
        raise DeviceError(f"{label}: module U{d.module} would start at I/O {module * 16:X}, past the "
                          f"{cpu.name}'s X/Y{xs.size - 1:X}; Un is the start I/O number without its last "
                          f"digit (U2 for X/Y020)")
    if d.number >= BUFFER_WORDS:
        raise DeviceError(f"{label}: buffer memory word {d.number} is past G{BUFFER_WORDS - 1} "
                          f"({BUFFER_WORDS - 1:X}H), the end of what the simulator models per module "
                          f"(docs/instructions.md)")
    return module, d.number


def locate(d, cpu: CpuProfile) -> tuple[Area, int]:
    """(area, number) of a device written in ST (`verifier.st.ast.Device`, not buffer
    memory) on `cpu`, or DeviceError saying why the simulator cannot run it there: an area
    the CPU profile lacks, a number in the wrong radix or past the end, an index register
    the CPU lacks, a digit or bit access of the wrong kind of device.

    The one check of written devices against a CPU profile: the simulator's compiler and
    `uitamr check --platform` both ask it, so they cannot disagree."""
    label = d.text or d.key
    area, index = _area_and_index(d.kind, d.address, label, cpu)
    if d.index is not None:
        z = cpu.areas.get("Z")
        if z is None:
            raise DeviceError(f"{cpu.name} has no index registers")
        if d.index >= z.size:
            raise DeviceError(f"device {label}: index register Z{d.index} does not exist on the "
                              f"{cpu.name} (Z0..Z{z.size - 1})")
        if d.digits is not None or d.bit is not None:
            raise DeviceError(f"{label}: index modification of a bit/digit access is not simulated")
    if d.digits is not None:
        if area.kind != "bit":
            raise DeviceError(f"digit specification needs a bit device: {label}")
        if index + d.digits * 4 > area.size:
            raise DeviceError(f"{label} runs past the end of {d.kind}")
    if d.bit is not None and area.kind != "word":
        raise DeviceError(f"{label}: only word devices have addressable bits")
    return area, index


def _area_and_index(kind: str, address: str, label: str, cpu: CpuProfile) -> tuple[Area, int]:
    """The area and number of device `label` (area `kind`, number `address` as written) on
    `cpu`, or DeviceError: an area the profile lacks, a number in the wrong radix or past
    the end. Device names (`parse_device`) and ST devices (`locate`) both ask it."""
    area = cpu.areas.get(kind)
    if area is None:
        raise DeviceError(f"device {label}: " + _no_area(kind, address, cpu))
    try:
        index = int(address, area.radix)
    except ValueError:
        raise DeviceError(f"device {label}: {kind} numbers are base {area.radix} on the {cpu.name}") from None
    if index >= area.size:
        raise DeviceError(f"device {label} does not exist on the {cpu.name}: {kind} runs "
                          f"{kind}0..{kind}{_fmt(area.size - 1, area.radix)}" + _fx3_special(kind, index, cpu))
    return area, index


def _no_area(kind: str, address: str, cpu: CpuProfile) -> str:
    """Why `cpu` has no device of area `kind`, and what to write instead where that is known:
    the FX3's special relays and registers are M8000.. and D8000.., not SM and SD."""
    if cpu.family == "fx3" and kind in ("SM", "SD"):
        plain = {"SM": "M", "SD": "D"}[kind]
        what = {"SM": "relays", "SD": "registers"}[kind]
        first, last = FX3_SPECIAL_RANGE[0], FX3_SPECIAL_RANGE[-1]
        text = f"the {cpu.name} has no {kind} devices; its special {what} are {plain}{first}..{plain}{last}"
        same = special_equivalent(f"{kind}{address}", cpu)
        if same:
            text += f": use {' or '.join(same[1])} ({same[0]})"
        return text
    return f"the {cpu.name} CPU profile has no {kind} devices the simulator can run"


def _fx3_phrase(kind: str, index: int, cpu: CpuProfile) -> str:
    """What an FX3 special relay/register number (M8002, D8400) is on `cpu`, whose special
    devices are SM/SD: its equivalent if `cpu` drives the same thing, else where to look."""
    area, what = FX3_SPECIAL[kind]
    serial = fx3_serial_equivalent(f"{kind}{index}", cpu)
    if serial is not None:
        return serial
    same = special_equivalent(f"{kind}{index}", cpu)
    if same:
        return (f"the FX3's special {what} {kind}{index} ({same[0]}) is "
                f"{' or '.join(same[1])} on the {cpu.name}")
    return f"FX3 special {what}s are {area} devices on the {cpu.name}"


def _is_fx3_special_elsewhere(kind: str, index: int, cpu: CpuProfile) -> bool:
    return cpu.family != "fx3" and kind in FX3_SPECIAL and index in FX3_SPECIAL_RANGE


def _fx3_special(kind: str, index: int, cpu: CpuProfile) -> str:
    """The hint added to 'does not exist' for an FX3 special number on another CPU."""
    return f"; {_fx3_phrase(kind, index, cpu)}" if _is_fx3_special_elsewhere(kind, index, cpu) else ""


def fx3_special_elsewhere(d, cpu: CpuProfile) -> str | None:
    """A warning for an FX3 special relay/register number (M8002, D8400) that exists on
    `cpu` as an ordinary device (a Q's M8002 is a plain internal relay, never set by the
    CPU): what the program most likely meant. None when `d` is not such a device."""
    if d.index is not None or d.digits is not None:
        return None
    return _fx3_special_warning(d.kind, d.address, d.text or d.key, cpu)


def _fx3_special_warning(kind: str, address: str, label: str, cpu: CpuProfile) -> str | None:
    """fx3_special_elsewhere's warning for the device `kind` `address` (decimal digits),
    named `label`: shared by the ST check and the scenario check (device_warning)."""
    if not address.isdigit():
        return None
    index = int(address, 10)
    area = cpu.areas.get(kind)
    if area is None or index >= area.size or not _is_fx3_special_elsewhere(kind, index, cpu):
        return None
    plain = {"M": "internal relay", "D": "data register"}[kind]
    return (f"{label} is an ordinary {plain} on the {cpu.name} (the CPU never sets it); "
            + _fx3_phrase(kind, index, cpu))


def _fmt(n: int, radix: int) -> str:
    return {8: f"{n:o}", 16: f"{n:X}"}.get(radix, str(n))


def device_value(name: str, a: DeviceAddress, value):
    """`value` checked for the device `a` (named `name`); ValueError says what it takes."""
    if a.bit is not None or (a.kind == "bit" and a.digits is None):
        if isinstance(value, bool) or (type(value) is int and value in (0, 1)):
            return bool(value)
        what = f"{name} is a bit of a word device" if a.bit is not None else f"{name} is a bit device"
        raise ValueError(f"{what}: give True or False (or 1/0), got {value!r:.60}")
    what = f"{name} is a digit group of bit devices" if a.digits is not None else f"{name} is a word device"
    if isinstance(value, bool) or isinstance(value, float):
        raise ValueError(f"{what}: give a whole number, got {'the float ' if isinstance(value, float) else ''}"
                         f"{value!r}")
    try:
        return operator.index(value)  # int, or an integer type such as numpy's
    except TypeError:
        raise ValueError(f"{what}: give a whole number, got {value!r:.60}") from None


class DeviceMemory:
    """All devices of one CPU.  `mem.D` is the list of D registers, `mem.M` the M relays...
    (generated code indexes these lists directly).  `mem["D100"]` reads by name."""

    def __init__(self, cpu: CpuProfile):
        self.cpu = cpu
        self.areas: dict[str, list] = {}
        for area in cpu.areas.values():
            self.areas[area.name] = [False] * area.size if area.kind == "bit" else [0] * area.size
            setattr(self, area.name, self.areas[area.name])

    def address(self, name: str) -> DeviceAddress:
        return parse_device(name, self.cpu)

    def __getitem__(self, name: str):
        a = self.address(name)
        return self.read(a)

    def __contains__(self, name) -> bool:
        """`"Y6" in project.devices`: whether this CPU has the device `name`. Without it Python
        tried `mem[0]`, `mem[1]` ... and a test's `in` ended in an AttributeError traceback."""
        if not isinstance(name, str):
            return False
        try:
            self.address(name)
        except DeviceError:
            return False
        return True

    def reader(self, name: str):
        """A function of no arguments reading device `name`, its address parsed once."""
        a = self.address(name)
        cells = self.areas[a.area]
        if a.bit is None and a.digits is None:
            index = a.index

            def read():
                return cells[index]
            read.item = (cells, index)  # verifier.sim.values.read_together merges it
            return read
        return lambda: self.read(a)

    def __setitem__(self, name: str, value) -> None:
        """`mem["D100"] = 5` from Python: a value of the wrong kind is refused, as for a
        label (a bit takes True/False or 0/1, a word or digit group a whole number, which
        wraps to the device's width as an INT label's does); the generated code and the
        instructions write through `write`."""
        a = self.address(name)
        self.write(a, device_value(name, a, value))

    def read(self, a: DeviceAddress):
        cells = self.areas[a.area]
        if a.bit is not None:
            return bool((cells[a.index] >> a.bit) & 1)
        if a.digits is not None:
            return self.read_digits(cells, a.index, a.digits)
        return cells[a.index]

    def write(self, a: DeviceAddress, value) -> None:
        cells = self.areas[a.area]
        if a.bit is not None:
            word = cells[a.index] & 0xFFFF
            word = word | (1 << a.bit) if value else word & ~(1 << a.bit)
            cells[a.index] = wrap16(word)
        elif a.digits is not None:
            self.write_digits(cells, a.index, a.digits, value)
        elif a.kind == "bit":
            cells[a.index] = bool(value)
        else:
            cells[a.index] = wrap16(int(value))

    @staticmethod
    def read_digits(cells: list, start: int, digits: int) -> int:
        value = 0
        for i in range(digits * 4):
            if cells[start + i]:
                value |= 1 << i
        return wrap16(value) if digits <= 4 else wrap32(value)

    @staticmethod
    def write_digits(cells: list, start: int, digits: int, value: int) -> None:
        # K1..K3 write only their 4/8/12 bits; the rest of the word is not touched.
        for i in range(digits * 4):
            cells[start + i] = bool((value >> i) & 1)
