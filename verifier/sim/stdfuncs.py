"""Standard functions (IEC 61131-3 as GX Works names them): code generators for the
compiler plus the run-time helpers the generated code calls.

A generator takes the compiled arguments `[(code, type), ...]` and returns `(code,
type)`.  Generators inline simple operations; the helpers here cover what needs an
operation-error report or a loop.
"""
from __future__ import annotations

import math

from . import datatypes
from .typesys import (ANYINT, ANYREAL, CompileError, StringT, bits_of, concrete, is_int,
                      is_real, is_string, norm_code, unify)

# GX Works spells STRING as STR (and WSTRING as WSTR) in conversion names: INT_TO_STR
_STRING_NAMES = {"STR": "STRING", "WSTR": "STRING", "WSTRING": "STRING"}
ELEMENTARY = ("BOOL", "INT", "DINT", "WORD", "DWORD", "UINT", "UDINT", "REAL", "LREAL",
              "TIME", "STRING")


# ----------------------------------------------------------------------------- helpers
def make_helpers(rt) -> dict:
    """Functions bound to one runtime, installed as globals of the generated module."""
    op_error = rt.operation_error
    div_zero = rt.cpu.div_zero_code

    def _idiv(a, b, k):
        if b == 0:
            op_error(k, "division by zero", div_zero)
            return 0
        q = abs(a) // abs(b)
        return q if (a >= 0) == (b >= 0) else -q

    def _idiv_n(a, b, k):
        """Quotient, or None after an operation error (the destination keeps its value,
        as the CPU skips the instruction)."""
        if b == 0:
            op_error(k, "division by zero", div_zero)
            return None
        q = abs(a) // abs(b)
        return q if (a >= 0) == (b >= 0) else -q

    def _imod(a, b, k):
        if b == 0:
            op_error(k, "MOD by zero", div_zero)
            return 0
        r = abs(a) % abs(b)
        return r if a >= 0 else -r

    def _rdiv(a, b, k):
        if b == 0:
            op_error(k, "division by zero", div_zero)
            return 0.0
        return a / b

    def _rmath(fn, x, k, name):
        try:
            return fn(x)
        except (ValueError, OverflowError):
            op_error(k, f"{name}({x}) is outside the function's domain")
            return 0.0

    def _expt(a, b, k):
        try:
            r = float(a) ** float(b)
        except (ZeroDivisionError, OverflowError):
            op_error(k, f"EXPT({a}, {b}) cannot be computed")
            return 0.0
        if isinstance(r, complex):
            op_error(k, f"EXPT({a}, {b}) has no real result")
            return 0.0
        return r

    # REAL -> integer as the CPU's conversion instruction does it (docs/instructions.md §3):
    # FX3 INT (FNC 129) rounds down, dropping the fraction; FX5/Q round the first digit
    # after the decimal point off (halves away from zero)
    truncates = rt.cpu.family == "fx3"

    def _r2i(x, type_name, k):
        """REAL -> integer: truncated on an FX3 CPU, rounded to the nearest whole number
        (halves away from zero) on FX5 and Q; see docs/instructions.md §3."""
        if math.isnan(x) or math.isinf(x):
            op_error(k, f"{x} cannot be converted to {type_name}")
            return 0
        v = int(abs(x)) if truncates else int(math.floor(abs(x) + 0.5))
        v = v if x >= 0 else -v
        t = datatypes.TYPES[type_name]
        lo, hi = ((-(1 << (t.bits - 1)), (1 << (t.bits - 1)) - 1) if t.kind == "signed"
                  else (0, (1 << t.bits) - 1))
        if not lo <= v <= hi:
            op_error(k, f"{x} is outside the range of {type_name}")
            return 0
        return v

    def _trunc(x, type_name, k):
        if math.isnan(x) or math.isinf(x):
            op_error(k, f"{x} cannot be truncated")
            return 0
        return datatypes.NORMALIZERS[type_name](int(x))

    def _to_bcd(v, bits, k):
        limit = 9999 if bits == 16 else 99999999
        if not 0 <= v <= limit:
            op_error(k, f"{v} cannot be written as BCD (0..{limit})")
            return 0
        out = 0
        for i, ch in enumerate(reversed(str(v))):
            out |= int(ch) << (4 * i)
        return out

    def _from_bcd(v, bits, k):
        v &= (1 << bits) - 1
        out = 0
        for i in range(bits // 4):
            nib = (v >> (4 * i)) & 0xF
            if nib > 9:
                op_error(k, f"H{v:X} is not a BCD value")
                return 0
            out += nib * 10 ** i
        return out

    def _mux(k_sel, values, k):
        if 0 <= k_sel < len(values):
            return values[k_sel]
        op_error(k, f"MUX selector {k_sel} is outside 0..{len(values) - 1}")
        return values[0]

    def _str_to(s, type_name, k):
        try:
            if type_name in ("REAL", "LREAL"):
                return float(s.strip())
            return int(s.strip(), 10)
        except ValueError:
            op_error(k, f"'{s}' is not a {type_name} number")
            return 0

    def _wdt(k):
        rt.fail(k, "a loop ran more than 1,000,000 iterations in one scan; the CPU would "
                   "stop with a watchdog timer error")

    return {
        "_idiv": _idiv, "_idiv_n": _idiv_n, "_imod": _imod, "_rdiv": _rdiv, "_rmath": _rmath,
        "_expt": _expt, "_r2i": _r2i, "_trunc": _trunc, "_to_bcd": _to_bcd,
        "_from_bcd": _from_bcd, "_mux": _mux, "_str_to": _str_to, "_wdt": _wdt,
        "_f32": datatypes.to_f32, "_math": math, "_rol": _rol, "_ror": _ror,
        "_digits_get": _digits_get, "_digits_set": _digits_set, "_mid": _mid,
        "_insert": _insert, "_delete": _delete, "_replace": _replace, "_find": _find,
        "_fmt_real": _fmt_real,
    }


def _rol(v, n, bits):
    n %= bits
    mask = (1 << bits) - 1
    v &= mask
    return ((v << n) | (v >> (bits - n))) & mask


def _ror(v, n, bits):
    n %= bits
    mask = (1 << bits) - 1
    v &= mask
    return ((v >> n) | (v << (bits - n))) & mask


def _digits_get(cells, start, digits):
    value = 0
    for i in range(digits * 4):
        if cells[start + i]:
            value |= 1 << i
    return datatypes.wrap16(value) if digits <= 4 else datatypes.wrap32(value)


def _digits_set(cells, start, digits, value):
    for i in range(digits * 4):
        cells[start + i] = bool((value >> i) & 1)


def _mid(s, length, pos):
    return s[pos - 1: pos - 1 + length] if pos >= 1 else ""


def _insert(s1, s2, pos):
    return s1[:pos] + s2 + s1[pos:]


def _delete(s, length, pos):
    return s[: pos - 1] + s[pos - 1 + length:] if pos >= 1 else s


def _replace(s1, s2, length, pos):
    return s1[: pos - 1] + s2 + s1[pos - 1 + length:] if pos >= 1 else s1


def _find(s1, s2):
    return s1.find(s2) + 1


def _fmt_real(x):
    return repr(float(x))


# ----------------------------------------------------------------------------- generators
def _arity(name, args, n, span, at_least=False):
    if (len(args) < n) if at_least else (len(args) != n):
        want = f"at least {n}" if at_least else str(n)
        raise CompileError(span, f"{name} takes {want} argument(s), got {len(args)}")


def arith(op: str, args, cx, span):
    """n-ary ADD/MUL, binary SUB/DIV/MOD, typed like the operators."""
    code, t = args[0]
    for rcode, rt_ in args[1:]:
        code, t = cx.binary_code(op, code, t, rcode, rt_, span)
    return code, t


def gen_conversion(src: str, dst: str, arg, cx, span):
    code, t = arg
    k = cx.loc(span)
    if dst == "BOOL":
        return f"(({code}) != 0)", "BOOL"
    if src == "BCD":
        bits = bits_of(dst)
        return f"_from_bcd({code}, {bits}, {k})", dst
    if dst == "BCD":
        bits = bits_of(concrete(t))
        return f"_to_bcd({code}, {bits}, {k})", "WORD" if bits == 16 else "DWORD"
    if dst == "STRING":
        if is_real(t):
            return f"_fmt_real({code})", StringT(255)
        return f"str(int({code}))", StringT(255)
    if is_string(t):
        return f"_str_to({code}, {concrete(dst)!r}, {k})", dst
    if dst in ("REAL", "LREAL"):
        return norm_code(dst, f"float({code})"), dst
    if is_real(t):
        return f"_r2i({code}, {dst!r}, {k})", dst
    if t == "BOOL":
        return f"int({code})", dst
    return norm_code(dst, code), dst


def gen_shift(name: str, args, cx, span):
    _arity(name, args, 2, span)
    (code, t), (n, _) = args
    t = concrete(t)
    bits = bits_of(t)
    mask = (1 << bits) - 1
    if name == "SHL":
        raw = f"((({code}) & {mask}) << ({n})) & {mask}"
    elif name == "SHR":
        raw = f"(({code}) & {mask}) >> ({n})"
    elif name == "ROL":
        raw = f"_rol({code}, {n}, {bits})"
    else:
        raw = f"_ror({code}, {n}, {bits})"
    if t in ("INT", "DINT"):
        raw = norm_code(t, raw)
    return raw, t


def generate(name: str, args, cx, span):
    """Code for a standard function call, or None when `name` is not one."""
    k = cx.loc
    if name in ("ADD", "MUL"):
        _arity(name, args, 2, span, at_least=True)
        return arith("+" if name == "ADD" else "*", args, cx, span)
    if name in ("SUB", "DIV", "MOD", "EXPT"):
        _arity(name, args, 2, span)
        return arith({"SUB": "-", "DIV": "/", "MOD": "MOD", "EXPT": "**"}[name], args, cx, span)
    if name in ("AND", "OR", "XOR"):
        _arity(name, args, 2, span, at_least=True)
        return arith(name, args, cx, span)
    if name == "NOT":
        _arity(name, args, 1, span)
        return cx.unary_code("NOT", *args[0], span)
    if name == "MOVE":
        _arity(name, args, 1, span)
        return args[0]
    if name == "ABS":
        _arity(name, args, 1, span)
        code, t = args[0]
        return (f"abs({code})" if is_real(t) else norm_code(t, f"abs({code})")), t
    if name in ("SQRT", "LN", "LOG", "EXP", "SIN", "COS", "TAN", "ASIN", "ACOS", "ATAN"):
        _arity(name, args, 1, span)
        code, t = args[0]
        fn = {"SQRT": "sqrt", "LN": "log", "LOG": "log10", "EXP": "exp", "SIN": "sin",
              "COS": "cos", "TAN": "tan", "ASIN": "asin", "ACOS": "acos", "ATAN": "atan"}[name]
        rtype = "LREAL" if t == "LREAL" else "REAL"
        return norm_code(rtype, f"_rmath(_math.{fn}, {code}, {k(span)}, {name!r})"), rtype
    if name in ("SHL", "SHR", "ROL", "ROR"):
        return gen_shift(name, args, cx, span)
    if name in ("MAX", "MIN"):
        _arity(name, args, 2, span, at_least=True)
        t = args[0][1]
        for _, at in args[1:]:
            t = unify(t, at)
        return f"{name.lower()}({', '.join(c for c, _ in args)})", t
    if name == "LIMIT":
        _arity(name, args, 3, span)
        (mn, t1), (x, t2), (mx, t3) = args
        return f"min(max({x}, {mn}), {mx})", unify(unify(t1, t2), t3)
    if name == "SEL":
        _arity(name, args, 3, span)
        (g, _), (a, t1), (b, t2) = args
        return f"(({b}) if ({g}) else ({a}))", unify(t1, t2)
    if name == "MUX":
        _arity(name, args, 3, span, at_least=True)
        t = args[1][1]
        for _, at in args[2:]:
            t = unify(t, at)
        return f"_mux({args[0][0]}, ({', '.join(c for c, _ in args[1:])},), {k(span)})", t
    if name in ("GT", "GE", "EQ", "LE", "LT", "NE"):
        _arity(name, args, 2, span, at_least=name != "NE")
        op = {"GT": ">", "GE": ">=", "EQ": "==", "LE": "<=", "LT": "<", "NE": "!="}[name]
        return "(" + f" {op} ".join(f"({c})" for c, _ in args) + ")", "BOOL"
    if name in ("TRUNC", "REAL_TO_INT_TRUNC"):
        _arity(name, args, 1, span)
        return f"_trunc({args[0][0]}, 'DINT', {k(span)})", "DINT"
    if name == "LEN":
        _arity(name, args, 1, span)
        return f"len({args[0][0]})", "INT"
    if name == "LEFT":
        _arity(name, args, 2, span)
        return f"({args[0][0]})[:max({args[1][0]}, 0)]", args[0][1]
    if name == "RIGHT":
        _arity(name, args, 2, span)
        return f"(({args[0][0]})[-({args[1][0]}):] if ({args[1][0]}) > 0 else '')", args[0][1]
    if name == "MID":
        _arity(name, args, 3, span)
        return f"_mid({args[0][0]}, {args[1][0]}, {args[2][0]})", args[0][1]
    if name == "CONCAT":
        _arity(name, args, 2, span, at_least=True)
        return "(" + " + ".join(c for c, _ in args) + ")", StringT(255)
    if name == "INSERT":
        _arity(name, args, 3, span)
        return f"_insert({args[0][0]}, {args[1][0]}, {args[2][0]})", StringT(255)
    if name == "DELETE":
        _arity(name, args, 3, span)
        return f"_delete({args[0][0]}, {args[1][0]}, {args[2][0]})", args[0][1]
    if name == "REPLACE":
        _arity(name, args, 4, span)
        return f"_replace({', '.join(c for c, _ in args)})", StringT(255)
    if name == "FIND":
        _arity(name, args, 2, span)
        return f"_find({args[0][0]}, {args[1][0]})", "INT"
    if "_TO_" in name:
        src, dst = (_STRING_NAMES.get(x, x) for x in name.split("_TO_", 1))
        known = set(ELEMENTARY) | {"BCD"}
        if src in known and dst in known:
            _arity(name, args, 1, span)
            return gen_conversion(src, dst, args[0], cx, span)
    return None


__all__ = ["make_helpers", "generate", "ANYINT", "ANYREAL", "is_int"]
