"""Calls in ST statements and expressions -> Python: function block instances (inlined
standard FB bodies), user FUNCTIONs with outputs and VAR_IN_OUT, MELSEC instructions with
their block operands (`Ref`s) and pulse forms.  A mixin of `codegen.BodyCompiler`."""
from __future__ import annotations

from typing import TYPE_CHECKING

from verifier.st import ast
from verifier.st.check import called_without

from . import instructions, stdfuncs
from .cpu import SEND_FLAGS
from .stdfbs import STANDARD_FBS, body_code
from .typesys import ArrayT, CompileError, FbT, StructT, Symbol, is_real

if TYPE_CHECKING:
    from .codegen import LValue


class CallCompiler:
    def call_expr(self, c: ast.Call):
        kind = self.m.classify_call(c, self)
        if kind == "function":
            code, t = self.function_call_code(c)
            if self.function_outputs(c):
                raise CompileError(c.span, "a FUNCTION with outputs (=>) must be called as a "
                                           "statement or as the whole right-hand side")
            return code, t
        if kind == "instruction":
            return self.call_instruction(c, as_stmt=False)
        if kind == "fb":
            raise CompileError(c.span, "a function block call is a statement, not a value")
        args = []
        for a in c.args:
            if a.name is not None:
                raise CompileError(a.span, f"{c.name} takes positional arguments")
            args.append(self.expr(a.value))
        res = stdfuncs.generate(c.key, args, self, c.span)
        if res is None:
            raise CompileError(c.span, f"unknown function {c.name!r}")
        return res

    def call_fb(self, c: ast.Call):
        code, t = self.expr(c.callee)
        if not isinstance(t, FbT):
            raise CompileError(c.span, f"{self.label_of(c.callee)} is not a function block instance")
        o = self.new_tmp("_o")
        self.em.line(f"{o} = {code}")
        if not t.standard:
            self.fb_calls[o] = t.name
        after = []
        en_code = None
        for a in c.args:
            if a.name is None:
                raise CompileError(a.span, "function block arguments must be named (IN := ...)")
            if a.key == "EN" and not a.output:
                en_code = self.expr(a.value)[0]
                continue
            mt, attr = self.m.member_of(t, a.name, a.span)
            section = self.m.member_section(t, a.key)
            if a.output:
                target = self.lvalue(a.value)
                after.append((target, f"{o}.{attr}", mt, a.span))
                continue
            if section == "VAR_IN_OUT":
                if isinstance(mt, (ArrayT, StructT, FbT)):
                    vcode, vt = self.expr(a.value)
                    self.em.line(f"{o}.{attr} = {vcode}")
                else:
                    target = self.lvalue(a.value)
                    for p in target.prep:
                        self.em.line(p)
                    self.em.line(f"{o}.{attr} = {target.read}")
                    after.append((target, f"{o}.{attr}", mt, a.span))
                continue
            if isinstance(mt, ArrayT):
                vcode, vt = self.expr(a.value)
                self.em.line(f"{o}.{attr}[:] = {vcode}")
                continue
            if isinstance(mt, StructT):
                vcode, vt = self.expr(a.value)
                self.em.line(f"{o}.{attr}._copy_from({vcode})")
                continue
            vcode, vt = self.expr(a.value)
            self.em.line(f"{o}.{attr} = {self.coerce(vcode, vt, mt, a.span)}")
        if en_code is not None:
            self.em.line(f"if {en_code}:")
            self.em.indent()
        std = STANDARD_FBS.get(t.name) if t.standard else None
        if std is not None and std.BODY:
            self.emit_lines(body_code(std, o, "_rt", self.new_tmp("_t")))  # inline, no call
        else:
            self.em.line(f"{o}._body()")
        for target, src, mt, span in after:
            for p in target.prep:
                self.em.line(p)
            self.emit_lines(target.write(self.coerce(src, mt, target.type, span)))
        if en_code is not None:
            self.em.dedent()

    def function_outputs(self, c: ast.Call) -> bool:
        info = self.m.functions.get(c.key)
        return bool(info and info.outputs and not self.m.is_variable(c, self))

    def function_call_code(self, c: ast.Call):
        info = self.m.functions[c.key]
        params = info.inputs
        values: dict[str, str] = {}
        pos = 0
        for a in c.args:
            if a.output:
                continue
            if a.name is None:
                if pos >= len(params):
                    raise CompileError(a.span, f"{c.name} takes {len(params)} input(s)")
                p = params[pos]
                pos += 1
            else:
                matches = [p for p in params if p.key == a.key]
                if not matches:
                    raise CompileError(a.span, f"{c.name} has no input {a.name}")
                p = matches[0]
            vcode, vt = self.expr(a.value)
            if isinstance(p.type, (ArrayT, StructT)):
                if vt != p.type:
                    raise CompileError(a.span, f"{c.name}.{p.name} is {p.type}, got {vt}")
                values[p.key] = vcode
            else:
                values[p.key] = self.coerce(vcode, vt, p.type, a.span)
        missing = [p.name for p in params if p.key not in values]
        if missing:  # the checker reports it first; never run the call with made-up inputs
            raise CompileError(c.span, called_without(c.name, missing))
        arglist = [values[p.key] for p in params]
        return f"{info.class_name}({', '.join(arglist)})", info.return_type

    def call_function_stmt(self, c: ast.Call, target: LValue | None):
        info = self.m.functions[c.key]
        code, rtype = self.function_call_code(c)
        if not info.outputs:
            if target is not None:
                self.emit_lines(target.write(self.coerce(code, rtype, target.type, c.span)))
            else:
                self.em.line(code)
            return
        r = self.new_tmp("_r")
        self.em.line(f"{r} = {code}")
        if target is not None:
            self.emit_lines(target.write(self.coerce(f"{r}[0]", rtype, target.type, c.span)))
        by_key = {o.key: i + 1 for i, o in enumerate(info.outputs)}
        # VAR_IN_OUT scalars are written back from the positional argument they came from
        for i, p in enumerate(info.inputs):
            if p.section == "VAR_IN_OUT" and p.key in by_key:
                arg = self.arg_for(c, p, i)
                if arg is not None:
                    lv = self.lvalue(arg)
                    for pr in lv.prep:
                        self.em.line(pr)
                    self.emit_lines(lv.write(self.coerce(f"{r}[{by_key[p.key]}]", p.type, lv.type, c.span)))
        for a in c.args:
            if a.output:
                if a.key not in by_key:
                    raise CompileError(a.span, f"{c.name} has no output {a.name}")
                o = info.outputs[by_key[a.key] - 1]
                lv = self.lvalue(a.value)
                for pr in lv.prep:
                    self.em.line(pr)
                self.emit_lines(lv.write(self.coerce(f"{r}[{by_key[a.key]}]", o.type, lv.type, a.span)))

    @staticmethod
    def arg_for(c: ast.Call, p: Symbol, position: int):
        pos = 0
        for a in c.args:
            if a.output:
                continue
            if a.name is None:
                if pos == position:
                    return a.value
                pos += 1
            elif a.key == p.key:
                return a.value
        return None

    def call_instruction(self, c: ast.Call, as_stmt: bool):
        spec, pulse = instructions.lookup(c.key, self.family)
        missing = instructions.not_on_cpu(c.name, self.m.cpu)
        if missing:
            raise CompileError(c.span, missing)
        want = 1 + len(spec.operands)
        if len(c.args) != want or any(a.name is not None for a in c.args):
            raise CompileError(c.span, f"{c.name} is called with {want} positional operands "
                                       f"(EN first), got {len(c.args)}")
        en_code, en_t = self.expr(c.args[0].value)
        if en_t != "BOOL":
            raise CompileError(c.args[0].span, f"EN of {c.name} must be BOOL, not {en_t}")
        k = self.loc(c.span)
        ops = []
        after = []
        for kind, a in zip(spec.operands, c.args[1:]):
            if kind == "val":
                vcode, vt = self.expr(a.value)
                if is_real(vt):
                    raise CompileError(a.span, f"{c.name} operand must be an integer")
                ops.append(vcode)
            else:
                ref, post = self.ref_code(a.value, kind, wide=spec.wide)
                ops.append(ref)
                after.extend(post)
        if pulse or spec.edge:
            if self.is_function:
                raise CompileError(c.span, f"{c.name} needs memory of its last EN: not inside a FUNCTION")
            slot = f"_p{len(self.pulse_slots)}"
            self.pulse_slots.append(slot)
            en_var = self.new_tmp("_en")
            self.em.line(f"{en_var} = {en_code}")
            if spec.edge == "fall":
                en_code = f"(self.{slot} and not {en_var})"
            else:
                en_code = f"({en_var} and not self.{slot})"
            call = f"_I.{spec.name}({en_code}, {', '.join(ops)}, {k})"
            if not as_stmt:
                raise CompileError(c.span, f"{c.name} (pulse form) must be called as a statement")
            self.em.line(call)
            self.em.line(f"self.{slot} = {en_var}")
        else:
            if not as_stmt:
                if after:
                    raise CompileError(c.span, f"call {c.name} as a statement here")
                return f"_I.{spec.name}({en_code}, {', '.join(ops)}, {k})", "BOOL"
            if en_code == "True" or spec.always:
                self.em.line(f"_I.{spec.name}({en_code}, {', '.join(ops)}, {k})")
            else:
                # EN FALSE: the instruction is not executed at all (as in ladder)
                self.em.line(f"if {en_code}: _I.{spec.name}(True, {', '.join(ops)}, {k})")
        for line in after:
            self.em.line(line)
        self.note_send_request(spec.name, c)
        return None, "BOOL"

    def note_send_request(self, name: str, c: ast.Call) -> None:
        """SET/OUT of a send-request flag (SET(TRUE, M8402)): remember where, so the bytes
        sent carry this ST location as their origin."""
        if name not in ("SET", "OUT", "MOV") or not isinstance(c.args[-1].value, ast.Device):
            return
        d = c.args[-1].value
        channel = SEND_FLAGS.get(self.family, {}).get(f"{d.kind}{d.address}")
        if channel and d.bit is None:
            area = self.m.cpu.areas[d.kind]
            self.em.line(f"if _A_{d.kind}[{int(d.address, area.radix)}]: "
                         f"_rt.origins[{channel!r}] = {self.m.loc_text(c.span)!r}")

    def ref_code(self, e: ast.Expr, kind: str, wide: bool = False) -> tuple[str, list[str]]:
        """A Ref to the block an instruction operand names; lines to run after the call
        (copy-back of FUNCTION locals)."""
        label = self.label_of(e)
        k = self.loc(e.span)
        if isinstance(e, (ast.IntLiteral, ast.RealLiteral, ast.BoolLiteral, ast.TimeLiteral,
                          ast.StringLiteral, ast.BinaryOp, ast.UnaryOp, ast.Call)):
            raise CompileError(e.span, "this operand must be a label, array element or device, "
                                       "not an expression")
        if isinstance(e, ast.Device) and e.bit is not None and e.index is None and e.module is None:
            area = self.m.cpu.areas.get(e.kind)
            self.device_lvalue(e)  # validates the device
            index = int(e.address, area.radix)
            return self.static_ref(f"_BitRef(_A_{e.kind}, {index}, {e.bit}, 'INT', _rt, {k}, {label!r})"), []
        if isinstance(e, ast.BitAccess):
            code, t = self.expr(e.base)
            self.check_bit(e.bit, t, e.span)
            if not (isinstance(e.base, ast.Name) and "." in code and not code.startswith("l_")
                    and self.lookup(e.base.name, e.span).write is None):
                raise CompileError(e.span, f"{label}: a bit of this label cannot be an instruction "
                                           "operand in the simulator; use a BOOL label or a device bit")
            obj, attr = code.rsplit(".", 1)
            ref = f"_BitRef({obj}, {attr!r}, {e.bit}, {t!r}, _rt, {k}, {label!r})"
            return (self.static_ref(ref) if self.stable(e.base) else ref), []
        if isinstance(e, ast.Device):
            d = e
            if d.bit is not None or d.digits is not None or d.index is not None or d.module is not None:
                raise CompileError(d.span, f"{label}: use a plain device as a block operand")
            lv = self.device_lvalue(d)
            area = self.m.cpu.areas[d.kind]
            index = int(d.address, area.radix)
            tname = "BOOL" if area.kind == "bit" else "INT"
            cls = "_DwordRef" if wide and area.kind == "word" else "_Ref"
            if wide and area.kind == "word":
                tname = "DINT"
            return self.static_ref(f"{cls}(_A_{d.kind}, {index}, {tname!r}, _rt, {k}, {label!r})"), []
        if isinstance(e, ast.Index):
            base_code, base_t = self.expr(e.base)
            read, elem_t, lv = self.index_access(e)
            if not isinstance(elem_t, str):
                raise CompileError(e.span, f"{label}: elements of {elem_t} cannot be an instruction operand")
            for p in lv.prep:
                self.em.line(p)
            flat = lv.read[len(base_code) + 1:-1]
            code = f"_Ref({base_code}, {flat}, {elem_t!r}, _rt, {k}, {label!r})"
            if lv.prep or not self.stable(e.base):
                return code, []
            return self.static_ref(code), []
        code, t = self.expr(e)
        if isinstance(t, ArrayT):
            if not isinstance(t.elem, str):
                raise CompileError(e.span, f"{label}: {t} cannot be an instruction operand")
            ref = f"_Ref({code}, 0, {t.elem!r}, _rt, {k}, {label!r})"
            return (self.static_ref(ref) if self.stable(e) else ref), []
        if not isinstance(t, str):
            raise CompileError(e.span, f"{label} ({t}) cannot be an instruction operand")
        if "." in code and not code.startswith("l_"):
            obj, attr = code.rsplit(".", 1)
            ref = f"_AttrRef({obj}, {attr!r}, {t!r}, _rt, {k}, {label!r})"
            return (self.static_ref(ref) if self.stable(e) else ref), []
        # a FUNCTION local: copy in, run, copy back
        cell = self.new_tmp("_cell")
        self.em.line(f"{cell} = [{code}]")
        return f"_Ref({cell}, 0, {t!r}, _rt, {k}, {label!r})", [f"{code} = {cell}[0]"]

    def stable(self, e: ast.Expr) -> bool:
        """True when the Python object behind e never changes for this instance (so a
        Ref to it can be built once, in __init__)."""
        if self.is_function:
            return False
        if isinstance(e, ast.Name):
            sym = self.lookup(e.name, e.span)
            return sym.section != "VAR_IN_OUT" and sym.write is None
        if isinstance(e, ast.Member):
            return self.stable(e.base) and self.m.member_section_of_expr(e, self) != "VAR_IN_OUT"
        return False

    def static_ref(self, code: str) -> str:
        if self.is_function:
            return code
        slot = f"_r{len(self.static_refs)}"
        self.static_refs.append((slot, code))
        return f"self.{slot}"
