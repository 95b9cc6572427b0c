"""Scenario files: what to run, against which robot, what to do to it, what to expect.

The format is documented for people in docs/scenarios.md. Loading is strict: an unknown
key, a wrong type or an impossible value is a `ScenarioError` naming the file, the key and,
where it can be found, the line — never a traceback.
"""
from __future__ import annotations

import re
import tomllib
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any, Callable, Iterator

from verifier import protocol
from verifier.amr.config import RobotConfig
from verifier.amr.faults import Fault, check_fault_addresses, keys_no_fault_has
from verifier.amr.schema import ConfigError, unknown_key
from verifier.digits import digit_problem
from verifier.place import Place
from verifier.plcfacts import BUFFER_WORDS, CHANNELS, channel_problem, serial_channels
from verifier.textfile import UnreadableText, read_utf8, text_lines
from verifier.tomlpos import decode_error_position, place_of_key, shown

from verifier.link.converter import ConverterConfig

from .conditions import Condition, ConditionError, parse_condition, unchanging
from .durations import format_duration, parse_duration_us
from .evidence import RuleOptions
from .expectations import KINDS, Expectation, describe_window
from .sources import SourceError, expand, unique

PLATFORMS = {
    # platform: (ST dialect of its engineering tool, default serial channel); each a CPU
    # profile of verifier.sim.cpu, its serial channels those of plcfacts.serial_channels
    "fx3u": ("gxworks2", "fx3:1"),
    "fx3g": ("gxworks2", "fx3:1"),
    "fx5u": ("gxworks3", "fx5:1"),
    "q": ("gxworks2", "q:1"),
}
#: A platform whose library and examples are another's -> that platform, whose bundled
#: scenarios it runs too, on its own CPU profile: the FX3G runs the FX3 ones, written for
#: the FX3U, with the FX3G's smaller X/Y and R ranges (verifier/sim/cpu.py), beside its own
#: (plc/scenarios/fx3g-*.toml).
BUNDLED_AS = {"fx3g": "fx3u"}
#: The platforms sources are told apart by when nobody names one (verifier.verify.platform):
#: the FX3G's devices are a part of the FX3U's and its instructions are the FX3's
#: (tests/test_verify_fx3g.py), so whatever loads on an FX3G loads on an FX3U too; an FX3G
#: is named (--platform fx3g, platform = "fx3g"), never told from the sources.
TOLD_PLATFORMS = tuple(platform for platform in PLATFORMS if platform not in BUNDLED_AS)


def bundled_platform(platform: str) -> str:
    """The platform whose bundled scenarios `platform` runs (itself, or BUNDLED_AS's)."""
    return BUNDLED_AS.get(platform, platform)


def bundled_platforms(platform: str) -> tuple[str, ...]:
    """The platforms whose bundled scenarios `--platform platform` runs: its own, and those
    of the platform it runs the library of (the FX3G: fx3g-* and the FX3U's fx3u-*)."""
    return tuple(dict.fromkeys((platform, bundled_platform(platform))))


DEFAULT_DURATION_US = 60_000_000
#: The longest run accepted (virtual time). A day of 10 ms scans takes the simulator about
#: an hour; anything longer is almost always a typo ("1000h") and would look like a hang.
MAX_DURATION_US = 24 * 3_600_000_000
DEFAULT_SCAN_US = 10_000
DEFAULT_RESPONSE_SIGNAL = "o_bErr"

TOP_KEYS = (
    "name", "description", "sources", "program", "platform", "channel", "duration", "scan",
    "scan_jitter", "seed", "watch", "protocol", "robot", "faults", "inputs", "expect", "rules",
    "response_handling", "initial", "c24", "converter",
)
PROTOCOL_KEYS = ("address", "field_order", "codes_10_13", "status_order", "manual_stop_counts_as_stop")
INPUT_KEYS = ("at", "set", "pulse")
EXPECT_KEYS = KINDS + ("after", "within", "name")
RULES_KEYS = ("min_period", "reply_timeout")
RESPONSE_KEYS = ("signal", "within")
C24_KEYS = ("unit", "channel", "no_reception", "no_reception_format", "byte_units", "receive_count", "end_code")
CONVERTER_KEYS = ("ip", "port", "delay", "connect", "packing", "refuse_until", "unreachable", "drops",
                  "split_reply", "split_gap")
#: The platforms with an Ethernet port the library drives (FX5U built-in, Q + QJ71E71-100).
TCP_PLATFORMS = ("fx5u", "q")
DEFAULT_PLATFORM = "fx3u"  # of a scenario file that names none
TCP_CHANNEL = "tcp"
#: Buffer memory of an intelligent module, as GX Works writes it: U0\G164, U3E\G10.
BUFFER_MEMORY = re.compile(r"^U([0-9A-F]{1,3})\\G([0-9]+)$", re.IGNORECASE)
#: Device names (X0, M8000, D100, SM400, ...) address the device memory, not labels.
DEVICE_NAME = re.compile(r"^(?:(?:X|Y|B|W|SB|SW)[0-9A-F]+|(?:M|L|F|S|T|C|D|R|ZR|SM|SD)[0-9]+)$", re.IGNORECASE)
#: Word devices (D100, W1F, SD8063, ZR0): a number set there is a word, never a bit meant as one
WORD_DEVICE = re.compile(r"^(?:(?:W|SW)[0-9A-F]+|(?:D|R|ZR|SD)[0-9]+)$", re.IGNORECASE)
_LABEL_PATH = re.compile(r"^[A-Za-z_][A-Za-z0-9_]*(\[[0-9]+\])*(\.[A-Za-z_][A-Za-z0-9_]*(\[[0-9]+\])*)*$")

Value = bool | int | float


class ScenarioError(Exception):
    """A scenario that cannot be used, with where: `file:line:col: key: message`."""

    def __init__(self, file: Path | str | None, key: str, message: str, place: Place | None = None):
        """`place`: the line and column in `file` (its own `file` is not read); `self.place`
        is that place in `file` (its `file` None when the scenario has no file)."""
        self.file, self.key, self.message = file, key, message
        self.place = place if place is None or file is None else place.in_file(str(file))
        where = str(file) if file is not None else "scenario"
        if place is not None:
            where = str(place.in_file(where))
        super().__init__(f"{where}: {key + ': ' if key else ''}{message}")

    def __reduce__(self):  # across --jobs' worker processes, as UnusableInput: the constructor takes the parts
        return type(self), (self.file, self.key, self.message, self.place)

    @staticmethod
    def together(errors: list["ScenarioError"]) -> "ScenarioError":
        """One error as it is; several (the mistakes of one file) as ScenarioErrors, in the
        file's order."""
        if len(errors) == 1:
            return errors[0]
        return ScenarioErrors(sorted(errors, key=lambda e: (e.place is None, e.place.line if e.place else 0,
                                                            e.place.col if e.place else 0)))


class ScenarioErrors(ScenarioError):
    """Several mistakes of one scenario file: `errors`, each a ScenarioError with its place;
    the first's key, message and place are this one's, its text every one's, a line each.
    `mistakes`: each as the JUnit report lists it (result.mistakes_of)."""

    def __init__(self, errors: list[ScenarioError]):
        first = errors[0]
        self.errors = list(errors)
        self.file, self.key, self.message, self.place = first.file, first.key, first.message, first.place
        Exception.__init__(self, "\n".join(str(error) for error in errors))

    @property
    def mistakes(self) -> list:
        from .result import mistakes_of
        return [mistake for error in self.errors for mistake in mistakes_of(error)]

    def __reduce__(self):
        return type(self), (self.errors,)


@dataclass(frozen=True)
class InputStep:
    at_us: int
    values: dict[str, Value]
    pulse_us: int | None = None
    key: str = ""  # where the scenario states it, e.g. "inputs[0]"


@dataclass(frozen=True)
class C24Setting:
    """QJ71C24N settings made in GX Works (switch settings / various control specification)
    for one channel of the module at start I/O `unit` (U0 = X/Y000, U2 = X/Y020); `unit`
    None: the module the program drives, wherever it is (--matrix against user sources)."""

    unit: int | None = 0
    channel: int = 1
    no_reception_us: int | None = None  # no-reception monitoring time (timer 0)
    byte_units: bool | None = None
    receive_count: int | None = None
    end_code: int | None = None  # 0xFFFF = no receive end code
    no_reception_format: int | None = None  # timer 0: 1 ends the message (X3), 0 an error (X4)
    key: str = ""


@dataclass(frozen=True)
class LabelUse:
    """Labels read or written by one key of a scenario, so that a label the program lacks,
    or one of the wrong type, is reported at that key and its line."""

    key: str  # "expect[0].that", "inputs[1].set", "watch[2]", "response_handling.signal"
    line: Place | None  # where the key stands in the file
    names: tuple[str, ...]
    condition: Condition | None = None
    values: dict[str, Value] | None = None  # what an input writes
    optional: bool = False  # the default response signal: dropped when the program lacks it


@dataclass(frozen=True)
class Scenario:
    name: str
    path: Path | None = None
    description: str = ""
    sources: tuple[Path, ...] = ()
    program: str | None = None
    platform: str = DEFAULT_PLATFORM
    channel: str | None = None
    duration_us: int = DEFAULT_DURATION_US
    scan_us: int = DEFAULT_SCAN_US
    scan_jitter_us: int = 0
    seed: int = 0
    watch: tuple[str, ...] = ()
    settings: protocol.Settings = field(default_factory=protocol.Settings)
    robot: RobotConfig = field(default_factory=RobotConfig)
    faults: tuple[Fault, ...] = ()
    inputs: tuple[InputStep, ...] = ()
    expectations: tuple[Expectation, ...] = ()
    options: RuleOptions = field(default_factory=RuleOptions)
    response_signal_given: bool = False
    key_lines: dict[str, Place | None] = field(default_factory=dict, compare=False)
    initial: tuple[tuple[str, Value], ...] = ()  # devices and buffer memory before the first scan
    c24: tuple[C24Setting, ...] = ()
    converter: ConverterConfig | None = None  # the TCP route: the robot behind a converter
    notes: tuple[str, ...] = ()  # for the reports: how this run differs from its file
    response_signal_key: str = "response_handling.signal"  # or "--response-signal" when given there
    platform_from_option: bool = False  # the platform is --platform's, not the file's (for messages)
    for_sources: bool = False  # a bundled scenario run against the user's sources (--matrix)
    program_from_option: bool = False  # the program is --program's, not the file's (for messages)
    channel_from_option: bool = False  # the channel is --channel's, not the file's (for messages)
    duration_from_option: bool = False  # the run's length is --duration's (for messages)

    @property
    def target(self) -> str:
        return PLATFORMS[self.platform][0]

    @property
    def serial_channel(self) -> str:
        if self.converter is not None:
            return TCP_CHANNEL
        return self.channel or PLATFORMS[self.platform][1]

    def variables(self, watched: bool = True) -> list[str]:
        """Every PLC label the run must sample: expectations, the response signal, watch
        (left out with `watched=False`, when no report lists the watched labels)."""
        names: list[str] = []
        for expectation in self.expectations:
            if expectation.condition is not None:
                names += sorted(expectation.condition.names)
        if self.options.response_signal is not None:
            names += sorted(self.options.response_signal.names)
        for step in self.inputs:
            names += list(step.values)
        if watched:
            names += list(self.watch)
        return list(dict.fromkeys(names))

    def label_uses(self) -> list[LabelUse]:
        """Every key that names PLC labels, with its line, in the order of the file."""
        uses: list[LabelUse] = []
        for expectation in self.expectations:
            if expectation.condition is not None:
                key = f"{expectation.key}.{expectation.kind}"
                uses.append(LabelUse(key, self.key_lines.get(key), tuple(sorted(expectation.condition.names)),
                                     condition=expectation.condition))
        for step in self.inputs:  # each label at its own name in the table `set`
            key = f"{step.key}.set"
            uses += [LabelUse(key, self.key_lines.get(f"{key}.{name}", self.key_lines.get(key)), (name,),
                              values={name: value}) for name, value in step.values.items()]
        for i, name in enumerate(self.watch):
            uses.append(LabelUse(f"watch[{i}]", self.key_lines.get(f"watch[{i}]"), (name,)))
        signal = self.options.response_signal
        if signal is not None:
            key = self.response_signal_key
            uses.append(LabelUse(key, self.key_lines.get(key), tuple(sorted(signal.names)), condition=signal,
                                 optional=not self.response_signal_given))
        return uses

    def where(self, key: str = "", line: Place | None = None) -> str:
        """`file:line:col: key` (as much of it as is known) for messages about this scenario;
        `line`: a place in this scenario's file."""
        text = str(self.path) if self.path is not None else f"scenario {self.name!r}"
        if line is not None:
            text = str(line.in_file(text))
        return f"{text}: {key}" if key else text

    def at(self, line: Place | None) -> Place | None:
        """The place `where(key, line)` names, in the file (UnusableInput's `at`), or None
        when it names no file's line."""
        if self.path is None or line is None:
            return None
        return line.in_file(str(self.path))

    def key_where(self, key: str) -> str:
        """`file:line:col: key` for the scenario's top-level `key`: where the file sets it, or
        the start of the file (1:1) when it leaves the key out: the file is the table the key
        belongs in, as a key missing from an [[inputs]] table is placed at its header."""
        return self.where(key, self._key_place(key))

    def key_at(self, key: str) -> Place | None:
        """The place `key_where(key)` names, as data."""
        return self.at(self._key_place(key))

    def _key_place(self, key: str) -> Place | None:
        place = self.key_lines.get(key)
        if place is None and self.path is not None:
            place = Place(None, 1, 1)
        return place

    def with_overrides(self, **changes: Any) -> "Scenario":
        changes = {k: v for k, v in changes.items() if v is not None}
        replaced = [key for key in ("program", "channel", "sources") if key in changes and key in self.key_lines]
        if replaced:
            # --program/--channel/SOURCES replace the file's: their errors are no longer at the file's line
            changes["key_lines"] = {k: v for k, v in self.key_lines.items() if k not in replaced}
        return replace(self, **changes)


DEFAULT_STOP_WITHIN_US = 5_000_000


def default_scenario(name: str = "healthy robot", duration_us: int = DEFAULT_DURATION_US) -> Scenario:
    """The run without a scenario file: a healthy robot, the default rules, and one
    expectation — the power-on stop goes out and is answered within 5 s (or the run) — so
    that a program that never talks to the robot does not pass by saying nothing."""
    return Scenario(
        name=name,
        description="default: a healthy robot, no faults, no inputs",
        duration_us=duration_us,
        expectations=(power_on_stop_expectation(duration_us),),
        options=RuleOptions(response_signal=parse_condition(DEFAULT_RESPONSE_SIGNAL)),
    )


def power_on_stop_expectation(duration_us: int, address: int = 1, after_us: int = 0) -> Expectation:
    """What every program must do: send the stop command and have it answered, within 5 s
    of power-on (or the whole run when shorter) - or of `after_us`, when the robot cannot
    be reached before (a converter refusing connections)."""
    stop = Expectation(
        kind="sent",
        label="",
        after_us=after_us,
        within_us=min(DEFAULT_STOP_WITHIN_US, duration_us - after_us),
        request=protocol.ControlRequest(address, protocol.ControlCode.ROBOT, protocol.RobotCommand.STOP),
    )
    return replace(stop, label=f"sent stop {describe_window(stop)}")


def scenario_power_on_stop(scenario: "Scenario") -> Expectation:
    """`power_on_stop_expectation` for `scenario`'s robot and run: after a converter's
    refusals (at most half the run), when it has one."""
    converter = scenario.converter
    reachable = min(converter.refuse_until_us, scenario.duration_us // 2) if converter is not None else 0
    return power_on_stop_expectation(scenario.duration_us, scenario.settings.address, reachable)


# --- loading -------------------------------------------------------------------------------


def load_scenario(path: Path | str, platform: str | None = None, sources_replaced: bool = False) -> Scenario:
    """The scenario file at `path`. `platform`: the CPU the run is on when the file names
    none (`--platform` of verify and check), else the default fx3u: its [converter],
    [[c24]] and devices are judged for the CPU they will run on. `sources_replaced`: the
    command's own ST files take the place of the file's `sources` (`uitamr verify FILES
    --scenario`): those are read as names only, not looked for (a copy of a bundled
    scenario names `../core/*.st`, which need not exist beside the copy)."""
    path = Path(path)
    try:
        if not path.exists():
            if path.is_symlink():
                raise ScenarioError(path, "", "a symbolic link to nothing (its target is missing, or a loop of links)")
            raise ScenarioError(path, "", "no such scenario file")
    except OSError as exc:  # a name too long for the file system, a folder that cannot be read ...
        raise ScenarioError(path, "", f"cannot read: {exc.strerror or exc}") from None
    try:
        text = read_utf8(path)
    except UnreadableText as exc:
        raise ScenarioError(path, "", exc.after_place(), exc.place) from None
    return parse_scenario(text, path, platform, sources_replaced)


def parse_scenario(text: str, path: Path | None = None, platform: str | None = None,
                   sources_replaced: bool = False) -> Scenario:
    try:
        data = tomllib.loads(text)
    except (ValueError, RecursionError) as exc:
        # TOMLDecodeError, int()'s limit of 4300 digits, or arrays nested too deep for tomllib
        from verifier.monitor.capture import capture_instead

        message, place = decode_error_position(exc, text)
        raise ScenarioError(path, "", f"not valid TOML: {message}{capture_instead(text, path)}", place) from None
    return _Reader(text, path, platform, sources_replaced).read(data)


#: how many characters follow the backslash of a TOML basic string's escape (`\t`: 1,
#: `\u0041`: 5, `\U0001F600`: 9, TOML 1.1's `\x41`: 3)
_ESCAPE_LENGTH = {"u": 5, "U": 9, "x": 3}


def _string_characters(lines: list[str], row: int, col: int, delimiter: str) -> Iterator[tuple[int, int]]:
    """The (line, column) in the file of each character of the TOML string value whose first
    character is at `row`, `col` and that ends at `delimiter` (a quote, or three), then the
    closing delimiter's own place. An escape of a basic string is one character, at its
    backslash; a line-ending backslash of a multi-line basic string takes no character, nor the
    blanks and line breaks after it; a line break in a multi-line string is one."""
    basic, multi = delimiter[0] == '"', len(delimiter) == 3
    trimming = False
    while row - 1 < len(lines):
        text, i = lines[row - 1], col - 1
        while i < len(text):
            if trimming and text[i] in " \t":
                i += 1
                continue
            trimming = False
            if text.startswith(delimiter, i):
                yield row, i + 1
                return
            if basic and text[i] == "\\":
                if multi and not text[i + 1:].strip(" \t"):
                    trimming = True  # a line-ending backslash
                    break
                yield row, i + 1
                i += 1 + _ESCAPE_LENGTH.get(text[i + 1:i + 2], 1)
                continue
            yield row, i + 1
            i += 1
        else:
            if not multi:
                return
            if not trimming:
                yield row, len(text) + 1  # the line break, a character of the value
        row, col = row + 1, 1


class _Reader:
    """Turns the parsed TOML into a Scenario; every error names its key and line."""

    def __init__(self, text: str, path: Path | None, platform: str | None = None, sources_replaced: bool = False):
        self.lines = text_lines(text)
        self.sources_replaced = sources_replaced  # the command's FILES stand in for `sources`
        self.path = path
        self.default_platform = platform.lower() if platform else DEFAULT_PLATFORM  # when the file names none
        self.platform_option = platform is not None  # that default is --platform's, not fx3u's
        self.base = path.parent if path is not None else Path.cwd()

    # --- errors --------------------------------------------------------------------------

    def fail(self, key: str, message: str, offset: int = 0, at_name: bool = False, at: str = "") -> ScenarioError:
        """The error at `key`'s value (at the key itself with `at_name`; at the key `at` instead
        when given: a label in an input's `set`); `offset` moves the column into a string value
        (a condition's own column, 1-based, past the quote)."""
        place = place_of_key(self.lines, at or key, at_name)
        if place is not None and offset:
            place = self._inside_string(place, offset)
        return ScenarioError(self.path, key, message, place)

    def _inside_string(self, place: Place, offset: int) -> Place:
        """The place of character `offset` (1-based; one past the last: the closing quote) of
        the string value that starts at `place`, followed back through the file: past the
        quote, line by line inside a multi-line string (a condition written over several lines
        with three quotes), an escape of a basic string (`\\t`, `\\u0041`) at its backslash, and
        a line-ending backslash with the blanks it trims taking no character. The value's own
        place when it is not a string."""
        line = self.lines[place.line - 1]
        start = place.col - 1
        delimiter = line[start:start + 3]
        if delimiter in ('"""', "\'\'\'"):
            row, col = place.line, place.col + 3  # the 1-based column of the value's first character
            if col > len(line):  # a newline right after the opening quotes is not part of the value
                row, col = row + 1, 1
        elif line[start:start + 1] in ("'", '"'):
            delimiter, row, col = line[start], place.line, place.col + 1
        else:
            return place
        for n, (at_row, at_col) in enumerate(_string_characters(self.lines, row, col, delimiter), 1):
            if n == offset:
                return Place(None, at_row, at_col)
        return place

    def line_of(self, key: str) -> Place | None:
        """Best effort: line and column of what sets `key` (e.g. "expect[1].within", "robot.x")."""
        return place_of_key(self.lines, key)

    # --- helpers -------------------------------------------------------------------------

    def table(self, value: Any, key: str) -> dict:
        if not isinstance(value, dict):
            raise self.fail(key, f"expected a table, got {shown(value)}")
        return value

    def array_of_tables(self, value: Any, key: str) -> list[dict]:
        if not isinstance(value, list) or not all(isinstance(item, dict) for item in value):
            raise self.fail(key, f"expected an array of tables ([[{key}]]), got {shown(value)}")
        return value

    def only(self, data: dict, allowed: tuple[str, ...], key: str) -> None:
        for name in data:
            if name not in allowed:
                where = f"{key}.{name}" if key else name
                raise self.fail(where, unknown_key(name, allowed), at_name=True)

    def string(self, value: Any, key: str) -> str:
        if not isinstance(value, str):
            raise self.fail(key, f"expected a string, got {shown(value)}")
        return value

    def duration(self, value: Any, key: str, *, positive: bool = True) -> int:
        try:
            us = parse_duration_us(value)
        except ValueError as exc:
            raise self.fail(key, str(exc)) from None
        if positive and us <= 0:
            raise self.fail(key, "must be longer than 0")
        return us

    def condition(self, value: Any, key: str):
        text = self.string(value, key)
        try:
            return parse_condition(text)
        except ConditionError as exc:
            raise self.fail(key, f"{exc.message} at column {exc.column} of {text!r}",
                            offset=exc.column) from None

    def constant_refused(self, condition, key: str):
        """`condition`, when it reads a label: one that reads none (`that = "TRUE"`) is the
        same at every moment, so it tells nothing about the program - it always passes, or
        can never pass."""
        problem = unchanging(condition, "name the program's labels (e.g. fbRobot.o_bErr) or devices (Y0)")
        if problem is not None:
            raise self.fail(key, problem)
        return condition

    def label(self, value: Any, key: str, at: str = "") -> str:
        """A label path; `at` is the key that names it, when it is a key (an input's `set`)."""
        text = self.string(value, key)
        if problem := digit_problem(text):  # wBuf[٢]
            raise self.fail(key, f"{text!r}: {problem}", at_name=bool(at), at=at)
        if not _LABEL_PATH.match(text):
            raise self.fail(key, f"{text!r} is not a label path (e.g. o_bOK, fbRobot.o_uState, wBuf[2])",
                            at_name=bool(at), at=at)
        return text

    # --- the document ----------------------------------------------------------------------

    def attempt(self, read: Callable[[], Any], default: Any = None) -> Any:
        """What `read` gives, or `default` after noting its ScenarioError in `self.errors`: the
        file's other keys are read on, so that every mistake of it is told in one run."""
        try:
            return read()
        except ScenarioError as exc:
            self.errors.append(exc)
            return default

    def read(self, data: dict) -> Scenario:
        self.errors: list[ScenarioError] = []
        attempt = self.attempt
        attempt(lambda: self.only(data, TOP_KEYS, ""))

        def read_name() -> str:
            name = self.string(data.get("name", self.path.stem if self.path else "scenario"), "name")
            if not name.strip():  # every report names the run by it: a JUnit test case with no name
                raise self.fail("name", "is empty: give the scenario a name, or leave 'name' out to use the file name")
            return name
        name = attempt(read_name, "scenario")
        description = attempt(lambda: self.string(data.get("description", ""), "description"), "")
        sources = attempt(lambda: tuple(self.sources(data["sources"])) if "sources" in data else (), ())

        def read_program() -> str | None:
            program = self.string(data["program"], "program") if "program" in data else None
            if program is not None and not program.strip():  # was "no PROGRAM '' in the sources", without a line
                raise self.fail("program", "is empty: give the name of the PROGRAM to run, or leave 'program' out "
                                           "when the sources hold only one")
            return program
        program = attempt(read_program)

        def read_platform() -> str | None:
            platform = self.string(data.get("platform", self.default_platform), "platform").lower()
            if platform not in PLATFORMS:
                raise self.fail("platform", f"unknown platform {platform!r}; expected one of {', '.join(PLATFORMS)}")
            return platform
        platform = attempt(read_platform)  # None: a mistake, and nothing is judged against it

        def read_channel() -> str | None:
            if "channel" not in data:
                return None
            channel = self.string(data["channel"], "channel")
            if channel not in CHANNELS:
                raise self.fail("channel", f"unknown channel {channel!r}; expected one of {', '.join(CHANNELS)}")
            problem = channel_problem(channel, platform) if platform is not None else None  # as verify's load would
            if problem is not None:
                owner = next((p for p in TOLD_PLATFORMS if channel in serial_channels(p)), None)
                if "platform" not in data and owner is not None:  # the platform is the default (or --platform's)
                    given = "--platform's" if self.platform_option else "the default platform"
                    problem += f" ({platform} is {given}: set platform = \"{owner}\", the CPU that has {channel})"
                raise self.fail("channel", problem)
            return channel
        channel = attempt(read_channel)

        def read_duration() -> int:
            duration = self.duration(data.get("duration", "60s"), "duration")
            if duration > MAX_DURATION_US:
                raise self.fail("duration", f"longer than the limit of {format_duration(MAX_DURATION_US)} of virtual "
                                            "time; split a longer soak test into several scenarios")
            return duration
        # a duration in error judges nothing else: the longest run, so no time is "after its end"
        duration = attempt(read_duration, None)
        duration_known = duration is not None
        duration = duration if duration_known else MAX_DURATION_US

        def read_scan() -> int:
            scan = self.duration(data.get("scan", "10ms"), "scan")
            if duration_known and scan > duration:
                raise self.fail("scan", "the scan time is longer than the whole run")
            return scan
        scan = attempt(read_scan, None)

        def read_jitter() -> int:
            jitter = self.duration(data["scan_jitter"], "scan_jitter", positive=False) if "scan_jitter" in data else 0
            if scan is not None and jitter >= scan:
                raise self.fail("scan_jitter", "must be shorter than the scan time")
            return jitter
        jitter = attempt(read_jitter, 0)

        def read_seed() -> int:
            seed = data.get("seed", 0)
            if isinstance(seed, bool) or not isinstance(seed, int):
                raise self.fail("seed", f"expected a whole number, got {shown(seed)}")
            return seed
        seed = attempt(read_seed, 0)

        def read_watch() -> tuple[str, ...]:
            watch = data.get("watch", [])
            if not isinstance(watch, list):
                raise self.fail("watch", "expected a list of label paths")
            return tuple(label for label in (attempt(lambda i=i, item=item: self.label(item, f"watch[{i}]"))
                                             for i, item in enumerate(watch)) if label is not None)
        watch = attempt(read_watch, ())
        settings = attempt(lambda: self.settings(data.get("protocol", {})), None)
        robot = attempt(lambda: self.robot(data.get("robot", {})), None)
        faults = attempt(lambda: self.faults(data.get("faults", [])), ())
        if settings is not None:
            try:
                check_fault_addresses(faults, settings.address)
            except ConfigError as exc:
                self.errors.append(self.fail(exc.path, exc.message))
        for i, fault in enumerate(faults):
            if duration_known and fault.at_s is not None and fault.at_s * 1_000_000 >= duration:
                self.errors.append(self.fail(f"faults[{i}].at_s", f"is at or after the end of the run "
                                                                  f"({format_duration(duration)}): the fault would "
                                                                  "never happen"))
        inputs = tuple(step for step in (
            attempt(lambda i=i, item=item: self.input_step(item, f"inputs[{i}]", duration))
            for i, item in enumerate(attempt(lambda: self.array_of_tables(data.get("inputs", []), "inputs"), [])))
            if step is not None)
        expectations = tuple(expectation for expectation in (
            attempt(lambda i=i, item=item: self.expectation(item, f"expect[{i}]", settings or protocol.Settings()))
            for i, item in enumerate(attempt(lambda: self.array_of_tables(data.get("expect", []), "expect"), [])))
            if expectation is not None)
        for expectation in expectations if robot is not None else ():
            if (expectation.kind == "reached_point" and expectation.within_us is not None and robot.is_taught(
                    expectation.point) and expectation.within_us < robot.point_duration_us(expectation.point)):
                takes = format_duration(robot.point_duration_us(expectation.point))
                self.errors.append(self.fail(
                    f"{expectation.key}.within",
                    f"point {expectation.point} takes the robot {takes} ([robot] point_duration_s / "
                    f"point_durations_s), longer than this window of "
                    f"{format_duration(expectation.within_us)}: it can never be reached in it; make 'within' longer"))
            if expectation.kind == "reached_point" and not robot.is_taught(expectation.point):
                self.errors.append(self.fail(
                    f"{expectation.key}.reached_point",
                    f"point {expectation.point} is not among the robot's taught_points "
                    f"{list(robot.taught_points)}: the robot accepts run-point {expectation.point} and "
                    "does nothing, so it is never reached; add it to [robot] taught_points"))
        options, signal_given = attempt(lambda: self.options(data.get("rules", {}), data.get("response_handling", None)),
                                        (None, False))
        initial = attempt(lambda: self.initial(data.get("initial", {})), ())
        c24 = tuple(setting for setting in (
            attempt(lambda i=i, item=item: self.c24(item, f"c24[{i}]", platform))
            for i, item in enumerate(attempt(lambda: self.array_of_tables(data.get("c24", []), "c24"), [])))
            if setting is not None) if platform is not None else ()
        seen_c24: dict[tuple[int, int], str] = {}
        for setting in c24:
            first = seen_c24.setdefault((setting.unit, setting.channel), setting.key)
            if first != setting.key:
                self.errors.append(self.fail(setting.key, f"U{setting.unit:X} channel {setting.channel} is already "
                                                          f"set in {first}: one [[c24]] table per module channel",
                                             at_name=True))
        converter = (attempt(lambda: self.converter(data["converter"], platform, duration,
                                                    "file" if "platform" in data
                                                    else "option" if self.platform_option else ""))
                     if "converter" in data and platform is not None else None)
        if "converter" in data and channel is not None:
            self.errors.append(self.fail("channel", "a scenario with [converter] reaches the robot over TCP: "
                                                    "it has no serial channel; remove 'channel'"))
        if self.errors:
            raise ScenarioError.together(self.errors)
        keys = [key for key in ("duration", "scan", "scan_jitter") if key in data]
        keys += [f"initial.{name}" for name, _ in initial] + [setting.key for setting in c24]
        keys += [f"faults[{i}]" for i in range(len(faults))]
        keys += [f"{e.key}.{e.kind}" for e in expectations if e.condition is not None]
        keys += [f"{step.key}.set" for step in inputs] + [f"watch[{i}]" for i in range(len(watch))]
        keys += ["response_handling.signal"] if signal_given else []
        keys += ["platform"] if "platform" in data else []
        keys += ["program"] if program is not None else []
        keys += ["channel"] if channel is not None else []
        keys += ["sources"] if "sources" in data else []
        conditions = [(f"{e.key}.{e.kind}", e.condition) for e in expectations if e.condition is not None]
        conditions += [("response_handling.signal", options.response_signal)] if signal_given else []
        return Scenario(
            name=name, path=self.path, description=description, sources=sources, program=program,
            platform=platform, channel=channel, duration_us=duration, scan_us=scan, scan_jitter_us=jitter, seed=seed,
            watch=watch, settings=settings, robot=robot, faults=faults, inputs=inputs,
            expectations=expectations, options=options, response_signal_given=signal_given,
            key_lines={key: self.line_of(key) for key in keys} | self.set_names(inputs)
            | self.names_in_conditions(conditions), initial=initial, c24=c24,
            converter=converter,
        )

    def names_in_conditions(self, conditions) -> dict[str, Place | None]:
        """Where each label of a condition stands in the file (`expect[0].that:fbEngine.o_bErr`),
        so that a label the program lacks is reported there, not at the condition's start."""
        places: dict[str, Place | None] = {}
        for key, condition in conditions:
            start = place_of_key(self.lines, key)
            if start is None:
                continue
            for name, column in condition.name_columns().items():
                places[f"{key}:{name}"] = self._inside_string(start, column)
        return places

    def set_names(self, inputs: tuple[InputStep, ...]) -> dict[str, Place | None]:
        """Where each label an input sets is named (`inputs[0].set.X0`), for the errors about it."""
        return {f"{step.key}.set.{name}": place_of_key(self.lines, f"{step.key}.set.{name}", at_name=True)
                for step in inputs for name in step.values}

    def converter(self, value: Any, platform: str, duration: int, platform_from: str = "file") -> ConverterConfig:
        """The [converter] table; `platform_from` says who named the platform: "file", "option"
        (--platform, for a file that names none) or "" (nobody: the default)."""
        item = self.table(value, "converter")
        self.only(item, CONVERTER_KEYS, "converter")
        if platform not in TCP_PLATFORMS:
            tcp = f"\"{TCP_PLATFORMS[0]}\" (or \"{TCP_PLATFORMS[-1]}\")"
            why = {"file": f"this scenario's platform is {platform!r}",
                   "option": f"this scenario names no platform and --platform {platform} runs it on the {platform}: "
                             f"give --platform {TCP_PLATFORMS[0]} (or {TCP_PLATFORMS[-1]}), or leave --platform out "
                             f"and add platform = {tcp} to the file"}.get(platform_from) or (
                f"this scenario names no platform, so it is {platform!r} (the default): add "
                f"platform = {tcp} to the file, or give --platform")
            raise self.fail("converter", f"the TCP route needs a PLC with an Ethernet port the library drives "
                                         f"({' or '.join(TCP_PLATFORMS)}); {why}")
        config = ConverterConfig()
        changes: dict[str, Any] = {}
        if "ip" in item:
            ip = self.string(item["ip"], "converter.ip")
            parts = ip.split(".")
            if len(parts) != 4 or not all(p.isascii() and p.isdigit() and len(p) <= 3 and int(p) <= 255
                                          for p in parts):  # '²' is a digit to isdigit(), not to int()
                raise self.fail("converter.ip", f"expected an IPv4 address like \"192.168.3.50\", got {ip!r}")
            changes["ip"] = ".".join(str(int(p)) for p in parts)
        if "port" in item:
            port = item["port"]
            if isinstance(port, bool) or not isinstance(port, int) or not 1 <= port <= 65535:
                raise self.fail("converter.port", f"expected a TCP port 1..65535, got {shown(port)}")
            changes["port"] = port
        for key, attr in (("delay", "delay_us"), ("connect", "connect_us"), ("packing", "pack_us"),
                          ("refuse_until", "refuse_until_us"), ("unreachable", "unreachable_us"),
                          ("split_gap", "split_gap_us")):
            if key in item:
                changes[attr] = self.duration(item[key], f"converter.{key}",
                                              positive=key in ("unreachable", "split_gap"))
        if "drops" in item:
            drops = item["drops"]
            if not isinstance(drops, list):
                raise self.fail("converter.drops", "expected a list of times, e.g. [\"20s\", \"40s\"]")
            changes["drops"] = tuple(self.duration(t, f"converter.drops[{i}]", positive=False)
                                     for i, t in enumerate(drops))
            for i, drop in enumerate(changes["drops"]):
                if drop >= duration:  # as for a fault's at_s: a drop that never happens tests nothing
                    raise self.fail(f"converter.drops[{i}]", f"is at or after the end of the run "
                                                             f"({format_duration(duration)}): the drop would never happen")
        if "split_reply" in item:
            if not isinstance(item["split_reply"], bool):
                raise self.fail("converter.split_reply", f"expected true or false, got {shown(item['split_reply'])}")
            changes["split_reply"] = item["split_reply"]
        return replace(config, **changes)

    def initial(self, value: Any) -> tuple[tuple[str, Value], ...]:
        table = self.table(value, "initial")
        result = []
        for name, item in table.items():
            key = f"initial.{name}"
            if problem := digit_problem(name):  # 'U0\G１６４'
                raise self.fail(key, problem, at_name=True)
            match = BUFFER_MEMORY.match(name)
            if match and int(match.group(2)) >= BUFFER_WORDS:
                raise self.fail(key, f"buffer memory ends at G{BUFFER_WORDS - 1} in the simulator")
            if not match and not DEVICE_NAME.match(name):
                raise self.fail(key, f"{name!r} is not a device (D8400, M10, X0) or buffer memory (U0\\G164); "
                                     "labels get their initial values in ST, or from [[inputs]] at \"0s\"")
            if isinstance(item, bool) and match:
                raise self.fail(key, "buffer memory holds words: give a number")
            if not isinstance(item, (bool, int)) or (match and not -0x8000 <= item <= 0xFFFF):
                raise self.fail(key, f"expected true/false or a whole number (a word: -32768..65535), got {shown(item)}")
            result.append((name, item))
        return tuple(result)

    def c24(self, item: dict, key: str, platform: str) -> C24Setting:
        self.only(item, C24_KEYS, key)
        if platform != "q":
            raise self.fail(key, f"the QJ71C24N is a Q-series module; this scenario's platform is {platform!r}")
        def whole(name: str, low: int, high: int) -> int | None:
            if name not in item:
                return None
            value = item[name]
            if isinstance(value, bool) or not isinstance(value, int) or not low <= value <= high:
                raise self.fail(f"{key}.{name}", f"expected a whole number {low}..{high}, got {shown(value)}")
            return value
        unit = whole("unit", 0, 0xFF)
        channel = whole("channel", 1, 2)
        no_reception = self.duration(item["no_reception"], f"{key}.no_reception") if "no_reception" in item else None
        byte_units = item.get("byte_units")
        if byte_units is not None and not isinstance(byte_units, bool):
            raise self.fail(f"{key}.byte_units", f"expected true (bytes) or false (words), got {shown(byte_units)}")
        end_code = item.get("end_code")
        if end_code == "none":
            end_code = 0xFFFF
        elif "end_code" in item:
            end_code = whole("end_code", 0, 0xFFFF)
        return C24Setting(
            unit=unit or 0, channel=channel or 1, no_reception_us=no_reception, byte_units=byte_units,
            receive_count=whole("receive_count", 1, 0xFFFF), end_code=end_code,
            no_reception_format=whole("no_reception_format", 0, 1), key=key,
        )

    def sources(self, value: Any) -> list[Path]:
        if isinstance(value, str):
            value = [value]
        if not isinstance(value, list) or not value:
            raise self.fail("sources", "expected a list of .st files, folders or glob patterns, relative to this file")
        found: list[Path] = []
        for i, item in enumerate(value):
            name = self.string(item, f"sources[{i}]")
            if self.sources_replaced:
                continue  # replaced by the command's own files: not looked for
            try:
                found += expand(name, self.base)
            except SourceError as exc:
                raise self.fail(f"sources[{i}]", str(exc)) from None
        return list(unique(found))

    def settings(self, value: Any) -> protocol.Settings:
        table = self.table(value, "protocol")
        self.only(table, PROTOCOL_KEYS, "protocol")
        try:
            return protocol.Settings(**table)
        except (ValueError, TypeError) as exc:
            key = next((k for k in table if k in str(exc)), "")
            raise self.fail(f"protocol.{key}" if key else "protocol", str(exc)) from None

    def robot(self, value: Any) -> RobotConfig:
        try:
            return RobotConfig.from_dict(self.table(value, "robot"), "robot")
        except ConfigError as exc:
            raise self.fail(exc.path, exc.message, at_name=exc.at_name) from None

    def faults(self, value: Any) -> tuple[Fault, ...]:
        items = self.array_of_tables(value, "faults")
        result = []
        for i, item in enumerate(items):
            try:
                result.append(Fault.from_dict(item, f"faults[{i}]"))
            except ConfigError as exc:  # noted, and the next fault read: every mistake of the file in one run
                path = exc.path if exc.path.startswith("faults[") else f"faults[{i}]"
                self.errors.append(self.fail(path, exc.message, at_name=exc.at_name))
                if path == f"faults[{i}].kind" and isinstance(item, dict):  # and keys no kind takes
                    self.errors += [self.fail(e.path, e.message, at_name=True)
                                    for e in keys_no_fault_has(item, f"faults[{i}]")]
        return tuple(result)

    def input_step(self, item: dict, key: str, duration: int) -> InputStep | None:
        """The input; None when a mistake of it is noted in `self.errors` (its `at` and each
        value are read on after one, so that all of the table's are told)."""
        told = len(self.errors)
        self.attempt(lambda: self.only(item, INPUT_KEYS, key))
        if "at" not in item or "set" not in item:
            raise self.fail(key, "an input needs 'at' (when) and 'set' (labels and values)")

        def read_at() -> int:
            at = self.duration(item["at"], f"{key}.at", positive=False)
            if at >= duration:
                raise self.fail(f"{key}.at", f"is at or after the end of the run ({format_duration(duration)}): "
                                             "the input would never be applied; make 'duration' longer")
            return at
        at = self.attempt(read_at)
        values = self.table(item["set"], f"{key}.set")
        if not values:
            raise self.fail(f"{key}.set", "sets nothing")
        checked: dict[str, Value] = {}

        def read_value(name: str, value: Any) -> None:
            self.label(name, f"{key}.set", at=f"{key}.set.{name}")
            if not isinstance(value, (bool, int, float)):
                raise self.fail(f"{key}.set.{name}", f"expected true/false or a number, got {shown(value)}")
            checked[name] = value
        for name, value in values.items():
            self.attempt(lambda name=name, value=value: read_value(name, value))
        if len(self.errors) > told:
            return None
        pulse = self.duration(item["pulse"], f"{key}.pulse") if "pulse" in item else None
        if pulse is not None and not any(isinstance(v, bool) for v in checked.values()):
            bit_as_number = next((name for name, v in checked.items()
                                  if v in (0, 1) and not WORD_DEVICE.match(name)), None)
            if bit_as_number is not None:  # `X0 = 1` meant as a bit: say so at the value, not at the pulse
                value = checked[bit_as_number]
                raise self.fail(f"{key}.set.{bit_as_number}",
                                f"is the number {shown(value)}, and a pulse sets BOOL labels back after a while: "
                                f"write {bit_as_number} = {'true' if value else 'false'} for a bit")
            numbers = ", ".join(f"{name} = {shown(value)}" for name, value in checked.items())
            raise self.fail(f"{key}.pulse", f"a pulse sets BOOL labels back after a while; this input sets no BOOL, "
                                            f"only numbers ({numbers}): write true or false for a BOOL label, "
                                            "or leave out the pulse")
        return InputStep(at, checked, pulse, key)

    def expectation(self, item: dict, key: str, settings: protocol.Settings) -> Expectation | None:
        """The expectation; None when a mistake of it is noted in `self.errors` (its window
        is read on after one, and what it expects after a mistake of the window)."""
        told = len(self.errors)
        self.attempt(lambda: self.only(item, EXPECT_KEYS, key))
        kinds = [kind for kind in KINDS if kind in item]
        if len(kinds) != 1:
            raise self.fail(key, f"give exactly one of {', '.join(KINDS)}")
        kind = kinds[0]
        after = self.attempt(lambda: self.duration(item["after"], f"{key}.after", positive=False)
                             if "after" in item else 0)
        within = self.attempt(lambda: self.duration(item["within"], f"{key}.within") if "within" in item else None)
        if len(self.errors) > told:
            self.attempt(lambda: self.expectation({k: v for k, v in item.items()
                                                   if k in EXPECT_KEYS and k not in ("after", "within")},
                                                  key, settings))
            return None
        value = item[kind]
        fields: dict[str, Any] = {}
        if kind in ("that", "always", "never"):
            fields["condition"] = self.constant_refused(self.condition(value, f"{key}.{kind}"), f"{key}.{kind}")
            what = {"that": "", "always": "always ", "never": "never "}[kind] + str(fields["condition"])
        elif kind == "sent":
            words = self.string(value, f"{key}.sent")
            try:
                fields["request"] = protocol.command_from_words(words.split(), settings.address)
            except protocol.CommandError as exc:
                raise self.fail(f"{key}.sent", str(exc)) from None
            what = f"sent {words}"
        else:
            if isinstance(value, bool) or not isinstance(value, int) or value not in range(1, 22):
                raise self.fail(f"{key}.reached_point", f"expected a point number 1-21, got {shown(value)}")
            fields["point"] = value
            what = f"robot reached point {value}"
        expectation = Expectation(kind=kind, label="", after_us=after, within_us=within, key=key,
                                  place=self.line_of(f"{key}.{kind}"), **fields)
        label = item.get("name")
        if label is None:
            label = f"{what} {describe_window(expectation)}".strip()
        elif not self.string(label, f"{key}.name").strip():
            raise self.fail(f"{key}.name", "is empty: name the expectation for the reports, or leave 'name' out "
                                           f"to have it described ({what!r})")
        return replace(expectation, label=self.string(label, f"{key}.name"))

    def options(self, rules: Any, response: Any) -> tuple[RuleOptions, bool]:
        rules = self.table(rules, "rules")
        self.only(rules, RULES_KEYS, "rules")
        options = RuleOptions(response_signal=parse_condition(DEFAULT_RESPONSE_SIGNAL))
        if "min_period" in rules:
            options = replace(options, min_period_us=self.duration(rules["min_period"], "rules.min_period"))
        if "reply_timeout" in rules:
            options = replace(options, reply_timeout_us=self.duration(rules["reply_timeout"], "rules.reply_timeout"))
        if response is None:
            return options, False
        response = self.table(response, "response_handling")
        self.only(response, RESPONSE_KEYS, "response_handling")
        if "signal" in response:
            key = "response_handling.signal"
            options = replace(options, response_signal=self.constant_refused(self.condition(response["signal"], key), key))
        if "within" in response:
            options = replace(
                options, response_within_us=self.duration(response["within"], "response_handling.within")
            )
        return options, "signal" in response

