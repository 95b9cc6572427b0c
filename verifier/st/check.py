"""Semantic check of GX Works structured text.

`check(files, target)` resolves every name, type and call across the given files (a POU
may use POUs and structures of the other files), annotates the trees in place — each
expression gets `.type`, each `Name` its `.symbol`, each `Call` its `.resolved`
`CallTarget` — and returns diagnostics for what GX Works would reject (errors) or what
is suspicious (warnings). The simulator reuses the annotations and `SymbolTable`.
"""
from __future__ import annotations

import functools
import math
import re
from pathlib import Path
from dataclasses import dataclass, field

from verifier import plcfacts
from verifier.bundled import PLC_DIR, library_file
from verifier.textfile import real_path
from verifier.st import ast, library, melsec, structure
from verifier.st import types as T
from verifier.st.devices import HEX_DEVICES, looks_like_device

REAL_MAX = 3.4028234663852886e38  # the largest 32-bit float
# branches of one IF or CASE: the simulator's Python compiler gives up near 3,000
MAX_BRANCHES = 1000


# ----------------------------------------------------------------------------- symbol table
@dataclass
class PouInfo:
    """A POU with its resolved label types: `labels` maps upper-case names to
    (VarDecl, Type)."""

    pou: ast.Pou
    file: str
    labels: dict[str, tuple[ast.VarDecl, T.Type]] = field(default_factory=dict)
    fb_type: T.FbType | None = None
    return_type: T.Type | None = None


@dataclass
class SymbolTable:
    """Everything resolved over a set of files: structures, global labels, POUs."""

    target: str
    structs: dict[str, T.StructOf] = field(default_factory=dict)
    struct_decls: dict[str, ast.StructDecl] = field(default_factory=dict)
    globals: dict[str, tuple[ast.VarDecl, T.Type]] = field(default_factory=dict)
    pous: dict[str, PouInfo] = field(default_factory=dict)

    def lookup(self, pou: PouInfo | None, name: str) -> tuple[ast.VarDecl, T.Type] | None:
        key = name.upper()
        if pou is not None and key in pou.labels:
            return pou.labels[key]
        return self.globals.get(key)


class _Reporter:
    def __init__(self) -> None:
        self.diagnostics: list[ast.Diagnostic] = []

    def at(self, node, severity: str, message: str) -> None:
        span = getattr(node, "span", None) or ast.NO_SPAN
        self.diagnostics.append(ast.Diagnostic.of_span(span, severity, message))

    def error(self, node, message: str) -> None:
        self.at(node, "error", message)

    def warning(self, node, message: str) -> None:
        self.at(node, "warning", message)


_MAX_NAME = 32  # GX Works label name length limit (characters)
#: names GX Works reads as devices or constants the reader does not treat as data:
#: pointers P, interrupt pointers I, nesting N, network numbers J (J1\W0), I/O numbers
#: U (U3\G0), E real constants (E1.5), SFC blocks/transitions BL/TR, function devices
#: FX/FY/FD, and the iQ-F/iQ-R long devices LZ, LT, LST, LC, RD (docs/st-dialect.md §4)
_OTHER_DEVICE_RE = re.compile(r"(?:P|I|N|J|E|BL|TR|FX|FY|FD|LZ|LTN|LSTN|LCN|LT|LST|LC|RD)[0-9]+|U[0-9][0-9A-F]*",
                              re.IGNORECASE)


_DIGIT_SPEC_RE = re.compile(r"[Kk][1-8]")
_CONSTANT_RE = re.compile(r"[Kk][0-9]+|[Hh][0-9A-Fa-f]+")


#: the type letters of Mitsubishi's FB-library label names (i_bEN, o_uErrId, i_udIpAddress)
#: and the GX Works2 data type each stands for, as docs/plc-library.md lists them
TYPE_LETTERS = {"b": "Bit", "w": "Word[Signed]", "u": "Word[Unsigned]", "ud": "Double Word[Unsigned]",
                "e": "FLOAT", "s": "String", "t": "Time"}
_LETTERED = re.compile(r"(?:i|o|io)_([a-z]+)[A-Z0-9]")


_EDITOR_TABLES = None  # verifier.export.types.TABLES, imported at the first use


def type_letters_problem(name: str, t: T.Type, target: str = "gxworks2") -> str | None:
    """Why the type letters of an i_/o_/io_ label name (`o_uCount`) do not name its type
    (an INT), or None: for labels in the convention's form whose letters it lists, of an
    elementary type (an array's element type)."""
    m = _LETTERED.match(name)
    if m is None or m.group(1) not in TYPE_LETTERS:
        return None
    global _EDITOR_TABLES
    if _EDITOR_TABLES is None:
        from verifier.export.types import TABLES  # the editor's type names (no import cycle at call time)

        _EDITOR_TABLES = TABLES
    TABLES = _EDITOR_TABLES
    element = t.element if isinstance(t, T.ArrayOf) else t
    if not isinstance(element, T.Elementary):
        return None
    editor = TABLES.get(target, TABLES["gxworks2"]).get(element.name)  # as the label editor names it
    if editor is None:
        return None
    letters, shown = m.group(1), editor.replace(" ", "")
    if shown.startswith(TYPE_LETTERS[letters].replace(" ", "")):
        return None
    right = [k for k, v in TYPE_LETTERS.items() if shown.startswith(v.replace(" ", ""))]
    rename = (f": rename it {name[:m.start(1)]}{right[0]}{name[m.end(1):]}" if right else
              ": give it the letters of its type, or another type")
    return (f"label '{name}' is {element.name} ({editor}), but its type letter{'s' if len(letters) > 1 else ''} "
            f"'{letters}' stand{'' if len(letters) > 1 else 's'} for {TYPE_LETTERS[letters]} in Mitsubishi's "
            f"FB-library label names (docs/plc-library.md){rename}")


#: the inputs that start an FB's work (IEC timers' IN, an EN, the FB library's i_bEN and
#: i_bExecute): given FALSE, the call resets the instance
#: the edge inputs that start a command FB (the library's i_bExecute, PLCopen's Execute)
_EXECUTE_INPUTS = ("I_BEXECUTE", "EXECUTE")
_START_INPUTS = {"IN", "EN", "I_BEN", *_EXECUTE_INPUTS}


#: the IEC counters' inputs that, given TRUE, set the count whatever the call's other
#: inputs hold: R (CTU, CTUD: to 0, before any count) and LD (CTD, CTUD: to PV)
_COUNTER_RESETS = {"CTU": {"R"}, "CTD": {"LD"}, "CTUD": {"R", "LD"}}


def _resets(call: ast.Call, following: ast.Call) -> bool:
    """Whether an FB call resets the instance before its `following` call, and is not a use:
    it gives the input that starts the FB's work the constant FALSE (`fbTmr(IN := FALSE)`,
    `fbCmd(i_bEN := TRUE, i_bExecute := FALSE)`), or it is an IEC counter's reset or preset,
    the constant TRUE to R or LD (`fbCnt(R := TRUE)`), that the following call gives back (an
    input keeps its value into the next call: one not given again would hold the counter at
    its reset in the use). FALSE to another input (an option) is a use, and so is TRUE to an
    input of a user FB named like a reset (`i_bReset`): what its body does in that call,
    outputs included, is the FB's own."""
    given = {a.name.upper(): a.value for a in call.args if not a.output and a.name is not None}
    if any(name in _START_INPUTS and _constant(value) is False for name, value in given.items()):
        return True
    fb = getattr(call.resolved, "fb_type", None)
    counter = _COUNTER_RESETS.get(fb.name.upper(), set()) if fb is not None and fb.standard else set()
    held = {name for name in counter if _constant(given.get(name)) is True}
    again = {a.name.upper() for a in following.args if not a.output and a.name is not None}
    return bool(held) and held <= again


def _always_returns(s: ast.Stmt) -> bool:
    """Whether a statement leaves the POU whichever way it runs: a RETURN, an IF or CASE
    with an ELSE whose every branch holds one at its own level, or a REPEAT whose body holds
    one before any EXIT (its body runs once at least; a FOR or WHILE may run no time)."""
    if isinstance(s, ast.Return):
        return True
    if isinstance(s, ast.Repeat):
        for x in s.body:
            if any(isinstance(n, ast.Exit) for n in ast.walk(x)):
                return False  # the loop may be left before the RETURN
            if _always_returns(x):
                return True
        return False
    if isinstance(s, ast.If):
        bodies = [b.body for b in s.branches] + [s.else_body]
    elif isinstance(s, ast.Case):
        bodies = [c.body for c in s.clauses] + [s.else_body]
    else:
        return False
    return all(body is not None and any(_always_returns(x) for x in body) for body in bodies)


def _constant(value: ast.Expr | None) -> bool | None:
    """TRUE or FALSE written as a literal, else None."""
    return value.value if isinstance(value, ast.BoolLiteral) else None


#: what a UITAMR_Pause or UITAMR_Stop called only under a condition does besides: they share
#: the priority slot, and a result left there uncollected is taken over by the next request
#: (docs/plc-library.md, "The mailbox (io_uMbx)"; it no longer holds the stop back)
PRIORITY_RESULT_LOST = ("; a {fb} not called when its result comes loses it to the next stop, pause or "
                        "resume, which takes the priority slot over: it then ends with 16#0316")
PRIORITY_FBS = ("UITAMR_PAUSE", "UITAMR_STOP")


def _execute_input(call: ast.Call) -> str | None:
    """The name of the edge input that starts an FB instance's command (i_bExecute, or
    PLCopen's Execute), as its type declares it, or None for an FB without one (a timer,
    the engine, a port)."""
    target = call.resolved
    if getattr(target, "kind", None) != "fb" or target.fb_type is None or target.fb_type.standard:
        return None
    return next((n for n, _t in target.fb_type.inputs if n.upper() in _EXECUTE_INPUTS), None)


def _always_calls(body: list[ast.Stmt], key: str, may_return: bool = True) -> bool:
    """Whether `body` calls the FB instance `key` on every run of it: a call in the body
    itself, or in every branch of an IF or CASE that has an ELSE (a loop may run no time),
    before any statement that may RETURN (the scans that take it do not reach the call)."""
    for s in body:
        if (isinstance(s, ast.CallStmt) and isinstance(s.call.callee, ast.Name)
                and s.call.callee.name.upper() == key):
            return True
        if isinstance(s, ast.If) and s.else_body is not None:
            if all(_always_calls(b.body, key, may_return) for b in s.branches) and \
                    _always_calls(s.else_body, key, may_return):
                return True
        if isinstance(s, ast.Case) and s.else_body is not None:
            if all(_always_calls(c.body, key, may_return) for c in s.clauses) and \
                    _always_calls(s.else_body, key, may_return):
                return True
        if may_return and _returns_in(s):  # (`may_return` False: the POU holds no RETURN)
            return False
    return False


def _returns_in(s: ast.Stmt) -> list[ast.Return]:
    """The RETURNs a statement holds, in the order of the text."""
    return sorted((n for n in ast.walk(s) if isinstance(n, ast.Return)), key=lambda n: (n.span.line, n.span.col))


@functools.lru_cache(maxsize=8192)
def label_name_problem(name: str, families: tuple[str, ...] = ()) -> str | None:
    """Why GX Works refuses `name` as a label, or None. Rules: docs/st-dialect.md §4.
    `families`: the CPU families whose instruction names are refused too
    (`melsec.families_for`). (A function of its arguments alone: remembered, as the same
    labels recur across POUs.)"""
    if name.startswith("_") or name.endswith("_"):
        return "must not start or end with '_'"
    if "__" in name:
        return "must not contain '__'"
    if name[0].isdigit():
        return "must not start with a digit"
    if _DIGIT_SPEC_RE.match(name):
        return "must not start with K1..K8 (read as a digit-specified device)"
    if looks_like_device(name) or _CONSTANT_RE.fullmatch(name) or _OTHER_DEVICE_RE.fullmatch(name):
        return "looks like a device or constant"
    reason = library.reserved_reason(name, families)
    if reason:
        return reason
    if len(name) > _MAX_NAME:
        return f"is longer than {_MAX_NAME} characters"
    return None


# ----------------------------------------------------------------------------- the checker
class Checker:
    def __init__(self, files: list[ast.SourceFile], target: str, platform: str | None = None) -> None:
        self.files = [f for f in files if f.ok]
        self.target = target
        #: the CPU families whose instruction names no label may take (docs/st-dialect.md §4)
        self.families = melsec.families_for(target, platform)
        #: with --platform the CPU fixes the editor: "use --target gxworks3" for a GX Works2
        #: CPU is no way out, it is refused as contradicting the CPU
        self.editor_fixed = platform is not None
        self.table = SymbolTable(target)
        self.rep = _Reporter()
        self.pou: PouInfo | None = None
        self.loop_depth = 0
        self.used: set[int] = set()
        #: (caller POU key, callee POU key, call) for every call of a user FB or FUNCTION
        self.calls: list[tuple[str, str, ast.Call]] = []
        self.pou_calls: list[ast.Call] = []  # the calls of the POU body being checked (check_bodies)
        self.pou_returns = False  # whether that body holds a RETURN: if not, none is looked for
        #: the bundled plc/ folder as the sources reach it (vendor/uitamr/plc), if they do
        self.plc_shown = _plc_as_given([f.filename for f in files])

    # ------------------------------------------------------------- declarations
    def collect(self) -> None:
        for f in self.files:
            for s in f.types:
                if s.key in self.table.struct_decls:
                    self.rep.error(s, f"structure '{s.name}' is defined twice")
                    continue
                self._check_name(s, s.name, "structure")
                self.table.struct_decls[s.key] = s
            for p in f.pous:
                if p.key in self.table.pous:
                    other = self.table.pous[p.key]
                    self.rep.error(p, f"POU '{p.name}' is already defined in {other.file}")
                    continue
                self._check_name(p, p.name, "POU")
                self.table.pous[p.key] = PouInfo(p, f.filename)
        for key, s in self.table.struct_decls.items():
            self.table.structs[key] = T.StructOf(s.name, ())
        for key, s in self.table.struct_decls.items():
            fields = []
            for v in s.fields:
                self._check_name(v, v.name, "member")
                instance = self._fb_type_name(v.type)
                if instance is not None:  # ASSUMPTION (docs/st-dialect.md): structures hold data only
                    self.rep.error(v.type, f"structure member '{v.name}' is an instance of the function block "
                                           f"{instance}: a structure holds data only; declare the instance "
                                           "as a label of the POU that calls it")
                    fields.append((v.name, T.ANY))
                    continue
                ft = self.resolve_type(v.type)
                fields.append((v.name, ft))
                if v.init is not None and self.target == "gxworks2" and not _is_zero(v.init):
                    self.rep.error(v.init, f"GX Works2 structures have no initial values: member '{v.name}' "
                                           "would start at 0 on the PLC; set it in the program")
            object.__setattr__(self.table.structs[key], "fields", tuple(fields))
        # FB types first so labels of FB type resolve in any order
        for info in self.table.pous.values():
            if info.pou.kind == "FUNCTION_BLOCK":
                info.fb_type = T.FbType(info.pou.name, standard=False)
        for f in self.files:
            for block in f.globals:
                self._check_block_kind(block, top_level=True)
                for v in block.variables:
                    t = self._declare(v)
                    if v.key in self.table.globals:
                        self.rep.error(v, f"global label '{v.name}' is declared twice")
                    self.table.globals[v.key] = (v, t)
        for info in self.table.pous.values():
            self._collect_pou(info)

    def _collect_pou(self, info: PouInfo) -> None:
        pou = info.pou
        if pou.return_type is not None:
            info.return_type = self.resolve_type(pou.return_type)
        inputs, outputs, in_outs, publics = [], [], [], []
        passed_in = []  # VAR_INPUT and VAR_IN_OUT in declaration order: a call's positional order
        for block in pou.var_blocks:
            self._check_block_kind(block, top_level=False, pou=pou)
            for v in block.variables:
                t = self._declare(v)
                if v.section == "VAR_EXTERNAL":
                    g = self.table.globals.get(v.key)
                    if g is None:
                        self.rep.error(v, f"VAR_EXTERNAL '{v.name}' has no VAR_GLOBAL declaration in the files checked: "
                                          "add the file that declares it in a VAR_GLOBAL block to the sources")
                    elif g[1] != t:
                        self.rep.error(v, f"VAR_EXTERNAL '{v.name}' is {t} but the global is {g[1]}")
                if v.key in info.labels:
                    self.rep.error(v, f"label '{v.name}' is declared twice in {pou.name}")
                    continue
                if v.key == pou.key:
                    self.rep.error(v, f"label '{v.name}' has the name of its POU; rename it")
                info.labels[v.key] = (v, t)
                if v.section == "VAR_INPUT":
                    inputs.append((v.name, t))
                    passed_in.append((v.name, t))
                elif v.section == "VAR_OUTPUT":
                    outputs.append((v.name, t))
                elif v.section == "VAR_IN_OUT":
                    in_outs.append((v.name, t))
                    passed_in.append((v.name, t))
                elif v.section == "VAR_PUBLIC":
                    publics.append((v.name, t))
                if pou.kind == "FUNCTION" and isinstance(t, T.FbType):
                    self.rep.error(v, f"a FUNCTION cannot hold a function block instance ('{v.name}'); "
                                      "make the POU a FUNCTION_BLOCK")
        if info.fb_type is not None:
            for attr, val in (("inputs", inputs), ("outputs", outputs), ("in_outs", in_outs),
                              ("publics", publics)):
                object.__setattr__(info.fb_type, attr, tuple(val))
        else:
            info.fb_type = None
            info.extra_inputs = inputs  # type: ignore[attr-defined]
        if pou.kind == "FUNCTION":
            info.fn_inputs = passed_in  # type: ignore[attr-defined]
            info.fn_in_outs = {name.upper() for name, _ in in_outs}  # type: ignore[attr-defined]
            info.fn_outputs = outputs  # type: ignore[attr-defined]

    def _check_block_kind(self, block: ast.VarBlock, top_level: bool, pou: ast.Pou | None = None) -> None:
        kw = block.keyword
        if top_level and not kw.startswith("VAR_GLOBAL"):
            self.rep.error(block, f"{kw} outside a POU; only VAR_GLOBAL blocks may stand alone")
        if not top_level and kw.startswith("VAR_GLOBAL"):
            self.rep.error(block, f"{kw} inside {pou.kind} {pou.name}; declare globals outside POUs "
                                  "(or use VAR_EXTERNAL)")
        if pou is not None and pou.kind == "FUNCTION" and kw in ("VAR_OUTPUT_RETAIN", "VAR_RETAIN", "VAR_PUBLIC"):
            self.rep.error(block, f"{kw} is not allowed in a FUNCTION")
        if pou is not None and pou.kind == "PROGRAM" and kw in ("VAR_INPUT", "VAR_OUTPUT", "VAR_IN_OUT"):
            self.rep.warning(block, f"{kw} in a PROGRAM: GX Works program blocks have no interface; "
                                    "use VAR or globals")
        if kw in ("VAR_OUTPUT_RETAIN", "VAR_PUBLIC", "VAR_PUBLIC_RETAIN") and self.target == "gxworks2":
            self.rep.error(block, f"{kw} exists only in GX Works3; use VAR_OUTPUT/VAR"
                                  + ("" if self.editor_fixed else " (or --target gxworks3)"))

    def _check_name(self, node, name: str, what: str) -> None:
        problem = label_name_problem(name, self.families)
        if problem:
            self.rep.error(node, f"{what} name '{name}' {problem}; rename it")

    def _declare(self, v: ast.VarDecl) -> T.Type:
        self._check_name(v, v.name, "label")
        t = self.resolve_type(v.type)
        letters = type_letters_problem(v.name, t, self.target)
        if letters:
            self.rep.warning(v, letters)
        if v.constant and v.init is None:
            self.rep.error(v, f"constant '{v.name}' needs an initial value (':= value')")
        if v.section == "VAR_IN_OUT" and v.init is not None:
            self.rep.error(v, f"VAR_IN_OUT '{v.name}' cannot have an initial value")
        if v.init is not None:
            try:
                self.check_initializer(v.init, t, v)
            except RecursionError:
                self.rep.error(v, "initial value nested too deeply to check; write it shorter")
                return t
            if self.target == "gxworks2" and not v.constant and v.section != "VAR_IN_OUT" \
                    and not _is_zero(v.init):
                ways = ("set it in the program on the first scan or declare it VAR CONSTANT" if self.editor_fixed
                        else "set it in the program on the first scan, declare it VAR CONSTANT, or use --target "
                             "gxworks3")
                self.rep.error(v.init, f"GX Works2 label tables have no initial value column: '{v.name}' "
                                       f"would start at 0 on the PLC; {ways}")
        return t

    def resolve_type(self, ref: ast.TypeRef) -> T.Type:
        if isinstance(ref, ast.StringType):
            if ref.wide and self.target == "gxworks2":
                self.rep.error(ref, library_missing("WSTRING", editor_fixed=self.editor_fixed))
            if ref.length is not None and not 1 <= ref.length <= 255:
                self.rep.error(ref, f"string length {ref.length} is outside 1..255")
            base = T.WSTRING if ref.wide else T.STRING
            return base
        if isinstance(ref, ast.ArrayType):
            dims = []
            for d in ref.dims:
                if d.low > d.high:
                    self.rep.error(d, f"array bounds {d.low}..{d.high}: the lower bound must not exceed the upper")
                for bound in (d.low, d.high):
                    if not structure.INDEX_MIN <= bound <= structure.INDEX_MAX:
                        self.rep.error(d, f"array bound {bound} is outside the index range "
                                          f"{structure.INDEX_MIN}..{structure.INDEX_MAX} GX Works allows")
                        break
                dims.append((d.low, d.high))
            if len(dims) > 3:
                self.rep.error(ref, "GX Works arrays have at most 3 dimensions")
            element = self.resolve_type(ref.element)
            return T.ArrayOf(f"ARRAY[{', '.join(f'{a}..{b}' for a, b in dims)}] OF {element}", element, tuple(dims))
        assert isinstance(ref, ast.NamedType)
        key = ref.key
        elementary = T.ELEMENTARY_BY_TARGET[self.target]
        if key in elementary:
            return elementary[key]
        if key in self.table.structs:
            return self.table.structs[key]
        if key in library.STANDARD_FBS:
            return library.STANDARD_FBS[key]
        info = self.table.pous.get(key)
        if info is not None and info.fb_type is not None:
            return info.fb_type
        if info is not None:
            self.rep.error(ref, f"'{ref.name}' is a {info.pou.kind}, not a type; only function blocks can be instantiated")
            return T.ANY
        if key in T.MISSING_TYPES:
            self.rep.error(ref, library_missing(key, self.target, self.editor_fixed))
            return T.ANY
        if key in _UNMODELLED_FBS:
            self.rep.error(ref, f"unknown type '{ref.name}'; {_UNMODELLED_FBS[key]}")
            return T.ANY
        self.rep.error(ref, f"unknown type '{ref.name}'; "
                       + (_in_library(ref.name, self.plc_shown) or "declare the structure or function block, or use a GX Works type"))
        return T.ANY

    def _fb_type_name(self, ref: ast.TypeRef) -> str | None:
        """The function block a declared type (or its array's element type) names, if any."""
        while isinstance(ref, ast.ArrayType):
            ref = ref.element
        if not isinstance(ref, ast.NamedType):
            return None
        if ref.key in library.STANDARD_FBS and ref.key not in self.table.structs:
            return ref.key
        info = self.table.pous.get(ref.key)
        return info.pou.name if info is not None and info.pou.kind == "FUNCTION_BLOCK" else None

    def check_initializer(self, init, t: T.Type, decl: ast.VarDecl) -> None:
        if isinstance(init, ast.ArrayInit):
            if not isinstance(t, T.ArrayOf):
                self.rep.error(init, f"array initial value for '{decl.name}', which is {t}")
                return
            count = 0
            for item in init.items:
                count += item.repeat if item.repeat is not None else 1
                if item.value is not None:
                    self.check_initializer(item.value, t.element, decl)
            if count > t.size:
                self.rep.error(init, f"{count} initial values for '{decl.name}', which has {t.size} elements")
            return
        if isinstance(init, ast.StructInit):
            if not isinstance(t, T.StructOf):
                self.rep.error(init, f"structure initial value for '{decl.name}', which is {t}")
                return
            for name, value in init.fields:
                ft = t.field(name)
                if ft is None:
                    self.rep.error(init, f"structure {t} has no member '{name}'")
                else:
                    self.check_initializer(value, ft, decl)
            return
        if isinstance(t, (T.FbType, T.ArrayOf, T.StructOf)):
            self.rep.error(init, f"'{decl.name}' is {t}; it cannot take a single initial value")
            return
        vt = self.expr(init)
        if not _is_constant(init):
            self.rep.error(init, "an initial value must be a constant")
        self._assign_compat(init, t, vt, f"initial value of '{decl.name}'")

    # ------------------------------------------------------------- bodies
    def check_bodies(self) -> None:
        for info in self.table.pous.values():
            self.pou = info
            self.loop_depth = 0
            self.pou_calls = []
            self.pou_returns = False  # a RETURN anywhere in the body (stmt); most POUs have none
            complete = True
            for s in info.pou.body:
                try:
                    self.stmt(s)
                except RecursionError:
                    complete = False
                    self.rep.error(s, "statement nested too deeply to check (an expression or block "
                                      "hundreds of levels deep); split it using intermediate labels")
            if complete:  # an unchecked statement may use any label
                self._unused(info)
                self._called_twice(info)
                self._execute_calls(info)
                self._c24_wiring(info)
                self._e71_wiring(info)
                self._completion_unread(info)
        self.pou = None

    def check_structure(self) -> None:
        """Recursion through FB instances, structures and calls; storage sizes."""
        graph = structure.containment_edges(self.table)  # read by both, built once
        findings, recursive = structure.recursive_types(self.table, graph)
        findings += structure.recursive_calls(self.table, self.calls, recursive)
        findings += structure.oversized(self.table, self.target, recursive, graph)
        for f in findings:
            self.rep.error(f.node, f.message)

    def check_files(self) -> None:
        """A file with nothing in it is most likely the wrong file."""
        for f in self.files:
            if not f.pous and not f.types and not f.globals:
                self.rep.diagnostics.append(ast.Diagnostic(
                    f.filename, 1, 1, "warning",
                    "no POU in file (it is empty or holds only comments); nothing to check or export"))

    def _called_twice(self, info: PouInfo) -> None:
        """An FB instance called twice in the same scan: both calls in the POU's own statement
        list, outside any IF, CASE or loop (so that both run, every scan). The instance has one
        memory: the second call sees the first one's edge memories and overwrites its outputs,
        so a command FB started by the second call ignores the first's rising edges, and what
        the program reads from it after the second call is the second use's. (Calls in
        different branches may be one a scan, and are not judged.) A call right after a
        reset call of the same instance (`_resets`: IN, EN, i_bEN or i_bExecute given FALSE,
        `fbTmr(IN := FALSE); fbTmr(IN := bRun, PT := T#1s);`, the IEC idiom that restarts
        a timer or re-arms an execute edge in one scan; an IEC counter's R or LD given TRUE
        and given back by the use) is that one use, and not judged.
        A RETURN between the two calls: inside an IF, CASE or loop (`IF c THEN RETURN;
        END_IF;`) the second call still runs with the first in every scan that does not take
        it, and the warning names it; a RETURN of the statement list itself (or an IF or CASE
        whose every branch, ELSE included, returns) ends what runs, and a call after it is not
        judged."""
        first: dict[str, ast.CallStmt] = {}
        last: dict[str, ast.CallStmt] = {}
        returns: list[ast.Return] = []  # the conditional RETURNs met so far, in order
        seen_at: dict[str, int] = {}  # how many of them came before first[key]
        for s in info.pou.body:
            if self.pou_returns and _always_returns(s):
                break  # nothing after it runs
            if not isinstance(s, ast.CallStmt):
                if self.pou_returns:  # (each statement walked for RETURNs was a third of the check)
                    returns += _returns_in(s)
                continue
            if not isinstance(s.call.callee, ast.Name):
                continue
            target = s.call.resolved
            if getattr(target, "kind", None) != "fb":
                continue
            key = s.call.callee.name.upper()
            previous = last.get(key)
            last[key] = s
            if key not in first or _resets(previous.call, s.call):
                first[key] = s  # a first use, or the use a later second call overwrites
                seen_at[key] = len(returns)
                continue
            earlier = first[key].span
            name = s.call.callee.name
            between = returns[seen_at[key]:]
            when = ("in every scan" if not between else
                    "in the same scan whenever the RETURN" + ("s" if len(between) > 1 else "") + " at "
                    + ", ".join(f"{r.span.line}:{r.span.col}" for r in between)
                    + (" are" if len(between) > 1 else " is") + " not taken")
            self.rep.warning(s, f"FB instance '{name}' is called a second time {when} (first at "
                                f"{earlier.line}:{earlier.col}): an instance has one memory, so this call "
                                f"overwrites the edges and outputs of the first; give the second use its own "
                                f"instance (e.g. {name}2 : {target.name})")

    def _c24_wiring(self, info: PouInfo) -> None:
        """A UITAMR_PortQC24 call whose module (i_uUnit) and channel (i_wChannel) are constants
        drives those: its i_bReadReq / i_bRecvErr given an X device of another channel or slot
        (X3 kept from the example for CH2 of a module at X/Y020), and a write in this POU to a
        receive-setting word (96H/A4H/A5H, 136H/144H/145H) of a module or channel no port here
        drives (U2\\G150, CH1's, for a port on CH2), are the half-moved module that
        docs/import-gxworks2.md section 5 lists the edits for: GX Works takes them, and on the
        PLC the replies are never read or the frames go out in word units."""
        driven: dict[tuple[int, int], ast.Call] = {}
        for node in self.pou_calls:
            target = getattr(node, "resolved", None)
            if getattr(target, "kind", None) != "fb" or target.name.upper() != "UITAMR_PORTQC24":
                continue
            args = {a.key: a for a in node.args if a.name is not None and not a.output}
            unit = _constant_arg(args["I_UUNIT"].value, self.table)[0] if "I_UUNIT" in args else None
            channel = _constant_arg(args["I_WCHANNEL"].value, self.table)[0] if "I_WCHANNEL" in args else None
            if unit is None or channel not in plcfacts.C24_BUFFER:
                continue
            driven.setdefault((unit, channel), node)
            for key, offsets, what in (("I_BREADREQ", plcfacts.C24_READ_REQUEST, "reception data read request"),
                                       ("I_BRECVERR", plcfacts.C24_ABNORMAL, "reception abnormal detection")):
                dev = args[key].value if key in args else None
                if not (isinstance(dev, ast.Device) and dev.kind == "X" and dev.module is None
                        and dev.bit is None and dev.digits is None and dev.index is None):
                    continue
                want = unit * 16 + offsets[channel]
                if dev.number != want:
                    right = f"X{want:X}"
                    self.rep.warning(dev, (
                        f"{args[key].name} := {dev.text or dev.key} is not the {what} of CH{channel} of the "
                        f"QJ71C24N at U{unit:X} (X/Y{unit * 16:03X}, from i_uUnit and i_wChannel): that is "
                        f"{right} (start + {offsets[channel]:X}H; C24 (Basic), docs/instructions.md §9); pass "
                        f"{right}, or the port never reads what the module received"))
        if len(driven) != 1:
            return  # no port with constants here, or several: which one a word was meant for is not known
        (port_unit, port_channel), call = next(iter(driven.items()))
        # modules the POU drives with its own G_OUTPUT / G_INPUT (another device on the other
        # channel): their settings are its own business
        own = {_constant_arg(node.args[1].value, self.table)[0] for node in self.pou_calls
               if getattr(node.resolved, "kind", None) == "instruction"
               and node.name.upper() in ("G_OUTPUT", "G_INPUT") and len(node.args) > 1}
        words = {addr: (channel, name) for channel, names in plcfacts.C24_BUFFER.items()
                 for name, addr in names.items()}
        for node in ast.walk(info.pou.body):
            dev = node.target if isinstance(node, ast.Assign) else None
            if not (isinstance(dev, ast.Device) and dev.module is not None and dev.kind == "G"
                    and dev.number in words and dev.index is None and dev.bit is None):
                continue
            unit = int(dev.module, 16)
            if unit > 0xFF:
                continue  # U3E0\G..: the CPU shared memory of a multiple CPU system, no module
            channel, name = words[dev.number]
            if (unit, channel) in driven or unit in own:
                continue
            right = plcfacts.C24_BUFFER[port_channel][name]
            self.rep.warning(dev, (
                f"{dev.key} is the {_C24_SETTING[name]} ({dev.number:X}H) of CH{channel} of the QJ71C24N at "
                f"U{unit:X}, but the port ({call.callee.name} at {call.span.line}:{call.span.col}) drives "
                f"CH{port_channel} of U{port_unit:X}: write U{port_unit:X}\\G{right} ({right:X}H) instead"))

    def _e71_wiring(self, info: PouInfo) -> None:
        """A UITAMR_PortE71 call whose module (i_sUnit, `'U2'`) is a constant: a status word
        passed that is not that module's open completion / reception status signal (U0\\G20480
        kept when the module moved to U2, or the two words swapped) makes the port wait for a
        connection or data another word shows; GX Works takes it without a word."""
        for node in self.pou_calls:
            target = getattr(node, "resolved", None)
            if getattr(target, "kind", None) != "fb" or target.name.upper() != "UITAMR_PORTE71":
                continue
            args = {a.key: a for a in node.args if a.name is not None and not a.output}
            unit_arg = args.get("I_SUNIT")
            text, shown = _constant_text(unit_arg.value, self.table) if unit_arg is not None else (None, "")
            m = re.fullmatch(r"U([0-9A-F]{1,2})", (text or "").strip(), re.IGNORECASE)
            if m is None:
                continue
            unit = int(m.group(1), 16)
            for key, want, what in (("I_UOPENSIGNAL", plcfacts.E71_OPEN_SIGNAL, "open completion signal"),
                                    ("I_URECVSIGNAL", plcfacts.E71_RECEIVE_SIGNAL,
                                     "fixed buffer reception status signal")):
                dev = args[key].value if key in args else None
                if not (isinstance(dev, ast.Device) and dev.module is not None and dev.kind == "G"
                        and dev.index is None and dev.bit is None):
                    continue
                if (int(dev.module, 16), dev.number) != (unit, want):
                    self.rep.warning(dev, (
                        f"{args[key].name} := {dev.key} is not the {what} ({want:X}H) of the QJ71E71 at "
                        f"U{unit:X} (from {unit_arg.name} := {shown}): pass U{unit:X}\\G{want} (the library's "
                        f"buffer addresses, docs/instructions.md §13)"))

    def _completion_unread(self, info: PouInfo) -> None:
        """The completion bits (done, error) of a dedicated instruction (G_OUTPUT, G_INPUT,
        ZP_OPEN ... ADPRW on FX5: the BITS2 operands) given a label of this POU's own that
        nothing in it reads: the program cannot know when the instruction completed, so a
        send held on by a level starts again at each completion, and an error completion goes
        unseen. A write to the label (`bDone[1] := FALSE`) is no reading of it."""
        operands: list[tuple[ast.Call, ast.Expr, ast.VarDecl]] = []
        for node in self.pou_calls:
            target = getattr(node, "resolved", None)
            if getattr(target, "kind", None) != "instruction" or target.signature is None or target.signature_errors:
                continue  # an operand in error (one BOOL for two bits ...) is told once, as that
            for p, a in zip(target.signature.params, node.args):
                root = a.value.base if isinstance(a.value, ast.Index) else a.value
                decl = getattr(root, "symbol", None)
                if (p.accepts == "BITS2" and isinstance(root, ast.Name) and isinstance(decl, ast.VarDecl)
                        and decl.section in ("VAR", "VAR_TEMP") and info.labels.get(decl.key, (None,))[0] is decl):
                    operands.append((node, a.value, decl))
        if not operands:
            return
        operands.sort(key=lambda found: (found[1].span.line, found[1].span.col))  # warned at the first use
        body = list(ast.walk(info.pou.body))  # walked once for both
        written = {id(n) for s in body if isinstance(s, ast.Assign) for n in ast.walk(s.target)}
        mine = {id(n) for _c, op, _d in operands for n in ast.walk(op)}
        read = {id(n.symbol) for n in body
                if isinstance(n, ast.Name) and id(n) not in written and id(n) not in mine}
        for call, op, decl in operands:
            if id(decl) in read:
                continue
            self.rep.warning(op, (
                f"{call.name}'s completion bits {decl.name} (done, error) are never read in {info.pou.name}: the "
                f"program cannot tell when it has completed or whether it failed; wait for {decl.name}[0] (done) "
                f"before starting the next one, and act on {decl.name}[1] (error)"))
            read.add(id(decl))  # one warning per label

    def _execute_calls(self, info: PouInfo) -> None:
        """FB instances started by a rising edge of i_bExecute (or Execute), the library's
        command FBs and PLCopen-style blocks of one's own, called in a way that cannot give
        them an edge, which GX Works imports without a word:
        - called only under a condition (inside an IF, CASE or loop, on no path of every
          scan): the instance sees its inputs, the falling edge among them, and hands its
          result back only in the scans it runs, so `IF X1 THEN fbStop(i_bExecute := TRUE`
          stops the robot once and a second press sends nothing (no falling edge was seen);
        - given the constant TRUE on every scan: one rising edge, in the first scan, and
          never another."""
        calls: dict[str, list[tuple[ast.CallStmt, int]]] = {}

        def walk(body: list[ast.Stmt], depth: int) -> None:
            for s in body:
                if isinstance(s, ast.CallStmt):
                    if isinstance(s.call.callee, ast.Name) and _execute_input(s.call) is not None:
                        calls.setdefault(s.call.callee.name.upper(), []).append((s, depth))
                elif isinstance(s, ast.If):
                    for b in s.branches:
                        walk(b.body, depth + 1)
                    walk(s.else_body or [], depth + 1)
                elif isinstance(s, ast.Case):
                    for c in s.clauses:
                        walk(c.body, depth + 1)
                    walk(s.else_body or [], depth + 1)
                elif isinstance(s, (ast.For, ast.While, ast.Repeat)):
                    walk(s.body, depth + 1)

        walk(info.pou.body, 0)
        for key, found in calls.items():
            first, depth = found[0]
            name, execute = first.call.callee.name, _execute_input(first.call)
            if not _always_calls(info.pou.body, key, self.pou_returns):
                # a call of the statement list itself that a RETURN before it may skip: the IF
                # written as a guard (`IF NOT X1 THEN RETURN; END_IF; fbStop(...)`)
                before = info.pou.body[:next(i for i, s in enumerate(info.pou.body) if s is first)] if depth == 0 else []
                if any(_always_returns(s) for s in before):
                    continue  # it never runs: not judged
                guard = next((r for s in before for r in _returns_in(s)), None)
                when, where = (("under a condition", "outside the IF") if guard is None else
                               (f"in the scans that do not take the RETURN at {guard.span.line}:{guard.span.col}",
                                "before the RETURN"))
                self.rep.warning(first, (
                    f"FB instance '{name}' is called only {when}: it sees {execute}, its "
                    f"falling edge included, and hands its result back only in the scans it is called, "
                    f"so after one command a new one gets no rising edge (a second press sends nothing); "
                    f"call it on every scan, {where}, and give the condition to {execute} "
                    f"({execute} := <button>) (docs/plc-library.md: call every FB on every scan)"
                    + (PRIORITY_RESULT_LOST.format(fb=first.call.resolved.fb_type.name)
                       if first.call.resolved.fb_type.name.upper() in PRIORITY_FBS else "")))
                continue
            for s, depth in found:
                value = next((a.value for a in s.call.args if not a.output and a.key == execute.upper()), None)
                if depth == 0 and isinstance(value, ast.BoolLiteral) and value.value is True:
                    self.rep.warning(value, (
                        f"{execute} := TRUE on every scan: '{name}' starts on a rising edge of {execute}, "
                        f"and a constant TRUE gives one, in its first scan, and never another; give "
                        f"{execute} the button or condition that starts the command, and TRUE to i_bEN"))

    def _unused(self, info: PouInfo) -> None:
        for decl, _t in info.labels.values():
            if decl.section in ("VAR", "VAR_TEMP") and id(decl) not in self.used:
                self.rep.warning(decl, f"label '{decl.name}' is declared but never used")

    def stmts(self, body: list[ast.Stmt]) -> None:
        for s in body:
            self.stmt(s)

    def stmt(self, s: ast.Stmt) -> None:
        # by the statement's class (the node classes are disjoint): one dictionary look-up
        # where a chain of isinstance tests took up to eleven
        method = _STMT_METHODS.get(type(s))
        if method is not None:
            method(self, s)

    def _assign(self, s: ast.Assign) -> None:
        tt = self.lvalue(s.target)
        vt = self.expr(s.value)
        if tt is not None:
            self._assign_compat(s.value, tt, vt, "assignment")

    def _call_stmt(self, s: ast.CallStmt) -> None:
        self.call(s.call, statement=True)

    def _if(self, s: ast.If) -> None:
        if len(s.branches) > MAX_BRANCHES:
            self.rep.error(s, f"IF with {len(s.branches) - 1} ELSIF branches: the simulator runs at most "
                              f"{MAX_BRANCHES - 1} in one statement; split it into several IF statements")
        for b in s.branches:
            self._bool_cond(b.cond, "IF condition")
            self.stmts(b.body)
        if s.else_body is not None:
            self.stmts(s.else_body)

    def _case(self, s: ast.Case) -> None:
        if len(s.clauses) > MAX_BRANCHES:
            self.rep.error(s, f"CASE with {len(s.clauses)} branches: the simulator runs at most "
                              f"{MAX_BRANCHES} in one statement; split it into several CASE statements")
        st = self.expr(s.selector)
        if not (T.is_group(st, "int", "int-literal", "any16", "any32", "any")):
            self.rep.error(s.selector, f"CASE needs an integer selector (INT or DINT), not {st}"
                                       + self._convert(st, T.INT, "; convert it, e.g. {}(...)"))
        seen: dict[int, ast.Node] = {}
        for clause in s.clauses:
            for label in clause.labels:
                values = [label] if not isinstance(label, ast.CaseRange) else [label.low, label.high]
                for v in values:
                    self.expr(v)
                if isinstance(label, ast.CaseRange):
                    lo, hi = label.low.value, label.high.value
                    if lo > hi:
                        self.rep.error(label, f"CASE range {lo}..{hi} is empty; write the lower bound first")
                    rng = range(lo, hi + 1) if hi - lo < 100_000 else range(lo, lo + 1)
                else:
                    rng = range(label.value, label.value + 1)
                for n in rng:
                    if n in seen:
                        self.rep.error(label, f"CASE value {n} appears twice")
                        break
                    seen[n] = label
            self.stmts(clause.body)
        if s.else_body is not None:
            self.stmts(s.else_body)

    def _for(self, s: ast.For) -> None:
        vt = self.lvalue(s.var)
        if vt is not None and not T.is_group(vt, "int", "any16", "any32"):
            self.rep.error(s.var, f"FOR variable must be INT or DINT, not {vt}")
        for part, what in ((s.start, "start"), (s.end, "end"), (s.step, "step")):
            if part is None:
                continue
            pt = self.expr(part)
            if vt is not None:
                self._assign_compat(part, vt, pt, f"FOR {what} value")
        if isinstance(s.step, ast.IntLiteral) and s.step.value == 0:
            self.rep.error(s.step, "FOR step 0 never ends the loop")
        self.loop_depth += 1
        self.stmts(s.body)
        self.loop_depth -= 1

    def _while(self, s: ast.While) -> None:
        self._bool_cond(s.cond, "WHILE condition")
        self.loop_depth += 1
        self.stmts(s.body)
        self.loop_depth -= 1

    def _repeat(self, s: ast.Repeat) -> None:
        self.loop_depth += 1
        self.stmts(s.body)
        self.loop_depth -= 1
        self._bool_cond(s.until, "UNTIL condition")

    def _exit(self, s: ast.Exit) -> None:
        if self.loop_depth == 0:
            self.rep.error(s, "EXIT outside a FOR, WHILE or REPEAT loop")

    def _return(self, s: ast.Return) -> None:
        self.pou_returns = True

    def _bool_cond(self, e: ast.Expr, what: str) -> None:
        t = self.expr(e)
        if not T.is_bool(t) and t is not T.ANY:
            self.rep.error(e, f"{what} must be BOOL, not {t}; compare it, e.g. x <> 0")

    def _assign_compat(self, node: ast.Expr, target: T.Type, source: T.Type, what: str) -> None:
        if source is T.VOID:
            self.rep.error(node, f"{what}: this call gives no value")
            return
        if target == source:
            return  # assignable, and no literal to range-check (a literal's type is no Elementary)
        problem = T.assignable(target, source, self.target)
        if problem:
            self.rep.error(node, f"{what}: {problem}")
            return
        if (T.is_group(source, "real-literal") and source.value is not None and isinstance(target, T.Elementary)
                and target.name == "REAL" and math.isfinite(source.value) and abs(source.value) > REAL_MAX):
            shown = node.text if isinstance(node, ast.RealLiteral) else f"{source.value:g}"
            self.rep.error(node, f"{what}: {shown} is outside the REAL range (about ±3.4E38); "
                                 "a REAL label cannot hold it")
        if T.is_group(source, "int-literal") and source.value is not None and isinstance(target, T.Elementary):
            if not T.fits(source.value, target):
                lo, hi = T.INT_RANGE[target.name]
                based = isinstance(node, ast.IntLiteral) and (node.radix != 10 or node.prefix == "H")
                if based and target.name in ("INT", "DINT") and 0 <= source.value <= (hi * 2 + 1):
                    self.rep.warning(node, f"{what}: {_lit_text(node)} is above {target} range ({lo}..{hi}); "
                                           f"it is stored as the bit pattern {source.value - (hi + 1) * 2}; "
                                           f"use a WORD/DWORD label for bit patterns")
                else:
                    self.rep.error(node, f"{what}: {source.value} is outside {target} range ({lo}..{hi})")

    # ------------------------------------------------------------- expressions
    def lvalue(self, e: ast.Expr) -> T.Type | None:
        """Type of an assignment target, reporting what cannot be written."""
        # the node classes are disjoint (no subclasses): tested by type, a plain name (most
        # targets) first
        cls = type(e)
        if cls is ast.Name:
            t = self.expr(e)
            root = e
        else:
            if isinstance(e, _LITERALS):
                self.expr(e)
                self.rep.error(e, f"cannot assign to the constant {_lit_text(e)}")
                return None
            if isinstance(e, _EXPRESSIONS):
                self.expr(e)
                self.rep.error(e, "cannot assign to an expression; the left of ':=' must be a label or device")
                return None
            t = self.expr(e)
            root = e
            while isinstance(root, (ast.Index, ast.Member, ast.BitAccess)):
                root = root.base
        symbol = root.symbol if type(root) is ast.Name else None
        if isinstance(symbol, ast.VarDecl):
            decl = symbol
            if decl.constant:
                self.rep.error(e, f"'{decl.name}' is a constant (VAR CONSTANT); it cannot be assigned")
            elif decl.section == "VAR_INPUT" and e is root and self.pou is not None and self.pou.pou.kind == "FUNCTION_BLOCK":
                self.rep.warning(e, f"'{decl.name}' is an input; writing it inside the FB hides the caller's value")
        elif isinstance(symbol, ast.Pou):
            pou = symbol
            if self.pou is None or pou is not self.pou.pou:
                self.rep.error(e, f"cannot assign to the POU name '{pou.name}' outside it")
        if cls is ast.Member and isinstance(e.base.type, T.FbType):
            kind = e.base.type.param(e.member)
            if kind and kind[0] == "output":
                self.rep.error(e, f"'{e.member}' is an output of {e.base.type}; it cannot be assigned from outside")
        if isinstance(t, T.FbType):
            self.rep.error(e, f"'{_text(e)}' is a function block instance; it cannot be assigned "
                              "(assign its inputs in a call instead)")
        if cls is ast.Device and e.kind in ("X",) and e.bit is None:
            self.rep.warning(e, f"writing input {e.text}: X devices are refreshed from the inputs each scan")
        return t

    def expr(self, e) -> T.Type:
        t = self._expr(e)
        try:
            e.type = t
        except AttributeError:
            pass
        return t

    def _expr(self, e) -> T.Type:
        # by the node's class (disjoint): one dictionary look-up for the chain of tests
        method = _EXPR_METHODS.get(type(e))
        return method(self, e) if method is not None else T.ANY

    def _int_literal(self, e: ast.IntLiteral) -> T.Type:
        return T.int_literal(e.value)

    def _real_literal(self, e: ast.RealLiteral) -> T.Type:
        if not math.isfinite(e.value):
            self.rep.error(e, f"{e.text} is outside the range of every real type (LREAL reaches about "
                              "±1.8E308)")
        return T.real_literal(e.value)

    def _bool_literal(self, e: ast.BoolLiteral) -> T.Type:
        return T.BOOL

    def _time_literal(self, e: ast.TimeLiteral) -> T.Type:
        if not -2**31 <= e.ms <= 2**31 - 1:
            self.rep.error(e, f"{e.text} is outside the TIME range (32-bit milliseconds)")
        return T.TIME

    def _string_literal(self, e: ast.StringLiteral) -> T.Type:
        if e.wide and self.target == "gxworks2":
            self.rep.error(e, "GX Works2 has no WSTRING; write the string in single quotes")
        return T.WSTRING if e.wide else T.STRING

    def _bit_access(self, e: ast.BitAccess) -> T.Type:
        bt = self.expr(e.base)
        w = T.width(bt)
        if T.is_group(bt, "any"):
            return T.ANY
        if w < 16 or T.is_group(bt, "real", "time", "string"):
            self.rep.error(e, f"'.{e.bit}' needs a WORD, INT, DWORD or DINT label, not {bt}")
        elif e.bit >= w:
            self.rep.error(e, f"bit {e.bit} does not exist in {bt} (bits 0..{w - 1})")
        return T.BOOL

    def _unary(self, e: ast.UnaryOp) -> T.Type:
        ot = self.expr(e.operand)
        if e.op == "NOT":
            if not T.is_any_bit(ot) and ot is not T.ANY:
                self.rep.error(e, f"NOT needs BOOL, WORD or DWORD, not {ot}")
            return ot
        if not T.is_any_num(ot) or T.is_group(ot, "bits"):
            if ot is not T.ANY:
                self.rep.error(e, f"'-' needs INT, DINT or REAL, not {ot}")
        if T.is_group(ot, "int-literal"):
            return T.int_literal(-ot.value if ot.value is not None else None)
        if T.is_group(ot, "real-literal"):
            return T.real_literal(-ot.value if ot.value is not None else None)
        return ot

    def _call_expr(self, e: ast.Call) -> T.Type:
        return self.call(e, statement=False)

    def _initializer_expr(self, e) -> T.Type:
        self.rep.error(e, "an array or structure value is only allowed as an initial value")
        return T.ANY

    def _name(self, e: ast.Name) -> T.Type:
        found = self.table.lookup(self.pou, e.name)
        if found is not None:
            decl, t = found
            e.symbol = decl
            self.used.add(id(decl))
            return t
        if self.pou is not None and e.key == self.pou.pou.key and self.pou.pou.kind == "FUNCTION":
            e.symbol = self.pou.pou
            return self.pou.return_type or T.ANY
        info = self.table.pous.get(e.key)
        if info is not None:
            e.symbol = info.pou
            return T.PouRef(info.pou.name)
        guess = self._label_hint(e.name)  # a label spelt nearly so first: `bEd` is bEnd, not the device B0ED
        if guess:
            self.rep.error(e, f"undefined label '{e.name}'{guess}")
        elif re.fullmatch(r"E[0-9]+", e.name, re.IGNORECASE):
            self.rep.error(e, f"undefined label '{e.name}'; E constants are not read here: write the REAL as 1.5 or 1.0E3")
        elif re.fullmatch(r"U[0-9A-F]{1,2}", e.name, re.IGNORECASE):
            # G.OUTPUT U2 ... in ladder (docs/st-dialect.md: the ST operand forms of Un)
            n = e.name[1:].upper()
            self.rep.error(e, f"undefined label '{e.name}'; ST does not write a module as {e.name} (ladder's Un): "
                              f"G_OUTPUT and G_INPUT take its start I/O number without the last digit (16#{n} for "
                              f"the module at X/Y{int(n, 16) * 16:03X}), ZP_OPEN and the other ZP_ instructions the string '{e.name}'; "
                              f"{e.name}\\G150 is its buffer memory")
        elif (m := _HEX_DEVICE_WITHOUT_DIGIT.fullmatch(e.name)) is not None:
            # the QJ71C24N manual's "XA", "XB": the device reader wants the digit first (as for H0FF)
            dev = f"{m[1].upper()}0{m[2].upper()}"
            self.rep.error(e, f"undefined label '{e.name}'; for the device write {dev}: a hexadecimal device "
                              f"number starts with a digit ({dev}, as 16#0{m[2].upper()}; docs/st-dialect.md)")
        elif re.fullmatch(r"H[0-9A-F]+", e.name, re.IGNORECASE):
            self.rep.error(e, f"undefined label '{e.name}'; for the hex constant write 16#{e.name[1:]} (or H0{e.name[1:]})")
        else:
            self.rep.error(e, f"undefined label '{e.name}'; declare it in a VAR block")
        return T.ANY

    def _label_hint(self, name: str) -> str:
        """'; did you mean 'fbRun'?' when a label this POU sees (its own, a global) or a POU
        is spelt nearly as `name`, else "" (the error path only)."""
        seen = [decl.name for decl, _t in (self.pou.labels.values() if self.pou is not None else ())]
        seen += [decl.name for decl, _t in self.table.globals.values()]
        seen += [info.pou.name for info in self.table.pous.values()]
        return _did_you_mean(name, seen)

    def _call_hint(self, name: str) -> str:
        """'; did you mean 'MOVE'?' for an unknown call spelt nearly as something that can
        be called here: an FB instance this POU sees, a FUNCTION, a standard function or an
        instruction of the editor (never a plain label: 'bMove' cannot be called), else ""
        (the error path only)."""
        labels = list(self.pou.labels.values()) if self.pou is not None else []
        seen = [decl.name for decl, t in labels + list(self.table.globals.values()) if isinstance(t, T.FbType)]
        seen += [info.pou.name for info in self.table.pous.values() if info.pou.kind == "FUNCTION"]
        seen += [n for n, sig in library.STANDARD_FUNCTIONS.items() if self.target in sig.targets]
        seen += [n for n in library.INSTRUCTIONS if library.instruction(n, self.target) is not None]
        return _did_you_mean(name, seen)

    def _device(self, e: ast.Device) -> T.Type:
        if e.bit is not None:
            return T.BOOL
        if e.digits is not None:
            return T.ANY16 if e.digits <= 4 else T.ANY32
        if e.kind in ("T", "C", "ST"):
            return T.ANY
        if e.is_bit:
            return T.BOOL
        return T.ANY16

    def _index(self, e: ast.Index) -> T.Type:
        bt = self.expr(e.base)
        for i in e.indices:
            it = self.expr(i)
            if not T.is_group(it, "int", "int-literal", "any16", "any32", "any"):
                self.rep.error(i, f"array index must be INT or DINT, not {it}")
        if T.is_group(bt, "any"):
            return T.ANY
        if not isinstance(bt, T.ArrayOf):
            self.rep.error(e, f"'[...]' needs an array; this is {bt}")
            return T.ANY
        if len(e.indices) != len(bt.dims):
            self.rep.error(e, f"{bt} needs {len(bt.dims)} index(es), {len(e.indices)} given")
            return bt.element
        for i, (lo, hi) in zip(e.indices, bt.dims):
            v = _const_int(i)
            if v is not None and not lo <= v <= hi:
                self.rep.error(i, f"index {v} is outside the array bounds {lo}..{hi}")
        return bt.element

    def _member(self, e: ast.Member) -> T.Type:
        bt = self.expr(e.base)
        if T.is_group(bt, "any"):
            return T.ANY
        if isinstance(bt, T.StructOf):
            ft = bt.field(e.member)
            if ft is None:
                self.rep.error(e, f"structure {bt} has no member '{e.member}'"
                                  + _did_you_mean(e.member, [n for n, _t in bt.fields]))
                return T.ANY
            return ft
        if isinstance(bt, T.FbType):
            p = bt.param(e.member)
            if p is None:
                self.rep.error(e, f"{bt} has no input or output '{e.member}'"
                                  + (self._internal_label(bt, e.member)
                                     or _did_you_mean(e.member, [n for group in (bt.inputs, bt.outputs)
                                                                 for n, _t in group])))
                return T.ANY
            if p[0] == "in_out":
                self.rep.error(e, f"'{e.member}' is a VAR_IN_OUT of {bt}; it cannot be read from outside")
            return p[1]
        if T.width(bt) >= 16 and re.fullmatch(r"[0-9A-Fa-f]", e.member):
            self.rep.error(e, f"bit '.{e.member}' of a label: write the bit number in decimal, e.g. .{int(e.member, 16)}")
            return T.BOOL
        self.rep.error(e, f"'.{e.member}' needs a structure or FB instance; this is {bt}")
        return T.ANY

    def _library_range(self, a: ast.Arg, fb: T.FbType) -> None:
        """A constant outside the range a UITAMR library FB checks its input against
        (library.LIBRARY_INPUT_RANGES): the FB would end with its error code at run time."""
        limits = library.LIBRARY_INPUT_RANGES.get((fb.name.upper(), a.key))
        if limits is None:
            return
        value, shown = _constant_arg(a.value, self.table)
        if value is None or limits[0] <= value <= limits[1]:
            return
        lo, hi, code = limits
        self.rep.warning(a.value, f"{a.name} := {shown or value} is outside {lo}..{hi}, the range {fb.name} accepts: "
                                  f"it ends with o_bErr and o_uErrId 16#{code:04X} instead of running "
                                  f"(see its header); give a value in {lo}..{hi}")

    def _internal_label(self, fb: T.FbType, member: str) -> str:
        """When `member` is a label of `fb`'s own VAR (`fbRun.fbCmd`: the UITAMR_Command instance
        inside UITAMR_RunPoint), the words that say so and what to read instead; else "".
        GX Works does not let a program read an FB's internal labels either (only its inputs
        and outputs); a scenario's `watch` and conditions may, as a monitor looks inside."""
        info = None if fb.standard else self.table.pous.get(fb.name.upper())
        label = info.labels.get(member.upper()) if info is not None else None
        if label is None or label[0].section not in ("VAR", "VAR_TEMP"):
            return ""
        v, t = label
        what = f"an internal instance of {t.name}" if isinstance(t, T.FbType) else "an internal label"
        outputs = ", ".join(n for n, _ in fb.outputs)
        instead = f"read its outputs instead ({outputs})" if outputs else "it has no outputs to read"
        if isinstance(t, T.FbType):
            instead += f", or call {t.name} in the program itself where it must act on {t.name}'s outputs"
        return (f": '{v.name}' is {what} (VAR) of {fb.name}, and a program reads only an FB's inputs "
                f"and outputs, as GX Works does; {instead}. A scenario's watch and conditions may read "
                "internal labels (the verifier looks inside the instance, as a monitor does)")

    def _convert(self, source: T.Type, target: T.Type, advice: str) -> str:
        """`advice` with the editor's conversion from `source` to `target` in its {}, or ""
        where the editor has no such function (so no message names one it would refuse)."""
        conv = library.conversion(T.concrete(source), target, self.target)
        return advice.format(conv) if conv else ""

    def _binary(self, e: ast.BinaryOp) -> T.Type:
        lt = self.expr(e.left)
        rt = self.expr(e.right)
        op = e.op
        if lt is T.ANY or rt is T.ANY:
            return T.BOOL if op in ("=", "<>", "<", ">", "<=", ">=") else (rt if lt is T.ANY else lt)
        if op == "**":
            base_ok = T.is_group(lt, "real", "real-literal")
            if not base_ok:
                self.rep.error(e.left, f"'**' needs a REAL base, not {lt}"
                                       + self._convert(lt, T.REAL, "; convert it, e.g. {}(...)"))
            if not T.is_any_num(rt):
                self.rep.error(e.right, f"'**' needs a numeric exponent, not {rt}")
            if not base_ok:  # reported once: no second error where the result is used
                return T.ANY
            return T.REAL if T.is_group(lt, "real-literal") else lt
        common = T.unify(lt, rt)
        if common is None:
            self.rep.error(e, f"'{op}' mixes {lt} and {rt}"
                              + (self._convert(rt, lt, "; convert one side (e.g. {}(...))")
                                 or self._convert(lt, rt, "; convert one side (e.g. {}(...))")))
            return T.BOOL if op in ("=", "<>", "<", ">", "<=", ">=") else lt
        if op in ("+", "-", "*", "/"):
            if not T.is_any_num(common) or T.is_group(common, "bits"):
                self.rep.error(e, f"'{op}' needs INT, DINT or REAL operands, not {common}; "
                                  + _no_arithmetic(common, self.target))
            if op == "/" and _const_int(e.right) == 0:
                self.rep.error(e.right, "division by zero")
            return self._fold(e, common)
        if op == "MOD":
            if not T.is_any_int(common) or T.is_group(common, "bits"):
                self.rep.error(e, f"MOD needs INT or DINT operands, not {common}")
            if _const_int(e.right) == 0:
                self.rep.error(e.right, "MOD by zero")
            return self._fold(e, common)
        if op in ("AND", "OR", "XOR"):
            if not T.is_any_bit(common):
                self.rep.error(e, f"{op} needs BOOL, WORD or DWORD operands, not {common}"
                                  + self._convert(common, T.WORD, "; for bit operations convert with {}"))
            return self._fold(e, common)
        # comparisons
        if isinstance(common, (T.ArrayOf, T.StructOf, T.FbType)):
            self.rep.error(e, f"'{op}' cannot compare {common} values")
        if op not in ("=", "<>") and common == T.BOOL:
            self.rep.error(e, f"'{op}' does not order BOOL values")
        return T.BOOL

    def _fold(self, e: ast.BinaryOp, common: T.Type) -> T.Type:
        if not T.is_group(common, "int-literal"):
            return common
        a, b = _const_int(e.left), _const_int(e.right)
        if a is None or b is None:
            return T.int_literal(None)
        try:
            value = {"+": a + b, "-": a - b, "*": a * b,
                     "/": int(a / b) if b else None, "MOD": a % b if b else None,
                     "AND": a & b, "OR": a | b, "XOR": a ^ b}[e.op]
        except KeyError:
            value = None
        return T.int_literal(value)

    # ------------------------------------------------------------- calls
    def call(self, c: ast.Call, statement: bool) -> T.Type:
        # every call of the body, in the order checked: the wiring and completion-bit checks
        # read these rather than walk each POU's tree again (three walks added a third to
        # the check of the library)
        self.pou_calls.append(c)
        name = c.key
        dotted = _ladder_spelling(c.callee, self.table, self.pou)
        if dotted is not None:  # SP.SOCOPEN(...): the ladder name of SP_SOCOPEN, not a member of a label 'SP'
            self.rep.error(c.callee, f"{dotted[0]} is how ladder writes the instruction; ST writes it with an "
                                     f"underscore: {dotted[1]}(...)")
            self._args_only(c)
            return T.ANY
        if not isinstance(c.callee, ast.Name):
            ct = self.expr(c.callee)
            if isinstance(ct, T.FbType):
                return self._fb_call(c, ct, statement)
            self.rep.error(c.callee, "only labels, functions and instructions can be called")
            self._args_only(c)
            return T.ANY
        found = self.table.lookup(self.pou, c.name)
        if found is not None:
            decl, t = found
            c.callee.symbol = decl
            c.callee.type = t
            self.used.add(id(decl))
            if isinstance(t, T.FbType):
                return self._fb_call(c, t, statement)
            if t is not T.ANY:  # ANY: its type was already reported unknown
                self.rep.error(c.callee, f"'{c.name}' is a label of type {t}, not a function block instance; it cannot be called")
            self._args_only(c)
            return T.ANY
        info = self.table.pous.get(name)
        if info is not None:
            if info.pou.kind == "FUNCTION":
                return self._user_function(c, info, statement)
            self.rep.error(c.callee, f"'{c.name}' is a {info.pou.kind}; declare an instance (inst : {c.name};) and call the instance")
            self._args_only(c)
            return T.ANY
        if name in library.STANDARD_FBS:
            self.rep.error(c.callee, f"'{c.name}' is a standard function block; declare an instance (tmr : {name};) and call it")
            self._args_only(c)
            return T.ANY
        sig = library.STANDARD_FUNCTIONS.get(name)
        if sig is not None:
            if self.target not in sig.targets:
                self.rep.error(c.callee, f"{name} does not exist in {_target_name(self.target)}")
            return self._signature_call(c, sig, statement, "standard_function")
        sig = library.instruction(name, self.target)
        if sig is not None:
            if self.target not in sig.targets:
                self.rep.error(c.callee, f"instruction {name} is not available for {_target_name(self.target)}"
                                         + _other_editor_hint(name, self.target, len(c.args)))
                wrong_editor = self.rep.diagnostics[-1]
                result = self._signature_call(c, sig, statement, "instruction")
                # with --platform, 'SP_SOCOPEN does not exist on the q' says it better: one error
                c.resolved.signature_errors.insert(0, wrong_editor)
                return result
            return self._signature_call(c, sig, statement, "instruction")
        if name in library.INSTRUCTIONS or name == "ADPRW":
            self.rep.error(c.callee, f"instruction {name} is not available for {_target_name(self.target)}"
                                     + _other_editor_hint(name, self.target, len(c.args)))
            self._args_only(c)
            return T.ANY
        hint = _in_library(c.name, self.plc_shown)
        self.rep.error(c.callee, f"unknown function or instruction '{c.name}'"
                                 + (f"; {hint}" if hint else self._call_hint(c.name)))
        self._args_only(c)
        return T.ANY

    def _args_only(self, c: ast.Call) -> None:
        for a in c.args:
            self.expr(a.value)

    def _fb_call(self, c: ast.Call, fb: T.FbType, statement: bool) -> T.Type:
        c.resolved = T.CallTarget("fb", fb.name, fb_type=fb,
                                  pou=self.table.pous[fb.name.upper()].pou if not fb.standard and fb.name.upper() in self.table.pous else None)
        if c.resolved.pou is not None and self.pou is not None:
            self.calls.append((self.pou.pou.key, c.resolved.pou.key, c))
        if not statement:
            self.rep.error(c, f"a function block instance call is a statement: write '{c.name}(...);' on its own and read the outputs as {c.name}.Q")
        seen = set()
        positional_reported = False
        for a in c.args:
            if a.name is None:
                self.expr(a.value)
                if not positional_reported:
                    self.rep.error(a, "function block calls take named arguments: write 'INPUT := value' (or 'OUTPUT => label')")
                    positional_reported = True
                continue
            if a.key in seen:
                self.rep.error(a, f"argument '{a.name}' is given twice")
            seen.add(a.key)
            p = fb.param(a.name)
            if p is None:
                self.expr(a.value)
                self.rep.error(a, f"{fb} has no parameter '{a.name}'" + _parameter_hint(fb, a.name))
                continue
            kind, pt = p
            if a.output:
                if kind != "output":
                    self.expr(a.value)
                    self.rep.error(a, f"'{a.name}' is not an output of {fb}; write '{a.name} := value' to pass it in")
                    continue
                tt = self.lvalue(a.value)
                if tt is not None:
                    self._assign_compat(a.value, tt, pt, f"output {a.name}")
            else:
                if kind == "output":
                    self.expr(a.value)
                    self.rep.error(a, f"'{a.name}' is an output of {fb}; bind it with '{a.name} => label'")
                    continue
                if kind == "in_out":
                    vt = self.lvalue(a.value)
                else:
                    vt = self.expr(a.value)
                if vt is not None:
                    self._assign_compat(a.value, pt, vt, f"input {a.name}")
                if kind == "input" and not fb.standard:
                    self._library_range(a, fb)
        for n, _t in fb.in_outs:
            if n.upper() not in seen:
                self.rep.error(c, f"VAR_IN_OUT '{n}' of {fb} must be connected in every call")
        return T.VOID if statement else T.ANY

    def _user_function(self, c: ast.Call, info: PouInfo, statement: bool) -> T.Type:
        c.resolved = T.CallTarget("function", info.pou.name, pou=info.pou)
        c.callee.symbol = info.pou
        if self.pou is not None:
            self.calls.append((self.pou.pou.key, info.pou.key, c))
        params = getattr(info, "fn_inputs", [])
        outputs = getattr(info, "fn_outputs", [])
        positional = [a for a in c.args if a.name is None]
        named = [a for a in c.args if a.name is not None]
        if positional and named:
            self.rep.error(c, "mix of positional and named arguments; use one style")
            self._args_only(c)
        elif positional:
            if len(positional) != len(params):
                missing = [pn for pn, _ in params[len(positional):]]
                self.rep.error(c, f"{info.pou.name} takes {len(params)} argument(s) ({', '.join(pn for pn, _ in params)}), "
                                  f"{len(positional)} given"
                                  + (f": {_inputs(missing)} missing; {NEEDS_EVERY_INPUT}" if missing else ""))
            for a, (pn, pt) in zip(positional, params):
                self._function_argument(a, pn, pt, info)
            for a in positional[len(params):]:
                self.expr(a.value)
        else:
            given = set()
            for a in named:
                key = a.key
                match = next(((pn, pt) for pn, pt in params if pn.upper() == key), None)
                out = next(((pn, pt) for pn, pt in outputs if pn.upper() == key), None)
                if key in given:
                    self.rep.error(a, f"argument '{a.name}' is given twice")
                given.add(key)
                if a.output and out is not None:
                    tt = self.lvalue(a.value)
                    if tt is not None:
                        self._assign_compat(a.value, tt, out[1], f"output {out[0]}")
                elif match is not None and not a.output:
                    self._function_argument(a, match[0], match[1], info)
                else:
                    self.expr(a.value)
                    self.rep.error(a, f"{info.pou.name} has no {'output' if a.output else 'input'} '{a.name}'")
            missing = [pn for pn, _ in params if pn.upper() not in given]
            if missing:
                self.rep.error(c, called_without(info.pou.name, missing) + ": add "
                                  + ", ".join(f"{pn} := ..." for pn in missing))
        if statement:
            self.rep.warning(c, f"the result of function {info.pou.name} is discarded")
        return info.return_type or T.ANY

    def _function_argument(self, a, name: str, param_type: T.Type, info: PouInfo) -> None:
        """One input of a user FUNCTION; a VAR_IN_OUT takes a label (the function writes it)."""
        if name.upper() in getattr(info, "fn_in_outs", ()):
            if isinstance(a.value, _NOT_LABELS):
                self.expr(a.value)
                what = "a constant" if _is_literal(a.value) else "an expression"
                self.rep.error(a.value, f"VAR_IN_OUT '{name}' of {info.pou.name} needs a label or device to work on, "
                                        f"not {what}")
                return
            vt = self.lvalue(a.value)
        else:
            vt = self.expr(a.value)
        self._assign_compat(a.value, param_type, vt, f"argument {name} of {info.pou.name}")

    def _signature_error(self, c: ast.Call, node, message: str) -> None:
        """An error about call `c` against its signature, recorded on `c.resolved` too."""
        self.rep.error(node, message)
        c.resolved.signature_errors.append(self.rep.diagnostics[-1])

    def _signature_call(self, c: ast.Call, sig: T.Signature, statement: bool, kind: str) -> T.Type:
        c.resolved = T.CallTarget(kind, sig.name, signature=sig)
        if any(a.name is not None for a in c.args):
            bad = next(a for a in c.args if a.name is not None)
            self._signature_error(c, bad, f"{sig.name} takes positional arguments in manual order: "
                                f"{sig.name}({', '.join(p.name for p in sig.params)})")
        n, np = len(c.args), len(sig.params)
        if n < np or (n > np and not sig.variadic):
            hint = _other_editor_hint(sig.name, self.target, n) if kind == "instruction" else ""
            self._signature_error(c, c, f"{sig.name} takes {np}{' or more' if sig.variadic else ''} argument(s) "
                              f"({', '.join(p.name for p in sig.params)}), {n} given" + hint)
        generic: T.Type | None = None
        first_type: T.Type | None = None
        for i, a in enumerate(c.args):
            p = sig.params[min(i, np - 1)] if i < np or sig.variadic else None
            if p is None:
                self.expr(a.value)
                continue
            if p.direction in ("out", "inout") and _is_literal(a.value):
                self.expr(a.value)
                self._signature_error(c, a.value, f"{sig.name} operand {p.name}: needs a label or device, not a constant")
                continue
            if p.direction in ("out", "inout"):
                at = self.lvalue(a.value)
            else:
                at = self.expr(a.value)
            if at is None:
                continue
            if i == 0:
                first_type = at
            problem = self._accepts(p, at, a.value)
            if problem:
                self._signature_error(c, a.value, f"{sig.name} operand {p.name}: {problem}")
            elif p.accepts.startswith("ANY_") and p.accepts != "ANY_INT" or p.accepts == "ANY" and sig.result == "SAME":
                if sig.name in ("SHL", "SHR", "ROL", "ROR") and i > 0:
                    continue
                if sig.name == "MUX" and i == 0 or sig.name == "SEL" and i == 0:
                    continue
                if generic is None:
                    generic = at
                else:
                    g = T.unify(generic, at)
                    if g is None:
                        self._signature_error(c, a.value, f"{sig.name}: {at} does not match the other operands ({generic}); convert it")
                    else:
                        generic = g
            elif p.accepts == "ANY_INT" and sig.result == "SAME":
                g = at if generic is None else T.unify(generic, at)
                if g is None:
                    self._signature_error(c, a.value, f"{sig.name}: {at} does not match the other operands ({generic}); convert it")
                else:
                    generic = g
        c.resolved.generic = generic
        if sig.result is None:  # instruction: value is ENO
            return T.BOOL
        if sig.result == "SAME":
            result = generic or T.ANY
        elif sig.result == "FIRST":
            result = first_type or T.ANY
        else:
            result = sig.result
        if statement:
            self.rep.warning(c, f"the result of {sig.name} is discarded")
        return result

    @staticmethod
    def _two_bits(t: T.Type, node: ast.Expr) -> str | None:
        """A completion-bits operand (ADPRW's d2, the SP_/ZP_ and G_ instructions' d) is the
        head of two bits, done and error: a single BOOL label, an array of one, or the last
        element of an array leaves the error bit nowhere (the simulator stopped the run
        there, on the first error completion only, after check had passed the program)."""
        need = "needs 2 bits (done, error) from its head: "
        if isinstance(t, T.ArrayOf):
            return None if t.size >= 2 else f"{need}{_text(node)} is an array of {t.size} BOOL"
        if isinstance(node, (ast.Name, ast.Member)):
            return (f"{need}{_text(node)} is a single BOOL label; declare it ARRAY[0..1] OF BOOL, "
                    "or use a bit device")
        if isinstance(node, ast.Index) and len(node.indices) == 1 and isinstance(node.indices[0], ast.IntLiteral):
            base = getattr(node.base, "type", None)
            if isinstance(base, T.ArrayOf) and len(base.dims) == 1 and node.indices[0].value == base.dims[0][1]:
                lo, hi = base.dims[0]
                return f"{need}{_text(node)} is the last element of {_text(node.base)} (ARRAY[{lo}..{hi}])"
        return None

    def _accepts(self, p: T.Param, t: T.Type, node: ast.Expr) -> str | None:
        a = p.accepts
        if t is T.ANY:
            return None
        if p.direction in ("out", "inout") and isinstance(node, ast.Device) and node.kind in ("K",):
            return "an output operand must be a label or device"
        if a == "ANY":
            return None
        if a == "BOOL":
            return None if T.is_bool(t) else f"needs BOOL, not {t}"
        if a in ("ANY16", "ANY32"):
            w = 16 if a == "ANY16" else 32
            if T.is_group(t, "int-literal"):
                if p.direction != "in":
                    return "needs a label or device, not a constant"
                return None
            if T.is_group(t, "any"):
                return None
            if isinstance(t, T.ArrayOf):
                return f"needs one {w}-bit value; pass an element such as x[0]"
            if T.width(t) == w and not T.is_group(t, "real", "time", "string"):
                return None
            if isinstance(node, ast.Device) and w == 32 and T.width(t) == 16:
                return None  # D0 as a 32-bit operand means D0-D1
            return f"needs a {w}-bit integer or bit string (INT/WORD{'/DINT/DWORD' if w == 32 else ''}), not {t}"
        if a == "BLOCK16":
            if isinstance(t, T.ArrayOf):
                t = t.element
            if T.width(t) == 16 and not T.is_group(t, "real"):
                return None
            return f"needs the head of a block of words (an INT/WORD array or its element, or a word device), not {t}"
        if a in ("BITS", "BITS2"):
            whole = t
            if isinstance(t, T.ArrayOf):
                t = t.element
            if not T.is_bool(t):
                return f"needs a bit (BOOL label, bit device or BOOL array), not {t}"
            return self._two_bits(whole, node) if a == "BITS2" else None
        if a == "ANY_NUM":
            return None if T.is_any_num(t) and not T.is_group(t, "bits") else f"needs INT, DINT or REAL, not {t}"
        if a == "ANY_INT":
            return None if T.is_any_int(t) else f"needs INT or DINT, not {t}"
        if a == "ANY_REAL":
            return None if T.is_group(t, "real", "real-literal") else \
                f"needs REAL, not {t}" + self._convert(t, T.REAL, "; convert it with {}")
        if a == "ANY_BIT":
            return None if T.is_any_bit(t) else \
                f"needs BOOL, WORD or DWORD, not {t}" + self._convert(t, T.WORD, "; convert it with {}")
        if a == "ANY_SIMPLE":
            return None if isinstance(t, (T.Elementary, T.Generic)) else f"needs a simple value, not {t}"
        # an elementary type name
        expected = T.ELEMENTARY_BY_TARGET["gxworks3"].get(a)
        if expected is None:
            return None
        return T.assignable(expected, t, self.target)



#: Checker.stmt and Checker._expr by the node's class (the syntax tree's node classes
#: are disjoint: no class derives from another that is checked)
_STMT_METHODS = {ast.Assign: Checker._assign, ast.CallStmt: Checker._call_stmt, ast.If: Checker._if,
                 ast.Case: Checker._case, ast.For: Checker._for, ast.While: Checker._while,
                 ast.Repeat: Checker._repeat, ast.Exit: Checker._exit, ast.Return: Checker._return}
_EXPR_METHODS = {ast.Name: Checker._name, ast.IntLiteral: Checker._int_literal,
                 ast.RealLiteral: Checker._real_literal, ast.BoolLiteral: Checker._bool_literal,
                 ast.TimeLiteral: Checker._time_literal, ast.StringLiteral: Checker._string_literal,
                 ast.Device: Checker._device, ast.Index: Checker._index, ast.Member: Checker._member,
                 ast.BitAccess: Checker._bit_access, ast.UnaryOp: Checker._unary, ast.BinaryOp: Checker._binary,
                 ast.Call: Checker._call_expr, ast.ArrayInit: Checker._initializer_expr,
                 ast.StructInit: Checker._initializer_expr}

# ----------------------------------------------------------------------------- helpers
#: Why a FUNCTION call that leaves out an input is an error. IEC 61131-3 lets a formal
#: call leave inputs at their initial values; that GX Works does not is an ASSUMPTION
#: (docs/st-dialect.md §8).
NEEDS_EVERY_INPUT = "GX Works needs every input of a function"


def _inputs(names: list[str]) -> str:
    return f"input{'s' if len(names) > 1 else ''} {', '.join(names)}"


def called_without(function: str, names: list[str]) -> str:
    """The error for a call of FUNCTION `function` that leaves out the inputs `names`
    (the checker's, and the simulator's when it is handed such a call)."""
    return f"{function} is called without {_inputs(names)}; {NEEDS_EVERY_INPUT}"


def library_missing(name: str, target: str = "gxworks2", editor_fixed: bool = False) -> str:
    """Why type `name` is refused and what to use; with `editor_fixed` (a --platform whose
    CPU only `target` programs) without the way out of the other editor."""
    hint = T.MISSING_TYPES.get(name, "")
    if editor_fixed:
        hint = hint.replace(" (or --target gxworks3)", "")
    return f"type {name} does not exist in {_target_name(target)}: " + hint


def _in_library(name: str, plc_shown: Path | None = None) -> str | None:
    """What to do when an undeclared name is a POU of the bundled UITAMR library: the file
    to add, under `plc_shown` (the bundled plc/ folder as the sources name it) if given."""
    path = library_file(name)
    if path is None:
        return None
    if plc_shown is not None and (plc_shown / path.relative_to(PLC_DIR)).is_file():
        path = plc_shown / path.relative_to(PLC_DIR)
    return f"the UITAMR library declares it: add {path} (or its folder) to the sources"


def _plc_as_given(filenames: list[str]) -> Path | None:
    """The bundled plc/ folder by the path the sources reach it (`vendor/uitamr/plc` for
    `vendor/uitamr/plc/core/UITAMR_Engine.st` given through a submodule or symlink), so
    that a missing library file is named the way the integrator writes it; None when no
    source lies in it. A copy of the library counts too (a git submodule is one: its
    `vendor/uitamr/plc/core/UITAMR_Engine.st` is no link to the installed toolkit's file):
    a source whose path ends as a library file's does under plc/ (`core/UITAMR_Engine.st`)."""
    for name in filenames:
        given = Path(name)
        try:
            inside = real_path(given).relative_to(PLC_DIR)
        except ValueError:
            # the parts below the root of an absolute path (`PLC_DIR / "/x"` is "/x" itself)
            parts = given.parts[1:] if given.anchor else given.parts
            inside = next((Path(*parts[k:]) for k in range(len(parts) - 1)
                           if (PLC_DIR / Path(*parts[k:])).is_file()), None)
            if inside is None:
                continue
        if len(inside.parts) < len(given.parts):
            return given.parents[len(inside.parts) - 1]
        if len(inside.parts) == len(given.parts) and not given.is_absolute():
            return Path(".")
    return None


def _target_name(target: str) -> str:
    return {"gxworks2": "GX Works2", "gxworks3": "GX Works3"}.get(target, target)


#: GX Works function blocks an integrator's program may use that the toolkit does not model,
#: and what to write instead
_UNMODELLED_FBS = {
    "TON_10": ("TON_10 is the FX5's 10 ms on-delay timer FB (a secondary source, docs/instructions.md section 4), "
               "which the toolkit does not model: declare a TON (the simulator times it in ms of virtual time)"),
}

#: the editor a file was written for, and how to check it (README, docs/ci.md)
_CHECK_FOR = {"gxworks3": ("GX Works3 (FX5U)", "check FX5U sources with --platform fx5u (or --target gxworks3)"),
              "gxworks2": ("GX Works2 (FX3U/FX3G, Q)", "check FX3 and Q sources with --platform fx3u, fx3g "
                                                       "or q (or --target gxworks2)")}


#: GX Works2 instructions of one CPU family: (its CPUs, the sources, the --platform choices);
#: FX3's ADPRW sent to '--platform fx3u, fx3g or q' where a Q has none. Kept beside the
#: simulator's instruction families (verifier.sim.instructions) by tests/test_check_platform.py.
_GX2_ONE_FAMILY = {"ADPRW": ("FX3U/FX3G", "FX3", "fx3u or fx3g")} | {
    name: ("Q", "Q", "q") for name in ("ZP_OPEN", "ZP_BUFSND", "ZP_BUFRCV", "ZP_CLOSE")}


def _other_editor_hint(name: str, target: str, given: int) -> str:
    """When instruction `name`, refused or mis-called on `target`, is the other editor's
    with `given` arguments: a hint that the file was written for that editor (a whole
    `plc/` folder checked with one target meets both)."""
    for other, (editor, how) in _CHECK_FOR.items():
        if other == target:
            continue
        if other == "gxworks2" and name in _GX2_ONE_FAMILY:
            cpus, sources, platforms = _GX2_ONE_FAMILY[name]
            editor = f"GX Works2 ({cpus})"
            how = f"check {sources} sources with --platform {platforms} (or --target gxworks2)"
        sig = library.instruction(name, other)
        if sig is None or other not in sig.targets:
            continue
        n = len(sig.params)
        if given == n or (sig.variadic and given > n):
            mine = library.instruction(name, target)
            if mine is not None and target in mine.targets:
                return f"; with {given} arguments it is the {editor} {name}: {how}"
            return f"; {name} is a {editor} instruction: {how}"
    return ""


def _text(e) -> str:
    from verifier.st.printer import expr_text

    try:
        return expr_text(e)
    except TypeError:
        return "this"


def _lit_text(e) -> str:
    return getattr(e, "text", "") or str(getattr(e, "value", "this constant"))


#: the QJ71C24N receive settings' names in plcfacts.C24_BUFFER, in the manual's words
_C24_SETTING = {"unit": "word/byte units", "recv_count": "received data count", "end_code": "receive end code"}


def _constant_arg(e, table: SymbolTable) -> tuple[int | None, str]:
    """The integer an argument always has, and how to show it: a literal (`3`, "3"), or a VAR
    CONSTANT label with a literal value (`i_wChannel := C24_CHANNEL`, as UITAMR_ExampleQ
    passes it: "C24_CHANNEL (3, the constant declared at 17:5)"); (None, "") otherwise."""
    value = _const_int(e)
    if value is not None:
        return value, str(value)
    decl = _declaration(e, table)
    if isinstance(decl, ast.VarDecl) and decl.constant and decl.init is not None:
        value = _const_int(decl.init)
        if value is not None:
            return value, f"{e.name} ({value}, the constant declared at {_declared_at(decl, e)})"
    return None, ""


def _constant_text(e, table: SymbolTable) -> tuple[str | None, str]:
    """The STRING an argument always has, and how to show it: a literal (`'U2'`), or a VAR
    CONSTANT label with one (`E71_UNIT, 'U2', the constant declared at 7:5`); (None, "")."""
    if isinstance(e, ast.StringLiteral):
        return e.value, f"'{e.value}'"
    decl = _declaration(e, table)
    if isinstance(decl, ast.VarDecl) and decl.constant and isinstance(decl.init, ast.StringLiteral):
        return decl.init.value, f"{e.name}, '{decl.init.value}', the constant declared at {_declared_at(decl, e)}"
    return None, ""


def _declaration(e, table: SymbolTable) -> ast.VarDecl | None:
    """The declaration that gives the label `e` its value: its own, or for a VAR_EXTERNAL
    the VAR_GLOBAL it names (`VAR_EXTERNAL CONSTANT G_CHANNEL : INT;` holds no value)."""
    decl = getattr(e, "symbol", None)
    if isinstance(decl, ast.VarDecl) and decl.section == "VAR_EXTERNAL":
        found = table.globals.get(decl.key)
        return found[0] if found is not None else decl
    return decl


def _declared_at(decl: ast.VarDecl, use) -> str:
    """Where a label is declared, for a message placed at `use`: line:col in the same file,
    file:line:col in another (a VAR_GLOBAL CONSTANT of the global label file)."""
    if decl.span.file != use.span.file:
        return str(decl.span.place)
    return f"{decl.span.line}:{decl.span.col}"


def _const_int(e) -> int | None:
    if isinstance(e, ast.IntLiteral):
        return e.value
    if isinstance(e, ast.UnaryOp) and e.op == "-":
        v = _const_int(e.operand)
        return -v if v is not None else None
    t = getattr(e, "type", None)
    if T.is_group(t, "int-literal"):
        return t.value
    return None


_LITERALS = (ast.IntLiteral, ast.RealLiteral, ast.BoolLiteral, ast.TimeLiteral, ast.StringLiteral)
_EXPRESSIONS = (ast.BinaryOp, ast.UnaryOp, ast.Call)
_NOT_LABELS = _LITERALS + _EXPRESSIONS  # what cannot be written to, so not given to a VAR_IN_OUT


def _is_literal(e) -> bool:
    return isinstance(e, _LITERALS)


def _is_zero(init) -> bool:
    """True for an initial value every label starts with anyway (0, FALSE, 0.0, T#0s,
    '', and arrays/structures of those): dropping it changes nothing on the PLC."""
    if isinstance(init, ast.ArrayInit):
        return all(item.value is None or _is_zero(item.value) for item in init.items)
    if isinstance(init, ast.StructInit):
        return all(_is_zero(value) for _, value in init.fields)
    if isinstance(init, (ast.IntLiteral, ast.RealLiteral, ast.BoolLiteral)):
        return not init.value
    if isinstance(init, ast.TimeLiteral):
        return init.ms == 0
    if isinstance(init, ast.StringLiteral):
        return init.value == ""
    return False


def _is_constant(e) -> bool:
    if isinstance(e, (ast.IntLiteral, ast.RealLiteral, ast.BoolLiteral, ast.TimeLiteral, ast.StringLiteral)):
        return True
    if isinstance(e, ast.UnaryOp):
        return _is_constant(e.operand)
    if isinstance(e, ast.BinaryOp):
        return _is_constant(e.left) and _is_constant(e.right)
    if isinstance(e, ast.Name) and isinstance(e.symbol, ast.VarDecl):
        return e.symbol.constant
    return False


def _no_arithmetic(t: T.Type, editor: str) -> str:
    """Why `t` takes no arithmetic, and the conversion that makes a number of it."""
    if T.is_group(t, "time"):
        return "arithmetic on TIME is not allowed (convert with TIME_TO_DINT, and back with DINT_TO_TIME)"
    if T.is_group(t, "string"):
        return "arithmetic on strings is not allowed (join them with CONCAT)"
    number = T.DINT if T.width(t) == 32 else T.INT
    conv = library.conversion(T.concrete(t), number, editor)
    return "arithmetic on bit strings is not allowed" + (f" (convert with {conv})" if conv else "")


def check_project(files: list[ast.SourceFile], target: str = "gxworks2",
                  platform: str | None = None) -> tuple[list[ast.Diagnostic], SymbolTable]:
    """Check `files` together; return the diagnostics and the symbol table. `platform` (a
    CPU profile name: fx3u, fx3g, fx5u, q): refuse the labels named like an instruction of
    that CPU; None: like an instruction of any CPU the target's editor programs."""
    checker = Checker(files, target, platform)
    try:
        checker.collect()
        checker.check_bodies()
        checker.check_structure()
        checker.check_files()
    except RecursionError:
        checker.rep.diagnostics.append(ast.Diagnostic(
            files[0].filename if files else "<none>", 1, 1, "error",
            "expression nested too deeply to check; split it into intermediate labels"))
    diags = sorted(checker.rep.diagnostics, key=lambda d: (d.file, d.line, d.col))
    return diags, checker.table


def check(files: list[ast.SourceFile], target: str = "gxworks2", platform: str | None = None) -> list[ast.Diagnostic]:
    """Diagnostics for `files` checked together (parse diagnostics not included);
    `platform` as check_project takes it."""
    return check_project(files, target, platform)[0]


def _ladder_spelling(callee: ast.Expr, table, pou) -> tuple[str, str] | None:
    """(`SP.SOCOPEN`, `SP_SOCOPEN`) when a call's callee is an instruction written with the
    ladder's dot (SP.SOCOPEN, ZP.OPEN, G.OUTPUT), not a member of a label of that name;
    st-dialect.md §1: the dot is not an ST character, the instruction takes an underscore."""
    if not (isinstance(callee, ast.Member) and isinstance(callee.base, ast.Name)):
        return None
    if table.lookup(pou, callee.base.name) is not None:
        return None
    joined = f"{callee.base.name}_{callee.member}"
    if joined.upper() not in library.INSTRUCTIONS:
        return None
    return f"{callee.base.name}.{callee.member}", joined


#: a device numbered in hexadecimal written without its leading digit (`XA` for X0A), in
#: the device's own capitals: the kinds are devices.py's, the longest tried first
_HEX_DEVICE_WITHOUT_DIGIT = re.compile(
    "(" + "|".join(sorted(HEX_DEVICES, key=len, reverse=True)) + ")([A-F][0-9A-F]*)")


def _did_you_mean(name: str, candidates: list[str]) -> str:
    """'; did you mean 'x'?' (verifier.amr.schema.did_you_mean, imported on the error
    path only), else ""."""
    from verifier.amr.schema import did_you_mean

    return did_you_mean(name, candidates)


def _parameter_hint(fb: T.FbType, name: str) -> str:
    """What to write instead of a parameter `fb` does not have: the library's old run
    input `i_bEnable` by its new name `i_bEN` (docs/plc-library.md), else the parameter
    spelt nearly so."""
    if name.upper() == "I_BENABLE" and fb.param("i_bEN") is not None:
        return "; its run input is i_bEN (renamed from i_bEnable, docs/plc-library.md): write 'i_bEN := ...'"
    names = [n for group in (fb.inputs, fb.outputs, fb.in_outs) for n, _t in group]
    return _did_you_mean(name, names)
