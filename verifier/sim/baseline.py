"""A plain tree-walking interpreter of the same checked AST: the baseline bench/simulate.py
measures the compiler against.  It shares the runtime, devices, standard FBs and
instruction models with the compiled simulator and walks the syntax tree on every scan.
Not used by the verifier itself."""
from __future__ import annotations

from verifier.st import ast

from . import datatypes
from .compiler import ModuleCompiler
from .instructions import InstructionSet
from .instructions import lookup as lookup_instruction
from .refs import Ref
from .stdfbs import STANDARD_FBS
from .stdfuncs import make_helpers
from .typesys import ArrayT, FbT, StringT, StructT, concrete, is_int, is_real, unify

_OPS = {
    "+": lambda a, b: a + b, "-": lambda a, b: a - b, "*": lambda a, b: a * b,
    "=": lambda a, b: a == b, "<>": lambda a, b: a != b, "<": lambda a, b: a < b,
    ">": lambda a, b: a > b, "<=": lambda a, b: a <= b, ">=": lambda a, b: a >= b,
}


class _Exit(Exception):
    pass


class _Return(Exception):
    pass


class Instance:
    """Memory of one FB/PROGRAM/structure: a dict of label key -> value."""

    def __init__(self, info, values: dict):
        self.info = info
        self.values = values


class Interpreter:
    def __init__(self, files: list[ast.SourceFile], rt, cpu):
        self.rt = rt
        self.mc = ModuleCompiler(files, rt, cpu)
        self.mc.build_symbols()
        self.ins = InstructionSet(rt)
        self.h = make_helpers(rt)
        self.globals = Instance(None, {k: self.default(s.type, s.decl.init, None) for k, s in self.mc.globals.items()})
        self.pulse: dict[tuple[int, int], bool] = {}

    # ------------------------------------------------------------------ memory
    def default(self, t, init=None, info=None):
        if isinstance(t, ArrayT):
            if isinstance(t.elem, (str, StringT)):
                return eval(self.mc.init_value(t, init, info, None))
            return [self.default(t.elem) for _ in range(t.size)]
        if isinstance(t, StructT):
            return Instance(None, {k: self.default(f.type, f.decl.init) for k, f in self.mc.struct_fields[t.name].items()})
        if isinstance(t, FbT):
            if t.standard:
                return STANDARD_FBS[t.name](self.rt)
            return self.new(t.name)
        return eval(self.mc.init_value(t, init, info, None))

    def new(self, key: str) -> Instance:
        info = self.mc.pous[key]
        values = {}
        for k, s in info.symbols.items():
            if s.section in ("VAR_EXTERNAL", "VAR_GLOBAL", "RETURN"):
                continue
            values[k] = self.default(s.type, s.decl.init, info)
        return Instance(info, values)

    def symbol(self, inst: Instance, key: str):
        s = inst.info.symbols.get(key) if inst.info else None
        return s if s is not None else self.mc.globals[key]

    def scope_of(self, inst: Instance, key: str) -> Instance:
        return inst if key in inst.values else self.globals

    # ------------------------------------------------------------------ places
    def place(self, e, inst):
        """(container, key, type) of a writable place; container is a dict or a list."""
        if isinstance(e, ast.Name):
            sym = self.symbol(inst, e.key)
            return self.scope_of(inst, e.key).values, e.key, sym.type
        if isinstance(e, ast.Member):
            base, bt = self.eval(e.base, inst)
            if isinstance(base, Instance):
                t = (self.mc.struct_fields[bt.name][e.key].type if isinstance(bt, StructT)
                     else base.info.symbols[e.key].type)
                return base.values, e.key, t
            t, attr = self.mc.member_of(bt, e.member, e.span)
            return base, attr, t
        if isinstance(e, ast.Index):
            base, bt = self.eval(e.base, inst)
            flat = 0
            for (lo, hi), ix in zip(bt.dims, e.indices):
                i, _ = self.eval(ix, inst)
                if not lo <= i <= hi:
                    self.rt.fail(self.mc.loc(ix.span), f"array index {i} is outside [{lo}..{hi}]")
                flat = flat * (hi - lo + 1) + (i - lo)
            return base, flat, bt.elem
        if isinstance(e, ast.Device):
            area = self.mc.cpu.areas[e.kind]
            return self.rt.dev.areas[e.kind], int(e.address, area.radix), "BOOL" if area.kind == "bit" else "INT"
        raise NotImplementedError(type(e).__name__)

    @staticmethod
    def load(container, key):
        if isinstance(container, dict):
            return container[key]
        if isinstance(container, list):
            return container[key]
        return getattr(container, key)

    @staticmethod
    def store(container, key, value):
        if isinstance(container, (dict, list)):
            container[key] = value
        else:
            setattr(container, key, value)

    def assign(self, target, value, vtype, inst):
        if isinstance(target, ast.BitAccess):
            c, k, t = self.place(target.base, inst)
            word = self.load(c, k)
            word = word | (1 << target.bit) if value else word & ~(1 << target.bit)
            self.store(c, k, datatypes.NORMALIZERS[t](word))
            return
        if isinstance(target, ast.Device) and target.bit is not None:
            c, k, _ = self.place(ast.Device(target.kind, target.address, target.number), inst)
            word = c[k] & 0xFFFF
            c[k] = datatypes.wrap16(word | (1 << target.bit) if value else word & ~(1 << target.bit))
            return
        c, k, t = self.place(target, inst)
        if isinstance(t, ArrayT):
            c[k][:] = value if not isinstance(c, dict) else value
            return
        self.store(c, k, self.convert(value, vtype, t))

    def convert(self, value, src, dst):
        if isinstance(dst, StringT):
            return value[: dst.length]
        if not isinstance(dst, str) or dst == "BOOL" or src == dst:
            return value
        if is_real(dst):
            return datatypes.NORMALIZERS[dst](float(value))
        if is_real(src) or src == "ANYREAL":
            return self.h["_r2i"](value, dst, None)
        return datatypes.NORMALIZERS[dst](value)

    # ------------------------------------------------------------------ expressions
    def eval(self, e, inst):
        """(value, type) of an expression: dispatch on the node class."""
        return self._eval[type(e)](self, e, inst)

    def _literal(self, e, inst):
        if isinstance(e, ast.BoolLiteral):
            return e.value, "BOOL"
        if isinstance(e, ast.IntLiteral):
            return e.value, "ANYINT"
        if isinstance(e, ast.RealLiteral):
            return e.value, "ANYREAL"
        if isinstance(e, ast.TimeLiteral):
            return e.ms, "TIME"
        return e.value, StringT(255)

    def _name(self, e, inst):
        key = e.name.upper()
        sym = self.symbol(inst, key)
        if sym.is_constant and sym.constant_value is not None:
            return sym.constant_value, sym.type
        values = inst.values
        return (values[key] if key in values else self.globals.values[key]), sym.type

    def _bit(self, e, inst):
        v, _ = self.eval(e.base, inst)
        return (v >> e.bit) & 1 == 1, "BOOL"

    def _place_value(self, e, inst):
        if isinstance(e, ast.Device) and e.bit is not None:
            c, k, _ = self.place(ast.Device(e.kind, e.address, e.number), inst)
            return (c[k] >> e.bit) & 1 == 1, "BOOL"
        c, k, t = self.place(e, inst)
        return self.load(c, k), t

    def _unary(self, e, inst):
        v, t = self.eval(e.operand, inst)
        if e.op == "-":
            return (-v if not isinstance(t, str) or t not in datatypes.TYPES else
                    datatypes.NORMALIZERS[t](-v)), t
        if t == "BOOL":
            return not v, t
        return datatypes.NORMALIZERS[concrete(t)](~v), t

    def binary(self, e, inst):
        a, at = self.eval(e.left, inst)
        b, bt = self.eval(e.right, inst)
        op = e.op
        if op in ("AND", "OR", "XOR"):
            r = {"AND": a & b, "OR": a | b, "XOR": a ^ b}[op]
            return (bool(r), "BOOL") if at == "BOOL" else (r, unify(at, bt))
        if op in ("=", "<>", "<", ">", "<=", ">="):
            return _OPS[op](a, b), "BOOL"
        t = unify(at, bt)
        k = self.mc.loc(e.span) if op in ("/", "MOD", "**") else None
        if op == "/":
            r = self.h["_rdiv"](a, b, k) if is_real(t) or t == "ANYREAL" else self.h["_idiv"](a, b, k)
        elif op == "MOD":
            r = self.h["_imod"](a, b, k)
        elif op == "**":
            return datatypes.to_f32(self.h["_expt"](a, b, k)), "REAL"
        else:
            r = _OPS[op](a, b)
        if t in ("ANYINT", "ANYREAL"):
            return r, t
        return datatypes.NORMALIZERS[t](r), t

    # ------------------------------------------------------------------ calls
    def call(self, c: ast.Call, inst):
        kind = self.mc.classify_call(c, _Classifier(inst))
        if kind == "fb":
            return self.call_fb(c, inst), "BOOL"
        if kind == "function":
            return self.call_function(c, inst)
        if kind == "instruction":
            return self.call_instruction(c, inst), "BOOL"
        args = [self.eval(a.value, inst) for a in c.args]
        return self.std_function(c, args)

    def std_function(self, c, args):
        name = c.key
        vals = [v for v, _ in args]
        t = args[0][1] if args else "INT"
        if name in ("SHL", "SHR", "ROL", "ROR"):
            bits = 32 if concrete(t) in ("DWORD", "DINT", "UDINT") else 16
            mask = (1 << bits) - 1
            v, n = vals[0] & mask, vals[1]
            r = {"SHL": (v << n) & mask, "SHR": v >> n, "ROL": self.h["_rol"](v, n, bits),
                 "ROR": self.h["_ror"](v, n, bits)}[name]
            return datatypes.NORMALIZERS[concrete(t)](r), t
        if "_TO_" in name:
            src, dst = name.split("_TO_", 1)
            v = vals[0]
            if dst == "BOOL":
                return v != 0, "BOOL"
            if dst == "BCD":
                return self.h["_to_bcd"](v, 16, None), "WORD"
            if src == "BCD":
                return self.h["_from_bcd"](v, 16, None), dst
            if t == "BOOL":
                v = int(v)
            return self.convert(v, t, dst), dst
        if name in ("MAX", "MIN"):
            return (max if name == "MAX" else min)(vals), t
        if name == "LIMIT":
            return min(max(vals[1], vals[0]), vals[2]), args[1][1]
        if name == "SEL":
            return (vals[2] if vals[0] else vals[1]), args[1][1]
        if name == "MOVE":
            return vals[0], t
        if name == "ABS":
            return abs(vals[0]), t
        raise NotImplementedError(f"baseline interpreter: standard function {name}")

    def call_fb(self, c: ast.Call, inst):
        obj, t = self.eval(c.callee, inst)
        outs = []
        for a in c.args:
            if a.output:
                outs.append(a)
                continue
            v, vt = self.eval(a.value, inst)
            if isinstance(obj, Instance):
                sym = obj.info.symbols[a.key]
                obj.values[a.key] = v if isinstance(sym.type, (ArrayT, StructT)) else self.convert(v, vt, sym.type)
            else:
                mt, attr = self.mc.member_of(t, a.name, a.span)
                setattr(obj, attr, self.convert(v, vt, mt))
        if isinstance(obj, Instance):
            self.run_body(obj)
            for a in outs:
                sym = obj.info.symbols[a.key]
                self.assign(a.value, obj.values[a.key], sym.type, inst)
        else:
            obj._body()
            for a in outs:
                mt, attr = self.mc.member_of(t, a.name, a.span)
                self.assign(a.value, getattr(obj, attr), mt, inst)
        return True

    def call_function(self, c: ast.Call, inst):
        info = self.mc.functions[c.key]
        frame = self.new(info.key)
        positional = [a for a in c.args if a.name is None]
        for p, a in zip(info.inputs, positional):
            v, vt = self.eval(a.value, inst)
            frame.values[p.key] = list(v) if isinstance(p.type, ArrayT) else self.convert(v, vt, p.type)
        for a in c.args:
            if a.name is not None and not a.output:
                v, vt = self.eval(a.value, inst)
                frame.values[a.key] = list(v) if isinstance(info.symbols[a.key].type, ArrayT) else self.convert(
                    v, vt, info.symbols[a.key].type)
        frame.values[info.key] = self.default(info.return_type)
        self.run_body(frame)
        return frame.values[info.key], info.return_type

    def call_instruction(self, c: ast.Call, inst):
        spec, pulse = lookup_instruction(c.key, self.mc.cpu.family)
        en, _ = self.eval(c.args[0].value, inst)
        if pulse:
            key = (id(inst), id(c))
            prev = self.pulse.get(key, False)
            self.pulse[key] = en
            en = en and not prev
        if not en:
            return False
        ops = []
        k = self.mc.loc(c.span)
        for kind, a in zip(spec.operands, c.args[1:]):
            if kind == "val":
                ops.append(self.eval(a.value, inst)[0])
                continue
            e = a.value
            if isinstance(e, ast.Index):
                base, bt = self.eval(e.base, inst)
                _, flat, et = self.place(e, inst)
                ops.append(Ref(base, flat, et, self.rt, k, ""))
            else:
                c_, key, t = self.place(e, inst)
                if isinstance(t, ArrayT):
                    ops.append(Ref(self.load(c_, key), 0, t.elem, self.rt, k, ""))
                elif isinstance(c_, list):
                    ops.append(Ref(c_, key, t, self.rt, k, ""))
                else:
                    ops.append(_DictRef(c_, key, t, self.rt, k))
        return getattr(self.ins, spec.name)(True, *ops, k)

    # ------------------------------------------------------------------ statements
    def run_body(self, inst: Instance) -> None:
        try:
            self.block(inst.info.pou.body, inst)
        except _Return:
            pass

    def block(self, stmts, inst):
        for s in stmts:
            self.stmt(s, inst)

    def stmt(self, s, inst):
        if isinstance(s, ast.Assign):
            v, vt = self.eval(s.value, inst)
            self.assign(s.target, v, vt, inst)
        elif isinstance(s, ast.CallStmt):
            self.call(s.call, inst)
        elif isinstance(s, ast.If):
            for br in s.branches:
                if self.eval(br.cond, inst)[0]:
                    self.block(br.body, inst)
                    return
            if s.else_body:
                self.block(s.else_body, inst)
        elif isinstance(s, ast.Case):
            sel, _ = self.eval(s.selector, inst)
            for clause in s.clauses:
                for lab in clause.labels:
                    if isinstance(lab, ast.CaseRange):
                        hit = self.eval(lab.low, inst)[0] <= sel <= self.eval(lab.high, inst)[0]
                    else:
                        hit = sel == self.eval(lab, inst)[0]
                    if hit:
                        self.block(clause.body, inst)
                        return
            if s.else_body:
                self.block(s.else_body, inst)
        elif isinstance(s, ast.For):
            start, st = self.eval(s.start, inst)
            self.assign(s.var, start, st, inst)
            step = self.eval(s.step, inst)[0] if s.step is not None else 1
            try:
                while True:
                    v, _ = self.eval(s.var, inst)
                    end, _ = self.eval(s.end, inst)
                    if (step > 0 and v > end) or (step < 0 and v < end):
                        break
                    self.block(s.body, inst)
                    v, vt = self.eval(s.var, inst)
                    self.assign(s.var, v + step, "ANYINT", inst)
            except _Exit:
                pass
        elif isinstance(s, ast.While):
            try:
                while self.eval(s.cond, inst)[0]:
                    self.block(s.body, inst)
            except _Exit:
                pass
        elif isinstance(s, ast.Repeat):
            try:
                while True:
                    self.block(s.body, inst)
                    if self.eval(s.until, inst)[0]:
                        break
            except _Exit:
                pass
        elif isinstance(s, ast.Exit):
            raise _Exit
        elif isinstance(s, ast.Return):
            raise _Return


Interpreter._eval = {
    ast.IntLiteral: Interpreter._literal, ast.BoolLiteral: Interpreter._literal,
    ast.RealLiteral: Interpreter._literal, ast.TimeLiteral: Interpreter._literal,
    ast.StringLiteral: Interpreter._literal, ast.Name: Interpreter._name,
    ast.BitAccess: Interpreter._bit, ast.Member: Interpreter._place_value,
    ast.Index: Interpreter._place_value, ast.Device: Interpreter._place_value,
    ast.UnaryOp: Interpreter._unary, ast.BinaryOp: Interpreter.binary, ast.Call: Interpreter.call,
}


class _Classifier:
    """What ModuleCompiler.classify_call needs to know about the calling scope."""

    def __init__(self, inst: Instance):
        self.info = inst.info


class _DictRef(Ref):
    """A scalar label (dict entry) used as an instruction operand."""

    def __init__(self, values: dict, key: str, type_name, rt, loc_id):
        super().__init__([], 0, type_name, rt, loc_id, key)
        self.values = values
        self.key = key

    def get(self, k: int = 0):
        return self.values[self.key]

    def set(self, k: int, value) -> None:
        self.values[self.key] = self.norm(value)

    def get_u16(self, k: int = 0) -> int:
        return int(self.values[self.key]) & 0xFFFF


def run_programs(interp: Interpreter, keys: list[str], stop_us: int) -> None:
    """Scan the named programs in order until virtual time `stop_us`."""
    rt = interp.rt
    programs = [interp.new(k.upper()) for k in keys]
    while rt.now_us < stop_us:
        rt.begin_scan()
        for p in programs:
            interp.run_body(p)
        rt.end_scan()


__all__ = ["Interpreter", "run_programs", "is_int"]
