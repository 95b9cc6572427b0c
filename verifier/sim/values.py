"""Python-side views of simulated ST memory: instance proxies with case-insensitive label
access, array views indexed by the ST bounds, and conversion of Python values into ST
values (with the same normalisation the generated code applies)."""
from __future__ import annotations

import keyword
import math
import numbers
import operator
from typing import Callable

from . import datatypes
from .typesys import ArrayT, FbT, StringT, StructT


def to_st(t, value, label: str, make_default=None):
    """Convert a Python value for a label of type t (raises ValueError with the label)."""
    if isinstance(t, StringT):
        if not isinstance(value, str):
            raise ValueError(f"{label} is a STRING; got {value!r}")
        return value[: t.length]
    if isinstance(t, str):
        if t == "BOOL":
            if isinstance(value, bool) or value in (0, 1):
                return bool(value)
            raise ValueError(f"{label} is BOOL; got {value!r}")
        if isinstance(value, bool):
            raise ValueError(f"{label} is {t}; got a bool")
        if t in ("REAL", "LREAL"):
            if not isinstance(value, numbers.Real) or not math.isfinite(value):
                raise ValueError(f"{label} is {t}; give a finite number, got {value!r}")
            return datatypes.NORMALIZERS[t](float(value))
        if isinstance(value, float):
            raise ValueError(f"{label} is {t}; got the float {value!r}")
        try:
            whole = operator.index(value)  # int, or an integer type such as numpy's
        except TypeError:
            raise ValueError(f"{label} is {t}; give a whole number, got {value!r}") from None
        return datatypes.NORMALIZERS[t](whole)
    raise ValueError(f"{label} ({t}) cannot be set from {value!r}")


def to_st_list(t: ArrayT, values, label: str, default) -> list:
    if isinstance(values, (str, bytes, dict)) or not hasattr(values, "__iter__"):
        raise ValueError(f"{label} is an array of {t.size}; give a list of values, got {values!r}")
    values = list(values)
    if len(values) > t.size:
        raise ValueError(f"{label} has {t.size} elements; got {len(values)} values")
    out = [to_st(t.elem, v, f"{label}[{i}]") for i, v in enumerate(values)]
    return out + [default] * (t.size - len(out))


def wrap(value, t, label: str, module, parent=None, step=None):
    """Python view of a stored value; a view of an instance, structure or array below
    another view (`parent`, reached by `step`: an attribute name or a list index) finds
    its memory again through it after `Project.restart`."""
    if isinstance(t, ArrayT):
        return ArrayView(value, t, label, module, parent, step)
    if isinstance(t, (StructT, FbT)):
        return InstanceProxy(value, module, label, parent=parent, step=step)
    return value


class InstanceProxy:
    """An FB/PROGRAM instance or structure: `fb.i_bExecute = True`, `fb.tmr.Q`."""

    __slots__ = ("_obj", "_module", "_label", "_project", "_parent", "_step", "_seen")

    def __init__(self, obj, module, label: str, project=None, parent=None, step=None):
        object.__setattr__(self, "_obj", obj)
        object.__setattr__(self, "_module", module)
        object.__setattr__(self, "_label", label)
        object.__setattr__(self, "_project", project)
        object.__setattr__(self, "_parent", parent)
        object.__setattr__(self, "_step", step)
        object.__setattr__(self, "_seen", module.restarts)

    def _fresh(self) -> None:
        """After a restart (`CompiledModule.restarts` moved on) a view taken from another
        one holds memory the CPU no longer has: take it again through the parent."""
        if self._parent is not None and self._seen != self._module.restarts:
            object.__setattr__(self, "_obj", self._parent._value_at(self._step))
            object.__setattr__(self, "_seen", self._module.restarts)

    def _value_at(self, attr: str):
        self._fresh()
        return getattr(self._obj, attr)

    def _holder(self, sym):
        """The object that stores a label: this instance's memory, or for a global label
        (a VAR_EXTERNAL of an FB or PROGRAM is the global itself) the globals object,
        which a restart re-initialises in place."""
        if sym is not None and sym.code and sym.code.startswith("_G."):
            return self._module.namespace["_G"]
        return self._obj

    def _symbols(self) -> dict:
        self._fresh()
        return self._module.class_symbols.get(type(self._obj), {})

    def _find(self, name: str):
        from .stdfbs import FB_PARAM_TYPES, StdFB

        self._fresh()
        key = name.upper()
        if isinstance(self._obj, StdFB):
            t = FB_PARAM_TYPES[self._obj.TYPE_NAME].get(key)
            if t is None:
                raise AttributeError(f"{self._label} ({self._obj.TYPE_NAME}) has no input/output {name}"
                                     + _guess(name, FB_PARAM_TYPES[self._obj.TYPE_NAME]))
            return key, t, None
        symbols = self._symbols()
        sym = symbols.get(key)
        if sym is None:  # the guess a scenario's misspelt label gets, for a test's too
            raise AttributeError(f"{self._label} has no label {name!r}"
                                 + _guess(name, [s.name for s in symbols.values()]))
        from .codegen import attr_name

        return attr_name(sym.name), sym.type, sym

    def __getattr__(self, name: str):
        if name.startswith("__"):
            raise AttributeError(name)
        attr, t, sym = self._find(name)
        if sym is not None and sym.code and not sym.code.startswith(("self.", "_G.")):
            value = eval(sym.code, self._module.namespace)  # constants and device-backed globals
            return wrap(value, t, f"{self._label}.{name}", self._module)
        holder = self._holder(sym)
        if holder is not self._obj:  # a VAR_EXTERNAL: found again after a restart through the globals
            parent = InstanceProxy(holder, self._module, "GLOBAL")
            return wrap(getattr(holder, attr), t, f"{self._label}.{name}", self._module, parent, attr)
        return wrap(getattr(self._obj, attr), t, f"{self._label}.{name}", self._module, self, attr)

    def __setattr__(self, name: str, value) -> None:
        attr, t, sym = self._find(name)
        label = f"{self._label}.{name}"
        if sym is not None and sym.is_constant:
            raise AttributeError(f"{label} is a constant")
        if isinstance(t, ArrayT):
            if not isinstance(t.elem, (str, StringT)):
                raise AttributeError(f"{label} is an array of {t.elem}: set its members one by one")
            default = datatypes.TYPES[t.elem].default if isinstance(t.elem, str) else ""
            getattr(self._holder(sym), attr)[:] = to_st_list(t, value, label, default)
            return
        if isinstance(t, (StructT, FbT)):
            raise AttributeError(f"{label} is a {t}: set its members one by one")
        st_value = to_st(t, value, label)
        if sym is not None and sym.write:
            ns = dict(self._module.namespace)
            ns["_v_"] = st_value
            exec(sym.write.format(v="_v_"), ns)
            return
        setattr(self._holder(sym), attr, st_value)

    def _names(self) -> list[str]:
        """The labels' names: a standard FB's (TON ...) inputs and outputs, else the
        declared labels."""
        from .stdfbs import FB_PARAM_TYPES, StdFB

        self._fresh()
        if isinstance(self._obj, StdFB):
            return list(FB_PARAM_TYPES[self._obj.TYPE_NAME])
        return [s.name for s in self._symbols().values()]

    def __dir__(self):
        return self._names()

    def _not_a_value(self) -> TypeError:
        """`assert fb.fbTimer`, `fb.stPos == 3`: an instance or structure read as a value."""
        from .stdfbs import StdFB

        self._fresh()
        names = self._names()
        cls = type(self._obj).__name__
        if isinstance(self._obj, StdFB):
            what, example = f"an instance of {self._obj.TYPE_NAME}", next((n for n in names if n.startswith("Q")), names[-1])
        else:
            outputs = [s.name for s in self._symbols().values() if s.section == "VAR_OUTPUT"]
            example = (outputs or names or ["label"])[0]
            info = next((i for i in self._module.pous.values() if i.class_name == cls), None)
            if cls.startswith("S_"):  # the compiler's structure classes (compiler.py)
                what = "a structure"
            elif info is not None:
                what = f"{'the PROGRAM' if info.kind == 'PROGRAM' else 'an instance of'} {info.pou.name}"
            else:
                what = "the global labels"
        return TypeError(f"{self._label} is {what}, not a value: read one of its labels, "
                         f"e.g. {self._label}.{example}")

    def __bool__(self):
        raise self._not_a_value()

    def __eq__(self, other):
        if isinstance(other, (bool, int, float, str)):
            raise self._not_a_value()
        return isinstance(other, InstanceProxy) and other._obj is self._obj

    def __hash__(self):
        return hash(id(self._obj))

    def __repr__(self) -> str:
        parts = []
        for name in self._names():
            try:
                v = getattr(self, name)
            except Exception:
                continue
            if isinstance(v, (InstanceProxy,)):
                continue
            parts.append(f"{name}={v!r}")
        return f"<{self._label}: {', '.join(parts)}>"

    def state(self) -> dict:
        """Current values of the elementary labels and arrays (for reports)."""
        out = {}
        for name in self._names():
            v = getattr(self, name)
            out[name] = list(v) if isinstance(v, ArrayView) else v
        return out


class ArrayView:
    """An ST array seen from Python, indexed by its ST bounds (`arr[1]` of ARRAY[1..8] is
    its first element); `list(view)` copies the values."""

    __slots__ = ("_cells", "_t", "_label", "_module", "_parent", "_step", "_seen")

    def __init__(self, cells, t: ArrayT, label: str, module, parent=None, step=None):
        self._cells = cells
        self._t = t
        self._label = label
        self._module = module
        self._parent = parent
        self._step = step
        self._seen = module.restarts

    def _fresh(self) -> None:
        """As InstanceProxy._fresh: the array's memory again after a restart."""
        if self._parent is not None and self._seen != self._module.restarts:
            self._cells = self._parent._value_at(self._step)
            self._seen = self._module.restarts

    def _value_at(self, flat: int):
        self._fresh()
        return self._cells[flat]

    def _flat(self, index) -> int:
        idx = index if isinstance(index, tuple) else (index,)
        if len(idx) != len(self._t.dims):
            raise IndexError(f"{self._label} has {len(self._t.dims)} dimension(s)")
        flat = 0
        for (lo, hi), i in zip(self._t.dims, idx):
            if isinstance(i, bool) or not isinstance(i, numbers.Integral):
                bounds = ", ".join(f"{a}..{b}" for a, b in self._t.dims)
                raise TypeError(f"{self._label} is indexed by whole numbers within its ST bounds "
                                f"[{bounds}]; got {i!r:.60}")
            i = operator.index(i)
            if not lo <= i <= hi:
                raise IndexError(f"index {i} is outside {self._label}[{lo}..{hi}]")
            flat = flat * (hi - lo + 1) + (i - lo)
        return flat

    def __getitem__(self, index):
        if isinstance(index, slice):
            return self._slice(index)
        self._fresh()
        flat = self._flat(index)
        return wrap(self._cells[flat], self._t.elem, f"{self._label}[{index}]", self._module, self, flat)

    def _slice(self, index: slice) -> list:
        """`a[2:5]` of ARRAY[1..8]: elements 2, 3, 4 by their ST indexes (start and stop
        default to the bounds, and are kept within them, as Python keeps a slice in a list)."""
        if len(self._t.dims) != 1:
            raise TypeError(f"{self._label} has {len(self._t.dims)} dimensions: slice one-dimensional "
                            "arrays only; read elements as a[i, j] or list(a) in storage order")
        (lo, hi), = self._t.dims
        for part in (index.start, index.stop, index.step):
            if part is not None and (isinstance(part, bool) or not isinstance(part, numbers.Integral)):
                raise TypeError(f"{self._label} is sliced by whole numbers within its ST bounds [{lo}..{hi}]; "
                                f"got {part!r:.60}")
        step = 1 if index.step is None else index.step
        if step == 0:
            raise ValueError("slice step cannot be zero")
        if step > 0:
            start = lo if index.start is None else max(index.start, lo)
            stop = hi + 1 if index.stop is None else min(index.stop, hi + 1)
        else:
            start = hi if index.start is None else min(index.start, hi)
            stop = lo - 1 if index.stop is None else max(index.stop, lo - 1)
        values = list(self)
        return [values[i - lo] for i in range(start, stop, step)]

    def __setitem__(self, index, value) -> None:
        self._fresh()
        self._cells[self._flat(index)] = to_st(self._t.elem, value, f"{self._label}[{index}]")

    def __len__(self) -> int:
        self._fresh()
        return len(self._cells)

    def __iter__(self):
        self._fresh()
        for flat, v in enumerate(self._cells):
            yield wrap(v, self._t.elem, f"{self._label}", self._module, self, flat)

    def __eq__(self, other) -> bool:
        try:
            return list(self) == list(other)
        except TypeError:
            return NotImplemented

    def __repr__(self) -> str:
        return repr(list(self))


def reader(root: "InstanceProxy", parts: list[str]):
    """A function of no arguments that reads the label at `parts` below `root`
    (["fbEngine", "o_bErr"], ["wBuf", "[2]"]) as `getattr`/`[]` on the proxies would, with
    the path resolved once: instances and arrays are stored in place (assignments copy
    into them), so only the last step is taken on each call. Labels whose value is
    computed on each read (constants, device-backed globals) keep the generic path."""
    target = root
    for part in parts[:-1]:
        target = target[int(part[1:-1])] if part.startswith("[") else getattr(target, part)
    last = parts[-1]
    if isinstance(target, ArrayView):
        if not last.startswith("["):
            raise AttributeError(f"{target._label} is an array: index it")
        cells, flat, elem = target._cells, target._flat(int(last[1:-1])), target._t.elem
        if isinstance(elem, (str, StringT)):
            return lambda: cells[flat]
        view = target
        index = int(last[1:-1])
        return lambda: view[index]
    if last.startswith("[") or not isinstance(target, InstanceProxy):
        index = int(last[1:-1]) if last.startswith("[") else None
        return (lambda: target[index]) if index is not None else (lambda: getattr(target, last))
    attr, t, sym = target._find(last)
    computed = sym is not None and sym.code and not sym.code.startswith(("self.", "_G."))
    if computed or not isinstance(t, (str, StringT)):
        return lambda: getattr(target, last)
    return _slot_reader(target._holder(sym), attr)


def _slot_reader(obj, attr: str):
    """`getattr(obj, attr)` as a function that `read_together` can merge with others."""
    def read():
        return getattr(obj, attr)
    read.slot = (obj, attr)
    return read


def read_together(readers: list) -> Callable[[], tuple]:
    """One function returning the values of all `readers` as a tuple: those that read a
    slot of an object (`reader` for a plain label) become plain attribute loads of one
    generated function, and so do those that read one cell of a list (a device word),
    the rest are called.  Read on every scan, it is kept cheap."""
    env: dict[str, object] = {}
    parts = []
    for k, read in enumerate(readers):
        slot, item = getattr(read, "slot", None), getattr(read, "item", None)
        if slot is not None and slot[1].isidentifier() and not keyword.iskeyword(slot[1]):
            env[f"o{k}"] = slot[0]
            parts.append(f"o{k}.{slot[1]}")
        elif item is not None and type(item[1]) is int:
            env[f"c{k}"] = item[0]
            parts.append(f"c{k}[{item[1]}]")
        else:
            env[f"r{k}"] = read
            parts.append(f"r{k}()")
    source = "def read_all():\n    return (" + "".join(p + ", " for p in parts) + ")\n"
    exec(compile(source, "<watched-labels>", "exec"), env)
    return env["read_all"]


def _guess(name: str, names) -> str:
    """"; did you mean 'fbEngine'?" for a label spelt nearly as one of `names`, else ""."""
    from verifier.amr.schema import did_you_mean

    return did_you_mean(name, names)
