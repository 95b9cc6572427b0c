"""CPU profiles: which devices a MELSEC CPU has, how they are numbered, and its special
relays/registers the simulator drives (always-ON, first scan, operation error).

Sources and assumptions are listed in docs/instructions.md ("CPU profiles").
"""
from __future__ import annotations

from dataclasses import dataclass, field

from .rs2_devices import FX3_CHANNELS, FX3_MODBUS_CHANNELS, FX5_CHANNELS


@dataclass(frozen=True)
class Area:
    name: str
    kind: str  # "bit" | "word"
    size: int
    radix: int = 10


@dataclass(frozen=True)
class CpuProfile:
    name: str
    family: str  # "fx3" | "fx5" | "q"
    areas: dict[str, Area]
    always_on: tuple[str, ...]
    always_off: tuple[str, ...]
    first_scan_on: tuple[str, ...]
    first_scan_off: tuple[str, ...]
    op_error_flags: tuple[str, ...]  # set on an operation error
    op_error_code: str  # word device receiving the error code
    div_zero_code: int  # error code of a division (or MOD) by zero
    # clock relays: device -> period in ms (OFF for the first half of each period, ON for
    # the second; docs/instructions.md §2)
    clocks: dict[str, int] = field(default_factory=dict)
    # clock relays whose half period is n units, n read from a register every scan:
    # relay -> (register, unit in µs, n written at power-on)
    settable_clocks: dict[str, tuple[str, int, int]] = field(default_factory=dict)
    # does an operation error stop the CPU by default?
    stops_on_op_error: bool = False
    # error code of the other operation errors (operand or value out of range); None: the
    # division-by-zero code
    range_error_code: int | None = None

    @property
    def op_error_default_code(self) -> int:
        return self.div_zero_code if self.range_error_code is None else self.range_error_code


def _areas(*areas: Area) -> dict[str, Area]:
    return {a.name: a for a in areas}


FX3U = CpuProfile(
    name="fx3u",
    family="fx3",
    areas=_areas(
        Area("X", "bit", 0o400, 8), Area("Y", "bit", 0o400, 8),
        Area("M", "bit", 8512), Area("S", "bit", 4096),
        Area("D", "word", 8512), Area("R", "word", 32768), Area("Z", "word", 8),
    ),
    always_on=("M8000",), always_off=("M8001",),
    first_scan_on=("M8002",), first_scan_off=("M8003",),
    op_error_flags=("M8067", "M8068"), op_error_code="D8067",
    div_zero_code=6706,
    clocks={"M8011": 10, "M8012": 100, "M8013": 1000, "M8014": 60000},
)

FX3G = CpuProfile(
    name="fx3g",
    family="fx3",
    areas=_areas(
        Area("X", "bit", 0o200, 8), Area("Y", "bit", 0o200, 8),
        Area("M", "bit", 8512), Area("S", "bit", 4096),
        Area("D", "word", 8512), Area("R", "word", 24000), Area("Z", "word", 8),
    ),
    always_on=FX3U.always_on, always_off=FX3U.always_off,
    first_scan_on=FX3U.first_scan_on, first_scan_off=FX3U.first_scan_off,
    op_error_flags=FX3U.op_error_flags, op_error_code=FX3U.op_error_code,
    div_zero_code=6706, clocks=FX3U.clocks,
)

_SM_CLOCKS = {"SM409": 10, "SM410": 100, "SM411": 200, "SM412": 1000, "SM413": 2000}
# SM414: 2n second clock, n in SD414; SM415: 2n ms clock, n in SD415 (both n = 30 at power-on)
_SM_SETTABLE_CLOCKS = {"SM414": ("SD414", 1_000_000, 30), "SM415": ("SD415", 1_000, 30)}

FX5U = CpuProfile(
    name="fx5u",
    family="fx5",
    areas=_areas(
        Area("X", "bit", 1024, 8), Area("Y", "bit", 1024, 8),
        Area("M", "bit", 32768), Area("L", "bit", 32768), Area("B", "bit", 32768, 16),
        Area("SM", "bit", 10000), Area("D", "word", 8000), Area("R", "word", 32768),
        Area("W", "word", 32768, 16), Area("SD", "word", 12000), Area("Z", "word", 24),
    ),
    # FX5 keeps the FX3-compatible SM8000/SM8002 beside SM400/SM402.
    always_on=("SM400", "SM8000"), always_off=("SM401", "SM8001"),
    first_scan_on=("SM402", "SM8002"), first_scan_off=("SM403", "SM8003"),
    op_error_flags=("SM0", "SM1"), op_error_code="SD0",
    # FX5 Programming Manual (Instructions) 6.2, "/": error code 3400 "0 is specified for
    # (s2) value"; 3405H for values out of range (docs/instructions.md section 2)
    div_zero_code=0x3400, range_error_code=0x3405,
    clocks=_SM_CLOCKS, settable_clocks=_SM_SETTABLE_CLOCKS,
)

QCPU = CpuProfile(
    name="q",
    family="q",
    areas=_areas(
        Area("X", "bit", 8192, 16), Area("Y", "bit", 8192, 16),
        Area("M", "bit", 8192), Area("L", "bit", 8192), Area("B", "bit", 8192, 16),
        Area("SM", "bit", 2048), Area("D", "word", 12288), Area("R", "word", 32768),
        Area("W", "word", 8192, 16), Area("SD", "word", 2048), Area("Z", "word", 20),
        Area("ZR", "word", 65536),
    ),
    always_on=("SM400",), always_off=("SM401",),
    first_scan_on=("SM402",), first_scan_off=("SM403",),
    op_error_flags=("SM0", "SM1"), op_error_code="SD0",
    div_zero_code=4100,
    clocks=_SM_CLOCKS, settable_clocks=_SM_SETTABLE_CLOCKS,
    stops_on_op_error=True,
)


def type_not_on_cpu(type_key: str, cpu: CpuProfile) -> str | None:
    """Why the elementary type `type_key` (upper case) has no place on `cpu`, or None.
    FLOAT [Double Precision] (LREAL) is "used for the Universal model QCPU only" among the
    GX Works2 CPUs (docs/st-dialect.md section 3): an FX3 CPU has no double-precision
    data. The simulator's compiler and `uitamr check --platform` both ask this."""
    if type_key == "LREAL" and cpu.family == "fx3":
        return (f"LREAL (FLOAT [Double Precision]) does not exist on the {cpu.name}: under "
                f"GX Works2 only the Universal model QCPU has it; use REAL")
    return None


PROFILES = {p.name: p for p in (FX3U, FX3G, FX5U, QCPU)}
# Accepted spellings of a CPU, and the default CPU of each editor target.
CPU_ALIASES = {"fx3": "fx3u", "fx3uc": "fx3u", "fx3gc": "fx3g", "fx5": "fx5u",
               "fx5uc": "fx5u", "qcpu": "q", "qnu": "q", "l": "q"}
# The CPUs each editor programs, its default first. GX Works2 programs the FX3 and Q
# CPUs, GX Works3 the FX5 (iQ-F), not the other way round: docs/import-gxworks2.md
# ("FX3U / FX3G / Q"), docs/import-gxworks3.md ("FX5U / FX5UC", series FX5CPU) and
# docs/verifier.md ("GX Works2 for FX3U and Q, GX Works3 for FX5U"); "GX Works2 has
# superseded GX Developer for new A/Q/L/FX projects and GX Works3 covers the MELSEC iQ-R
# and iQ-F platforms" (https://industrialmonitordirect.com/blogs/knowledgebase/gx-developer-reference-typical-plc-controlled-system-architecture).
TARGET_CPUS = {"gxworks2": ("fx3u", "fx3g", "q"), "gxworks3": ("fx5u",)}
TARGET_DEFAULT_CPU = {target: cpus[0] for target, cpus in TARGET_CPUS.items()}
EDITOR_NAMES = {"gxworks2": "GX Works2", "gxworks3": "GX Works3"}

# The timer resolutions the simulator's TON/TOF/TP can count in (ms): the timer devices
# of the CPUs modelled come in 100 ms, 10 ms and 1 ms kinds (docs/instructions.md §4).
TIMER_RESOLUTIONS_MS = (1, 10, 100)


# Send-request flags of the serial channels: writing TRUE to one of them is where a
# transmission starts, so the compiler records that ST location as the bytes' origin.
SEND_FLAGS = {
    "fx3": {"M8402": "fx3:1", "M8422": "fx3:2"},
    "fx5": {"SM8561": "fx5:1", "SM8571": "fx5:2"},
    "q": {},
}


def profile_for(target: str, cpu: str | None = None) -> CpuProfile:
    """CPU profile for an editor target ("gxworks2", "gxworks3") or a "target:cpu" pair
    ("gxworks2:q"), refusing a CPU the editor does not program."""
    for what, value in (("target", target), ("cpu", cpu)):
        if (value is not None or what == "target") and not isinstance(value, str):
            raise TypeError(f"{what} is a name such as {'gxworks2' if what == 'target' else 'fx3u'!r}; got {value!r:.60}")
    editor, colon, named = target.partition(":")
    editor = editor.lower()  # 'GXWorks2' as 'gxworks2:Q' already was
    if editor not in TARGET_CPUS:
        raise ValueError(f"unknown target {editor!r}; use one of {sorted(TARGET_CPUS)}")
    if colon and cpu is not None and _cpu_key(named) != _cpu_key(cpu):
        raise ValueError(f"target {target!r} and cpu={cpu!r} name two CPUs; name the CPU once")
    if cpu is None:
        cpu = named if colon else TARGET_DEFAULT_CPU[editor]
    key = _cpu_key(cpu)
    if key not in PROFILES:
        raise ValueError(f"unknown CPU {cpu!r}; use one of {sorted(PROFILES)}")
    if key not in TARGET_CPUS[editor]:
        other = next(t for t, cpus in TARGET_CPUS.items() if key in cpus)
        raise ValueError(f"{EDITOR_NAMES[editor]} does not program the {key.upper()} CPU ({EDITOR_NAMES[other]} "
                         f"does): use target={other!r} with cpu={key!r}, or a CPU {EDITOR_NAMES[editor]} "
                         f"programs: {', '.join(TARGET_CPUS[editor])}")
    return PROFILES[key]


def _cpu_key(cpu: str) -> str:
    return CPU_ALIASES.get(cpu.lower(), cpu.lower())


def _special_roles(cpu: CpuProfile) -> list[tuple[str, tuple[str, ...]]]:
    """What each special relay/register the profile drives is for, as (role, devices)."""
    roles = [("always ON", cpu.always_on), ("always OFF", cpu.always_off),
             ("ON in the first scan", cpu.first_scan_on), ("OFF in the first scan", cpu.first_scan_off),
             ("operation error", cpu.op_error_flags), ("operation error code", (cpu.op_error_code,))]
    roles += [(f"{ms} ms clock", (relay,)) for relay, ms in cpu.clocks.items()]
    return roles


def special_equivalent(device: str, cpu: CpuProfile) -> tuple[str, tuple[str, ...]] | None:
    """(role, `cpu`'s devices for it) when `device` (`SM400`, `M8002`) is a special relay or
    register another CPU profile drives and `cpu` drives another one for the same thing:
    ("ON in the first scan", ("SM402",)) for M8002 on a Q. None otherwise."""
    device = device.upper()
    for other in PROFILES.values():
        for role, devices in _special_roles(other):
            if device in devices:
                mine = dict(_special_roles(cpu)).get(role, ())
                return (role, mine) if mine and device not in mine else None
    return None


# The FX3's special relays and registers (M8000..M8511, D8000..D8511): on the other CPUs
# these numbers are ordinary devices or none at all; their special devices are SM and SD.
FX3_SPECIAL = {"M": ("SM", "relay"), "D": ("SD", "register")}
FX3_SPECIAL_RANGE = range(8000, 8512)

# The FX3's serial-communication devices (RS2 ch1 / ch2, docs/instructions.md §7) and what
# stands for each on the other CPU families: the FX5's RS2 devices (§8, ASSUMPTION there
# but for SD8621/SD8631), or nothing, with where the setting lives instead. A program moved
# from an FX3U to an FX5U or a Q names these first; "FX3 special registers are SD devices"
# would send it to SD8400, an unrelated number nothing reads.
_FX5_SERIAL_SOURCE = "docs/instructions.md §8"
_FX5_LINE_SETTINGS = ("no device on the fx5u: its serial ports take the line settings from the module "
                      "parameters (GX Works3: Module Parameter > 485 Serial Port, docs/import-gxworks3.md §4)")
_Q_SERIAL = ("no device on the q: a QJ71C24N is driven with G_OUTPUT / G_INPUT and its switch settings "
             "(UITAMR_PortQC24, docs/import-gxworks2.md)")
#: each FX3 RS2 device's role (a field of Rs2Devices) as the messages name it, and its unit on the FX5
_RS2_ROLES = (("format_register", "communication format", ""), ("send_remaining", "bytes left to send", ""),
              ("receive_count", "received byte count", ""), ("timeout_setting", "receive time-out", ", in ms"),
              ("send_request", "send request", ""), ("receive_complete", "receive complete", ""),
              ("timeout_flag", "time-out flag", ""))


def _fx3_serial() -> dict[str, tuple[str, dict[str, str]]]:
    """FX3 device -> (its role, what stands for it per family), from the RS2 port model's
    own device tables (rs2_devices), so the check and the simulator name the same devices."""
    table: dict[str, tuple[str, dict[str, str]]] = {}
    for channel, fx3 in FX3_CHANNELS.items():
        fx5 = FX5_CHANNELS[channel]
        for field_name, role, unit in _RS2_ROLES:
            theirs = getattr(fx5, field_name)
            text = _FX5_LINE_SETTINGS if theirs is None else f"{theirs} on the fx5u{unit} ({_FX5_SERIAL_SOURCE})"
            table[getattr(fx3, field_name)] = (f"RS2 ch{channel} {role}", {"fx5": text, "q": _Q_SERIAL})
    eight_bit = " / ".join(c.eight_bit_mode for c in FX5_CHANNELS.values() if c.eight_bit_mode)
    table["M8161"] = ("8-bit mode of CRC", {
        "fx5": f"SM8161 on the fx5u (docs/instructions.md §6); RS2's 8-bit mode is {eight_bit} there",
        "q": "no device on the q: it has no CRC instruction (the library computes the CRC in ST)"})
    return table


FX3_SERIAL = _fx3_serial()

# The FX3U-485ADP-MB MODBUS master's registers (docs/instructions.md §10), several of them
# RS2's numbers in the other mode: a program moved from an FX3U ADPRW route was sent to
# SD8621 for the slave response time-out, which on the FX5 is a module parameter.
_FX5_MODBUS_PARAMETER = ("a module parameter on the fx5u (GX Works3: Module Parameter > 485 Serial Port, "
                         "docs/import-gxworks3.md §4)")
_FX5_MODBUS_UNKNOWN = ("no device known on the fx5u: the register of the FX5 ADPRW's error code was not found "
                       "(docs/instructions.md §10)")
_MODBUS_ROLES = (("response_timeout", "slave response time-out", _FX5_MODBUS_PARAMETER),
                 ("retries", "retries", _FX5_MODBUS_PARAMETER),
                 ("error_code", "MODBUS error code", _FX5_MODBUS_UNKNOWN),
                 ("error_details", "MODBUS error details", _FX5_MODBUS_UNKNOWN))
FX3_MODBUS = {getattr(devices, field_name): (f"the FX3U-485ADP-MB's ADPRW ch{channel} {role}",
                                             {"fx5": fx5})  # a Q has no ADPRW: RS2's hint says enough
              for channel, devices in FX3_MODBUS_CHANNELS.items() for field_name, role, fx5 in _MODBUS_ROLES}


def fx3_serial_equivalent(device: str, cpu: CpuProfile) -> str | None:
    """'the FX3's M8402 (RS2 ch1 send request) is SM8561 on the fx5u (...)' for an FX3
    serial-communication device named on another CPU family, with its meaning for the
    FX3U-485ADP-MB MODBUS master too where it has one; None for other devices."""
    key = device.upper()
    parts = []
    for table in (FX3_SERIAL, FX3_MODBUS):
        entry = table.get(key)
        if entry is None or cpu.family not in entry[1]:
            continue
        role, texts = entry
        text = texts[cpu.family]
        verb = "has" if text.startswith("no device") else "is"
        parts.append(f"as {role} it {verb} {text}" if parts else f"the FX3's {key} ({role}) {verb} {text}")
    return "; ".join(parts) or None
