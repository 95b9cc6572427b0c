"""Run one scenario: the simulated PLC, the virtual RS-485 line and the robot, scan by scan
in virtual time; then judge the evidence.

This is the only module that touches the simulator, the line and the robot; everything
after the run (rules, expectations, reports) works on plain data.
"""
from __future__ import annotations

import gc
import math
import os
import re
import time
from functools import lru_cache
from pathlib import Path
from dataclasses import replace
from typing import Any, Callable

from verifier.amr.robot import Robot
from verifier.amr.schema import did_you_mean
from verifier.link import Line
from verifier.link.converter import Converter
from verifier.place import Place
from verifier.sim.values import InstanceProxy, read_together
from verifier.textfile import shown_path

from .durations import format_seconds
from .events_shown import thin_line_events
from .evidence import RunEvidence, Samples
from .expectations import judge
from .overwritten import overwritten_input_notes
from .result import (KEEP_ALL, RULE_EVENTS, Keep, LineEvent, Mistake, ScenarioMistakes, ScenarioResult, TraceRecord,
                     UnusableInput, judged_with, summarize_diagnostics)
from .rules import check_all
from .scenario import (BUFFER_MEMORY, DEFAULT_PLATFORM, DEVICE_NAME, Scenario, ScenarioError, bundled_platform,
                       scenario_power_on_stop)
from .stream import Stream
from .traffic import analyse, converter_drops

Progress = Callable[[int, int], None]  # (virtual now, virtual end) in µs
PROGRESS_STEP_US = 1_000_000  # report progress every virtual second
STREAM_EVERY_US = 10_000_000  # how often a run judged as it goes takes the settled frames

_DEVICE = DEVICE_NAME
# `_Plc.cpu_notes` (with the parsed files they are about) by (files, CPU, program, working
# folder): worked out once per process, as every scenario on the same sources shares the files
_CPU_NOTES: dict[tuple[int, str, str, str], tuple[list, list[str]]] = {}
_CPU_NOTES_MAX = 16


class _Plc:
    """The simulated PLC as the runner uses it: load, attach the line, scan, read, write."""

    def __init__(self, scenario: Scenario, line: Line | Converter):
        import verifier
        from verifier.sim.errors import LoadError

        if not scenario.sources:
            raise _key_mistake(scenario, "sources", "no ST sources: name them on the command line or in 'sources'")
        missing = [str(p) for p in scenario.sources if not p.is_file()]
        if missing:
            raise _key_mistake(scenario, "sources", f"no such ST file: {', '.join(missing)}")
        try:
            self.project = verifier.load(
                *[str(p) for p in scenario.sources],
                target=scenario.target,
                cpu=scenario.platform,
                scan_ms=scenario.scan_us / 1000,
                jitter_ms=scenario.scan_jitter_us / 1000,
                seed=scenario.seed,
                # compile only what the program runs (every file is still checked)
                programs=None if scenario.program is None else [scenario.program],
            )
        except LoadError as exc:
            exc = exc.shown_from(os.getcwd())  # plc/MAIN.st:7:1, as `uitamr check` and "sent by" name it
            hint = _platform_hint(scenario)
            # one JUnit test case per error, each at its place (the message lists them all)
            each = [Mistake(text + hint, place) for place, text in exc.located()]
            raise UnusableInput(str(exc) + hint, at=exc.place(), mistakes=each or None) from None
        try:
            if isinstance(line, Converter):
                self.project.attach_tcp(line)
            else:
                self.project.attach_serial(scenario.serial_channel, line)
        except ValueError as exc:
            raise _key_mistake(scenario, "channel", str(exc)) from None
        self.name = self._program_name(scenario)
        self.program = self.project.program(self.name)

    def cpu_notes(self) -> list[str]:
        """Devices the program uses that exist on this CPU but are another CPU family's
        special relays or registers (M8002 on a Q is an ordinary relay the CPU never sets):
        `uitamr check --platform`'s warnings, for the POUs compiled for this run (those the
        program uses when the scenario names it)."""
        project = self.project
        if project.cpu.family == "fx3":
            return []  # the FX3's own special numbers: nothing to say
        cwd = os.getcwd()
        key = (id(project.files), project.cpu.name, self.name.upper(), cwd)
        cached = _CPU_NOTES.get(key)
        if cached is None:
            from verifier.sim.cpucheck import cpu_diagnostics

            found = cpu_diagnostics(project.files, project.cpu, pous=set(project.module.pous))
            notes = [f"{_relative(str(d.place), cwd)}: {d.message}" for d in found if not d.is_error]
            if len(_CPU_NOTES) >= _CPU_NOTES_MAX:
                del _CPU_NOTES[next(iter(_CPU_NOTES))]
            cached = _CPU_NOTES[key] = (project.files, notes)  # the files kept alive: their id is not reused
        return cached[1]

    def _program_name(self, scenario: Scenario) -> str:
        programs = self.project.pou_names("PROGRAM")
        listing = ", ".join(programs) or "none"
        wanted = (scenario.program or "").upper()
        other = next((pou for f in self.project.files for pou in f.pous if pou.key == wanted), None)
        if other is not None and other.kind != "PROGRAM":  # the FB under test named instead of its caller
            raise _key_mistake(scenario, "program", f"{other.name} is a {other.kind}, not a PROGRAM: name the "
                               f"PROGRAM that calls it (the sources define: {listing})")
        if not programs:
            # SOURCES given on the command line: the file is all there is
            raise _key_mistake(scenario, "sources", "the sources define no PROGRAM, only function blocks and "
                               "functions: give also the .st file of the PROGRAM to run")
        if scenario.program is None:
            if len(programs) == 1:
                return programs[0]
            if scenario.for_sources:  # the bundled file is not the user's to change
                raise UnusableInput(f"--matrix runs one PROGRAM of your sources under the bundled fault sets: say which "
                                    f"with --program; the sources define: {listing}")
            if scenario.path is None:  # no file to name it in: the option alone
                raise UnusableInput(f"say which PROGRAM to run with --program; the sources define: {listing}")
            raise _key_mistake(scenario, "program", f"say which PROGRAM to run (program = \"{programs[0]}\" "
                               f"in the file, or --program); the sources define: {listing}")
        for name in programs:
            if name.upper() == scenario.program.upper():
                return name
        raise _key_mistake(scenario, "program", f"no PROGRAM {scenario.program!r} in the sources; "
                           f"they define: {listing}")

    def program_file(self) -> Path | None:
        """The ST file that defines the PROGRAM that runs."""
        return next((Path(f.filename) for f in self.project.files for pou in f.pous
                     if pou.key == self.name.upper() and pou.kind == "PROGRAM"), None)

    @property
    def now_us(self) -> int:
        return self.project.now_us

    def run(self, until_us: int, before_scan, after_scan) -> None:
        """Scan the program until virtual time `until_us`, with a hook on each side of a
        scan (each called with the project, verifier.sim.project.Project)."""
        self.project.after_scan.append(after_scan)
        try:
            self.project.run_programs([self.name], until_us=until_us, on_scan=before_scan)
        finally:
            self.project.after_scan.remove(after_scan)

    def problem(self, name: str) -> str | None:
        """Why `name` is not a single value this program can read, or None."""
        if _DEVICE.match(name):
            try:
                self.project.devices[name.upper()]
            except (KeyError, ValueError) as exc:
                return str(exc)
            return None
        target, shown = self.program, ""
        parts = _path_parts(name)
        for index, part in enumerate(parts):
            try:
                inside = target
                target = _step(target, part)
            except _MISSING:
                hint = "" if part.startswith("[") else _did_you_mean(part, inside, parts[index + 1:])
                if not shown:
                    return f"the program {self.name} has no label {name!r}{hint}"
                what = f"element {part}" if part.startswith("[") else f"member {part!r}"
                return f"no label {name!r} in the program {self.name}: {shown} has no {what}{hint}"
            shown += part if part.startswith("[") or not shown else f".{part}"
        if not isinstance(_plain(target), (bool, int, float, str)):
            return (f"{name!r} in {self.name} is not a single value (an array or FB instance?); "
                    "name one element or member, e.g. wBuf[2] or fbRobot.o_bBusy")
        return None

    def read(self, name: str) -> Any:
        if _DEVICE.match(name):
            return self.project.devices[name.upper()]
        target = self.program
        for part in _path_parts(name):
            target = target[int(part[1:-1])] if part.startswith("[") else getattr(target, part)
        return target

    def reader(self, name: str) -> Callable[[], Any]:
        """`read(name)` with the label path resolved once (for reading every scan)."""
        from verifier.sim.values import reader

        if _DEVICE.match(name):
            return self.project.devices.reader(name.upper())
        return reader(self.program, _path_parts(name))

    def write(self, name: str, value: Any) -> None:
        if _DEVICE.match(name):
            self.project.devices[name.upper()] = value
            return
        parts = _path_parts(name)
        target = self.program
        for part in parts[:-1]:
            target = target[int(part[1:-1])] if part.startswith("[") else getattr(target, part)
        last = parts[-1]
        if last.startswith("["):
            target[int(last[1:-1])] = value
        else:
            setattr(target, last, value)

    def diagnostics(self) -> list[str]:
        """Each of the simulator's diagnostics, its ST file as the reports show ST files
        (relative to the working folder when inside it, as the frames' origins)."""
        import dataclasses

        cwd = os.getcwd()
        return [str(dataclasses.replace(d, location=_relative(d.location, cwd))) for d in self.project.diagnostics]

    def diagnostic_summary(self) -> list[str]:
        cwd = os.getcwd()
        return summarize_diagnostics(self.project.diagnostics, lambda location: _relative(location, cwd))


_MISSING = (AttributeError, KeyError, IndexError, TypeError, ValueError, LookupError)


def _step(target: Any, part: str) -> Any:
    """`target`'s member or element `part` (a name, or "[3]")."""
    return target[int(part[1:-1])] if part.startswith("[") else getattr(target, part)


def _has_path(target: Any, parts: list[str]) -> bool:
    try:
        for part in parts:
            target = _step(target, part)
    except _MISSING:
        return False
    return True


def _did_you_mean(part: str, instance: Any, rest: list[str] = ()) -> str:
    """'; did you mean 'fbBatt'?' when `instance` (a program or FB) has a label spelt
    nearly as `part` (a scenario's typo of an instance or member name) that also has the
    `rest` of the path (fbEngine.o_bErr does not offer the BOOL bEngineOn), else ''."""
    if not isinstance(instance, InstanceProxy):
        return ""  # a value or an array: no labels to offer
    names = [n for n in instance._names() if _has_path(instance, [n, *rest])]  # a standard FB's (TON) too
    return did_you_mean(part, names)


def _path_parts(name: str) -> list[str]:
    return re.findall(r"[A-Za-z_][A-Za-z0-9_]*|\[[0-9]+\]", name)


def _platform_hint(scenario: Scenario) -> str:
    """When the sources do not load on the scenario's platform but do on another (an FX5U
    program in a scenario without `platform`, which means fx3u): a line saying which to set."""
    from .platform import platforms_that_load

    fits, _ = platforms_that_load(scenario.sources)
    if not fits or scenario.platform in fits:
        return ""
    larger = bundled_platform(scenario.platform)
    if larger != scenario.platform and larger in fits:
        # an FX3G program that names a device only the FX3U has: the program does not fit
        # the CPU named, and another platform to give would hide that
        named = f"--platform {scenario.platform}" if scenario.platform_from_option else _key_where(scenario, "platform")
        # the file's key names the CPU: it is the key to change (--platform only overrides it)
        change = (f"set platform = \"{larger}\" in {scenario.path} (or give --platform {larger})"
                  if not scenario.platform_from_option and scenario.path is not None else f"give --platform {larger}")
        return (f"\n{named}: the sources load on the {larger} but not on the {scenario.platform}, which has fewer "
                f"devices (docs/instructions.md §2; `uitamr check --platform {scenario.platform}` lists every one it "
                f"lacks): for an {scenario.platform.upper()} use devices it has; for an {larger.upper()} {change}")
    if scenario.platform_from_option:  # the option is to blame, not a file's key
        return (f"\n--platform {scenario.platform}: the sources load on {', '.join(fits)}, not on "
                f"{scenario.platform}: give --platform {fits[0]}")
    if scenario.path is None and scenario.channel_from_option:
        # --channel fx5:1 picked the CPU its port belongs to: the option is to blame, not a default
        from verifier.plcfacts import serial_channels

        return (f"\n--channel {scenario.channel}: a port of the {scenario.platform}, on which the sources do not "
                f"load; they load on {', '.join(fits)}: give a port of the {fits[0]} "
                f"({', '.join(serial_channels(fits[0]))}) or leave --channel out")
    if scenario.path is None:  # no file's key to point at
        return (f"\nthe sources load on {', '.join(fits)}, not on {scenario.platform} (the default): "
                f"give --platform {fits[0]}")
    defaulted = "platform" not in scenario.key_lines and scenario.platform == DEFAULT_PLATFORM
    now = f"{scenario.platform} (the default)" if defaulted else scenario.platform
    return (f"\n{_key_where(scenario, 'platform')}: the sources load on {', '.join(fits)}, not on {now}: "
            f'set platform = "{fits[0]}" in the scenario, or give --platform {fits[0]}')


def _key_where(scenario: Scenario, key: str) -> str:
    """Where the scenario's `key` ('program', 'channel', 'sources', 'platform') was given:
    `file:line:col: key`, `--key` when the command line's option replaced the file's, the
    SOURCES arguments when they replaced the file's sources, else the start of the file
    (Scenario.key_where). The runner's one way to place a key: it knows the command line."""
    return _key_place(scenario, key)[0]


def _key_place(scenario: Scenario, key: str) -> tuple[str, Place | None]:
    """`_key_where(scenario, key)`, and the place it names as data (UnusableInput's `at`):
    none for the SOURCES arguments or an option."""
    if key in scenario.key_lines:
        line = scenario.key_lines[key]
        return scenario.where(key, line), scenario.at(line)
    if key == "sources" and scenario.sources:  # SOURCES are arguments, no option: name the files
        shown = [_display_path(p) for p in scenario.sources[:3]]
        more = f" and {len(scenario.sources) - 3} more" if len(scenario.sources) > 3 else ""
        return f"SOURCES ({', '.join(shown)}{more})", None
    if key != "sources" and getattr(scenario, f"{key}_from_option"):
        return f"--{key}", None  # given on the command line: no file is where to look
    return scenario.key_where(key), scenario.key_at(key)


def _key_mistake(scenario: Scenario, key: str, text: str) -> UnusableInput:
    """`text` as the mistake of the scenario's `key`: the message and the place (for the
    JUnit report) from `_key_place`, so that the two cannot disagree."""
    where, at = _key_place(scenario, key)
    return UnusableInput(f"{where}: {text}", at=at)


def _line_mistake(scenario: Scenario, key: str, line: Place | None, text: str) -> UnusableInput:
    """`text` as the mistake of `key` at `line` of the scenario file: message and place."""
    return UnusableInput(f"{scenario.where(key, line)}: {text}", at=scenario.at(line))


def _display_path(path: Path | None) -> str | None:
    """A path as people want to read it: relative to the working folder when inside it, as
    the user reached it (textfile.shown_path)."""
    if path is None:
        return None
    return shown_path(path, os.getcwd())


@lru_cache(maxsize=1024)
def _relative(origin: str | None, cwd: str) -> str | None:
    """An ST location "file:line:col" (the file's name may hold a ':', as a Windows path's
    drive does) with the file relative to the working folder `cwd` when inside it, by the
    path the sources reached it (a toolkit vendored by a symlink shows as
    vendor/uitamr/plc/..., not where the link leads; textfile.shown_path).
    Worked out once per location: every frame of a long run names the ST line that sent
    it, and the frames then share one string."""
    place = Place.of_location(origin)
    if place is None:
        return origin
    return f"{shown_path(place.file, cwd)}:{place.line}:{place.col}"


def _trace_records(frames: list, end_us: int) -> list[TraceRecord]:
    """The line's frames that started before `end_us` as trace records, converted in place
    (one frame at a time is held twice, not the whole trace), with origins relative to the
    working folder and equal frames sharing one bytes object (a status poll and its reply
    repeat thousands of times in an hour)."""
    cwd = os.getcwd()
    shared: dict[bytes, bytes] = {}
    kept = len(frames)
    while kept and frames[kept - 1].t_start_us >= end_us:  # in start order: the late ones are last
        kept -= 1
    del frames[kept:]
    for k, f in enumerate(frames):
        data = bytes(f.data)
        frames[k] = TraceRecord(f.t_start_us, f.t_end_us, f.direction, shared.setdefault(data, data),
                                _relative(f.origin, cwd))
    return frames


class _NewRuleEvents:
    """The events the rules read that happened since the last call: the line's "gap"
    events and the converter's drops (a robot's events, and the converter's others, are
    for reports only). With `drop_the_rest`, the converter's events are let go of once
    read (no report lists them)."""

    def __init__(self, line: Line, converter: Converter | None, drop_the_rest: bool):
        self.line, self.converter, self.drop_the_rest = line, converter, drop_the_rest
        self.gaps_read = 0
        self.converter_read = 0
        self.read: list[LineEvent] = []  # every one returned, for the trace (ScenarioResult.rule_events)

    def __call__(self, end_us: float = float("inf")) -> list:
        gaps = self.line.gaps
        new = [e for e in gaps[self.gaps_read:] if e.t_us <= end_us]
        self.gaps_read = len(gaps)
        if self.converter is not None:
            events = self.converter.events
            new += [e for e in events[self.converter_read:] if e.kind == "converter.dropped" and e.t_us <= end_us]
            self.converter_read = len(events)
            if self.drop_the_rest:
                events.clear()
                self.converter_read = 0
        self.read += [LineEvent(e.t_us, e.kind, e.message) for e in new]
        return new


def _plain(value: Any) -> Any:
    """A sampled value as bool/int/float (the simulator may hand back typed wrappers)."""
    if isinstance(value, (bool, int, float)):
        return value
    for cast in (int, float):
        try:
            return cast(value)
        except (TypeError, ValueError):
            continue
    return value


def _check_labels(plc: _Plc, scenario: Scenario) -> Scenario:
    """Every label the scenario reads or writes must exist and have the type its key needs:
    a BOOL where a condition is expected, a value that fits the label an input writes. A
    missing default response signal is dropped. Errors name the file, line and key."""
    kinds: dict[str, str] = {}
    mistakes: list[UnusableInput] = []  # every one, in the file's order: not a run per misspelt label
    for use in scenario.label_uses():
        missing, line = None, use.line
        for name in use.names:
            if (missing := plc.problem(name)) is not None:
                line = scenario.key_lines.get(f"{use.key}:{name}", use.line)  # the label inside a condition
                break
        if missing is not None and use.optional:
            scenario = _without_default_signal(plc, scenario)
            continue
        if missing is not None:
            mistakes.append(_line_mistake(scenario, use.key, line, missing))
            continue
        for name in use.names:
            value = _plain(plc.read(name))
            kinds[name] = "bool" if isinstance(value, bool) else "STRING" if isinstance(value, str) else "number"
        problem = use.condition.type_error(kinds) if use.condition is not None else None
        for name, value in (use.values or {}).items():
            problem = problem or _input_problem(plc, name, value)
        if problem and use.optional:  # the default signal: an o_bErr that is not a BOOL is not it
            scenario = _without_default_signal(plc, scenario)
        elif problem:
            mistakes.append(_line_mistake(scenario, use.key, use.line, problem))
    mistakes.sort(key=lambda m: (m.place is None, m.place.line if m.place else 0, m.place.col if m.place else 0))
    if len(mistakes) == 1:
        raise mistakes[0]
    if mistakes:
        raise ScenarioMistakes(mistakes)
    return scenario


def _without_default_signal(plc: _Plc, scenario: Scenario) -> Scenario:
    """`scenario` without the default response signal the program does not have (or not as
    a BOOL), with the FB outputs its message may offer instead."""
    return replace(scenario, options=replace(scenario.options, response_signal=None,
                                             response_signal_hint=_error_outputs(plc)))


def _error_outputs(plc: _Plc) -> str:
    """The BOOL `o_bErr` outputs of the program's FB instances ("fbEngine.o_bErr, ..."), at
    most three, in declaration order: what a scenario may name as the response signal when the
    program has no `o_bErr` of its own. "" when it has none."""
    program = plc.program
    if not isinstance(program, InstanceProxy):
        return ""
    found = []
    for name in program._names():
        label = f"{name}.o_bErr"
        if plc.problem(label) is None and isinstance(_plain(plc.read(label)), bool):
            found.append(label)
    return ", ".join(found[:3]) + (", ..." if len(found) > 3 else "")


def _input_problem(plc: _Plc, name: str, value: Any) -> str | None:
    """Why `value` cannot be written to `name`, or None. Tried on the real label before
    the first scan (and put back): the simulator's own conversion is the judge of range."""
    before = _plain(plc.read(name))
    if isinstance(before, str):  # a scenario's values are true/false and numbers: it cannot say one
        return f"{name} is a STRING: an input sets BOOL and number labels only; set a BOOL the program reads instead"
    if isinstance(before, bool) != isinstance(value, bool):
        if isinstance(before, bool):
            return f"{name} is a BOOL (a bit): set it to true or false, not {value!r}"
        return f"{name} is a number: set it to a number, not {str(value).lower()}"
    if _DEVICE.match(name) and isinstance(value, float) and not math.isfinite(value):  # int(inf): OverflowError
        return f"{name} is a word device: give a whole number -32768..65535, not {value}"
    try:
        plc.write(name, value)
    except (ValueError, TypeError, AttributeError) as exc:
        return str(exc)  # nothing was written: nothing to put back (a constant refuses that too)
    try:
        after = _plain(plc.read(name))
    finally:
        plc.write(name, before)
    if isinstance(value, float) and isinstance(after, float):
        fits = abs(after - value) <= 1e-6 * max(1.0, abs(value))  # REAL keeps about 7 digits
    elif _DEVICE.match(name) and isinstance(value, int) and -0x8000 <= value <= 0xFFFF:
        fits = (after - value) % 0x10000 == 0  # a word device holds any 16-bit pattern (16#FFFF)
    else:
        fits = after == value
    if not fits:
        return f"{value!r} does not fit {name}: it would read back as {after!r}"
    return None


def _apply_plc_settings(plc: _Plc, scenario: Scenario) -> None:
    """[[c24]] module settings, then [initial] devices and buffer memory, before the first scan."""
    for setting in scenario.c24:
        line = scenario.key_lines.get(setting.key)
        if scenario.platform != "q":
            raise _line_mistake(scenario, setting.key, line,
                                f"the QJ71C24N is a Q-series module; the platform is {scenario.platform}")
        # unit None (--matrix): the settings go to whichever module the program drives
        try:
            plc.project.configure_c24(
                setting.unit, setting.channel, byte_units=setting.byte_units, receive_count=setting.receive_count,
                end_code=setting.end_code,
                no_reception_ms=None if setting.no_reception_us is None else setting.no_reception_us / 1000,
                no_reception_format=setting.no_reception_format,
            )
        except (ValueError, KeyError) as exc:
            raise _line_mistake(scenario, setting.key, line, str(exc)) from None
    for name, value in scenario.initial:
        key = f"initial.{name}"
        buffer = BUFFER_MEMORY.match(name)
        if buffer:
            words = plc.project.c24_buffer(int(buffer.group(1), 16))
            words[int(buffer.group(2))] = value - 0x10000 if value > 0x7FFF else value
            continue
        problem = plc.problem(name) or _input_problem(plc, name, value)
        if problem:
            raise _line_mistake(scenario, key, scenario.key_lines.get(key), problem)
        plc.write(name, value)


UNREAD_NOTE_US = 1_000_000  # a message unread this long at the end of the run is not being read


def _c24_signal_inputs(scenario: Scenario, plc: _Plc, modules: list[int]) -> list[str]:
    """A note for each `[[inputs]]` entry that sets one of the input signals of a QJ71C24N
    the program drives (its reception data read request or reception abnormal detection,
    X3/X4 and XA/XB from the module's start I/O): the module turns those on and off itself,
    so a button wired there fights it (journey32b: a jog button on X3 beside the port's
    i_bReadReq := X3, and the jog was never sent)."""
    from verifier.sim.instructions.c24 import ABNORMAL, READ_REQUEST

    signals = {}
    for un in modules:
        for channel in (1, 2):
            signals[un * 16 + READ_REQUEST[channel]] = (un, f"CH{channel} reception data read request")
            signals[un * 16 + ABNORMAL[channel]] = (un, f"CH{channel} reception abnormal detection")
    notes = []
    for step in scenario.inputs:
        key = f"{step.key}.set"
        for name in step.values:
            try:  # the CPU's own reading of the name (X3, x03: the Q numbers X in hex)
                device = plc.project.devices.address(name)
            except KeyError:
                continue  # a label
            if device.area != "X" or device.index not in signals:
                continue
            un, what = signals[device.index]
            where = scenario.where(key, scenario.key_lines.get(f"{key}.{name}", scenario.key_lines.get(key)))
            notes.append(f"{where}: {name} is the {what} of the QJ71C24N at U{un:X} that the program drives: the "
                         f"module turns it on and off itself, so a button or sensor wired there fights the module "
                         f"(and the program reads the module's signal); wire it to an X input that is not one of "
                         f"the module's signals")
    return notes


def _c24_notes(scenario: Scenario, plc: _Plc, violations: dict | None = None) -> list[str]:
    """Replies left in the program's QJ71C24N (the port reads on another input signal than
    the module's read request: the run shows only repeated attempts), and a [[c24]] for a
    module the program never drove, which changed nothing: the robot hangs on the module
    the program's G_OUTPUT / G_INPUT address, so its settings - the no-reception time a
    fault set may rely on - were not in force. Said, with the module the program did use.
    And, when the line saw frames of the wrong length (UITAMR-FORMAT in `violations`), a
    channel the program sent on in word units: the library's port counts bytes."""
    from verifier.sim.instructions.c24 import ABNORMAL, BUFFER, READ_REQUEST

    if scenario.platform != "q":
        return []
    used = plc.project.c24_addressed()
    if not used:
        return []
    notes = _c24_signal_inputs(scenario, plc, used)
    for un, channel, count, since_us in plc.project.c24_unread():
        if plc.now_us - since_us < UNREAD_NOTE_US:
            continue  # a reply that came in the last moments of the run
        read, error = READ_REQUEST[channel], ABNORMAL[channel]
        notes.append(f"QJ71C24N U{un:X} CH{channel}: {count} received message(s) never read by G_INPUT, the "
                     f"oldest since {format_seconds(since_us)}; the module's reception data read request for "
                     f"CH{channel} is X{un * 16 + read:X} (reception abnormal detection X{un * 16 + error:X}): "
                     f"is that what the program passes to the port (i_bReadReq, i_bRecvErr)?")
    for un, channel, count, since_us, recv_count, end_code in plc.project.c24_unfinished():
        if plc.now_us - since_us < UNREAD_NOTE_US:
            continue  # a reply still coming in
        words = BUFFER[channel]
        notes.append(f"QJ71C24N U{un:X} CH{channel}: {count} received byte(s) wait in the module as an unfinished "
                     f"message since {format_seconds(since_us)}: it ends at the received data count "
                     f"({words['recv_count']:X}H = {recv_count}) or the receive end code ({words['end_code']:X}H = "
                     + ("none" if end_code == 0xFFFF else f"{end_code:04X}H") + "). UITAMR_PortQC24 needs a count "
                     f"of 8 bytes and no end code: set {words['recv_count']:X}H = 8 and {words['end_code']:X}H = "
                     f"FFFFH in the module's parameters, or in the first scan (U{un:X}\\G{words['recv_count']} := 8; "
                     f"U{un:X}\\G{words['end_code']} := 16#FFFF, as UITAMR_ExampleQ does); in a scenario, [[c24]] "
                     f"receive_count = 8, end_code = \"none\"")
    for un, channel, since_us, before, gap_us in plc.project.c24_joined():
        notes.append(f"QJ71C24N U{un:X} CH{channel}: {before} received byte(s) from {format_seconds(since_us)} waited "
                     f"{gap_us / 1000:.0f} ms in the module for the received data count and were read as one message "
                     f"with the bytes after them: no no-reception monitoring time (timer 0) is set, so a short reply "
                     f"(an exception, 5 bytes; noise) puts every later reply out of step. Set timer 0 with format 1 "
                     f"in GX Works (docs/plc-library.md, platform notes: QJ71C24N); in a scenario, [[c24]] "
                     f"no_reception = \"5ms\"")
    if (violations or {}).get("UITAMR-FORMAT"):
        # frames of the wrong length from a channel in word units: the port counted bytes
        for un, channel, count, nbytes in plc.project.c24_word_unit_sends():
            word = BUFFER[channel]["unit"]
            notes.append(f"QJ71C24N U{un:X} CH{channel} is in word units (buffer memory {word:X}H = 0, the "
                         f"module's default): G_OUTPUT sent a count of {count} as {nbytes} bytes. UITAMR_PortQC24 "
                         f"counts bytes: set byte units ({word:X}H = 1) in the module's parameters, or in the "
                         f"first scan (U{un:X}\\G{word} := 1, as UITAMR_ExampleQ does); in a scenario, [[c24]] "
                         f"byte_units = true")
    for setting in scenario.c24:
        if setting.unit is None or setting.unit in used:
            continue
        where = scenario.where(setting.key, scenario.key_lines.get(setting.key))
        notes.append(f"{where}: unit = {setting.unit} (U{setting.unit:X}) is not the QJ71C24N the program drives "
                     f"(its G_OUTPUT/G_INPUT address {', '.join(f'U{u:X}' for u in used)}); these settings "
                     f"were not in force: give unit = {used[0]}")
    return notes


def _missed_fault_notes(scenario: Scenario, robot, end_us: int) -> list[str]:
    """A reply fault that met no request (a window in which the program sent nothing, a
    request number never reached, `requests = "control"` while only status reads went
    out) tested nothing, though the run may pass: said, at the fault's line; so did a state
    fault that struck and changed nothing (off_tape with no tape task running). A window that
    opens only after the run's end (`end_us`: --duration, or a CPU that stopped) is not one
    the program left empty: --duration's own note names those faults, a stop is said as such."""
    notes = []
    for index, fault in robot.reply_faults_missed():
        key = f"faults[{index}]"
        where = scenario.where(key, scenario.key_lines.get(key))
        if fault.at_us is not None and fault.at_us >= end_us:
            if scenario.duration_from_option and fault.at_us >= scenario.duration_us:
                continue  # "--duration ... ends the run before ... scripted fault(s), not tested"
            why = f"the simulation stopped at {format_seconds(end_us)}, before its window opened at {fault.at_s:g} s"
        elif fault.at_s is not None:
            window = f"from {fault.at_s:g} s" + (f" for {fault.duration_s:g} s" if fault.duration_s else "")
            why = f"no {fault.requests + ' ' if fault.requests != 'any' else ''}request reached the robot {window}"
        else:
            why = f"request {fault.on_request} never reached the robot"
        notes.append(f"{where}: {fault.describe()}: {why}, so this fault was not tested")
    for index, fault, why in robot.state_faults_without_effect():
        key = f"faults[{index}]"
        notes.append(f"{scenario.where(key, scenario.key_lines.get(key))}: {fault.describe()}: {why}, "
                     "so this fault was not tested")
    return notes


def _input_schedule(scenario: Scenario) -> list[tuple[int, dict[str, Any]]]:
    steps: list[tuple[int, dict[str, Any]]] = []
    for step in scenario.inputs:
        steps.append((step.at_us, dict(step.values)))
        if step.pulse_us is not None:
            steps.append((step.at_us + step.pulse_us,
                          {name: not value for name, value in step.values.items() if isinstance(value, bool)}))
    return sorted(steps, key=lambda s: s[0])


def _expecting_something(scenario: Scenario) -> Scenario:
    """A scenario with no expectation expects what every program must do - the power-on
    stop sent and answered, after a converter's refusals - as the run without a scenario
    file and --matrix do: judged by the rules alone, a program that never reaches the robot
    (a wrong channel, a converter at another address) would break none and pass."""
    if scenario.expectations:
        return scenario
    stop = scenario_power_on_stop(scenario)
    note = "no [[expect]] in the scenario: it expects what every program must do, the power-on stop sent and answered"
    return replace(scenario, expectations=(stop,), notes=(note,) + scenario.notes)


def _silence_note(scenario: Scenario, plc: _Plc, converter: Converter | None) -> str:
    """What a run in which nothing reached the robot's line says: and, where the program did
    talk, where to (another serial port, a TCP connection, a converter that was not there),
    with the setting that puts the robot on that route."""
    from verifier.sim.instructions.tcp import TcpPort

    rt = plc.project.rt
    channel = scenario.serial_channel
    note = f"the program sent nothing on {channel} in the whole run"
    other = {name: port.sent_count for name, port in sorted(rt.ports.items())
             if port.sent_count and name != channel}
    sent = "; ".join(f"it sent {count} frame(s) on {name}" for name, count in other.items())
    if converter is not None:
        note += " (nothing reached the robot's line through the converter"
        if converter.open_count == 0:
            note += ": the program opened no connection to it"
        elif converter.first_failed_open is not None and converter.accepted_count == 0:
            cfg = converter.config
            note += (f": {converter.first_failed_open}; set the scenario's [converter] ip and port to what the program "
                     f"opens, or, if the converter is at {cfg.ip}:{cfg.port}, make the program open that (its "
                     "port FB's address and port inputs)")
        note += ")"
        from verifier.sim.instructions.tcp import FixedBufferPort

        for port in rt.pollers:
            if isinstance(port, FixedBufferPort) and port.closes_while_open and not port.sends:
                # opened, then closed by the program itself, never used: it did not see it open
                note += (f"; the {port.name} opened the connection ({port.open_count} open(s)) and the "
                         f"program closed it again each time without sending: the port learns of the open "
                         f"from i_uOpenSignal, the module's open completion signal - does the program pass "
                         f"U{port.un:X}\\G{port.OPEN_SIGNAL} (and U{port.un:X}\\G{port.RECEIVE_SIGNAL} as "
                         f"i_uRecvSignal)?")
        if sent:
            note += f"; {sent}: a serial port, not the TCP route: drop [converter] from the scenario"
        return note
    opens = sum(poller.open_count for poller in rt.pollers if isinstance(poller, TcpPort))
    if sent:
        first = next(iter(other))
        # either side may be wrong: the scenario's port, or the program's (its port FB's channel)
        note += (f"; {sent}: the robot hangs on {channel} in this run: give --channel {first}, "
                 f'or channel = "{first}" in the scenario; or, if the robot is wired to {channel}, make the '
                 f"program drive {channel}")
    elif opens:
        note += (f"; it opened TCP connections ({opens} open(s)): the robot is behind a serial-to-TCP converter "
                 "on that route: add a [converter] table to the scenario (docs/scenarios.md)")
    return note


def _judge_whole(scenario: Scenario, trace: list[TraceRecord], end_us: int, events: list[LineEvent],
                 samples: Samples, stopped_early: bool):
    """Every rule's violations and every expectation's result, the run judged as a whole."""
    evidence = RunEvidence(scenario.settings, trace, end_us, events, samples, scenario.options, stopped_early,
                           scenario.duration_from_option)
    traffic = analyse(trace, scenario.settings, scenario.options, converter_drops(events))
    return check_all(evidence, traffic), [judge(expectation, evidence, traffic) for expectation in scenario.expectations]


def _set_up(scenario: Scenario) -> tuple[Scenario, Robot, Line, Converter | None, _Plc]:
    """The robot, the line (and the converter of the TCP route) and the PLC a run of
    `scenario` scans, with the labels the scenario names checked against the program and its
    PLC settings applied; ScenarioError/UnusableInput for input that cannot run."""
    scenario = _expecting_something(scenario)
    robot = Robot(scenario.settings, scenario.robot, list(scenario.faults))
    line = Line(robot)
    # the TCP route: the PLC talks to a converter, the rules judge the line behind it
    converter = Converter(line, scenario.converter) if scenario.converter is not None else None
    plc = _Plc(scenario, converter or line)
    plc.project.keep_serial_log(False)  # the line records every frame: the trace below
    scenario = _check_labels(plc, scenario)
    _apply_plc_settings(plc, scenario)
    return scenario, robot, line, converter, plc


def scenario_mistake(scenario: Scenario) -> ScenarioError | UnusableInput | None:
    """Why `scenario` cannot run (a label it names that the program does not have, ST that
    does not load, ...), found by setting the run up without scanning; None when it can.
    For saying the mistakes of every scenario of a command together once one of them has
    one: the runs would be of no use then."""
    try:
        _set_up(scenario)
    except (ScenarioError, UnusableInput) as exc:
        return exc
    return None


def run_scenario(scenario: Scenario, progress: Progress | None = None, *, plain: bool = False,
                 keep: Keep = KEEP_ALL) -> ScenarioResult:
    """Run `scenario` to its end and judge it. UnusableInput for input that cannot run.

    `keep` says what the result holds for reports beyond the verdict and the findings:
    every frame, the watched labels' changes and the events (verifier.verify.result.Keep).
    A run that keeps no frames is judged as it goes (verifier.verify.stream): the verdict,
    findings and frame counts are the same either way.

    `plain` runs every scan (no idle scans jumped over, verifier.sim.idle) and reads the
    watched labels by their names on each, recording them all: the reference the fast
    path is tested against (same result, byte for byte; `uitamr verify --every-scan`)."""
    wall_start = time.perf_counter()
    scenario, robot, line, converter, plc = _set_up(scenario)
    # every label the scenario names is read on each scan (a change marks the scan busy for
    # the idle check, which then need not compare the whole state); the watched ones are
    # recorded only when a report lists them
    names = scenario.variables()
    recorded = scenario.variables(watched=keep.details and keep.watched)
    samples = Samples(recorded)
    recorded_names = frozenset(recorded)
    picked = [k for k, name in enumerate(names) if name in recorded_names]
    schedule = _input_schedule(scenario)
    aborted = aborted_at = None
    end = scenario.duration_us
    from verifier.sim.errors import SimulationError

    # the fast path jumps over idle scans (verifier.sim.idle); the plain one runs them all
    idle = None if plain else plc.project.skip_idle_scans(
        [plc.name], read_devices=tuple(name for name in names if _DEVICE.match(name)),
        next_input_us=lambda: schedule[0][0] if schedule else float("inf"))

    rt = plc.project.rt

    def apply_inputs(_project=None) -> None:
        now = rt.now_us
        while schedule and schedule[0][0] <= now:
            for name, value in schedule.pop(0)[1].items():
                plc.write(name, value)
            if idle is not None:
                idle.busy = True

    read_all = read_together([plc.reader(name) for name in names])
    last: list[Any] = [object()]  # the values at the previous scan: record only changes

    def sample_on_change(_project=None) -> None:
        values = read_all()
        if values != last[0]:
            last[0] = values
            samples.record(rt.now_us, {names[k]: _plain(values[k]) for k in picked})
            if idle is not None:
                idle.busy = True

    def sample_plainly(_project=None) -> None:
        samples.record(plc.now_us, {name: _plain(plc.read(name)) for name in names})

    sample = sample_plainly if plain else sample_on_change  # plain: the reference path

    # judged as it goes unless the run is the reference path (plain): the trace and the
    # page take the frames from files written as the run goes; else as a whole at the end
    streamed = not plain and (not keep.frames or keep.frames_to_file is not None)
    stream = Stream(scenario.settings, scenario.options, samples, scenario.expectations, _relative,
                    keep.frames_to_file if keep.frames else None, scenario.name,
                    scenario.duration_from_option) if streamed else None
    rule_events = _NewRuleEvents(line, converter, drop_the_rest=not keep.details)
    taken_us = 0
    events_dropped = 0
    # what was made before the run (the compiled program, the scenario, the caller's objects)
    # is kept out of the garbage collector's full passes while the run goes: an hour of
    # fx3u-healthy made two, each walking every object again (about 5 % of the hour's CPU
    # time). Not when the caller froze objects itself: unfreezing would thaw theirs too.
    freeze = gc.isenabled() and gc.get_freeze_count() == 0
    if freeze:
        gc.freeze()
    try:
        while plc.now_us < end:
            plc.run(min(end, plc.now_us + PROGRESS_STEP_US), apply_inputs, sample)
            if stream is not None and plc.now_us - taken_us >= STREAM_EVERY_US:
                taken_us = plc.now_us
                stream.take(line.take_settled(), line.settled_until_us, rule_events())
                if not keep.details:
                    robot.events.clear()  # read by no rule, listed by no report asked for
                elif keep.events_at_most is not None:  # the page's: it shows the first ones
                    events_dropped += thin_line_events(line, keep.events_at_most, min(plc.now_us, end))
            if progress is not None:
                progress(plc.now_us, end)
    except SimulationError as exc:
        exc.location = _relative(exc.location, os.getcwd())  # as the frames' origins name ST files
        aborted, aborted_at = str(exc), exc.location
        end = min(end, plc.now_us)
    finally:
        if freeze:
            gc.unfreeze()
    if converter is not None:
        converter.advance(max(end, converter.now_us))
    else:
        line.advance(max(end, line.now_us))
    if stream is not None:
        rest = [frame for frame in line.hand_over_trace() if frame.t_start_us < end]
        violations, outcomes = stream.finish(rest, end, aborted is not None, rule_events(end))
        trace, tx_count, rx_count = [], stream.tx_count, stream.rx_count
    else:
        trace = _trace_records(line.hand_over_trace(), end)
    line_events = line.events if converter is None else sorted(line.events + converter.events, key=lambda e: e.t_us)
    events = [LineEvent(e.t_us, e.kind, e.message) for e in line_events if e.t_us <= end]
    if stream is None:
        violations, outcomes = _judge_whole(scenario, trace, end, events, samples, aborted is not None)
        tx_count = sum(1 for frame in trace if frame.direction == "tx")
        rx_count = len(trace) - tx_count
    signal = scenario.options.response_signal
    # the notes name the file as the headline does (`file`): a bundled scenario under --matrix
    # is loaded by its absolute path, and its notes named that beside a relative headline
    named = replace(scenario, path=Path(_display_path(scenario.path))) if scenario.path is not None else scenario
    return ScenarioResult(
        name=scenario.name,
        file=_display_path(scenario.path),
        description=scenario.description,
        program=plc.name,
        platform=scenario.platform,
        channel=scenario.serial_channel,
        sources=[_display_path(p) for p in scenario.sources],  # as `file`: relative when inside the working folder
        duration_us=scenario.duration_us,
        scan_us=scenario.scan_us,
        scan_jitter_us=scenario.scan_jitter_us,
        seed=scenario.seed,
        settings=scenario.settings,
        **judged_with(scenario.options),
        signal_held=[] if signal is None else samples.spans(signal).stretches(),
        rule_events=rule_events.read if stream is not None else [e for e in events if e.kind in RULE_EVENTS],
        faults=[fault.describe() for fault in scenario.faults],
        converter=scenario.converter.describe() if scenario.converter is not None else None,
        trace=trace if keep.frames else [],
        frame_counts=None if keep.frames and stream is None else (tx_count, rx_count),
        trace_file=stream.trace_file if stream is not None else None,
        events=events if keep.details else [],
        events_dropped=events_dropped,  # counted only when the run keeps events (Keep.events_at_most)
        violations=violations,
        expectations=outcomes,
        diagnostics=plc.diagnostics(),
        diagnostic_summary=plc.diagnostic_summary(),
        watched={name: list(samples.changes.get(name, [])) for name in scenario.watch} if keep.details and keep.watched else {},
        aborted=aborted,
        aborted_at=aborted_at,
        program_file=_display_path(plc.program_file()),
        ended_us=end,
        wall_s=time.perf_counter() - wall_start,
        notes=list(scenario.notes) + plc.cpu_notes() + _c24_notes(named, plc, violations) + _missed_fault_notes(named, robot, end)
        + overwritten_input_notes(named, plc.project.files, plc.name, _relative)
        + ([] if tx_count else [_silence_note(scenario, plc, converter)]),
    )
