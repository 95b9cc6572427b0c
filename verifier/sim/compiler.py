"""Checked ST files -> one generated Python module per simulated project.

Layout of the generated module:
- `S_<name>` classes for structures (`__slots__`, `_copy_from`),
- `_Globals` for global labels (one instance, `_G`),
- `FB_<name>` / `PRG_<name>` classes for function blocks and programs: labels are
  attributes, `_body()` runs one call of the POU,
- `FN_<name>` plain functions for FUNCTIONs (labels are Python locals).
The source is compiled with `compile()`; `CompiledModule.span_at(lineno)` maps a line of it
back to the ST statement it implements.
"""
from __future__ import annotations

from dataclasses import dataclass, field

from verifier.st import ast

from . import datatypes
from .codegen import BodyCompiler, Emitter, attr_name
from .cpu import CpuProfile, type_not_on_cpu
from .errors import SimulationError
from .inline import Body, Inliner
from .instructions import InstructionSet
from .instructions import lookup as lookup_instruction
from .refs import AttrRef, BitRef, DwordRef, Ref
from .stdfbs import STANDARD_FBS, FB_PARAM_TYPES
from .stdfuncs import make_helpers
from .purity import pure_functions, remembered
from .reach import needed
from .storage import check_storage
from .typesys import (ArrayT, CompileError, FbT, PouInfo, StringT, StructT, Symbol, anyint_helpers,
                      concrete, is_int, is_real, norm_code)

GENERATED_FILE = "<st-simulation>"


@dataclass
class CompiledModule:
    namespace: dict
    source: str
    spans: list
    pous: dict[str, PouInfo]
    structs: dict[str, dict[str, Symbol]]
    globals: dict[str, Symbol]
    class_symbols: dict[type, dict[str, Symbol]] = field(default_factory=dict)
    filename: str = GENERATED_FILE
    restarts: int = 0  # Project.restart's count: views of memory taken before one find it again

    def span_at(self, lineno: int):
        if 1 <= lineno <= len(self.spans):
            return self.spans[lineno - 1]
        return None


class ModuleCompiler:
    def __init__(self, files: list[ast.SourceFile], rt, cpu: CpuProfile, inline: bool = True,
                 programs: frozenset[str] | None = None):
        self.files = files
        self.inline = inline
        self.programs = programs  # generate only what these PROGRAMs need (None: every POU)
        self.rt = rt
        self.cpu = cpu
        self.structs: dict[str, ast.StructDecl] = {}
        self.struct_fields: dict[str, dict[str, Symbol]] = {}
        self.pous: dict[str, PouInfo] = {}
        self.functions: dict[str, PouInfo] = {}
        self.globals: dict[str, Symbol] = {}
        self.em = Emitter()
        self._locs: dict[object, int] = {}
        self.oob: list[tuple[str, str, int, int]] = []
        self.areas: set[str] = set()
        self.buffers: set[int] = set()

    # ------------------------------------------------------------------ shared services
    def loc_text(self, span) -> str:
        return str(span) if span is not None else "?"

    def loc(self, span) -> int:
        key = self.loc_text(span)
        k = self._locs.get(key)
        if k is None:
            k = self._locs[key] = self.rt.location_id(key)
        return k

    def oob_id(self, span, label, lo, hi) -> int:
        self.oob.append((self.loc_text(span), label, lo, hi))
        return len(self.oob) - 1

    def use_area(self, kind: str) -> None:
        self.areas.add(kind)

    def buffer_global(self, module: int) -> str:
        self.buffers.add(module)
        return f"_U{module:X}"

    # ------------------------------------------------------------------ types
    def resolve_type(self, t: ast.TypeRef):
        if isinstance(t, ast.StringType):
            return StringT(t.length or 32)
        if isinstance(t, ast.ArrayType):
            dims = tuple((d.low, d.high) for d in t.dims)
            for lo, hi in dims:
                if hi < lo:
                    raise CompileError(t.span, f"array bounds {lo}..{hi} are empty")
            return ArrayT(dims, self.resolve_type(t.element))
        if isinstance(t, ast.NamedType):
            key = t.key
            et = datatypes.lookup(key)
            why = type_not_on_cpu(key, self.cpu) if et is not None else None
            if why:
                raise CompileError(t.span, why)
            if et is not None:
                return StringT(32) if et.name == "STRING" else et.name
            if key in self.structs:
                return StructT(key)
            if key in STANDARD_FBS:
                return FbT(key, True)
            info = self.pous.get(key)
            if info is not None and info.kind == "FUNCTION_BLOCK":
                return FbT(key, False)
            raise CompileError(t.span, f"unknown type {t.name!r}")
        raise CompileError(getattr(t, "span", None), f"cannot simulate type {type(t).__name__}")

    def default_code(self, t) -> str:
        return default_code(t)

    def member_of(self, base_t, member: str, span):
        key = member.upper()
        if isinstance(base_t, StructT):
            f = self.struct_fields[base_t.name].get(key)
            if f is None:
                raise CompileError(span, f"structure {base_t.name} has no member {member}")
            return f.type, attr_name(f.name)
        if isinstance(base_t, FbT):
            if base_t.standard:
                mt = FB_PARAM_TYPES[base_t.name].get(key)
                if mt is None:
                    raise CompileError(span, f"{base_t.name} has no input/output {member}")
                return mt, key
            sym = self.pous[base_t.name].symbols.get(key)
            if sym is None:
                raise CompileError(span, f"function block {base_t.name} has no label {member}")
            return sym.type, attr_name(sym.name)
        raise CompileError(span, f"{base_t} has no members")

    def member_section(self, base_t, key: str) -> str:
        if isinstance(base_t, FbT) and not base_t.standard:
            sym = self.pous[base_t.name].symbols.get(key)
            return sym.section if sym else "VAR"
        return "VAR_INPUT"

    def member_section_of_expr(self, e: ast.Member, bc: BodyCompiler) -> str:
        _, t = bc.expr(e.base)
        return self.member_section(t, e.key)

    # ------------------------------------------------------------------ constants
    def const(self, e, info: PouInfo | None):
        if isinstance(e, ast.IntLiteral):
            return e.value
        if isinstance(e, ast.RealLiteral):
            return float(e.value)
        if isinstance(e, ast.BoolLiteral):
            return e.value
        if isinstance(e, ast.TimeLiteral):
            return e.ms
        if isinstance(e, ast.StringLiteral):
            return e.value
        if isinstance(e, ast.Name):
            sym = (info.symbols.get(e.key) if info else None) or self.globals.get(e.key)
            if sym is not None and sym.is_constant and sym.constant_value is not None:
                return sym.constant_value
            raise CompileError(e.span, f"{e.name} is not a constant")
        if isinstance(e, ast.UnaryOp):
            v = self.const(e.operand, info)
            if e.op == "-":
                return -v
            return (not v) if isinstance(v, bool) else ~v
        if isinstance(e, ast.BinaryOp):
            a = self.const(e.left, info)
            b = self.const(e.right, info)
            op = e.op
            if op in ("+", "-", "*"):
                return {"+": a + b, "-": a - b, "*": a * b}[op]
            if op == "/":
                if b == 0:
                    raise CompileError(e.span, "division by zero in a constant")
                if isinstance(a, float) or isinstance(b, float):
                    return a / b
                q = abs(a) // abs(b)
                return q if (a >= 0) == (b >= 0) else -q
            if op == "MOD":
                if b == 0:
                    raise CompileError(e.span, "MOD by zero in a constant")
                r = abs(a) % abs(b)
                return r if a >= 0 else -r
            if op in ("AND", "OR", "XOR"):
                return {"AND": a & b, "OR": a | b, "XOR": a ^ b}[op]
        raise CompileError(getattr(e, "span", None), "an initial value, CASE label or bound must be a constant")

    def try_const(self, e, info):
        if not isinstance(e, (ast.IntLiteral, ast.Name, ast.UnaryOp, ast.BinaryOp)):
            return None
        try:
            v = self.const(e, info)
        except CompileError:
            return None
        return v if isinstance(v, int) and not isinstance(v, bool) else None

    def init_value(self, t, init, info, span):
        """Python literal (repr) of an elementary/array initial value."""
        if isinstance(t, ArrayT):
            flat = []
            if init is not None:
                if not isinstance(init, ast.ArrayInit):
                    raise CompileError(span, "an array is initialised with [ ... ]")
                self._flatten(init, flat, info)
            if len(flat) > t.size:
                raise CompileError(span, f"{len(flat)} initial values for {t.size} elements")
            if not isinstance(t.elem, (str, StringT)):
                if flat:
                    raise CompileError(span, "initial values for arrays of structures/FBs are not simulated")
                return self.default_code(t)
            values = [self._norm(t.elem, v, span) for v in flat]
            default = self._norm(t.elem, None, span)
            if not values:
                return f"[{default!r}] * {t.size}"
            return repr(values + [default] * (t.size - len(values)))
        return repr(self._norm(t, None if init is None else self.const(init, info), span))

    def _flatten(self, init: ast.ArrayInit, out: list, info):
        for item in init.items:
            n = item.repeat if item.repeat is not None else 1
            if isinstance(item.value, ast.ArrayInit):
                sub = []
                self._flatten(item.value, sub, info)
                out.extend(sub * n)
            elif isinstance(item.value, ast.StructInit):
                raise CompileError(item.span, "initial values for arrays of structures are not simulated")
            else:
                out.extend([self.const(item.value, info)] * n)

    def _norm(self, t, value, span):
        if isinstance(t, StringT):
            return "" if value is None else str(value)[: t.length]
        et = datatypes.TYPES[t]
        if value is None:
            return et.default
        if t == "BOOL":
            if not isinstance(value, bool):
                if value in (0, 1):
                    return bool(value)
                raise CompileError(span, f"{value!r} is not a BOOL")
            return value
        if isinstance(value, str):
            raise CompileError(span, f"{value!r} is not a {t}")
        if isinstance(value, float) and et.is_integer:
            raise CompileError(span, f"{value} is not an integer")
        return et.normalize(value)

    # ------------------------------------------------------------------ symbols
    def build_symbols(self) -> None:
        for f in self.files:
            for sd in f.types:
                self.structs[sd.key] = sd
            for pou in f.pous:
                if pou.key in self.pous:
                    raise CompileError(pou.span, f"{pou.name} is defined twice")
                cls = {"FUNCTION": "FN_", "FUNCTION_BLOCK": "FB_", "PROGRAM": "PRG_"}[pou.kind]
                self.pous[pou.key] = PouInfo(pou, pou.kind, pou.key, class_name=cls + pou.key)
        for key, sd in self.structs.items():
            fields = {}
            for v in sd.fields:
                fields[v.key] = Symbol(v.name, v.key, self.resolve_type(v.type), v, "", "VAR")
            self.struct_fields[key] = fields
        for f in self.files:
            for block in f.globals:
                for v in block.variables:
                    self.globals[v.key] = self.global_symbol(v)
        for info in self.pous.values():
            self.pou_symbols(info)
            if info.kind == "FUNCTION":
                self.functions[info.key] = info

    def global_symbol(self, v: ast.VarDecl) -> Symbol:
        t = self.resolve_type(v.type)
        sym = Symbol(v.name, v.key, t, v, f"_G.{attr_name(v.name)}", "VAR_GLOBAL")
        if v.constant:
            sym.is_constant = True
            if isinstance(t, str) and v.init is not None:
                sym.constant_value = self._norm(t, self.const(v.init, None), v.span)
                sym.code = repr(sym.constant_value)
        if v.at is not None:
            self.device_symbol(sym, v.at)
        return sym

    def device_symbol(self, sym: Symbol, d: ast.Device) -> None:
        """A global label assigned to a device (`bStart AT X0 : BOOL`)."""
        bc = BodyCompiler(self, PouInfo(None, "PROGRAM", "<globals>"), Emitter())
        lv = bc.device_lvalue(d)
        if lv.prep:
            raise CompileError(d.span, "index-modified devices cannot hold a label")
        t = sym.type
        if t == "BOOL" and lv.type == "BOOL":
            sym.code, sym.write = lv.read, lv.write_tpl
        elif t in ("INT",) and lv.type == "INT" and d.digits is None:
            sym.code, sym.write = lv.read, lv.write_tpl
        elif t in ("WORD", "UINT") and lv.type == "INT" and d.digits is None:
            sym.code = f"({lv.read} & 65535)"
            sym.write = lv.write(norm_code("INT", "{v}"))  # the device holds the signed image
        else:
            raise CompileError(d.span, f"a {t} label assigned to {d.text or d.key} is not simulated "
                                       "(BOOL on bit devices, INT/WORD/UINT on word devices are)")
        sym.device = d

    def pou_symbols(self, info: PouInfo) -> None:
        pou = info.pou
        is_fn = info.kind == "FUNCTION"
        for v in pou.variables:
            if v.section == "VAR_EXTERNAL":
                g = self.globals.get(v.key)
                if g is None:
                    raise CompileError(v.span, f"VAR_EXTERNAL {v.name} has no VAR_GLOBAL")
                info.symbols[v.key] = g
                continue
            t = self.resolve_type(v.type)
            code = f"l_{attr_name(v.name)}" if is_fn else f"self.{attr_name(v.name)}"
            sym = Symbol(v.name, v.key, t, v, code, v.section)
            if v.constant:
                sym.is_constant = True
                if isinstance(t, str) and v.init is not None:
                    sym.constant_value = self._norm(t, self.const(v.init, info), v.span)
                    sym.code = repr(sym.constant_value)
            if v.key in info.symbols:
                raise CompileError(v.span, f"{v.name} is declared twice in {pou.name}")
            info.symbols[v.key] = sym
            if v.section in ("VAR_INPUT", "VAR_IN_OUT"):
                info.inputs.append(sym)
            if v.section in ("VAR_OUTPUT",) or (is_fn and v.section == "VAR_IN_OUT"
                                                 and isinstance(t, (str, StringT))):
                info.outputs.append(sym)
        if is_fn:
            if pou.return_type is None:
                info.return_type = None
            else:
                info.return_type = self.resolve_type(pou.return_type)
                info.symbols[pou.key] = Symbol(pou.name, pou.key, info.return_type, None, "_ret", "RETURN")

    # ------------------------------------------------------------------ calls
    def is_variable(self, c: ast.Call, bc: BodyCompiler) -> bool:
        if not isinstance(c.callee, ast.Name):
            return True
        return c.key in bc.info.symbols and bc.info.symbols[c.key].section != "RETURN" or c.key in self.globals

    def classify_call(self, c: ast.Call, bc: BodyCompiler) -> str:
        if self.is_variable(c, bc):
            return "fb"
        if c.key in self.functions:
            return "function"
        if c.key in self.pous:
            raise CompileError(c.span, f"{c.name} is a {self.pous[c.key].kind.replace('_', ' ')}: "
                                       "call an instance of it")
        if lookup_instruction(c.key, self.cpu.family) is not None:
            return "instruction"
        return "std"

    # ------------------------------------------------------------------ generation
    def compile(self) -> CompiledModule:
        return instantiate(self.generate(), self.rt)

    def generate(self) -> "Generated":
        """The Python source and code object of the files, and the tables they index."""
        first_location = len(self.rt.locations)
        self.build_symbols()
        check_storage(self.struct_fields, self.pous, self.globals,
                      {key: sd.name for key, sd in self.structs.items()})
        if self.programs is not None:
            wanted = needed(self.files, self.programs)
            self.pous = {key: info for key, info in self.pous.items() if key in wanted}
            self.functions = {key: info for key, info in self.functions.items() if key in wanted}
        em = self.em
        for key, sd in self.structs.items():
            self.gen_struct(key, sd)
        self.gen_globals()
        bodies: dict[str, tuple[Body, BodyCompiler]] = {}
        for info in self.pous.values():
            if info.kind == "FUNCTION":
                self.gen_function(info)
            else:
                bodies[info.key] = self.gen_body(info)
        inliner = Inliner({k: b for k, (b, _) in bodies.items()}) if self.inline else None
        for key, (body, bc) in bodies.items():
            lines, spans = inliner.expanded(key) if inliner else (body.lines, body.spans)
            self.gen_class(self.pous[key], lines, spans, bc)
        source = "\n".join(em.lines) + "\n"
        try:
            code = compile(source, GENERATED_FILE, "exec")
        except (SyntaxError, RecursionError, MemoryError) as e:
            # Python's own nesting limits (about 200 parentheses in one expression)
            lineno = getattr(e, "lineno", None)
            span = em.spans[lineno - 1] if lineno and 0 < lineno <= len(em.spans) else None
            raise CompileError(span, "expression nested too deeply to simulate; "
                                     "split it into several statements") from None
        return Generated(
            self.files, self.cpu, self.inline, source, code, list(em.spans), self.pous, self.struct_fields,
            self.globals, list(self.structs), [self.functions[k].class_name for k in pure_functions(self.functions)],
            self.rt.locations[first_location:], first_location, list(self.oob), sorted(self.buffers))

    def gen_struct(self, key: str, sd: ast.StructDecl) -> None:
        em = self.em
        fields = self.struct_fields[key]
        attrs = [attr_name(f.name) for f in fields.values()]
        em.span = sd.span
        em.line(f"class S_{key}:")
        em.indent()
        em.line(f"__slots__ = {tuple(attrs)!r}")
        em.line("def __init__(self):")
        em.indent()
        for f, a in zip(fields.values(), attrs):
            em.line(f"self.{a} = {self.value_code(f.type, f.decl.init, None, f.decl.span)}")
        if not attrs:
            em.line("pass")
        em.dedent()
        em.line("def _copy_from(self, o):")
        em.indent()
        for f, a in zip(fields.values(), attrs):
            em.line(self.copy_line(f.type, f"self.{a}", f"o.{a}"))
        em.line("return self")
        em.dedent()
        em.dedent()

    def copy_line(self, t, dst: str, src: str) -> str:
        if isinstance(t, ArrayT):
            if isinstance(t.elem, StructT):
                return f"for _d, _s in zip({dst}, {src}): _d._copy_from(_s)"
            return f"{dst}[:] = {src}"
        if isinstance(t, StructT):
            return f"{dst}._copy_from({src})"
        return f"{dst} = {src}"

    def value_code(self, t, init, info, span) -> str:
        if isinstance(t, (str, StringT)) or (isinstance(t, ArrayT) and isinstance(t.elem, (str, StringT))):
            return self.init_value(t, init, info, span)
        if init is not None and not isinstance(init, ast.StructInit):
            raise CompileError(span, f"{t} is initialised with ( name := value, ... )")
        return self.default_code(t)

    def init_members(self, target: str, t, init: ast.StructInit, info, span) -> None:
        for name, value in init.fields:
            mt, attr = self.member_of(t, name, span)
            if isinstance(value, ast.StructInit):
                self.init_members(f"{target}.{attr}", mt, value, info, span)
            else:
                self.em.line(f"{target}.{attr} = {self.value_code(mt, value, info, span)}")

    def gen_globals(self) -> None:
        em = self.em
        syms = [s for s in self.globals.values() if s.code.startswith("_G.")]
        em.span = None
        em.line("class _Globals:")
        em.indent()
        em.line(f"__slots__ = {tuple(s.code[3:] for s in syms)!r}")
        em.line("def __init__(self):")
        em.indent()
        em.line("pass")
        self.init_labels([(s.code.replace("_G.", "self.", 1), s) for s in syms], None)
        em.dedent()
        em.dedent()

    def init_labels(self, places: list[tuple[str, Symbol]], info) -> None:
        """Lines giving each label its declared initial value."""
        for code, s in places:
            self.em.span = s.decl.span
            self.em.line(f"{code} = {self.value_code(s.type, s.decl.init, info, s.decl.span)}")
            if isinstance(s.decl.init, ast.StructInit):
                self.init_members(code, s.type, s.decl.init, info, s.decl.span)

    def gen_body(self, info: PouInfo) -> tuple[Body, BodyCompiler]:
        pou = info.pou
        body_em = Emitter()
        body_em.depth = 2
        bc = BodyCompiler(self, info, body_em)
        temps = [s for s in info.symbols.values() if s.section == "VAR_TEMP"]
        body_em.span = pou.span
        for s in temps:
            body_em.line(f"{s.code} = {self.value_code(s.type, s.decl.init, info, s.decl.span)}")
        bc.block(pou.body)
        if not body_em.lines:
            body_em.line("pass")
        return Body(body_em.lines, body_em.spans, 2, bc.fb_calls), bc

    def gen_class(self, info: PouInfo, lines: list[str], spans: list, bc: BodyCompiler) -> None:
        em = self.em
        pou = info.pou
        own = [s for s in info.symbols.values() if s.code.startswith("self.")]
        slots = ["_rt"] + [s.code[5:] for s in own] + bc.pulse_slots + [slot for slot, _ in bc.static_refs]
        em.span = pou.span
        em.line(f"class {info.class_name}:")
        em.indent()
        em.line(f"__slots__ = {tuple(slots)!r}")
        em.line("def __init__(self):")
        em.indent()
        em.line("self._rt = _rt")
        self.init_labels([(s.code, s) for s in own], info)
        em.span = pou.span
        for slot in bc.pulse_slots:
            em.line(f"self.{slot} = False")
        for slot, code in bc.static_refs:
            em.line(f"self.{slot} = {code}")
        em.dedent()
        em.line("def _body(self):")
        em.lines.extend(lines)
        em.spans.extend(spans)
        em.dedent()

    def gen_function(self, info: PouInfo) -> None:
        em = self.em
        pou = info.pou
        body_em = Emitter()
        body_em.depth = 1
        bc = BodyCompiler(self, info, body_em)
        body_em.span = pou.span
        params = []
        for s in info.inputs:
            arg = "a_" + s.code[2:]
            params.append(arg)
            if s.section == "VAR_INPUT" and isinstance(s.type, ArrayT):
                if isinstance(s.type.elem, (str, StringT)):
                    body_em.line(f"{s.code} = list({arg})")
                else:
                    body_em.line(f"{s.code} = [_x._copy_from(_y) for _x, _y in zip({self.default_code(s.type)}, {arg})]")
            elif s.section == "VAR_INPUT" and isinstance(s.type, StructT):
                body_em.line(f"{s.code} = {self.default_code(s.type)}._copy_from({arg})")
            else:
                body_em.line(f"{s.code} = {arg}")
        locals_ = []
        for s in info.symbols.values():
            if s.section in ("VAR_INPUT", "VAR_IN_OUT", "RETURN", "VAR_GLOBAL") or s.is_constant and not s.code.startswith("l_"):
                continue
            if not s.code.startswith("l_"):
                continue
            locals_.append((s.code, s))
        saved, self.em = self.em, body_em
        self.init_labels(locals_, info)
        self.em = saved
        body_em.span = pou.span
        if info.return_type is not None:
            body_em.line(f"_ret = {self.default_code(info.return_type)}")
        else:
            body_em.line("_ret = None")
        bc.block(pou.body)
        body_em.span = pou.span
        body_em.line(bc.return_code())
        em.span = pou.span
        em.line(f"def {info.class_name}({', '.join(params)}):")
        em.lines.extend(body_em.lines)
        em.spans.extend(body_em.spans)


def default_code(t) -> str:
    """Python expression building a fresh default value of type t."""
    if isinstance(t, str):
        return repr(datatypes.TYPES[t].default)
    if isinstance(t, StringT):
        return "''"
    if isinstance(t, StructT):
        return f"S_{t.name}()"
    if isinstance(t, FbT):
        return f"_STD_{t.name}(_rt)" if t.standard else f"FB_{t.name}()"
    if isinstance(t, ArrayT):
        if isinstance(t.elem, (str, StringT)):
            return f"[{default_code(t.elem)}] * {t.size}"
        return f"[{default_code(t.elem)} for _ in range({t.size})]"
    raise CompileError(None, f"no default for {t}")


@dataclass
class Generated:
    """What code generation made of one set of parsed files for one CPU. It holds no
    run-time state (the location and index tables are plain lists), so `uitamr verify`
    generates and compiles the library once and runs scenario after scenario on it."""
    files: list
    cpu: CpuProfile
    inline: bool
    source: str
    code: object
    spans: list
    pous: dict[str, PouInfo]
    struct_fields: dict[str, dict[str, Symbol]]
    globals: dict[str, Symbol]
    struct_keys: list[str]
    pure_functions: list[str]  # class names of FUNCTIONs whose results can be remembered
    locations: list[str]  # the runtime's location table from `first_location` on
    first_location: int
    oob: list[tuple[str, str, int, int]]
    buffers: list[int]


def namespace(rt, cpu: CpuProfile, oob: list, buffers) -> dict:
    """The globals the generated code runs in, bound to one runtime."""

    def _oob(index, k):
        location, label, lo, hi = oob[k]
        raise SimulationError(
            f"index {index} is outside {label}[{lo}..{hi}]; the real CPU does not "
            "check this and would silently read or overwrite neighbouring memory",
            location, rt.now_us)

    ns = {"__name__": "verifier_sim_generated", "_rt": rt, "_I": InstructionSet(rt),
          "_Ref": Ref, "_AttrRef": AttrRef, "_BitRef": BitRef,
          "_DwordRef": DwordRef, "_oob": _oob}
    ns.update(make_helpers(rt))
    ns.update(anyint_helpers())
    for name, cls in STANDARD_FBS.items():
        ns[f"_STD_{name}"] = cls
    for area in cpu.areas:
        ns[f"_A_{area}"] = rt.dev.areas[area]
    for module in buffers:
        ns[f"_U{module:X}"] = rt.buffer(module)
    return ns


def instantiate(generated: Generated, rt) -> CompiledModule:
    """The generated code run into a namespace of `rt`: classes, functions, globals."""
    if len(rt.locations) != generated.first_location + len(generated.locations):
        # a runtime other than the one the code was generated with: give it the same table
        if len(rt.locations) != generated.first_location:
            raise ValueError("the runtime's location table does not match the generated code")
        rt.locations.extend(generated.locations)
    ns = namespace(rt, generated.cpu, generated.oob, generated.buffers)
    exec(generated.code, ns)
    for name in generated.pure_functions:
        ns[name] = remembered(ns[name])
    ns["_G"] = ns["_Globals"]()
    module = CompiledModule(ns, generated.source, generated.spans, generated.pous, generated.struct_fields,
                            generated.globals)
    for info in generated.pous.values():
        if info.kind != "FUNCTION":
            module.class_symbols[ns[info.class_name]] = info.symbols
    for key in generated.struct_keys:
        module.class_symbols[ns[f"S_{key}"]] = generated.struct_fields[key]
    module.class_symbols[ns["_Globals"]] = generated.globals
    return module


#: generated code by parsed files (the parse cache hands back the same list for the same
#: texts), CPU, inlining and programs; the entry keeps the files alive, so their id is not
#: reused
_GENERATED: dict[tuple[int, str, bool, frozenset[str] | None], Generated] = {}
_GENERATED_MAX = 8


def compile_files(files: list[ast.SourceFile], rt, cpu: CpuProfile, inline: bool = True, *,
                  programs: frozenset[str] | None = None) -> CompiledModule:
    """The files compiled for a runtime: every POU, or (`programs`, upper-case PROGRAM
    names) only what those PROGRAMs need (`reach.needed`)."""
    key = (id(files), cpu.name, inline, programs)
    generated = _GENERATED.get(key)
    if generated is None or generated.files is not files or rt.locations:
        generated = ModuleCompiler(files, rt, cpu, inline, programs).generate()
        if generated.first_location == 0:
            if len(_GENERATED) >= _GENERATED_MAX:
                _GENERATED.pop(next(iter(_GENERATED)))
            _GENERATED[key] = generated
    return instantiate(generated, rt)


__all__ = ["compile_files", "CompiledModule", "CompileError", "concrete", "is_int", "is_real"]
