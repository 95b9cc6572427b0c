"""The simulator's Python API: load ST, call functions, drive FB instances and programs
scan by scan in virtual time, attach serial endpoints.  See docs/testing-st.md."""
from __future__ import annotations

import math
import sys
from pathlib import Path
from typing import Callable, Iterable

from verifier import plcfacts
from verifier.st import ast
from verifier.st.check import called_without
from verifier.st.source import read_source
from verifier.textfile import text_lines

from .compiler import GENERATED_FILE, CompiledModule, compile_files, default_code
from .cpu import profile_for
from .errors import OPTION_PLACE, LoadError, SimulationError, option_error
from .instructions import InstructionSet
from .runtime import Runtime
from .typesys import ArrayT, CompileError, StringT, StructT
from .values import InstanceProxy, to_st, to_st_list, wrap


class _NotGiven(str):
    """The default of `load`'s target, "gxworks2", told apart from the same name given."""


#: the editor `load` reads for when given no target (and so the FX3U, its default CPU)
DEFAULT_TARGET = _NotGiven("gxworks2")


def load(*paths, target: str = DEFAULT_TARGET, cpu: str | None = None, scan_ms: float = 10,
         jitter_ms: float = 0, seed: int = 0, stop_on_operation_error: bool | None = None,
         sources: dict[str, str] | None = None, timer_resolution_ms: int = 1,
         programs: Iterable[str] | None = None) -> "Project":
    """Parse, check and compile ST files into a simulated CPU.

    `paths` are .st files (or directories, whose *.st files are loaded); `sources` maps
    file names to ST text for sources that are not on disk.  `target` is the editor
    ("gxworks2", "gxworks3", or "gxworks2:q" to pick the CPU); `cpu` picks the CPU profile
    ("fx3u", "fx3g", "fx5u", "q").  `programs` (PROGRAM names) makes the simulator compile
    only those programs and what they use, which loads a large library faster; every file
    is parsed and checked all the same. Names that are not all PROGRAMs of the files are
    ignored (everything is compiled). Raises LoadError listing file:line:col diagnostics;
    with neither `target` nor `cpu` given ("gxworks2", the FX3U), sources that load on the
    FX5U or a Q instead get a last line naming the target to give."""
    texts: dict[str, str] = {}
    problems = []
    if sources is not None and not isinstance(sources, dict):
        raise TypeError(f"sources maps file names to ST text, e.g. {{'main.st': 'PROGRAM ...'}}; got {sources!r:.60}")
    for p in paths:
        if not isinstance(p, (str, Path)):
            raise TypeError(f"load() takes the files as separate arguments: load('a.st', 'b.st'), "
                            f"or load(*files); got {p!r:.60}")
        path = Path(p)
        files = sorted(path.glob("*.st")) if path.is_dir() else [path]
        if path.is_dir() and not files:
            problems.append(_empty_folder(path))
        for f in files:
            # the one ST reader (UTF-8, else Shift-JIS), shared with check and export
            text, unreadable = read_source(f)
            texts[str(f)] = text
            problems += unreadable
    texts.update(sources or {})
    if problems:
        raise LoadError(problems)
    try:
        return Project(texts, target=str(target) if target is DEFAULT_TARGET else target, cpu=cpu, scan_ms=scan_ms, jitter_ms=jitter_ms,
                       seed=seed, stop_on_operation_error=stop_on_operation_error,
                       timer_resolution_ms=timer_resolution_ms, programs=programs)
    except LoadError as exc:
        note = _target_note(texts) if target is DEFAULT_TARGET and cpu is None and exc.located() else None
        if note is None:
            raise
        raise LoadError(exc.diagnostics + [note]) from None


def _target_note(texts: dict[str, str]) -> ast.Diagnostic | None:
    """For sources that failed to load for the default target: a note naming the target
    whose CPU loads them (the FX5U's GX Works3, a Q), None when none does. An FX5U
    integrator who left out target= otherwise read only errors inside the library's port FB
    (`device SM8561: the fx3u has no SM devices`)."""
    for target, cpu in (("gxworks3", "fx5u"), ("gxworks2:q", "q")):
        profile = profile_for(target, cpu)
        try:  # as Project loads them, without making one (the pytest plugin would show it)
            files, _ = _parsed_and_checked(texts, target.split(":")[0], profile.name)
            compile_files(files, Runtime(profile), profile)
        except (LoadError, CompileError):
            continue
        return ast.Diagnostic(f"{OPTION_PLACE}target={str(DEFAULT_TARGET)!r})", 0, 0, "note",
                              f"the sources load with target={target!r} (the {cpu} CPU): give target={target!r}")
    return None


def _empty_folder(path: Path) -> ast.Diagnostic:
    """The error for a folder given to `load` that has no .st file of its own (`load("plc")`
    would otherwise load nothing, and `instance(...)` say only that no POU is loaded)."""
    below = sorted({f.parent for f in path.rglob("*.st") if f.is_file()})
    hint = ""
    if below:
        named = ", ".join(repr(str(d)) for d in below[:6]) + (", ..." if len(below) > 6 else "")
        hint = f"; name the folders that hold them: {named}"
    return ast.Diagnostic(str(path), 0, 0, "error", "no .st files in this folder (load reads a folder's own "
                          f"*.st files, not its subfolders){hint}")


class Project:
    """One simulated CPU running the loaded ST."""

    def __init__(self, texts: dict[str, str], target: str = "gxworks2", cpu: str | None = None,
                 scan_ms: float = 10, jitter_ms: float = 0, seed: int = 0,
                 stop_on_operation_error: bool | None = None, timer_resolution_ms: int = 1,
                 programs: Iterable[str] | None = None):
        try:
            self.cpu = profile_for(target, cpu)
        except ValueError as e:
            raise option_error(str(e), **({"target": target} if cpu is None else {"target": target, "cpu": cpu})) from None
        editor = target.split(":", 1)[0].lower()  # as profile_for reads it
        self.target = editor
        files, warnings = _parsed_and_checked(texts, editor, self.cpu.name)
        self.warnings = list(warnings)
        self.files = files
        for name, value in (("scan_ms", scan_ms), ("jitter_ms", jitter_ms)):
            if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
                raise option_error(f"{name} must be a finite number of milliseconds; got {value!r:.60}",
                                   **{name: value})
        scan_us, jitter_us = round(scan_ms * 1000), round(jitter_ms * 1000)
        if scan_us <= 0:
            raise option_error("the scan time must be at least 0.001 ms (1 µs; the virtual clock counts whole µs)",
                               scan_ms=scan_ms)
        if not 0 <= jitter_us < scan_us:
            raise option_error(f"the jitter must be at least 0 and less than the scan time ({scan_ms:g} ms)",
                               jitter_ms=jitter_ms, scan_ms=scan_ms)
        if stop_on_operation_error is not None and not isinstance(stop_on_operation_error, bool):
            raise option_error("stop_on_operation_error is True, False or None (the CPU's default); "
                               f"got {stop_on_operation_error!r:.60}", stop_on_operation_error=stop_on_operation_error)
        try:
            self.rt = Runtime(self.cpu, scan_us=scan_us, jitter_us=jitter_us,
                              seed=seed, stop_on_operation_error=stop_on_operation_error,
                              timer_resolution_ms=timer_resolution_ms)
        except ValueError as e:  # the timer resolution (scan and jitter are checked above)
            raise option_error(str(e), timer_resolution_ms=timer_resolution_ms) from None
        try:
            self.programs = _only_programs(files, programs)
            self.module: CompiledModule = compile_files(files, self.rt, self.cpu, programs=self.programs)
        except CompileError as e:
            span = e.span
            raise LoadError([ast.Diagnostic(getattr(span, "file", "<st>"), getattr(span, "line", 0),
                                            getattr(span, "col", 0), "error", e.message)]) from None
        self._programs: dict[str, object] = {}
        self.before_scan: list[Callable[["Project"], None]] = []
        self.after_scan: list[Callable[["Project"], None]] = []
        self.touched: list[InstanceProxy] = []  # instances handed out (shown on test failure)
        self.idle_scans = None  # a verifier.sim.idle.IdleScans while a run skips idle scans
        _register(self)

    # ------------------------------------------------------------------ state
    @property
    def devices(self):
        return self.rt.dev

    @property
    def now_us(self) -> int:
        return self.rt.now_us

    @property
    def now_s(self) -> float:
        return self.rt.now_us / 1e6

    @property
    def scan_count(self) -> int:
        return self.rt.scan_count

    @property
    def diagnostics(self):
        """Operation errors and other run-time findings the CPU let pass."""
        return self.rt.diagnostics

    @property
    def globals(self) -> InstanceProxy:
        return InstanceProxy(self.module.namespace["_G"], self.module, "GLOBAL", self)

    def pou_names(self, kind: str | None = None) -> list[str]:
        return [i.pou.name for i in self.module.pous.values() if kind is None or i.kind == kind]

    # ------------------------------------------------------------------ functions and instances
    def _pou(self, name: str):
        info = self.module.pous.get(name.upper())
        if info is None:
            if self._left_out(name):
                raise KeyError(f"{name!r} is not compiled: the project was loaded with programs="
                               f"{sorted(self.programs)}, which compiles only what those programs use")
            raise KeyError(f"no POU named {name!r}; loaded: {', '.join(self.pou_names())}")
        return info

    def _left_out(self, name: str) -> bool:
        """Whether `name` is a POU of the files that programs= left out of the compile."""
        return self.programs is not None and any(pou.key == name.upper() for f in self.files for pou in f.pous)

    def call(self, name: str, *args, **kwargs):
        """Call a FUNCTION with positional arguments in declaration order (Python lists for
        arrays; named ones by keyword); returns its value."""
        value, _ = self.call_full(name, *args, **kwargs)
        return value

    def call_full(self, name: str, *args, **kwargs):
        """(value, {output name: value}) of a FUNCTION call."""
        info = self._pou(name)
        if info.kind != "FUNCTION":
            raise TypeError(f"{info.pou.name} is a {info.kind}; use project.instance()")
        params = info.inputs
        if len(args) > len(params):
            raise TypeError(f"{info.pou.name} takes {len(params)} input(s), got {len(args)}")
        given = dict(zip([p.key for p in params], args))
        for k, v in kwargs.items():
            if k.upper() not in {p.key for p in params}:
                raise TypeError(f"{info.pou.name} has no input {k}")
            given[k.upper()] = v
        missing = [p.name for p in params if p.key not in given]
        if missing:
            raise TypeError(f"{called_without(info.pou.name, missing)}: "
                            f"call({info.pou.name!r}, {', '.join(p.name for p in params)})")
        converted = []
        for p in params:
            label = f"{info.pou.name}.{p.name}"
            if isinstance(p.type, ArrayT):
                default = eval(self.module_default(p.type.elem), self.module.namespace)
                converted.append(to_st_list(p.type, given[p.key], label, default))
            else:
                converted.append(to_st(p.type, given[p.key], label))
        fn = self.module.namespace[info.class_name]
        result = self._guard(lambda: fn(*converted))
        if info.outputs:
            ret, *outs = result
            return (wrap(ret, info.return_type, info.pou.name, self.module),
                    {o.name: wrap(v, o.type, o.name, self.module) for o, v in zip(info.outputs, outs)})
        return wrap(result, info.return_type, info.pou.name, self.module), {}

    def module_default(self, t) -> str:
        return default_code(t)

    def instance(self, name: str) -> "Instance":
        """A new FUNCTION_BLOCK instance with its own memory, or the PROGRAM (programs
        exist once per CPU)."""
        info = self._pou(name)
        if info.kind == "FUNCTION":
            raise TypeError(f"{info.pou.name} is a FUNCTION; use project.call()")
        if info.kind == "PROGRAM":
            obj = self._program_obj(info.key)
            for inst in self.touched:
                if inst._obj is obj:
                    return inst
        else:
            obj = self.module.namespace[info.class_name]()
        inst = Instance(obj, self, info.pou.name)
        self.touched.append(inst)
        return inst

    def program(self, name: str) -> "Instance":
        info = self._pou(name)
        if info.kind != "PROGRAM":
            raise TypeError(f"{info.pou.name} is a {info.kind}, not a PROGRAM")
        return self.instance(name)

    def _program_obj(self, key: str):
        obj = self._programs.get(key)
        if obj is None:
            obj = self._programs[key] = self.module.namespace[self.module.pous[key].class_name]()
        return obj

    def get(self, path: str):
        """Value by dotted path: "MAIN.fbRobot.o_bBusy", "GLOBAL.bRun", or a device "D100"."""
        head, _, rest = path.partition(".")
        if head.upper() == "GLOBAL":
            obj = self.globals
        elif head.upper() in self.module.pous or self._left_out(head):  # left out: _pou says so
            obj = self.program(head)
        else:
            try:
                return self.devices[path]  # a device: "D100", or a bit of a word "D100.5"
            except (KeyError, ValueError):
                if not rest:
                    raise
            raise KeyError(f"{path!r}: no POU named {head!r} and not a device; the POUs are "
                           f"{', '.join(sorted(self.pou_names()))}") from None
        for part in rest.split(".") if rest else []:
            obj = getattr(obj, part)
        return obj

    # ------------------------------------------------------------------ running
    def scan(self, bodies: Iterable[Callable[[], None]]) -> None:
        self._run(list(bodies), stop_us=None, scans=1)

    def run_programs(self, names: list[str], ms: float | None = None, scans: int | None = None,
                     until_us: int | None = None, on_scan: Callable[["Project"], None] | None = None):
        """Run PROGRAMs in the given order, one scan after another: for `ms` of virtual
        time, or `scans` scans, or until virtual time `until_us`.  `on_scan(project)` runs
        at the start of every scan, before the programs (set inputs, sample labels)."""
        if isinstance(names, str):
            raise TypeError(f"run_programs takes a list of PROGRAM names: run_programs([{names!r}], ...)")
        bodies = [self._program_obj(self._pou(n).key)._body for n in names]
        for n in names:
            if self._pou(n).kind != "PROGRAM":
                raise TypeError(f"{n} is not a PROGRAM")
        stop = _stop_time(self.rt.now_us, ms, until_us, scans)
        if on_scan is not None:
            self.before_scan.append(on_scan)
        try:
            self._run(bodies, stop, scans)
        finally:
            if on_scan is not None:
                self.before_scan.remove(on_scan)

    def _run(self, bodies, stop_us, scans) -> None:
        if scans is not None and (isinstance(scans, bool) or not isinstance(scans, int) or scans < 0):
            raise ValueError(f"scans must be a whole number of scans, 0 or more; got {scans!r}")
        if scans is None and stop_us is None:
            raise ValueError("say how long to run: ms=..., scans=... or until_us=... (with none the "
                             "run would never end)")
        rt = self.rt
        begin, end = rt.begin_scan, rt.end_scan
        before, after = self.before_scan, self.after_scan
        remaining = scans if scans is not None else -1
        # idle-scan skipping (verifier.sim.idle) only when running to a time, not a count
        idle = self.idle_scans if scans is None else None

        def loop():
            nonlocal remaining
            while remaining != 0 and (stop_us is None or rt.now_us < stop_us):
                started = rt.now_us
                begin()
                for cb in before:
                    cb(self)
                for b in bodies:
                    b()
                for cb in after:
                    cb(self)
                end()
                remaining -= 1
                if idle is not None:
                    idle.after_scan(started, stop_us)

        self._guard(loop)

    def skip_idle_scans(self, names: list[str], *, read_devices: tuple[str, ...] = (),
                        next_input_us=None):
        """Let timed runs of the PROGRAMs `names` jump over idle scans (verifier.sim.idle).
        `read_devices`: devices the caller reads between scans; `next_input_us()`: when the
        caller next writes an input. Returns the IdleScans (its `reason` says when it
        cannot skip)."""
        from .idle import INFINITY, IdleScans

        roots = [self.module.namespace["_G"]] + [self._program_obj(self._pou(n).key) for n in names]
        self.idle_scans = IdleScans(self, roots, read_devices=read_devices,
                                    next_input_us=next_input_us or (lambda: INFINITY))
        return self.idle_scans

    def restart(self, off_ms: float = 0) -> None:
        """Power the CPU off for `off_ms` of virtual time and on again (RUN from the
        start): labels return to their initial values, device memory and module buffers
        are cleared, the serial ports forget what they were doing, and the next scan is a
        first scan again (M8002/SM402).  Attached lines and robots keep running.
        ASSUMPTION: no latched (battery-backed) device ranges and no VAR_RETAIN labels
        are kept — set them again from Python after the restart if your CPU keeps them."""
        rt = self.rt
        self.idle_scans, rt.dirty_log = None, None  # the labels start again: a new walk needed
        self.module.restarts += 1  # views taken from others find their memory again (values.py)
        rt.advance_to(rt.now_us + round(off_ms * 1000))
        for cells in rt.dev.areas.values():
            zero = False if cells and isinstance(cells[0], bool) else 0
            cells[:] = [zero] * len(cells)
        for buf in rt.buffers.values():
            buf[:] = [0] * len(buf)
        rt.power_on_devices()
        rt.pollers.clear()
        rt.origins.clear()
        rt.scan_count = 0
        ns = self.module.namespace
        ns["_I"] = InstructionSet(rt)
        # in place: a `project.globals` view taken before the restart stays the CPU's
        ns["_G"].__init__()
        programs = {id(obj): key for key, obj in self._programs.items()}
        self._programs.clear()
        for inst in self.touched:
            # the instances handed out stay usable: each now holds fresh memory (a held
            # PROGRAM the CPU's new one, an FB a new instance at its initial values)
            key = programs.get(id(inst._obj))
            fresh = self._program_obj(key) if key is not None else type(inst._obj)()
            object.__setattr__(inst, "_obj", fresh)

    def advance(self, ms: float) -> None:
        """Let virtual time pass without scanning (the CPU in STOP)."""
        self.rt.advance_to(self.rt.now_us + round(ms * 1000))

    # ------------------------------------------------------------------ serial
    def serial_channels(self) -> list[str]:
        """The serial channels this CPU has (verifier.plcfacts.FAMILY_CHANNELS)."""
        return plcfacts.serial_channels(self.cpu.name)

    def _serial_channel(self, channel: str):
        """The channel by name; ValueError naming the channels this CPU has otherwise."""
        problem = plcfacts.channel_problem(channel, self.cpu.name)
        if problem is not None:
            raise ValueError(problem)
        return self.rt.channel(channel)

    def attach_serial(self, channel: str, endpoint) -> None:
        """Connect a serial channel of this CPU (`serial_channels()`: "fx3:1", "fx3:2",
        "fx5:1", "fx5:2", "q:1", "q:2", "adp:1") to an endpoint with the verifier.link.Line
        master interface."""
        self._serial_channel(channel).attach(endpoint)

    def attach_tcp(self, endpoint) -> None:
        """Connect the PLC's Ethernet port (FX5U socket / QJ71E71 fixed buffer instructions)
        to a peer with the verifier.link.converter.Converter interface."""
        for attr in ("open", "send", "receive_until", "peer_closed", "close"):
            if not callable(getattr(endpoint, attr, None)):
                raise TypeError(f"TCP endpoint needs a {attr}() method (the verifier.link.converter.Converter interface)")
        if self.rt.tcp_endpoint is not None and self.rt.tcp_endpoint is not endpoint:
            raise ValueError(f"the Ethernet port is already attached to a {type(self.rt.tcp_endpoint).__name__}; it has one "
                             "peer: load the project again (verifier.load) to attach another")
        self.rt.tcp_endpoint = endpoint

    def serial_log(self, channel: str):
        """Frames the PLC sent on a channel of this CPU (`serial_channels()`):
        [SentFrame(t_start_us, t_end_us, data, origin)]."""
        port = self._serial_channel(channel)
        if not self.rt.keep_sent:
            raise RuntimeError("the serial log is off (keep_serial_log(False)): read the frames from "
                               "the line the channel is attached to")
        return list(port.sent)

    def keep_serial_log(self, keep: bool) -> None:
        """Whether the serial channels keep every frame sent for `serial_log` (the default).
        A caller whose attached line records the traffic itself turns it off: an hour of
        traffic is thousands of frames kept twice."""
        self.rt.keep_sent = keep
        for channel in self.rt.ports.values():
            channel.keep_sent = keep

    def configure_c24(self, un: int | None = 0, channel: int = 1, *, byte_units: bool | None = None,
                      receive_count: int | None = None, end_code: int | None = None,
                      no_reception_ms: float | None = None, no_reception_format: int | None = None) -> None:
        """QJ71C24N settings normally made in GX Works (switch settings / buffer memory):
        word or byte units, received data count, receive end code (0xFFFF = none), the
        no-reception monitoring time that ends a message on a silent line and its format
        (1: the message is read normally, X3/XA - the default here; 0: a reception error,
        X4/XB). `un=None` makes
        them for the module the program drives, wherever it is: each one its G_OUTPUT /
        G_INPUT address, from the first call on; a settings word the program has assigned
        by then (U2\\G310 := 1) keeps the program's value, as over a setting made in GX
        Works. Only a module the program addresses is on the robot's
        line; settings for another one change nothing (`c24_addressed` tells which are)."""
        from .instructions.c24 import BUFFER

        if self.cpu.family != "q":
            raise ValueError(f"the QJ71C24N is a Q-series module and this project's CPU is {self.cpu.name}: "
                             f"configure_c24 needs a Q CPU (verifier.load(..., cpu='q'))")
        if type(channel) is not int or channel not in BUFFER:
            raise ValueError(f"the QJ71C24N has channels {' and '.join(map(str, BUFFER))}; got channel={channel!r}")
        if no_reception_format is not None and (type(no_reception_format) is not int
                                                or no_reception_format not in (0, 1)):
            raise ValueError(f"no_reception_format is 0 or 1 (timer 0's format 0 or format 1); "
                             f"got {no_reception_format!r}")
        settings = dict(byte_units=byte_units, receive_count=receive_count, end_code=end_code,
                        no_reception_ms=no_reception_ms, no_reception_format=no_reception_format)
        if un is None:
            self.rt.c24_for_program[channel] = settings
            for _un, module in self._program_c24():
                module.configure_for_program(channel, settings)
            return
        last_un = self.cpu.areas["X"].size // 16 - 1  # the start I/O's upper digits: U0 = X/Y000
        if type(un) is not int or not 0 <= un <= last_un:
            raise ValueError(f"un is the module's start I/O number without its last digit, 0..{last_un:X}H "
                             f"(0 for X/Y000, 2 for X/Y020); got un={un!r}")
        self._instructions().c24(un).configure(channel, **settings)

    def c24_unread(self) -> list[tuple[int, int, int, int]]:
        """(start I/O, channel, messages, since µs) for the received messages that wait in
        a QJ71C24N the program drives, not read by G_INPUT: a program that reads on the
        wrong input signal leaves every reply there."""
        return [(un, *waiting) for un, module in self._program_c24() for waiting in module.unread()]

    def c24_unfinished(self) -> list[tuple[int, int, int, int, int, int]]:
        """(start I/O, channel, bytes, since µs, received data count, end code) of the bytes a
        QJ71C24N channel the program drives holds as a message not yet ended."""
        return [(un, *waiting) for un, module in self._program_c24() for waiting in module.unfinished()]

    def c24_joined(self) -> list[tuple[int, int, int, int, int]]:
        """(start I/O, channel, since µs, bytes before the silence, silence µs) of the first
        message a QJ71C24N channel the program drives completed across a silence, with no
        no-reception monitoring time (timer 0) set."""
        return [(un, *joined) for un, module in self._program_c24() for joined in module.joined_messages()]

    def c24_word_unit_sends(self) -> list[tuple[int, int, int, int]]:
        """(start I/O, channel, count, bytes sent) of the first G_OUTPUT a QJ71C24N channel
        the program drives sent in word units (buffer memory 96H / 136H = 0, the default)."""
        return [(un, *sent) for un, module in self._program_c24() for sent in module.word_unit_sends()]

    def c24_addressed(self) -> list[int]:
        """Start I/O numbers (U0 -> 0) of the QJ71C24N modules the program's G_OUTPUT /
        G_INPUT have addressed so far."""
        return [un for un, _module in self._program_c24()]

    def _program_c24(self) -> list:
        """(start I/O, module) of the QJ71C24N modules the program's G_OUTPUT / G_INPUT have
        addressed so far, by start I/O: the ones on the robot's line."""
        return [(un, module) for un, module in sorted(self._instructions()._c24.items()) if module.addressed]

    def _instructions(self):
        return self.module.namespace["_I"]

    def c24_buffer(self, un: int = 0) -> list[int]:
        """Buffer memory of the QJ71C24N at start I/O `un` (the same words as U0\\G...)."""
        return self.rt.buffer(un)

    # ------------------------------------------------------------------ errors
    def _guard(self, fn):
        try:
            return fn()
        except SimulationError as err:
            err.source_line = self._source_line(err.location)
            raise
        except RecursionError:
            err = SimulationError("function blocks call each other without end (recursion)",
                                  self._st_location(sys.exc_info()[2]), self.rt.now_us)
            err.source_line = self._source_line(err.location)
            raise err from None
        except Exception as e:  # a fault of the simulator itself: point at the ST line anyway
            err = SimulationError(f"simulator fault while running this statement: {e!r}",
                                  self._st_location(sys.exc_info()[2]), self.rt.now_us)
            err.source_line = self._source_line(err.location)
            raise err from e

    def _source_line(self, location: str | None) -> str | None:
        """The ST text of the line a location "file:line:col" points at."""
        if not location:
            return None
        file, line, _ = location.rsplit(":", 2)
        for f in self.files:
            if f.filename == file:
                lines = text_lines(f.text)
                n = int(line)
                return lines[n - 1] if 1 <= n <= len(lines) else None
        return None

    def _st_location(self, tb) -> str | None:
        loc = None
        while tb is not None:
            if tb.tb_frame.f_code.co_filename == GENERATED_FILE:
                span = self.module.span_at(tb.tb_lineno)
                if span is not None:
                    loc = str(span)
            tb = tb.tb_next
        return loc


class Instance(InstanceProxy):
    """An FB or PROGRAM instance you can drive: labels by name, `scan()`, `run(ms=...)`."""

    __slots__ = ()

    def __init__(self, obj, project: Project, label: str):
        super().__init__(obj, project.module, label, project)

    def scan(self, n: int = 1) -> "Instance":
        """Run n scans in which only this instance is called."""
        self._project._run([self._obj._body], None, n)
        return self

    def run(self, ms: float | None = None, scans: int | None = None,
            until: Callable[["Instance"], bool] | None = None, timeout_ms: float = 60_000) -> "Instance":
        """Scan repeatedly for `ms` of virtual time (or `scans` scans, or until
        `until(instance)` is true — at most `timeout_ms`)."""
        p = self._project
        if until is not None:
            if not callable(until):
                raise TypeError(f"until is a function of the instance that says when to stop, e.g. "
                                f"until=lambda fb: fb.o_bDone; got {until!r:.60}")
            if ms is not None or scans is not None:
                raise TypeError("run(until=...) scans until the condition holds: give the most virtual "
                                "time to wait as timeout_ms=..., not ms= or scans=")
            stop = _stop_time(p.rt.now_us, timeout_ms, None, what="timeout_ms")
            while not until(self):
                if p.rt.now_us >= stop:
                    raise TimeoutError(f"{self._label}: condition not met within {timeout_ms} ms of virtual time")
                p._run([self._obj._body], None, 1)
            return self
        p._run([self._obj._body], _stop_time(p.rt.now_us, ms, None, scans, until_word="until"), scans)
        return self


def _stop_time(now: int, ms, until_us, scans=None, what: str = "ms", until_word: str = "until_us"):
    """The virtual time to stop at. `until_word` is how the caller's own third way to say it
    is spelt (an instance's run takes until=, run_programs until_us=)."""
    given = [f"{name}=" for name, v in (("ms", ms), ("scans", scans), ("until_us", until_us)) if v is not None]
    if len(given) > 1 and what == "ms":
        raise ValueError(f"say how long to run once: {' and '.join(given)} are both given; "
                         f"give one of ms=..., scans=... or {until_word}=...")
    if ms is not None:
        if isinstance(ms, bool) or not isinstance(ms, (int, float)) or not math.isfinite(ms) or ms < 0:
            raise ValueError(f"{what} must be a finite number of milliseconds, 0 or more; got {ms!r}")
        return now + round(ms * 1000)
    if until_us is not None and (isinstance(until_us, bool) or not isinstance(until_us, int)):
        raise ValueError(f"until_us must be a whole number of microseconds; got {until_us!r}")
    return until_us


#: parsed and checked sources by (editor, CPU, file names and texts): `uitamr verify` loads
#: the same library for scenario after scenario; the trees are only read after the check
_CHECKED: dict[tuple, tuple[list, list]] = {}
_CHECKED_MAX = 8


def _parsed_and_checked(texts: dict[str, str], editor: str, cpu: str | None = None) -> tuple[list, list]:
    """The parsed files and the warnings of parsing and checking them (LoadError for errors);
    `cpu` (a CPU profile name): the CPU whose instruction names no label may take."""
    from verifier import st

    key = (editor, cpu, tuple(texts.items()))
    found = _CHECKED.get(key)
    if found is not None:
        return found
    files = [st.parse(text, name, target=editor) for name, text in texts.items()]
    errors = [d for f in files for d in f.diagnostics if d.is_error]
    if errors:
        raise LoadError(errors)
    warnings = [d for f in files for d in f.diagnostics if not d.is_error]
    checked = _run_checker(files, editor, cpu)
    errors = [d for d in checked if d.is_error]
    if errors:
        raise LoadError(errors)
    warnings.extend(d for d in checked if not d.is_error)
    if len(_CHECKED) >= _CHECKED_MAX:
        _CHECKED.pop(next(iter(_CHECKED)))
    _CHECKED[key] = (files, warnings)
    return files, warnings


def _only_programs(files, programs: Iterable[str] | None) -> frozenset[str] | None:
    """`programs` as compile_files takes them: upper-case, and None (compile everything)
    unless each names a PROGRAM of the files, so that asking for a missing one still
    finds every POU loaded and the caller's "no such PROGRAM" can list them."""
    if programs is None:
        return None
    if isinstance(programs, str):
        raise TypeError(f"programs is a list of PROGRAM names, e.g. [{programs!r}]")
    wanted = frozenset(name.upper() for name in programs)
    defined = {pou.key for f in files for pou in f.pous if pou.kind == "PROGRAM"}
    return wanted if wanted and wanted <= defined else None


def _run_checker(files, target, platform=None):
    # import the function itself: `verifier.st.check` becomes the submodule once imported
    from verifier.st.check import check

    return check(files, target, platform)


_LIVE: list = []


def _register(project: Project) -> None:
    """Projects created during the current test (the pytest plugin shows their state)."""
    _LIVE.append(project)
    del _LIVE[:-8]


def live_projects() -> list[Project]:
    return list(_LIVE)


def forget_projects() -> None:
    _LIVE.clear()


__all__ = ["load", "Project", "Instance", "LoadError", "SimulationError", "StructT", "StringT"]
