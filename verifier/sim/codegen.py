"""ST statements and expressions -> Python source, one POU at a time.

The generated code works on canonical Python values (see `datatypes`): every arithmetic
result is normalised to its ST type (INT wraps at 16 bits, REAL is rounded to single
precision...), array indexes are checked against the declared bounds with the ST
location of the access, and every emitted line remembers the ST statement it came from,
so a run-time error is reported at an ST line, not a Python one.
"""
from __future__ import annotations

import keyword
import re

from verifier.st import ast

from . import datatypes
from .calls import CallCompiler
from .cpu import SEND_FLAGS
from .devices import DeviceError, locate, locate_buffer
from .instructions.c24 import SETTING_WORDS as C24_SETTING_WORDS
from .typesys import (ANYINT, ANYREAL, ArrayT, CompileError, FbT, PouInfo, StringT, StructT,
                      Symbol, concrete, is_int, is_real, is_string, norm_code, unify)

LOOP_LIMIT = 1_000_000


def attr_name(name: str) -> str:
    return name + "_" if keyword.iskeyword(name) or name in ("None", "True", "False") else name


class Emitter:
    """Indented Python lines, each tagged with the ST span it implements."""

    def __init__(self):
        self.lines: list[str] = []
        self.spans: list[object] = []
        self.depth = 0
        self.span = None

    def line(self, text: str) -> None:
        self.lines.append("    " * self.depth + text)
        self.spans.append(self.span)

    def indent(self):
        self.depth += 1

    def dedent(self):
        self.depth -= 1


class LValue:
    """A writable place: lines to prepare it, code to read it, a template to write it."""

    def __init__(self, type_, read: str, write: str, prep=(), label: str = ""):
        self.type = type_
        self.read = read
        self.write_tpl = write  # contains {v}
        self.prep = list(prep)
        self.label = label

    def write(self, value_code: str) -> str:
        return self.write_tpl.format(v=value_code)


class BodyCompiler(CallCompiler):
    """Compiles the statements of one POU (FB/PROGRAM method body or FUNCTION)."""

    def __init__(self, module, info: PouInfo, em: Emitter):
        self.m = module  # the ModuleCompiler: symbols, types, runtime, location table
        self.info = info
        self.em = em
        self.family = module.cpu.family
        self.is_function = info.kind == "FUNCTION"
        self.tmp = 0
        self.static_refs: list[tuple[str, str]] = []  # (slot, code) created in __init__
        self.pulse_slots: list[str] = []
        self.fb_calls: dict[str, str] = {}  # temp holding an instance -> its user FB type
        self.loop_vars: dict[str, tuple[str, int, int]] = {}  # FOR counter -> (local, min, max)

    # ------------------------------------------------------------------ helpers
    def new_tmp(self, prefix="_t") -> str:
        self.tmp += 1
        return f"{prefix}{self.tmp}"

    def loc(self, span) -> int:
        return self.m.loc(span)

    def lookup(self, name: str, span) -> Symbol:
        key = name.upper()
        sym = self.info.symbols.get(key) or self.m.globals.get(key)
        if sym is None:
            raise CompileError(span, f"unknown label {name!r}")
        return sym

    # ------------------------------------------------------------------ expressions
    def expr(self, e: ast.Expr):
        if isinstance(e, ast.IntLiteral):
            return repr(e.value), ANYINT
        if isinstance(e, ast.RealLiteral):
            return repr(float(e.value)), ANYREAL
        if isinstance(e, ast.BoolLiteral):
            return ("True" if e.value else "False"), "BOOL"
        if isinstance(e, ast.TimeLiteral):
            return repr(datatypes.wrap32(e.ms)), "TIME"
        if isinstance(e, ast.StringLiteral):
            return repr(e.value), StringT(max(len(e.value), 1))
        if isinstance(e, ast.Name):
            sym = self.lookup(e.name, e.span)
            loop = self.loop_vars.get(e.key)
            return (loop[0] if loop else sym.code), sym.type
        if isinstance(e, ast.Device):
            lv = self.device_lvalue(e)
            return lv.read, lv.type
        if isinstance(e, ast.Index):
            code, t, _ = self.index_access(e)
            return code, t
        if isinstance(e, ast.Member):
            return self.member(e)
        if isinstance(e, ast.BitAccess):
            code, t = self.expr(e.base)
            self.check_bit(e.bit, t, e.span)
            return f"(({code}) >> {e.bit} & 1 == 1)", "BOOL"
        if isinstance(e, ast.UnaryOp):
            code, t = self.expr(e.operand)
            return self.unary_code(e.op, code, t, e.span)
        if isinstance(e, ast.BinaryOp):
            spine = [e]
            while isinstance(spine[-1].left, ast.BinaryOp):
                spine.append(spine[-1].left)
            if len(spine) > LONG_CHAIN:
                return self.chain(spine)
            lc, lt = self.expr(e.left)
            rc, rt_ = self.expr(e.right)
            code, t = self.binary_code(e.op, lc, lt, rc, rt_, e.span)
            known = self.counter_arith(e) if self.loop_vars and is_int(t) and t != "BOOL" else None
            return (known[0], t) if known is not None else (code, t)
        if isinstance(e, ast.Call):
            return self.call_expr(e)
        raise CompileError(e.span, f"cannot simulate expression {type(e).__name__}")

    def counter_arith(self, e) -> tuple[str, int, int] | None:
        """(code, lowest, highest) of integer arithmetic over FOR counters and constants
        (`24 + i`, `8 + 2 * i + 1`, `i / BYTES_PER_WORD`, `i MOD 2`) whose every step stays
        within 0..32767 for the counters' whole range: no step can wrap in any integer
        type and no divisor is zero or negative (truncation equals floor), so plain
        Python arithmetic gives the CPU's result without a wrap or a helper call per
        loop step.  None when that is not certain; at least one FOR counter must occur."""
        if isinstance(e, ast.Name) and e.key in self.loop_vars:
            v, lo, hi = self.loop_vars[e.key]
            t = self.lookup(e.name, e.span).type
            return (v, lo, hi) if is_int(t) and t != "BOOL" and 0 <= lo and hi <= 32767 else None
        if not isinstance(e, ast.BinaryOp) or e.op not in ("+", "-", "*", "/", "MOD"):
            return None
        left, right = self._arith_operand(e.left), self._arith_operand(e.right)
        if left is None or right is None or (left[3] and right[3]):
            return None  # both constant: not a counter expression (constants fold elsewhere)
        (lc, llo, lhi, _), (rc, rlo, rhi, _) = left, right
        if e.op in ("/", "MOD"):
            if rlo != rhi or rlo <= 0 or llo < 0:
                return None  # only a positive constant divisor
            op = "//" if e.op == "/" else "%"
            lo, hi = (llo // rlo, lhi // rlo) if op == "//" else ((llo, lhi) if lhi < rlo else (0, rlo - 1))
        else:
            op = e.op
            apply = _ARITH[op]
            corners = [apply(a, b) for a in (llo, lhi) for b in (rlo, rhi)]
            lo, hi = min(corners), max(corners)
        if lo < 0 or hi > 32767:
            return None
        return f"({lc} {op} {rc})", lo, hi

    def counter_index(self, ix):
        """(code, lowest, highest) of an array index that is a FOR counter or arithmetic
        on one (see counter_arith), else None."""
        if isinstance(ix, ast.Name):
            return self.loop_vars.get(ix.key)
        if isinstance(ix, ast.BinaryOp) and self.loop_vars:
            _, t = self.expr(ix)
            if is_int(t) and t != "BOOL":
                return self.counter_arith(ix)
        return None

    def _arith_operand(self, e):
        value = self.m.try_const(e, self.info)
        if value is not None:
            return (repr(value), value, value, True) if 0 <= value <= 32767 else None
        known = self.counter_arith(e)
        return None if known is None else (*known, False)

    def chain(self, spine: list[ast.BinaryOp]):
        """A long left-deep chain (a + b + c + ...): each step is the code binary_code
        gives, its value held in a temporary, the steps in one flat tuple evaluated left
        to right - the same operations without the deep nesting Python cannot compile."""
        code, t = self.expr(spine[-1].left)
        steps = []
        for node in reversed(spine):
            rc, rt_ = self.expr(node.right)
            step, t = self.binary_code(node.op, code, t, rc, rt_, node.span)
            code = self.new_tmp("_c")
            steps.append(f"({code} := {step})")
        return f"({', '.join(steps)})[-1]", t

    def check_bit(self, bit: int, t, span) -> None:
        width = {"WORD": 16, "INT": 16, "UINT": 16, "DWORD": 32, "DINT": 32, "UDINT": 32}.get(t)
        if width is None:
            raise CompileError(span, f"bit access .{bit} needs a WORD/INT/DWORD/DINT label, not {t}")
        if not 0 <= bit < width:
            raise CompileError(span, f"bit {bit} does not exist in a {width}-bit {t}")

    def unary_code(self, op, code, t, span):
        if op == "-":
            if t in (ANYINT, ANYREAL) or is_real(t):
                return f"(-({code}))", t
            return norm_code(t, f"-({code})"), t
        # NOT
        if t == "BOOL":
            return f"(not ({code}))", "BOOL"
        if t in ("WORD", "UINT"):
            return f"(({code}) ^ 65535)", t
        if t in ("DWORD", "UDINT"):
            return f"(({code}) ^ 4294967295)", t
        if is_int(t):
            return f"(~({code}))", t
        raise CompileError(span, f"NOT needs BOOL or a bit string, not {t}")

    def binary_code(self, op, lc, lt, rc, rt_, span):
        if op in ("=", "<>", "<", ">", "<=", ">="):
            py = {"=": "==", "<>": "!="}.get(op, op)
            # a REAL operand against a constant: the constant is a REAL too
            lc, rc = _real_typed(lc, lt, rt_), _real_typed(rc, rt_, lt)
            return f"(({lc}) {py} ({rc}))", "BOOL"
        if op in ("AND", "OR", "XOR"):
            py = {"AND": "&", "OR": "|", "XOR": "^"}[op]
            if lt == "BOOL" or rt_ == "BOOL":
                if lt != "BOOL" or rt_ != "BOOL":
                    raise CompileError(span, f"{op} mixes BOOL with {lt if lt != 'BOOL' else rt_}")
                if op != "XOR" and cannot_fail(rc):
                    # nothing to miss when the right side is skipped: Python's short-circuit
                    # `and`/`or` give the same value as & and | on BOOLs, in fewer steps
                    py = "and" if op == "AND" else "or"
                return f"(({lc}) {py} ({rc}))", "BOOL"
            t = unify(lt, rt_)
            code = f"(({lc}) {py} ({rc}))"
            return (norm_code(t, code) if lt != rt_ else code), t
        t = unify(lt, rt_)
        if is_string(t):
            raise CompileError(span, f"operator {op} does not apply to STRING")
        if t not in (ANYINT, ANYREAL) and is_int(t):
            # a constant sub-expression meeting a typed operand is computed in that type,
            # as the CPU's 16/32-bit instructions compute it
            lc = _typed_literal(lc, lt, t)
            rc = _typed_literal(rc, rt_, t)
        k = self.loc(span)
        if op == "**":
            return f"_f32(_expt({lc}, {rc}, {k}))", "REAL"
        if t == ANYINT:  # both literals: constant arithmetic, typed later
            # _anyint(...) marks each step; norm_code retypes the marks to the type the
            # expression meets, so every step wraps there as on the CPU (identity otherwise)
            if op == "/":
                return f"_anyint(_idiv({lc}, {rc}, {k}))", ANYINT
            if op == "MOD":
                return f"_anyint(_imod({lc}, {rc}, {k}))", ANYINT
            return f"_anyint(({lc}) {op} ({rc}))", ANYINT
        if is_real(t) or t == ANYREAL:
            real_t = concrete(t)
            lc, rc = _real_typed(lc, lt, t), _real_typed(rc, rt_, t)
            if op == "/":
                raw = f"_rdiv({lc}, {rc}, {k})"
            elif op == "MOD":
                raise CompileError(span, "MOD needs integer operands")
            else:
                raw = f"({lc}) {op} ({rc})"
            return norm_code(real_t, raw), real_t
        if t == "BOOL":
            raise CompileError(span, f"operator {op} does not apply to BOOL")
        if op == "/":
            return norm_code(t, f"_idiv({lc}, {rc}, {k})"), t
        if op == "MOD":
            return f"_imod({lc}, {rc}, {k})", t
        return norm_code(t, f"({lc}) {op} ({rc})"), t

    def coerce(self, code: str, src, dst, span) -> str:
        """Code converting a value of type src to be stored in a dst label."""
        if src == dst:
            return code
        if isinstance(dst, (ArrayT, StructT, FbT)):
            raise CompileError(span, f"cannot assign {src} to {dst}")
        if dst == "BOOL":
            if src != "BOOL":
                raise CompileError(span, f"cannot assign {src} to BOOL")
            return code
        if is_string(dst):
            if not is_string(src):
                raise CompileError(span, f"cannot assign {src} to STRING")
            return norm_code(dst, code) if isinstance(dst, StringT) else code
        if _is_number(code) and isinstance(dst, str) and dst in datatypes.TYPES and src != "BOOL":
            value = eval(code)
            if is_real(dst):
                return repr(datatypes.NORMALIZERS[dst](float(value)))
            if isinstance(value, int):
                return repr(datatypes.NORMALIZERS[dst](value))
        if src == ANYINT or src == ANYREAL:
            try:
                value = eval(code, {"__builtins__": {}}, {})  # a folded literal expression
            except Exception:
                value = None
            if isinstance(value, (int, float)) and not isinstance(value, bool):
                if is_real(dst):
                    return repr(datatypes.NORMALIZERS[dst](float(value)))
                if isinstance(value, float):
                    raise CompileError(span, f"cannot assign a REAL constant to {dst}")
                return repr(datatypes.NORMALIZERS[dst](value))
        if is_real(dst):
            if is_real(src) or src == ANYREAL:
                return norm_code(dst, code) if dst == "REAL" and src != "REAL" else code
            return norm_code(dst, f"float({code})")
        if is_int(dst):
            if is_real(src) or src == ANYREAL:
                return f"_r2i({code}, {dst!r}, {self.loc(span)})"
            if src == "BOOL":
                raise CompileError(span, f"cannot assign BOOL to {dst} (use BOOL_TO_{dst})")
            return norm_code(dst, code)
        return code

    # ------------------------------------------------------------------ places
    def device_lvalue(self, d: ast.Device) -> LValue:
        cpu = self.m.cpu
        label = d.text or d.key
        if d.module is not None:
            try:
                module, idx = locate_buffer(d, cpu)
            except DeviceError as e:
                raise CompileError(d.span, str(e)) from None
            g = self.m.buffer_global(module)
            write = f"{g}[{idx}] = {{v}}"
            if idx in C24_SETTING_WORDS:
                # the program sets the QJ71C24N up itself: settings made for "the module the
                # program drives" (configure_c24(None, ...)) do not replace this word
                write += f"; _rt.c24_written.add(({module}, {idx}))"
            return LValue("INT", f"{g}[{idx}]", write, label=label)
        try:
            area, index = locate(d, cpu)
        except DeviceError as e:
            raise CompileError(d.span, str(e)) from None
        cells = f"_A_{d.kind}"
        self.m.use_area(d.kind)
        idx_code = str(index)
        if d.index is not None:
            self.m.use_area("Z")
            t = self.new_tmp()
            k = self.m.oob_id(d.span, label, 0, area.size - 1)
            prep = [f"{t} = {index} + _A_Z[{d.index}]", f"if not 0 <= {t} < {area.size}: _oob({t}, {k})"]
            # a read needs the checked index inside one expression
            read = (f"({cells}[{t}] if 0 <= ({t} := {index} + _A_Z[{d.index}]) < {area.size} "
                    f"else _oob({t}, {self.m.oob_id(d.span, label, 0, area.size - 1)}))")
            kind = "BOOL" if area.kind == "bit" else "INT"
            return LValue(kind, read, f"{cells}[{t}] = {{v}}", prep, label)
        place = f"{cells}[{idx_code}]"
        if d.digits is not None:
            t = "INT" if d.digits <= 4 else "DINT"
            return LValue(t, f"_digits_get({cells}, {idx_code}, {d.digits})",
                          f"_digits_set({cells}, {idx_code}, {d.digits}, {{v}})", [], label)
        if d.bit is not None:
            mask = 1 << d.bit
            read = f"(({place}) >> {d.bit} & 1 == 1)"
            write = (f"{place} = (((({place}) | {mask}) if ({{v}}) else (({place}) & ~{mask})) "
                     f"+ 32768 & 65535) - 32768")
            return LValue("BOOL", read, write, [], label)
        prep = []
        flag_channel = SEND_FLAGS.get(self.family, {}).get(f"{d.kind}{index}")
        if area.kind == "bit":
            write = f"{place} = {{v}}"
            if flag_channel:
                loc = self.m.loc_text(d.span)
                write = (f"{place} = {{v}}\nif {place}: _rt.origins[{flag_channel!r}] = {loc!r}")
            return LValue("BOOL", place, write, prep, label)
        # values reach a word device already converted to INT by coerce()
        return LValue("INT", place, f"{place} = {{v}}", prep, label)

    def index_access(self, e: ast.Index):
        """(read code, element type, LValue) of an array element with checked bounds."""
        base_code, base_t = self.expr(e.base)
        if not isinstance(base_t, ArrayT):
            raise CompileError(e.span, f"{self.label_of(e.base)} is not an array")
        if len(e.indices) != len(base_t.dims):
            raise CompileError(e.span, f"{self.label_of(e.base)} has {len(base_t.dims)} "
                                       f"dimension(s), {len(e.indices)} index(es) given")
        label = self.label_of(e.base)
        prep = []
        flat_parts = []
        strides = _strides(base_t.dims)
        const_offset = 0
        for (lo, hi), ix, st in zip(base_t.dims, e.indices, strides):
            code, t = self.expr(ix)
            if not is_int(t):
                raise CompileError(ix.span, f"array index must be an integer, not {t}")
            loop = self.counter_index(ix)
            if loop is not None and lo <= loop[1] and loop[2] <= hi:
                # a FOR counter (or arithmetic on one) whose whole range lies inside the
                # bounds: no check needed
                part = f"{loop[0]} - {lo}" if lo else loop[0]
                flat_parts.append(part if st == 1 else f"({part}) * {st}")
                continue
            value = self.m.try_const(ix, self.info)
            if value is not None:
                if not lo <= value <= hi:
                    raise CompileError(ix.span, f"index {value} is outside {label}[{lo}..{hi}]")
                const_offset += (value - lo) * st
                continue
            tmp = self.new_tmp()
            k = self.m.oob_id(ix.span, label, lo, hi)
            prep.append(f"{tmp} = {code}")
            prep.append(f"if not {lo} <= {tmp} <= {hi}: _oob({tmp}, {k})")
            part = f"{tmp} - {lo}" if lo else tmp
            flat_parts.append(part if st == 1 else f"({part}) * {st}")
        if const_offset or not flat_parts:
            flat_parts.append(str(const_offset))
        flat = " + ".join(flat_parts)
        place = f"{base_code}[{flat}]"
        elem_t = base_t.elem
        if prep:
            # expression form: checks folded into one conditional expression
            read = self.checked_expr(e, base_code, base_t, label)
        else:
            read = place
        lv = LValue(elem_t, place, f"{place} = {{v}}", prep, f"{label}[...]")
        return read, elem_t, lv

    def checked_expr(self, e: ast.Index, base_code, base_t: ArrayT, label: str) -> str:
        """An array read with bounds checks as a single Python expression (walrus temps)."""
        parts = []
        conds = []
        strides = _strides(base_t.dims)
        fails = []
        for (lo, hi), ix, st in zip(base_t.dims, e.indices, strides):
            value = self.m.try_const(ix, self.info)
            if value is not None:
                parts.append(str((value - lo) * st))
                continue
            loop = self.counter_index(ix)
            if loop is not None and lo <= loop[1] and loop[2] <= hi:
                part = f"{loop[0]} - {lo}" if lo else loop[0]
                parts.append(part if st == 1 else f"({part}) * {st}")
                continue
            code, _ = self.expr(ix)
            tmp = self.new_tmp()
            k = self.m.oob_id(ix.span, label, lo, hi)
            conds.append(f"{lo} <= ({tmp} := {code}) <= {hi}")
            fails.append(f"_oob({tmp}, {k})")
            part = f"{tmp} - {lo}" if lo else tmp
            parts.append(part if st == 1 else f"({part}) * {st}")
        code = f"{base_code}[{' + '.join(parts)}]"
        for cond, fail in reversed(list(zip(conds, fails))):
            code = f"({code} if {cond} else {fail})"
        return code

    def label_of(self, e) -> str:
        if isinstance(e, ast.Name):
            return e.name
        if isinstance(e, ast.Member):
            return f"{self.label_of(e.base)}.{e.member}"
        if isinstance(e, ast.BitAccess):
            return f"{self.label_of(e.base)}.{e.bit}"
        if isinstance(e, ast.Index):
            return f"{self.label_of(e.base)}[...]"
        if isinstance(e, ast.Device):
            return e.text or e.key
        return "?"

    def member(self, e: ast.Member):
        base_code, base_t = self.expr(e.base)
        t, attr = self.m.member_of(base_t, e.member, e.span)
        return f"{base_code}.{attr}", t

    def lvalue(self, e: ast.Expr) -> LValue:
        if isinstance(e, ast.Name):
            sym = self.lookup(e.name, e.span)
            if sym.is_constant:
                raise CompileError(e.span, f"{e.name} is a constant")
            write = sym.write if sym.write else f"{sym.code} = {{v}}"
            return LValue(sym.type, sym.code, write, label=e.name)
        if isinstance(e, ast.Device):
            return self.device_lvalue(e)
        if isinstance(e, ast.Index):
            _, _, lv = self.index_access(e)
            return lv
        if isinstance(e, ast.Member):
            code, t = self.member(e)
            return LValue(t, code, f"{code} = {{v}}", label=self.label_of(e))
        if isinstance(e, ast.BitAccess):
            base = self.lvalue(e.base)
            self.check_bit(e.bit, base.type, e.span)
            mask = 1 << e.bit
            new = f"((({base.read}) | {mask}) if ({{v}}) else (({base.read}) & ~{mask}))"
            write = base.write(norm_code(base.type, new))  # keeps the {v} placeholder
            return LValue("BOOL", f"(({base.read}) >> {e.bit} & 1 == 1)", write, base.prep,
                          f"{base.label}.{e.bit}")
        raise CompileError(e.span, "this expression cannot be assigned to")

    # ------------------------------------------------------------------ statements
    def block(self, stmts: list[ast.Stmt]) -> None:
        if not stmts:
            self.em.line("pass")
            return
        before = len(self.em.lines)
        for s in stmts:
            self.stmt(s)
        if len(self.em.lines) == before:
            self.em.line("pass")

    def stmt(self, s: ast.Stmt) -> None:
        saved = self.em.span
        self.em.span = s.span
        try:
            method = getattr(self, "stmt_" + type(s).__name__, None)
            if method is None:
                raise CompileError(s.span, f"cannot simulate statement {type(s).__name__}")
            method(s)
        except RecursionError:
            raise CompileError(s.span, "expression nested too deeply to simulate; "
                                       "split it into several statements") from None
        finally:
            self.em.span = saved

    def emit_lines(self, text: str) -> None:
        for ln in text.split("\n"):
            self.em.line(ln)

    def stmt_Empty(self, s):
        pass

    def stmt_Assign(self, s: ast.Assign):
        target = self.lvalue(s.target)
        for p in target.prep:
            self.em.line(p)
        if isinstance(target.type, ArrayT):
            self.copy_array(target, s.value, s.span)
            return
        if isinstance(target.type, StructT):
            code, t = self.expr(s.value)
            if t != target.type:
                raise CompileError(s.span, f"cannot assign {t} to {target.type}")
            self.em.line(f"({target.read})._copy_from({code})")
            return
        v = s.value
        if (isinstance(v, ast.BinaryOp) and v.op == "/"):
            lc, lt = self.expr(v.left)
            rc, rt_ = self.expr(v.right)
            t = unify(lt, rt_)
            if is_int(t) and t != ANYINT:
                lc, rc = _typed_literal(lc, lt, t), _typed_literal(rc, rt_, t)
                q = self.new_tmp("_q")
                self.em.line(f"{q} = _idiv_n({lc}, {rc}, {self.loc(v.span)})")
                self.em.line(f"if {q} is not None:")
                self.em.indent()
                self.emit_lines(target.write(self.coerce(norm_code(t, q), t, target.type, s.span)))
                self.em.dedent()
                return
        if isinstance(v, ast.Call) and self.function_outputs(v):
            self.call_function_stmt(v, target)
            return
        code, t = self.expr(v)
        self.emit_lines(target.write(self.coerce(code, t, target.type, s.span)))

    def copy_array(self, target: LValue, value: ast.Expr, span):
        code, t = self.expr(value)
        if not isinstance(t, ArrayT) or t.size != target.type.size or t.elem != target.type.elem:
            raise CompileError(span, f"cannot assign {t} to {target.type}")
        if isinstance(t.elem, StructT):
            self.em.line(f"for _d, _s in zip({target.read}, {code}): _d._copy_from(_s)")
        else:
            self.em.line(f"{target.read}[:] = {code}")

    def stmt_CallStmt(self, s: ast.CallStmt):
        c = s.call
        kind = self.m.classify_call(c, self)
        if kind == "fb":
            self.call_fb(c)
        elif kind == "function":
            self.call_function_stmt(c, None)
        elif kind == "instruction":
            self.call_instruction(c, as_stmt=True)
        else:
            code, _ = self.call_expr(c)
            self.em.line(code)

    def stmt_If(self, s: ast.If):
        for i, br in enumerate(s.branches):
            code, t = self.expr(br.cond)
            if t != "BOOL":
                raise CompileError(br.cond.span, f"condition must be BOOL, not {t}")
            self.em.line(("if " if i == 0 else "elif ") + code + ":")
            self.em.indent()
            self.block(br.body)
            self.em.dedent()
        if s.else_body:
            self.em.line("else:")
            self.em.indent()
            self.block(s.else_body)
            self.em.dedent()

    def stmt_Case(self, s: ast.Case):
        code, t = self.expr(s.selector)
        sel = self.new_tmp("_c")
        self.em.line(f"{sel} = {code}")
        first = True
        for clause in s.clauses:
            conds = []
            singles = []
            for lab in clause.labels:
                if isinstance(lab, ast.CaseRange):
                    lo = self.m.const(lab.low, self.info)
                    hi = self.m.const(lab.high, self.info)
                    conds.append(f"{lo} <= {sel} <= {hi}")
                else:
                    singles.append(self.m.const(lab, self.info))
            if len(singles) == 1:
                conds.insert(0, f"{sel} == {singles[0]!r}")
            elif singles:
                conds.insert(0, f"{sel} in {{{', '.join(map(repr, singles))}}}")
            self.em.line(("if " if first else "elif ") + " or ".join(conds) + ":")
            first = False
            self.em.indent()
            self.block(clause.body)
            self.em.dedent()
        if s.else_body:
            if first:
                self.block(s.else_body)
            else:
                self.em.line("else:")
                self.em.indent()
                self.block(s.else_body)
                self.em.dedent()

    def stmt_For(self, s: ast.For):
        var = self.lvalue(s.var)
        if var.prep or not is_int(var.type):
            raise CompileError(s.var.span, "the FOR variable must be a plain integer label")
        start = self.m.try_const(s.start, self.info)
        end = self.m.try_const(s.end, self.info)
        step = 1 if s.step is None else self.m.try_const(s.step, self.info)
        t = var.type
        lo_t, hi_t = _int_range(t)
        if (start is not None and end is not None and step not in (None, 0)
                and lo_t <= end + step <= hi_t and not _assigns(s.body, s.var)
                and _iterations(start, end, step) <= LOOP_LIMIT):
            # constant bounds and a body that leaves the counter alone: a Python range (more
            # iterations than the watchdog allows go the guarded way: FOR i := 0 TO 2000000000
            # ran for hours instead of stopping with the CPU's watchdog timer error)
            v = self.new_tmp("_i")
            head = len(self.em.lines)
            self.em.line(f"for {v} in range({start}, {end + (1 if step > 0 else -1)}, {step}):")
            self.em.indent()
            self.emit_lines(var.write(v))
            body = len(self.em.lines)
            last = start + ((end - start) // step) * step
            known = isinstance(s.var, ast.Name)
            if known:  # inside the body the counter is the Python loop variable, in a known range
                self.loop_vars[s.var.key] = (v, min(start, last), max(start, last))
            try:
                self.block(s.body)
            finally:
                if known:
                    self.loop_vars.pop(s.var.key, None)
            self.em.dedent()
            n = _iterations(start, end, step)
            self.em.line("else:")
            self.em.indent()
            self.emit_lines(var.write(repr(start + n * step)))
            self.em.dedent()
            if step == 1 and n > 0 and len(self.em.lines) - body == 3:
                self._copy_loop_as_slice(head, body, v, start, n)
            return
        sc, st = self.expr(s.start)
        ec, et = self.expr(s.end)
        self.emit_lines(var.write(self.coerce(sc, st, t, s.start.span)))
        e_tmp = self.new_tmp("_e")
        self.em.line(f"{e_tmp} = {ec}")
        if s.step is None:
            step_code, cond = "1", f"{var.read} <= {e_tmp}"
        elif step is not None:
            step_code = repr(step)
            cond = f"{var.read} <= {e_tmp}" if step > 0 else f"{var.read} >= {e_tmp}"
        else:
            step_code = self.new_tmp("_s")
            self.em.line(f"{step_code} = {self.expr(s.step)[0]}")
            cond = f"({var.read} <= {e_tmp} if {step_code} >= 0 else {var.read} >= {e_tmp})"
        self.guarded_loop(cond, s.span)
        self.block(s.body)
        self.emit_lines(var.write(norm_code(t, f"{var.read} + {step_code}")))
        self.em.dedent()

    def _copy_loop_as_slice(self, head: int, body: int, v: str, start: int, n: int) -> None:
        """A FOR loop over constant bounds whose whole body copies one element of an array
        label into another, index for index (`dst[i + a] := src[i + b]`: the 16-word copies
        of the port FBs), emitted above as `for v in range(...)`, its counter's write, the
        copy, and the `else:` with the counter's last value: run it as one slice assignment
        (a list copy in C, the same elements), the counter then written once with its last
        value, as the loop leaves it (nothing runs between the iterations that could read it:
        the body is that one line, and its indexes are in range, the compiler having left out
        their check). When both names hold the same list (VAR_IN_OUT handed the one array
        twice), the element-by-element loop runs as before: an overlapping copy differs."""
        lines, spans = self.em.lines, self.em.spans
        copy = _ELEMENT_COPY.fullmatch(lines[body].strip())
        if copy is None or copy["dst"] == copy["src"]:
            return
        dst, src = _index_offset(copy["di"], v), _index_offset(copy["si"], v)
        if dst is None or src is None or start + dst < 0 or start + src < 0:
            return
        indent = lines[head][: len(lines[head]) - len(lines[head].lstrip())]
        loop, loop_spans = lines[head:], spans[head:]
        final = lines[-1].strip()  # the counter's last value, under the loop's `else:`
        d, s = copy["dst"], copy["src"]
        fast = [f"if {d} is not {s}:",
                f"    {d}[{start + dst}:{start + dst + n}] = {s}[{start + src}:{start + src + n}]",
                f"    {final}",
                "else:"]
        del lines[head:], spans[head:]
        lines.extend(indent + text for text in fast)
        spans.extend([loop_spans[0]] * len(fast))
        lines.extend("    " + text for text in loop)
        spans.extend(loop_spans)

    def stmt_While(self, s: ast.While):
        code, _ = self.expr(s.cond)
        self.guarded_loop(code, s.span)
        self.block(s.body)
        self.em.dedent()

    def guarded_loop(self, cond: str, span) -> None:
        """`while cond:` with an iteration counter standing in for the CPU's watchdog
        timer (a loop that never ends in the simulator stops it with the ST location)."""
        n = self.new_tmp("_n")
        self.em.line(f"{n} = 0")
        self.em.line(f"while {cond}:")
        self.em.indent()
        self.em.line(f"{n} += 1")
        self.em.line(f"if {n} > {LOOP_LIMIT}: _wdt({self.loc(span)})")

    def stmt_Repeat(self, s: ast.Repeat):
        self.guarded_loop("True", s.span)
        self.block(s.body)
        code, _ = self.expr(s.until)
        self.em.line(f"if {code}: break")
        self.em.dedent()

    def stmt_Exit(self, s):
        self.em.line("break")

    def stmt_Return(self, s):
        self.em.line(self.return_code())

    def return_code(self) -> str:
        if not self.is_function:
            return "return"
        outs = self.info.outputs
        if outs:
            return "return (_ret, " + ", ".join(o.code for o in outs) + ")"
        return "return _ret"


LONG_CHAIN = 16  # operators in a left-deep chain compiled step by step (see chain())


def _iterations(start: int, end: int, step: int) -> int:
    """How often FOR start TO end BY step runs its body (step not 0)."""
    return max(0, (end - start) // step + 1) if (end - start) * step >= 0 else 0


def _typed_literal(code: str, src, dst) -> str:
    if src == ANYINT and not _is_number(code):
        return norm_code(dst, code)
    return code


def _real_typed(code: str, src, dst) -> str:
    """A constant (`1.3`, or a constant expression) meeting a REAL operand is a REAL on
    the CPU: single precision before the operation, as a REAL label holding it would be
    (`1.3 / r` and `c / r` with c := 1.3 give the same 12.999999 for r = 0.1). LREAL and
    labels are left as they are."""
    if src not in (ANYREAL, ANYINT) or not is_real(dst) or concrete(dst) != "REAL":
        return code
    try:
        value = float(code)
    except ValueError:
        return norm_code("REAL", code) if src == ANYREAL else code
    return repr(datatypes.NORMALIZERS["REAL"](value))


def _is_number(code: str) -> bool:
    """Is `code` a plain numeric literal (so a conversion can be done at compile time)?"""
    text = code[1:] if code.startswith("-") else code
    return text.isdigit() or text.replace(".", "", 1).isdigit()


def _strides(dims) -> list[int]:
    """Row-major strides of a flattened multi-dimensional array."""
    strides = []
    stride = 1
    for lo, hi in reversed(dims):
        strides.append(stride)
        stride *= hi - lo + 1
    return strides[::-1]


_PLAIN_TOKEN = re.compile(r"\s+|([A-Za-z_][A-Za-z0-9_]*(?:\.[A-Za-z_][A-Za-z0-9_]*)*)(\s*\()?"
                          r"|\d+|\[\d+\]|==|!=|<=|>=|[()<>&|^+\-~]")
_OPERATOR_WORDS = {"not", "and", "or"}  # may stand before a parenthesis
_PLAIN_WORDS = _OPERATOR_WORDS | {"True", "False"}


def cannot_fail(code: str) -> bool:
    """True when generated expression code only reads labels, constant-address devices
    and literals through comparisons and bit/sign operators: no call, no computed index,
    no division, no walrus - evaluating it or not changes nothing but its value."""
    pos = 0
    while pos < len(code):
        m = _PLAIN_TOKEN.match(code, pos)
        if m is None:
            return False
        name, call = m.group(1), m.group(2)
        if name is not None and (call is not None and name not in _OPERATOR_WORDS
                                 or keyword.iskeyword(name) and name not in _PLAIN_WORDS):
            return False
        pos = m.end()
    return True


_ARITH = {"+": int.__add__, "-": int.__sub__, "*": int.__mul__}


# `dst[index] = src[index]`: an element copy between two label arrays (attribute chains),
# each index the loop variable plus or minus a constant, with no range check emitted
_ELEMENT_COPY = re.compile(r"(?P<dst>[A-Za-z_]\w*(?:\.\w+)+)\[(?P<di>[^\[\]]+)\] = "
                           r"(?P<src>[A-Za-z_]\w*(?:\.\w+)+)\[(?P<si>[^\[\]]+)\]")


def _index_offset(code: str, v: str) -> int | None:
    """The constant c of an index `v`, `c + v`, `v + c` or `v - c` (in brackets or not);
    None for anything else."""
    if code == v:
        return 0
    if code.startswith("(") and code.endswith(")"):
        code = code[1:-1]
    m = re.fullmatch(rf"(\d+) \+ {v}|{v} ([+-]) (\d+)", code)
    if m is None:
        return None
    if m.group(1) is not None:
        return int(m.group(1))
    return int(m.group(3)) * (1 if m.group(2) == "+" else -1)


def _int_range(t):
    t = concrete(t)
    info = datatypes.TYPES.get(t)
    if info is None or not info.is_integer:
        return (-(1 << 31), (1 << 31) - 1)
    if info.kind == "signed":
        return (-(1 << (info.bits - 1)), (1 << (info.bits - 1)) - 1)
    return (0, (1 << info.bits) - 1)


def _assigns(stmts, var: ast.Expr) -> bool:
    """Does any statement (nested) assign the label `var`?"""
    if not isinstance(var, ast.Name):
        return True
    key = var.key

    def visit(node) -> bool:
        if isinstance(node, ast.Assign):
            t = node.target
            return isinstance(t, ast.Name) and t.key == key
        if isinstance(node, ast.For):
            if isinstance(node.var, ast.Name) and node.var.key == key:
                return True
            return any(visit(s) for s in node.body)
        if isinstance(node, ast.If):
            return any(visit(s) for b in node.branches for s in b.body) or any(
                visit(s) for s in (node.else_body or []))
        if isinstance(node, ast.Case):
            return any(visit(s) for c in node.clauses for s in c.body) or any(
                visit(s) for s in (node.else_body or []))
        if isinstance(node, (ast.While, ast.Repeat)):
            return any(visit(s) for s in node.body)
        if isinstance(node, ast.CallStmt):
            # an output binding or an instruction output operand may write it
            return any(isinstance(a.value, ast.Name) and a.value.key == key
                       and (a.output or a is not node.call.args[0]) for a in node.call.args)
        return False

    return any(visit(s) for s in stmts)
