"""`uitamr verify`: run PLC programs against the emulated robot and check the traffic.

Exit codes: 0 compliant, 1 violations or failed expectations, 2 unusable input.
"""
from __future__ import annotations

import os
import shutil
import signal
import sys
import time
from contextlib import contextmanager
from itertools import accumulate
from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait
from concurrent.futures.process import BrokenProcessPool
from dataclasses import replace
from pathlib import Path

import click
from rich.console import Console
from rich.markup import escape
from rich.progress import BarColumn, Progress, TextColumn, TimeElapsedColumn

from verifier.commands.check import not_st
from verifier.commands.numbers import INT, IntRange
from verifier.commands.report_files import (JudgingCommand, ReportError, check_folders, check_not_inputs,
                                             junit_of_mistakes, junit_of_refused_report, report_options, text_console,
                                             usage_error_junit, write_reports)
from verifier.verify.durations import format_duration, format_seconds, parse_duration_us
from verifier.verify import spool
from verifier.verify.events_shown import EVENTS_AT_MOST
from verifier.verify.result import KEEP_ALL, Keep, ScenarioMistakes, ScenarioResult, UnusableInput, mistakes_of
from verifier.bundled import plc_dir as bundled_plc_dir
from verifier.digits import digit_problem
from verifier.textfile import is_folder, real_path, shown_path
from verifier.verify.scenario import (
    CHANNELS, DEFAULT_DURATION_US, MAX_DURATION_US, PLATFORMS, TOLD_PLATFORMS, Scenario, ScenarioError, ScenarioErrors,
    bundled_platforms, default_scenario, load_scenario,
)
from verifier.verify.sources import SourceError, expand, st_files_in, unique

EXIT_PASS, EXIT_FAIL, EXIT_UNUSABLE = 0, 1, 2
SHOW_PROGRESS_AFTER_S = 0.5
PLAIN_PROGRESS_EVERY_S = 30.0  # progress lines in CI logs (not a terminal)
STOP_CHECK_EVERY_S = 0.2  # how soon a SIGTERM or Ctrl-C held while --jobs workers run is acted on


def bundled_scenarios() -> list[Path]:
    return sorted((bundled_plc_dir() / "scenarios").glob("*.toml"))


class _Duration(click.ParamType):
    """A duration option: a number with a unit, longer than 0 (or 0 itself, with or
    without a unit, with `zero_ok`) and at most `maximum_us`."""

    name = "duration"

    def __init__(self, maximum_us: int | None = None, zero_ok: bool = False):
        self.maximum_us = maximum_us
        self.zero_ok = zero_ok

    def convert(self, value, param, ctx):
        if isinstance(value, int):
            return value
        if self.zero_ok and _is_zero(value):
            return 0  # nothing needs no unit: `--tolerance 0` (docs/commissioning.md)
        try:
            us = parse_duration_us(value)
        except ValueError as exc:
            self.fail(str(exc), param, ctx)
        if us < 0 or (us == 0 and not self.zero_ok):
            self.fail(f"{value!r} must be longer than 0", param, ctx)
        if self.maximum_us is not None and us > self.maximum_us:
            self.fail(f"{value!r} is longer than the limit of {format_duration(self.maximum_us)} of virtual time; "
                      "split a longer soak test into several runs (--seed differs per run)", param, ctx)
        return us


def _is_zero(value) -> bool:
    """'0', '0.00', '-0', '00': a bare number that is zero (of the digits 0-9: a '٠' goes on to
    say what is wrong with it)."""
    if digit_problem(str(value)):
        return False
    try:
        return float(str(value).strip()) == 0
    except ValueError:
        return False


def _unusable(message: str, *more: str, done: str | None = None) -> None:
    """Exit 2 with the errors; `done`: what was still written (a report of them)."""
    console = text_console(stderr=True)
    for text in (message, *more):
        console.print(f"[bold red]error:[/] {escape(text)}", markup=True)
    if done:
        console.print(f"[dim]{escape(done)}[/]")
    sys.exit(EXIT_UNUSABLE)


def _unusable_input(junit_path: str | None, inputs, error: Exception) -> None:
    """Exit 2 for input the run cannot use (a scenario's mistake, ST that does not load),
    after writing the mistakes to --junit's file as errors, each at the place the error
    holds (not over one of `inputs`, the run's input files as far as they are known)."""
    mistakes = mistakes_of(error)
    # the console shows each scenario file's mistake as its own error line, and ST that does
    # not load as one message listing its errors (the JUnit report has a test case for each)
    messages = ([mistake.message for mistake in mistakes] if isinstance(error, (ScenarioMistakes, ScenarioErrors))
                else [str(error)])
    _unusable_after(messages, junit_of_mistakes(junit_path, mistakes, "uitamr verify", inputs) if junit_path else None)


def _refused_report(junit_path: str | None, error: ReportError, inputs, results=()) -> None:
    """Exit 2 for a report that cannot be written, after writing that mistake to --junit's
    file when the refused report is another one (not over one of `inputs`), beside the
    `results` of the runs when they were done."""
    _unusable_after([str(error)], junit_of_refused_report(junit_path, error, "uitamr verify", inputs, results))


def _unusable_after(messages: list[str], junit: tuple[bool, str] | None) -> None:
    """Exit 2 with `messages`, after what writing --junit's file gave (None: no JUnit to
    write): the line that it was written, or why not as one more error."""
    if junit is None:
        _unusable(*messages)
    written, said = junit
    if written:
        _unusable(*messages, done=said)
    _unusable(*messages, said)


def _read_scenarios(files, platform: str | None = None, sources_replaced: bool = False) -> list[Scenario]:
    """Every scenario file read; the mistakes of all of them reported together, as `uitamr
    check` does (one at a time, a folder of scenarios took a run per mistake to clean up).
    `sources_replaced`: SOURCES were given, their `sources` are not looked for."""
    read, mistakes = [], []
    for f in files:
        try:
            read.append(load_scenario(f, platform, sources_replaced))
        except ScenarioError as exc:
            mistakes.append(exc)
    _raise_together(mistakes)
    return read


#: the platform a serial channel belongs to, by the family of its default port (fx3:, fx5:,
#: q:); adp:1 is on FX3 and FX5 CPUs alike, so it names none; fx3: is the FX3U's, as a
#: program is told from its sources (an FX3G is named with --platform fx3g)
_CHANNEL_PLATFORMS = {PLATFORMS[platform][1].split(":")[0]: platform for platform in TOLD_PLATFORMS}


def _scenarios(sources, program, platform, channel, scenario_files, matrix, duration, scan, seed) -> list[Scenario]:
    from verifier.link.converter import ConverterConfig
    from verifier.verify.matrix import for_user_sources, without_repeats
    from verifier.verify.platform import infer_platform, platforms_that_load, uses_tcp_route

    platform_given = platform is not None  # --platform, as against told from the sources
    resolved = _source_files(sources) if sources else ()
    scenario_files = _scenario_files(scenario_files)
    given = {real_path(f) for f in scenario_files}
    own = _read_scenarios(scenario_files, platform, bool(resolved))  # --platform: the CPU they run on
    bundled_files: list[Path] = []
    if matrix or (not sources and not scenario_files):
        found = bundled_scenarios()
        if not found:
            raise UnusableInput(f"no bundled scenarios in {bundled_plc_dir() / 'scenarios'}")
        bundled_files = [f for f in found if real_path(f) not in given]
    overrides = {"program": program, "platform": platform, "channel": channel,
                 "duration_us": duration, "scan_us": scan, "seed": seed}
    if resolved:
        own = [s.with_overrides(sources=resolved) for s in own]
    if platform is None and channel is not None and resolved and not own:
        platform = _CHANNEL_PLATFORMS.get(channel.split(":")[0])  # --channel q:1: a Q CPU's port
        overrides["platform"] = platform
    if resolved and matrix:
        # the user's program under the robot/fault set of every bundled scenario of its platform
        platform = platform or infer_platform(resolved)
        bundled = _read_scenarios(bundled_files)
        tcp = uses_tcp_route(resolved, program)  # serial programs under serial scenarios, TCP ones behind a converter
        # an FX3G runs the FX3U's scenarios on its own CPU profile beside its own (scenario.BUNDLED_AS)
        bundled = [_on_platform(s.with_overrides(platform=platform, duration_us=duration, scan_us=scan, seed=seed),
                                s.platform)
                   for s in bundled if s.platform in bundled_platforms(platform) and (s.converter is not None) == tcp]
        if not bundled:
            route = "over TCP" if tcp else "on a serial line"
            raise UnusableInput(f"no bundled scenario is written for the {platform} {route}")
        scenarios = [s.with_overrides(**overrides) for s in own]
        scenarios += without_repeats([for_user_sources(s, resolved, program, channel) for s in bundled])
    else:
        bundled = _read_scenarios(bundled_files)  # only without SOURCES: their own sources
        if platform is not None and bundled:
            # the bundled examples are written for their platform: --platform picks them (an
            # FX3G its own and the FX3U's, those run on the FX3G below: scenario.BUNDLED_AS)
            bundled = [s for s in bundled if s.platform in bundled_platforms(platform)]
            if not bundled and not own:
                raise UnusableInput(f"no bundled scenario is written for the {platform}")
        if not own and not bundled:
            if resolved and platform is None:
                fits, errors = platforms_that_load(resolved)
                if len(fits) == 1:
                    platform = fits[0]
                elif not fits and errors:
                    # ST errors on every CPU: shown for the one that finds fewest (ties: fx3u, fx5u, q),
                    # not always the FX3U's - an FX5U program with an initial value was told GX Works2's
                    # "label tables have no initial value column" beside its own mistakes
                    platform = min(errors, key=lambda told: len(errors[told].located()))
                else:
                    platform = None  # loads on several: the default, fx3u
                overrides["platform"] = platform
            own = [replace(default_scenario(duration_us=duration or DEFAULT_DURATION_US), sources=resolved)]
            if resolved and uses_tcp_route(resolved, program):
                # a program that opens a TCP connection reaches the robot through a
                # converter, as --matrix runs it: a healthy one, wherever the program opens
                own = [replace(own[0], converter=ConverterConfig(any_address=True), description=(
                    "default: a healthy robot behind a healthy converter at the address the program opens, "
                    "no faults, no inputs"))]
        scenarios = [s.with_overrides(**overrides) for s in own]
        scenarios += [_on_platform(s.with_overrides(**overrides), s.platform) for s in bundled]
    if duration is not None:
        scenarios = [_cut_short(s) for s in scenarios]
    # what the command line set, for the messages that blame an option rather than a file's line
    scenarios = [replace(s, platform_from_option=platform_given, program_from_option=program is not None,
                         channel_from_option=channel is not None, duration_from_option=duration is not None)
                 for s in scenarios]
    if channel is not None:
        scenarios = _channel_over_tcp(scenarios, channel)
    if scan is not None and duration is not None and scan > duration:
        # both values are the options': no file's line is to blame
        raise UnusableInput(f"--scan {format_duration(scan)}: the scan time is longer than the whole run "
                            f"(--duration {format_duration(duration)})")
    for scenario in scenarios:
        _check_options(scenario, scan, duration)  # the option is to blame: its first clash is enough
    # a file that names no sources is the file's mistake: every such file named, as a mistake
    # in reading them is (`_read_scenarios`)
    mistakes = [UnusableInput(_no_sources(scenario), at=scenario.key_at("sources"))
                for scenario in scenarios if not scenario.sources]
    if len(mistakes) == 1:
        raise mistakes[0]
    if mistakes:
        raise ScenarioMistakes(mistakes)
    return scenarios


def _on_platform(scenario: Scenario, written_for: str) -> Scenario:
    """`scenario` (a bundled one, written for `written_for`) with a note when --platform runs
    it on another CPU (the FX3U's scenarios on an FX3G: scenario.BUNDLED_AS); its name still
    says the platform it was written for."""
    if scenario.platform == written_for:
        return scenario
    note = f"written for the {written_for}, run on the {scenario.platform} CPU profile (--platform {scenario.platform})"
    return replace(scenario, notes=scenario.notes + (note,))


def _no_sources(scenario: Scenario) -> str:
    if scenario.path is None:
        return "the default scenario: no ST sources: give them as arguments (uitamr verify FILE.st ...)"
    return (f"{scenario.key_where('sources')}: no ST sources: list them in the file "
            f"({_sources_example(scenario.path)}) or give them as arguments (uitamr verify FILE.st ...)")


def _sources_example(scenario_file: Path) -> str:
    """A `sources` line for `scenario_file`, whose paths are relative to its folder: the .st
    files of the working folder, or of a folder in it, that hold some (`verify/x.toml` and
    plc/MAIN.st: "../plc/*.st"); else those of a plc/ folder of the working folder, said so."""
    cwd = Path.cwd()
    here = real_path(scenario_file).parent

    def pattern(folder: Path) -> str:
        try:
            return Path(os.path.relpath(folder / "*.st", here)).as_posix()
        except ValueError:  # another drive (Windows): no relative path leads there
            return (folder / "*.st").as_posix()

    try:
        folders = [cwd, *sorted(f for f in cwd.iterdir() if f.is_dir() and not f.name.startswith("."))]
        found = [folder for folder in folders if any(folder.glob("*.st"))][:3]
    except OSError:
        found = []
    if found:
        return " or ".join(f'sources = ["{pattern(folder)}"] for the .st files in '
                           + ("the working folder" if folder == cwd else f"{shown_path(folder, cwd)}/")
                           for folder in found) + ": paths relative to the file's folder"
    return (f'sources = ["{pattern(cwd / "plc")}"] for .st files in plc/ of the working folder: paths relative '
            "to the file's folder")


def _check_options(scenario: Scenario, scan: int | None, duration: int | None) -> None:
    """UnusableInput when an option on the command line clashes with `scenario` (fine in its
    file: checked there)."""
    if scenario.scan_us > scenario.duration_us:
        key = "scan" if scan is None else "duration"  # the file's value the option met
        option = f"--scan {format_duration(scan)}" if scan is not None else ""
        if duration is not None:
            option += (" and " if option else "") + f"--duration {format_duration(duration)}"
        default = "" if key in scenario.key_lines or key != "scan" else ", the default"
        raise UnusableInput(
            f"{scenario.key_where(key)}: the scan time "
            f"({format_duration(scenario.scan_us)}{default}) is longer than the whole run "
            f"({format_duration(scenario.duration_us)})" + (f" with {option}" if option else ""),
            at=scenario.key_at(key))
    if scenario.scan_jitter_us >= scenario.scan_us:
        raise UnusableInput(
            f"{scenario.key_where('scan_jitter')}: must be shorter than "
            f"the scan time ({format_duration(scenario.scan_us)})"
            + (f" with --scan {format_duration(scan)}" if scan is not None else ""), at=scenario.key_at("scan_jitter"))


def _channel_over_tcp(scenarios: list[Scenario], channel: str) -> list[Scenario]:
    """`--channel` names a serial port; a scenario whose robot is reached over TCP
    ([converter]) has none, and ran as if the option were not there. Such a run says so in
    a note; when no run has a serial port at all, the option is a mistake (exit 2)."""
    if all(s.converter is not None for s in scenarios):
        raise UnusableInput(f"--channel {channel}: names a serial port, and every scenario of this run reaches the "
                            "robot over TCP through a converter ([converter], or a program that uses the Ethernet "
                            "instructions): it has no serial port to replace; leave --channel out")
    note = (f"--channel {channel} not applied: this scenario reaches the robot over TCP through its converter, "
            "not a serial port")
    return [replace(s, notes=s.notes + (note,)) if s.converter is not None else s for s in scenarios]


def _cut_short(scenario: Scenario) -> Scenario:
    """`scenario` with a note when --duration ends its run before some of its scripted faults
    or converter drops, or before some of its operator inputs: they were not tested, though the run may pass (with --matrix nothing
    else says so: the scenario's own expectations are not applied)."""
    end = scenario.duration_us
    # the time the robot strikes at (Fault.at_us, rounded to the µs), as _missed_fault_notes reads it
    missed = [f.describe() for f in scenario.faults if f.at_us is not None and f.at_us >= end]
    if scenario.converter is not None:
        missed += [f"converter drop at {format_seconds(t)}" for t in scenario.converter.drops if t >= end]
    notes = []
    if missed:
        notes.append(f"--duration {format_duration(end)} ends the run before {len(missed)} of its scripted fault(s), "
                     f"not tested: {'; '.join(missed)}")
    # operator inputs too: the run would go on as if no one pressed them
    late = [f"{step.key} at {format_seconds(step.at_us)}" for step in scenario.inputs if step.at_us >= end]
    if late:
        notes.append(f"--duration {format_duration(end)} ends the run before {len(late)} of its operator input(s), "
                     f"not applied: {'; '.join(late)}")
    return replace(scenario, notes=scenario.notes + tuple(notes))


def _with_signal(scenario: Scenario, text: str) -> Scenario:
    from verifier.verify.conditions import ConditionError, parse_condition, unchanging

    try:
        signal = parse_condition(text)
    except ConditionError as exc:
        raise UnusableInput(f"--response-signal: {exc.message} at column {exc.column} of {text!r}") from None
    problem = unchanging(signal, "name the program's output (e.g. fbRobot.o_bErr)")
    if problem is not None:
        raise UnusableInput(f"--response-signal: {problem}")
    options = replace(scenario.options, response_signal=signal)
    return replace(scenario, options=options, response_signal_given=True, response_signal_key="--response-signal")


def _given_beside_list_rules(ctx: click.Context) -> list[str]:
    """The options (and SOURCES) the command line gives beside --list-rules, which only
    prints the rules: each would do nothing."""
    given = []
    for param in ctx.command.params:
        if param.name == "list_rules" or ctx.get_parameter_source(param.name) in (
                None, click.core.ParameterSource.DEFAULT):
            continue
        given.append(param.opts[0] if isinstance(param, click.Option) else param.human_readable_name)
    return given


def _scenario_files(names) -> list[Path]:
    """--scenario values: files, and folders standing for their *.toml files."""
    files: list[Path] = []
    for name in names:
        path = Path(name)
        if is_folder(path):
            found = sorted(path.glob("*.toml"))
            if not found:
                sources = st_files_in(path)  # a folder of ST sources given as the scenario
                hint = (f" but {len(sources)} .st file(s): give it without --scenario, as SOURCES (uitamr verify "
                        f"{name} ...)") if sources else ""
                raise UnusableInput(f"the folder {path} holds no scenario (.toml) file{hint}")
            files += found
        elif path.suffix.lower() == ".st":  # as a .toml among the SOURCES is sent to --scenario
            raise UnusableInput(f"{name} is ST source, not a scenario: give it without --scenario "
                                f"(uitamr verify {name} ...)")
        else:
            files.append(path)
    return files


def _named_inputs(sources, scenario_files) -> list[Path]:
    """The input files the command line names, for a run that could not start: SOURCES'
    folders and patterns as their .st files, --scenario folders as their .toml files (a
    name that stands for none, as given), so that the JUnit report of its mistakes is not
    written over one of them."""
    found: list[Path] = []
    for name in sources:
        try:
            found += _source_files([name])
        except UnusableInput:
            found.append(Path(name))
    for name in scenario_files:
        try:
            found += _scenario_files([name])
        except UnusableInput:
            found.append(Path(name))
    return found


def _inputs_given(params: dict) -> list[Path]:
    """`_named_inputs` of the values click read from a command line it refuses; the names as
    given when the file system refuses one (a name too long): click's message is the one
    to show, not that."""
    sources, scenario_files = params.get("sources") or (), params.get("scenario_files") or ()
    try:
        return _named_inputs(sources, scenario_files)
    except OSError:
        return [Path(name) for name in (*sources, *scenario_files)]


def _source_files(sources) -> tuple[Path, ...]:
    """The .st files named on the command line: files, folders (recursively) or patterns."""
    found: list[Path] = []
    for name in sources:
        if Path(name).suffix.lower() == ".toml":
            raise UnusableInput(f"{name} is a scenario, not ST source: give it as --scenario {name}")
        try:
            files = expand(name, Path.cwd())
            found += files
        except SourceError as exc:
            scenarios = list(Path(name).glob("*.toml")) if is_folder(name) else []
            if scenarios:  # a folder of scenarios given as SOURCES (uitamr verify plc/scenarios)
                raise UnusableInput(f"the folder {name} holds no .st file but {len(scenarios)} scenario (.toml) "
                                    f"file(s): give it as --scenario {name} (with the .st files, if the scenarios "
                                    "name none, as SOURCES)") from None
            raise UnusableInput(str(exc)) from None
        # read as ST, a capture was "1:1: '#' must follow a radix" and a trace "unexpected character '{'"
        shown = [Path(name)] if Path(name).is_file() else files  # as the user named it
        others = [f"{path}: {what}" for path in shown if path.suffix.lower() != ".st" and (what := not_st(path))]
        if others:
            raise UnusableInput("; ".join(others))
    return unique(found)


def _run_batch(batch: list[Scenario], every_scan: bool, keep: Keep) -> list[ScenarioResult]:
    return _run_each(batch, every_scan, keep)


def _run_each(scenarios: list[Scenario], every_scan: bool, keep: Keep, progress_of=None) -> list[ScenarioResult]:
    """Each scenario run in turn (`progress_of(position)`: the run's progress callback).
    Once one cannot run (a label it names that the program does not have), the others are
    only set up, and the mistakes of all of them are raised together: one at a time, a
    folder of scenarios took a run per mistake to clean up (as _read_scenarios says of the
    files' own mistakes)."""
    from verifier.verify.runner import run_scenario, scenario_mistake

    results, mistakes = [], []
    for position, scenario in enumerate(scenarios):
        if mistakes:
            mistakes.append(scenario_mistake(scenario))
            continue
        try:
            results.append(run_scenario(scenario, progress_of(position) if progress_of else None,
                                        plain=every_scan, keep=keep))
        except (ScenarioError, UnusableInput) as exc:
            mistakes.append(exc)
    _raise_together(_said_once(mistakes))
    return results


def _raise_together(mistakes: list[Exception | None]) -> None:
    """Raise the mistakes found (None: a scenario without one), one as it is, several as
    ScenarioMistakes."""
    found = [mistake for mistake in mistakes if mistake is not None]
    if len(found) == 1:
        raise found[0]
    if found:
        raise ScenarioMistakes(found)


def _said_once(mistakes: list[Exception | None]) -> list[Exception | None]:
    """The runs' mistakes with the same one of several scenarios (sources that do not load,
    shared by them) kept once."""
    kept = []
    for mistake in mistakes:
        if mistake is None or all(str(mistake) != str(seen) for seen in kept):
            kept.append(mistake)
    return kept


def _worker_started() -> None:
    """In each --jobs worker: SIGTERM kills it, as the pool expects. A forked worker inherited
    the command's own SIGTERM handler (`_terminate_as_exit`), which raises SystemExit; the pool
    stops its workers with SIGTERM when one of them was killed, and a worker sending its
    results at that moment caught the SystemExit and sent them again, into a pipe nobody
    read any more: the command hung for ever instead of saying a worker was lost.

    Ctrl-C is ignored: the terminal sends it to the workers too, and each then sent its
    KeyboardInterrupt back as its batch's result and went on with the next batch; the command
    stops its workers itself (`_HeldSignals`, `_stop_workers`)."""
    signal.signal(signal.SIGTERM, signal.SIG_DFL)
    signal.signal(signal.SIGINT, signal.SIG_IGN)


def _batches(scenarios: list[Scenario], jobs: int) -> list[list[int]]:
    """Scenarios (by index) grouped for the worker processes, longest batch first.

    A worker parses and checks a set of sources once and keeps it (sim.project's cache):
    scenarios with the same sources go in the same batch, so each set is parsed by one
    worker instead of by every worker. A batch holds at most a 1/(2 jobs) share of the
    scans to simulate (at least one scenario), so the workers still finish together."""
    cost = [max(1, s.duration_us // s.scan_us) for s in scenarios]
    limit = sum(cost) / (2 * jobs)
    groups: dict[tuple, list[int]] = {}
    for i, scenario in enumerate(scenarios):
        groups.setdefault((scenario.sources, scenario.target), []).append(i)
    batches: list[list[int]] = []
    for members in groups.values():
        batch: list[int] = []
        for i in sorted(members, key=lambda k: -cost[k]):
            if batch and sum(cost[k] for k in batch) + cost[i] > limit:
                batches.append(batch)
                batch = []
            batch.append(i)
        batches.append(batch)
    return sorted(batches, key=lambda b: -sum(cost[k] for k in b))


class _LazyProgress:
    """A rich progress bar that appears only once the run has taken more than a moment."""

    def __init__(self, console: Console, total_us: int, enabled: bool):
        self.console, self.total, self.enabled = console, total_us, enabled
        self.started = time.perf_counter()
        self.bar: Progress | None = None
        self.done_us = 0
        self.last_update = 0.0

    def update(self, done_us: int, label: str) -> None:
        now = time.perf_counter()
        if not self.enabled:
            self._plain(now, done_us, label)
            return
        if self.bar is None:
            if now - self.started < SHOW_PROGRESS_AFTER_S or done_us >= self.total:
                return  # a moment's work, or the work done: no bar to show (it would be erased at once)
            self.bar = Progress(
                TextColumn("{task.description}"), BarColumn(), TextColumn("{task.percentage:>3.0f}%"),
                TimeElapsedColumn(), console=self.console, transient=True,
            )
            # the task as far as the work is, before the bar is drawn: started first, its first
            # frame said 0 % (add_task draws at once) though the run was well on, or even done
            self.task = self.bar.add_task(label, total=self.total, completed=done_us)
            self.bar.start()
            self.last_update = now
            return
        if now - self.last_update < 0.1 and done_us < self.total:
            return
        self.last_update = now
        self.bar.update(self.task, completed=done_us, description=label)

    def _plain(self, now: float, done_us: int, label: str) -> None:
        """Not a terminal (a CI log): a plain line now and then, so a long run is not a hang."""
        if now - max(self.started, self.last_update) < PLAIN_PROGRESS_EVERY_S or done_us >= self.total:
            return
        self.last_update = now
        share = 100 * done_us / self.total if self.total else 100
        self.console.print(f"verify: {share:.0f}% of {format_seconds(self.total)} virtual time done ({label})",
                           highlight=False, markup=False)

    def stop(self) -> None:
        if self.bar is not None:
            self.bar.stop()


def _run_all(scenarios: list[Scenario], jobs: int, progress: _LazyProgress,
             every_scan: bool = False, keep: Keep = KEEP_ALL) -> list[ScenarioResult]:
    from verifier.verify.runner import scenario_mistake

    if jobs > 1 and len(scenarios) > 1:
        results: list[ScenarioResult | None] = [None] * len(scenarios)
        done = 0
        waiting = _batches(scenarios, jobs)  # not given to a worker yet, longest first
        # a worker per batch at most: the pool forks all its workers at once, and --jobs 5000
        # forked 5000 processes for two scenarios (the run never ended)
        workers = min(jobs, len(waiting))
        mistakes: dict[int, Exception | None] = {}  # by the scenario's index: said in the scenarios' order
        # a batch goes to the pool only when a worker is free for it: the pool never holds one
        # that the command would have to cancel (see _HeldSignals for what cancelling did)
        with _HeldSignals() as held, ProcessPoolExecutor(max_workers=workers, initializer=_worker_started) as pool:
            running: dict = {}
            try:
                while running or (waiting and not mistakes):
                    while waiting and not mistakes and len(running) < workers:
                        batch = waiting.pop(0)
                        running[pool.submit(_run_batch, [scenarios[i] for i in batch], every_scan, keep)] = batch
                    finished, _ = wait(running, timeout=STOP_CHECK_EVERY_S, return_when=FIRST_COMPLETED)
                    held.let_go()  # SIGTERM or Ctrl-C: raised here, where no lock of the pool is held
                    for future in finished:
                        batch = running.pop(future)
                        try:
                            batch_results = future.result()
                        except (ScenarioError, UnusableInput) as exc:
                            mistakes[min(batch)] = exc  # the batches still waiting: only set up, below
                            continue
                        for index, result in zip(batch, batch_results):
                            results[index] = result
                            done += scenarios[index].duration_us
                        progress.update(done, f"{sum(r is not None for r in results)}/{len(scenarios)} scenarios")
            except BaseException as exc:
                _stop_workers(pool)  # the command is ending: the batches running are not waited for
                if isinstance(exc, BrokenProcessPool):
                    raise UnusableInput(f"a worker process of --jobs {jobs} stopped without a word (killed, or out "
                                        "of memory?): run again, or with fewer jobs") from None
                raise
        if mistakes:
            for batch in waiting:
                mistakes.update((i, scenario_mistake(scenarios[i])) for i in batch)
            _raise_together(_said_once([mistakes[i] for i in sorted(mistakes)]))
        return [r for r in results if r is not None]
    offsets = [0, *accumulate(s.duration_us for s in scenarios)]

    def progress_of(position: int):
        label = f"[{position + 1}/{len(scenarios)}] {scenarios[position].name}"
        return lambda now, end: progress.update(offsets[position] + now, label)

    return _run_each(scenarios, every_scan, keep, progress_of)


def _spool_folder(report_path: str, report: str) -> str:
    """A hidden folder beside the report (the trace, or else the page) for the runs' trace
    lines (Keep.frames_to_file; verifier.verify.spool); ReportError when it cannot be made."""
    folder = real_path(report_path).parent
    try:
        return spool.make(folder)
    except OSError as exc:
        raise ReportError(f"cannot write the {report} in {folder}: {exc.strerror or exc}", report_path) from None


class _HeldSignals:
    """SIGTERM and Ctrl-C held while the main thread waits for the --jobs workers, and given
    to the handlers they were held from (`_terminate_as_exit`'s SystemExit 143, Python's
    KeyboardInterrupt) at `let_go`, where the main thread holds none of the pool's locks.

    Raised from the handler, the SystemExit went off wherever the main thread was, inside
    concurrent.futures' waiting; the clean-up then cancelled the batches the pool had not
    handed out yet, and on Python 3.11 the pool's own thread, finding its workers gone (a CI
    time-out signals the whole process group), failed on a cancelled batch
    (InvalidStateError: "Exception in thread" on stderr) before it closed its queue of
    batches; the thread feeding that queue stayed blocked on the full pipe, and the exit,
    which waits for it, never came: a CI job's time-out hung for good (1 CI run in 12; most
    runs signalled just after a batch came back). Only a handler Python code set is held:
    an ignored signal stays ignored, one without a handler (SIG_DFL) still ends the process."""

    SIGNALS = (signal.SIGTERM, signal.SIGINT)

    def __init__(self) -> None:
        self.previous: dict = {}
        self.caught: list[int] = []

    def __enter__(self) -> _HeldSignals:
        try:
            for sig in self.SIGNALS:
                if callable(signal.getsignal(sig)):
                    self.previous[sig] = signal.signal(sig, self._note)
        except ValueError:  # not the main thread (an embedding application): no handler runs in this one
            pass
        return self

    def _note(self, signum, frame) -> None:
        self.caught.append(signum)

    def let_go(self) -> None:
        """The signals that came, each given to its own handler (`_terminate_as_exit`'s and
        Python's raise: the first one ends the command)."""
        caught, self.caught = self.caught, []
        for signum in caught:
            self.previous[signum](signum, None)

    def __exit__(self, kind, value, traceback) -> None:
        for sig, handler in self.previous.items():
            signal.signal(sig, handler)
        if kind is None:
            self.let_go()  # one that came while the pool shut down


def _stop_workers(pool) -> None:
    """The pool's worker processes killed, with what they were running: the command is
    ending (SIGTERM, Ctrl-C, a worker lost). Without it, `uitamr verify` sent SIGTERM alone
    (not its process group: `kill PID`, `docker stop`) waited for its workers to finish their
    batches, hours with a long --duration, and Ctrl-C for those the pool had queued. The pool
    sees them gone and closes its queues itself. SIGKILL: a worker forked a moment ago has
    the command's handlers still, not SIG_DFL. The processes are the pool's own (`_processes`,
    in ProcessPoolExecutor since Python 3.2); a stand-in pool without them has nothing to stop."""
    for process in list((getattr(pool, "_processes", None) or {}).values()):
        try:
            process.kill()
        except (OSError, ValueError):  # gone already, or closed by the pool
            pass


@contextmanager
def _terminate_as_exit():
    """SIGTERM (what a CI job's time-out sends) ends the command as Ctrl-C does, through
    its clean-up, instead of at once: the spool folder is removed, the workers stop."""
    def terminated(signum, frame):
        raise SystemExit(128 + signal.SIGTERM)

    try:
        previous = signal.signal(signal.SIGTERM, terminated)
    except ValueError:  # not the main thread (an embedding application): leave it be
        yield
        return
    try:
        yield
    finally:
        signal.signal(signal.SIGTERM, previous)


@click.command(cls=JudgingCommand, maker="uitamr verify", inputs_of=_inputs_given,
               context_settings={"help_option_names": ["-h", "--help"]})
@click.argument("sources", nargs=-1, type=click.Path())
@click.option("--program", help="The PROGRAM POU to run (default: the scenario's, or the only one).")
@click.option("--platform", type=click.Choice(sorted(PLATFORMS), case_sensitive=False),
              help="PLC platform (sets the ST dialect, the CPU and the serial port); fx3g: an FX3G, the FX3 library on the FX3G CPU profile. Default: the scenario's; with SOURCES and no scenario, told from the devices and instructions the sources use (never fx3g). Without SOURCES: runs the bundled scenarios of that platform (fx3g: its own fx3g-* and the fx3u ones, all on the FX3G).")
@click.option("--channel", type=click.Choice(CHANNELS),
              help="The PLC serial port the robot hangs on (default: the scenario's, or the platform's first port).")
@click.option("--scenario", "scenario_files", multiple=True, type=click.Path(),
              help="Scenario file (TOML), or a folder of them; repeat for several. Default: the bundled scenarios, or a healthy robot when SOURCES are given.")
@click.option("--response-signal", "response_signal", metavar="CONDITION",
              help="The program's output that shows failed replies were noticed (UITAMR-RESPONSE-HANDLING), e.g. fbRobot.o_bErr; replaces the scenarios' (default: o_bErr when the program has it).")
@click.option("--matrix", is_flag=True,
              help="Run every bundled scenario. With SOURCES: those of the program's platform and route (serial, or TCP through a converter), with their robot, faults and rules but not their example-specific inputs and expectations (see docs/verifier.md).")
@click.option("--duration", type=_Duration(MAX_DURATION_US), help="Virtual run time, e.g. 60s (overrides the scenarios'; default 60s).")
@click.option("--scan", type=_Duration(), help="PLC scan time, e.g. 10ms (overrides the scenarios'; default 10ms).")
@click.option("--seed", type=INT, help="Seed for everything random in the run (overrides the scenarios').")
@click.option("--jobs", "-j", type=IntRange(min=1), default=1, show_default=True, help="Scenarios run in parallel processes.")
@click.option("--every-scan", is_flag=True,
              help="Run every scan and read every watched label by name on each (the reference path; several times slower). The default jumps over idle scans and gives the same report.")
@report_options
@click.option("--list-rules", is_flag=True, help="Print the rules (id, title, source) and exit.")
@click.option("--violations", "first", type=IntRange(min=0), default=3, show_default=True,
              help="Times listed per broken rule and scenario on the console (0: counts only).")
def command(sources, program, platform, channel, response_signal, scenario_files, matrix, duration, scan, seed, jobs,
            every_scan, json_path, junit_path, trace_path, html_path, list_rules, first):
    """Run PLC programs against the emulated robot on a virtual RS-485 line and check
    every frame and gap against the robot's manual.

    With no arguments: the bundled library examples against the bundled scenarios.
    Exit status: 0 compliant, 1 violations or failed expectations, 2 unusable input.
    """
    from verifier.verify import report_console

    console = text_console()
    if list_rules:
        from verifier.verify.rules import RULES

        ctx = click.get_current_context()
        if given := _given_beside_list_rules(ctx):
            # `--list-rules --junit r.xml` wrote no report and said nothing: a CI job then read
            # an earlier run's file, or none. Refused as a usage mistake, as click refuses one
            mistake = click.UsageError(f"--list-rules prints the rules and exits: it runs nothing and writes no "
                                       f"report, so {', '.join(given)} would do nothing; leave "
                                       f"{'it' if len(given) == 1 else 'them'} out", ctx)
            raise usage_error_junit(junit_path, mistake, "uitamr verify", _inputs_given(ctx.params))

        for rule in RULES:
            console.print(f"[bold]{rule.id}[/] — {rule.title}\n    {rule.explanation}")
        sys.exit(EXIT_PASS)
    try:
        check_folders(json_path, junit_path, trace_path, html_path)
    except ReportError as exc:
        _refused_report(junit_path, exc, _named_inputs(sources, scenario_files))
    try:
        scenarios = _scenarios(sources, program, platform, channel, scenario_files, matrix, duration, scan, seed)
        if response_signal is not None:
            scenarios = [_with_signal(s, response_signal) for s in scenarios]
        inputs = [p for s in scenarios for p in ([s.path] if s.path else []) + list(s.sources)]
        check_not_inputs(inputs, json_path, junit_path, trace_path, html_path)
    except (ScenarioError, UnusableInput) as exc:
        _unusable_input(junit_path, _named_inputs(sources, scenario_files), exc)
    except ReportError as exc:
        _refused_report(junit_path, exc, inputs)
    stderr = text_console(stderr=True)
    progress = _LazyProgress(stderr, sum(s.duration_us for s in scenarios), stderr.is_terminal)
    # the reports that list frames do not make a run hold them: they go to files in a hidden
    # folder beside the trace (or the page), removed at the end whatever happens to the runs
    # and their workers
    try:
        spool_folder = _spool_folder(trace_path or html_path, "trace" if trace_path else "HTML report") \
            if trace_path or html_path else None
    except ReportError as exc:
        _refused_report(junit_path, exc, inputs)
    try:
        with _terminate_as_exit():
            try:
                # a run holds every frame and watched change only for the reports that list them
                # the page shows at most EVENTS_AT_MOST events of a run: without --json, which
                # lists them all, a run keeps no more than the page can show
                keep = Keep(frames=bool(trace_path or html_path), details=bool(json_path or html_path),
                            watched=bool(json_path), frames_to_file=spool_folder,
                            events_at_most=None if json_path else EVENTS_AT_MOST)
                results = _run_all(scenarios, jobs, progress, every_scan, keep)
            except (ScenarioError, UnusableInput) as exc:
                progress.stop()
                _unusable_input(junit_path, inputs, exc)
            progress.stop()
            try:
                report_console.render(results, console, first=first)
                write_reports(results, console, json_path, junit_path, trace_path, html_path)
            except ReportError as exc:
                _refused_report(junit_path, exc, inputs, results)
    finally:
        if spool_folder is not None:
            shutil.rmtree(spool_folder, ignore_errors=True)
    sys.exit(EXIT_PASS if all(r.passed for r in results) else EXIT_FAIL)
