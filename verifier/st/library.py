"""What GX Works provides without a declaration: standard functions, standard function
blocks, and the MELSEC instructions this project calls (with their ST operand order,
docs/st-dialect.md section 1)."""
from __future__ import annotations

from verifier.st import melsec
from verifier.st.types import (
    BOOL, DINT, DWORD, INT, LREAL, REAL, STRING, TIME, UDINT, UINT, WORD, WSTRING,
    FbType, Param, Signature,
)

# ----------------------------------------------------------------------------- standard FBs
STANDARD_FBS: dict[str, FbType] = {}


def _fb(name, inputs, outputs):
    STANDARD_FBS[name] = FbType(name, tuple(inputs), tuple(outputs), (), (), True)


for _timer in ("TON", "TOF", "TP"):
    _fb(_timer, [("IN", BOOL), ("PT", TIME)], [("Q", BOOL), ("ET", TIME)])
_fb("R_TRIG", [("CLK", BOOL)], [("Q", BOOL)])
_fb("F_TRIG", [("CLK", BOOL)], [("Q", BOOL)])
_fb("CTU", [("CU", BOOL), ("R", BOOL), ("PV", INT)], [("Q", BOOL), ("CV", INT)])
_fb("CTD", [("CD", BOOL), ("LD", BOOL), ("PV", INT)], [("Q", BOOL), ("CV", INT)])
_fb("CTUD", [("CU", BOOL), ("CD", BOOL), ("R", BOOL), ("LD", BOOL), ("PV", INT)],
    [("QU", BOOL), ("QD", BOOL), ("CV", INT)])
_fb("SR", [("S1", BOOL), ("R", BOOL)], [("Q1", BOOL)])
_fb("RS", [("S", BOOL), ("R1", BOOL)], [("Q1", BOOL)])

# ----------------------------------------------------------------------------- standard functions
STANDARD_FUNCTIONS: dict[str, Signature] = {}


def _fn(name, params, result, variadic=False, targets=("gxworks2", "gxworks3")):
    STANDARD_FUNCTIONS[name] = Signature(
        name, "function", tuple(Param(n, a) for n, a in params), result, variadic, targets)


for _name in ("ADD", "MUL"):
    _fn(_name, [("IN1", "ANY_NUM"), ("IN2", "ANY_NUM")], "SAME", variadic=True)
for _name in ("SUB", "DIV"):
    _fn(_name, [("IN1", "ANY_NUM"), ("IN2", "ANY_NUM")], "SAME")
_fn("MOD", [("IN1", "ANY_INT"), ("IN2", "ANY_INT")], "SAME")
_fn("EXPT", [("IN1", "ANY_REAL"), ("IN2", "ANY_NUM")], "FIRST")
_fn("MOVE", [("IN", "ANY")], "SAME")
_fn("ABS", [("IN", "ANY_NUM")], "SAME")
for _name in ("SQRT", "LN", "LOG", "EXP", "SIN", "COS", "TAN", "ASIN", "ACOS", "ATAN"):
    _fn(_name, [("IN", "ANY_REAL")], "SAME")
for _name in ("SHL", "SHR", "ROL", "ROR"):
    _fn(_name, [("IN", "ANY_BIT"), ("N", "ANY_INT")], "FIRST")
for _name in ("AND", "OR", "XOR"):
    _fn(_name, [("IN1", "ANY_BIT"), ("IN2", "ANY_BIT")], "SAME", variadic=True)
_fn("NOT", [("IN", "ANY_BIT")], "SAME")
_fn("SEL", [("G", "BOOL"), ("IN0", "ANY"), ("IN1", "ANY")], "SAME")
for _name in ("MAX", "MIN"):
    _fn(_name, [("IN1", "ANY_SIMPLE"), ("IN2", "ANY_SIMPLE")], "SAME", variadic=True)
_fn("LIMIT", [("MN", "ANY_SIMPLE"), ("IN", "ANY_SIMPLE"), ("MX", "ANY_SIMPLE")], "SAME")
_fn("MUX", [("K", "ANY_INT"), ("IN0", "ANY"), ("IN1", "ANY")], "SAME", variadic=True)
for _name in ("GT", "GE", "EQ", "LE", "LT", "NE"):
    _fn(_name, [("IN1", "ANY_SIMPLE"), ("IN2", "ANY_SIMPLE")], BOOL)
_fn("TRUNC", [("IN", "ANY_REAL")], DINT)
_fn("LEN", [("IN", "STRING")], INT)
_fn("LEFT", [("IN", "STRING"), ("L", "ANY_INT")], STRING)
_fn("RIGHT", [("IN", "STRING"), ("L", "ANY_INT")], STRING)
_fn("MID", [("IN", "STRING"), ("L", "ANY_INT"), ("P", "ANY_INT")], STRING)
_fn("CONCAT", [("IN1", "STRING"), ("IN2", "STRING")], STRING, variadic=True)
_fn("INSERT", [("IN1", "STRING"), ("IN2", "STRING"), ("P", "ANY_INT")], STRING)
_fn("DELETE", [("IN", "STRING"), ("L", "ANY_INT"), ("P", "ANY_INT")], STRING)
_fn("REPLACE", [("IN1", "STRING"), ("IN2", "STRING"), ("L", "ANY_INT"), ("P", "ANY_INT")], STRING)
_fn("FIND", [("IN1", "STRING"), ("IN2", "STRING")], INT)

# Type conversions as GX Works names them: INT_TO_WORD, WORD_TO_INT, DINT_TO_INT,
# BOOL_TO_INT, REAL_TO_INT ... ; STRING conversions are spelt STR (INT_TO_STR).
_CONV_TYPES = {"BOOL": BOOL, "INT": INT, "DINT": DINT, "WORD": WORD, "DWORD": DWORD,
               "REAL": REAL, "LREAL": LREAL, "TIME": TIME, "STR": STRING,
               "UINT": UINT, "UDINT": UDINT, "WSTR": WSTRING}
_GX3_ONLY = {"UINT", "UDINT", "WSTR"}
for _src, _st in _CONV_TYPES.items():
    for _dst, _dt in _CONV_TYPES.items():
        if _src == _dst or (_src in ("STR", "WSTR") and _dst in ("STR", "WSTR")):
            continue
        if _src == "TIME" and _dst in ("REAL", "LREAL") or _dst == "TIME" and _src in ("REAL", "LREAL"):
            continue
        _targets = ("gxworks3",) if _src in _GX3_ONLY or _dst in _GX3_ONLY else ("gxworks2", "gxworks3")
        _fn(f"{_src}_TO_{_dst}", [("IN", _st.name)], _dt, targets=_targets)
_CONV_SPELLING = {t.name: name for name, t in _CONV_TYPES.items()}


def conversion(source, target, editor: str) -> str | None:
    """The function converting type `source` to `target` as `editor` spells it
    (STRING is STR: STR_TO_INT), or None where the editor has none (TIME and REAL)."""
    name = f"{_CONV_SPELLING.get(getattr(source, 'name', None))}_TO_{_CONV_SPELLING.get(getattr(target, 'name', None))}"
    sig = STANDARD_FUNCTIONS.get(name)
    return name if sig is not None and editor in sig.targets else None


for _t in ("INT", "DINT", "WORD", "DWORD"):
    _fn(f"{_t}_TO_BCD", [("IN", _t)], WORD if _t in ("INT", "WORD") else DWORD)
    _fn(f"BCD_TO_{_t}", [("IN", "WORD" if _t in ("INT", "WORD") else "DWORD")], INT if _t == "INT" else (DINT if _t == "DINT" else (WORD if _t == "WORD" else DWORD)))

# ----------------------------------------------------------------------------- MELSEC instructions
INSTRUCTIONS: dict[str, Signature] = {}


def _ins(name, params, targets=("gxworks2", "gxworks3"), pulse=True, note=""):
    sig = Signature(name, "instruction",
                    (Param("EN", "BOOL"),) + tuple(Param(n, a, d) for n, a, d in params),
                    None, False, targets, note)
    INSTRUCTIONS[name] = sig
    if pulse:
        INSTRUCTIONS[name + "P"] = Signature(name + "P", "instruction", sig.params, None, False,
                                             targets, note + " (runs once on the rising edge of EN)")


_ins("MOV", [("s", "ANY16", "in"), ("d", "ANY16", "out")])
_ins("DMOV", [("s", "ANY32", "in"), ("d", "ANY32", "out")])
_ins("BMOV", [("s", "BLOCK16", "in"), ("n", "ANY16", "in"), ("d", "BLOCK16", "out")])
_ins("FMOV", [("s", "ANY16", "in"), ("n", "ANY16", "in"), ("d", "BLOCK16", "out")])
_ins("CML", [("s", "ANY16", "in"), ("d", "ANY16", "out")])
_ins("XCH", [("d1", "ANY16", "inout"), ("d2", "ANY16", "inout")])
_ins("SWAP", [("d", "ANY16", "inout")])
_ins("INC", [("d", "ANY16", "inout")])
_ins("DEC", [("d", "ANY16", "inout")])
_ins("WAND", [("s1", "ANY16", "in"), ("s2", "ANY16", "in"), ("d", "ANY16", "out")])
_ins("WOR", [("s1", "ANY16", "in"), ("s2", "ANY16", "in"), ("d", "ANY16", "out")])
_ins("WXOR", [("s1", "ANY16", "in"), ("s2", "ANY16", "in"), ("d", "ANY16", "out")])
_ins("BCD", [("s", "ANY16", "in"), ("d", "ANY16", "out")])
_ins("BIN", [("s", "ANY16", "in"), ("d", "ANY16", "out")])
_ins("ZRST", [("d1", "ANY", "out"), ("d2", "ANY", "out")])
_ins("SET", [("d", "BITS", "out")], pulse=False)
_ins("RST", [("d", "ANY", "out")], pulse=False)
_ins("OUT", [("d", "BITS", "out")], pulse=False)
_ins("PLS", [("d", "BITS", "out")], pulse=False)
_ins("PLF", [("d", "BITS", "out")], pulse=False)
# serial communication (docs/st-dialect.md section 1)
_ins("RS2", [("s", "BLOCK16", "in"), ("m", "ANY16", "in"), ("n", "ANY16", "in"),
             ("n1", "ANY16", "in"), ("d", "BLOCK16", "out")], pulse=False,
     note="FX3U/FX3G: s send head, m bytes to send, n bytes to receive, n1 channel, d receive head; "
          "FX5: s, n1 send count, n2 receive count, n3 channel, d")
_ins("CRC", [("s", "BLOCK16", "in"), ("n", "ANY16", "in"), ("d", "ANY16", "out")],
     note="CRC-16/MODBUS of n bytes from s into d")
_ins("ADPRW", [("s", "ANY16", "in"), ("s1", "ANY16", "in"), ("s2", "ANY16", "in"),
               ("s3", "ANY16", "in"), ("s4d", "BLOCK16", "inout")], targets=("gxworks2",), pulse=False,
     note="FX3U-485ADP-MB MODBUS master: slave, function, address, count, data head")
INSTRUCTIONS["ADPRW_FX5"] = Signature(
    "ADPRW", "instruction",
    (Param("EN", "BOOL"), Param("s", "ANY16"), Param("s1", "ANY16"), Param("s2", "ANY16"),
     Param("s3", "ANY16"), Param("s4d1", "BLOCK16", "inout"), Param("d2", "BITS2", "out")),
    None, False, ("gxworks3",), "FX5 MODBUS master: slave, function, address, count, data head, completion bits")
_ins("G_OUTPUT", [("Un", "ANY16", "in"), ("s1", "BLOCK16", "inout"), ("s2", "BLOCK16", "in"),
                  ("d", "BITS2", "out")], pulse=False,
     note="QJ71C24N non-procedural send: Un start I/O, s1 control data, s2 send data, d completion bits")
_ins("G_INPUT", [("Un", "ANY16", "in"), ("s", "BLOCK16", "inout"), ("d1", "BLOCK16", "out"),
                 ("d2", "BITS2", "out")], pulse=False,
     note="QJ71C24N non-procedural receive: Un start I/O, s control data, d1 receive data, d2 completion bits")

# Ethernet (docs/instructions.md "Ethernet"): the ladder forms SP.SOCOPEN ... and ZP.OPEN ...
# run once on the rising edge of EN; U / Un is the module as a string ('U0')
_ins("SP_SOCOPEN", [("U", "STRING", "in"), ("s1", "ANY16", "in"), ("s2", "BLOCK16", "inout"),
                    ("d", "BITS2", "out")], targets=("gxworks3",), pulse=False,
     note="FX5 socket open: U 'U0', s1 connection, s2 control data, d completion bits")
_ins("SP_SOCSND", [("U", "STRING", "in"), ("s1", "ANY16", "in"), ("s2", "BLOCK16", "inout"),
                   ("s3", "BLOCK16", "in"), ("d", "BITS2", "out")], targets=("gxworks3",), pulse=False,
     note="FX5 socket send: U 'U0', s1 connection, s2 control data, s3 byte count + data, d completion bits")
_ins("SP_SOCRCV", [("U", "STRING", "in"), ("s1", "ANY16", "in"), ("s2", "BLOCK16", "inout"),
                   ("d1", "BLOCK16", "out"), ("d2", "BITS2", "out")], targets=("gxworks3",), pulse=False,
     note="FX5 socket receive: U 'U0', s1 connection, s2 control data, d1 byte count + data, d2 completion bits")
_ins("SP_SOCCLOSE", [("U", "STRING", "in"), ("s1", "ANY16", "in"), ("s2", "BLOCK16", "inout"),
                     ("d", "BITS2", "out")], targets=("gxworks3",), pulse=False,
     note="FX5 socket close: U 'U0', s1 connection, s2 control data, d completion bits")
_ins("ZP_OPEN", [("Un", "STRING", "in"), ("s1", "ANY16", "in"), ("s2", "BLOCK16", "inout"),
                 ("d", "BITS2", "out")], targets=("gxworks2",), pulse=False,
     note="QJ71E71 open: Un module ('U0'), s1 connection, s2 control data, d completion bits")
_ins("ZP_BUFSND", [("Un", "STRING", "in"), ("s1", "ANY16", "in"), ("s2", "BLOCK16", "inout"),
                   ("s3", "BLOCK16", "in"), ("d", "BITS2", "out")], targets=("gxworks2",), pulse=False,
     note="QJ71E71 fixed buffer send: Un, s1 connection, s2 control data, s3 length + data, d completion bits")
_ins("ZP_BUFRCV", [("Un", "STRING", "in"), ("s1", "ANY16", "in"), ("s2", "BLOCK16", "inout"),
                   ("d1", "BLOCK16", "out"), ("d2", "BITS2", "out")], targets=("gxworks2",), pulse=False,
     note="QJ71E71 fixed buffer receive: Un, s1 connection, s2 control data, d1 length + data, d2 completion bits")
_ins("ZP_CLOSE", [("Un", "STRING", "in"), ("s1", "ANY16", "in"), ("s2", "BLOCK16", "inout"),
                  ("d", "BITS2", "out")], targets=("gxworks2",), pulse=False,
     note="QJ71E71 close: Un, s1 connection, s2 control data, d completion bits")


def instruction(name: str, target: str) -> Signature | None:
    """The instruction called `name` (upper case) on `target`, if there is one."""
    if name == "ADPRW" and target == "gxworks3":
        return INSTRUCTIONS["ADPRW_FX5"]
    sig = INSTRUCTIONS.get(name)
    if sig is None or name == "ADPRW_FX5":
        return None
    return sig


#: names a label may not take: ST keywords, types, standard functions/FBs, instructions
KEYWORDS = frozenset("""
ACTION END_ACTION ARRAY OF AT CASE ELSE END_CASE CONFIGURATION END_CONFIGURATION CONSTANT
EN ENO EXIT FALSE F_EDGE FOR TO BY DO END_FOR FUNCTION END_FUNCTION FUNCTION_BLOCK
END_FUNCTION_BLOCK IF THEN ELSIF END_IF INITIAL_STEP END_STEP NOT MOD AND XOR OR PROGRAM
END_PROGRAM R_EDGE READ_ONLY READ_WRITE REPEAT UNTIL END_REPEAT RESOURCE END_RESOURCE
RETAIN NON_RETAIN PERSISTENT RETURN STEP STRUCT END_STRUCT TASK TRANSITION END_TRANSITION
TRUE TYPE END_TYPE VAR END_VAR VAR_INPUT VAR_OUTPUT VAR_IN_OUT VAR_TEMP VAR_EXTERNAL
VAR_ACCESS VAR_CONFIG VAR_GLOBAL VAR_CONSTANT VAR_RETAIN VAR_PUBLIC WHILE END_WHILE WITH
BOOL BYTE WORD DWORD LWORD SINT INT DINT LINT USINT UINT UDINT ULINT REAL LREAL TIME DATE
TIME_OF_DAY TOD DATE_AND_TIME DT STRING WSTRING ANY ANY_NUM ANY_INT ANY_REAL ANY_BIT
ANY16 ANY32
""".split())
RESERVED_DEVICE_WORDS = frozenset(
    ["COM" + str(i) for i in range(1, 10)] + ["LPT" + str(i) for i in range(1, 10)]
    + ["AUX", "CON", "PRN", "NUL"])


def reserved_reason(name: str, families: tuple[str, ...] = ()) -> str | None:
    """Why GX Works would refuse `name` as a reserved word, or None. `families`: the CPU
    families (verifier.st.melsec: fx3, fx5, q) whose instruction names are refused too,
    as `melsec.families_for` picks them for the target and platform checked."""
    key = name.upper()
    if key in KEYWORDS:
        return "is an ST keyword or type name"
    if key in INSTRUCTIONS or key == "ADPRW":
        return "is a reserved instruction name"
    if key in STANDARD_FUNCTIONS:
        return "is a standard function name"
    if key in STANDARD_FBS:
        return "is a standard function block name"
    family = melsec.instruction_family(key, families)
    if family is not None:
        cpus, editor = melsec.FAMILIES[family]
        return (f"is the name of a MELSEC instruction of the {cpus} CPU ({editor} refuses every "
                f"instruction name of the CPU as a label, docs/st-dialect.md section 4)")
    if key in RESERVED_DEVICE_WORDS:
        return "is a reserved device name of the operating system"
    return None


# The inputs of the UITAMR library's FBs that the FBs themselves check against a range, with
# the error code they end with outside it (`uitamr check` warns at a constant out of range:
# `i_wPoint := 25` imported without a word and failed at the first command). Each range is
# the one the FB's ST checks and each code is in its header; tests/test_check_integrator.py
# derives them from plc/ and compares, so the table cannot drift from the ST.
LIBRARY_INPUT_RANGES: dict[tuple[str, str], tuple[int, int, int]] = {
    ("UITAMR_BUILDCONTROL", "I_WADDRESS"): (1, 247, 0x0301),
    ("UITAMR_BUILDCONTROL", "I_WCODE"): (1, 13, 0x0301),
    ("UITAMR_BUILDCONTROL", "I_WCOMMAND"): (0, 255, 0x0301),
    ("UITAMR_BUILDSTATUS", "I_WADDRESS"): (1, 247, 0x0301),
    ("UITAMR_BUILDSTATUS", "I_WQUERY"): (0, 3, 0x0301),
    ("UITAMR_RUNPOINT", "I_WPOINT"): (1, 21, 0x0301),
    ("UITAMR_SETSPEED", "I_WSTAGE"): (1, 4, 0x0301),
    ("UITAMR_READSTATUS", "I_WQUERY"): (0, 3, 0x0301),
    ("UITAMR_JOG", "I_WDIRECTION"): (0, 6, 0x0301),
    ("UITAMR_PORTFX3", "I_WCHANNEL"): (1, 2, 0x0304),
    ("UITAMR_PORTFX5", "I_WCHANNEL"): (1, 2, 0x0304),
    ("UITAMR_PORTQC24", "I_WCHANNEL"): (1, 2, 0x0304),
    ("UITAMR_PORTTCPFX5", "I_WCONNECTION"): (1, 8, 0x0304),
    ("UITAMR_PORTE71", "I_WCONNECTION"): (1, 7, 0x0304),
}
