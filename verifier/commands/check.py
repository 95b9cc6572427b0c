"""`uitamr check SOURCES...`: parse and type-check GX Works structured text.

Prints each finding as `file:line:col: error|warning: message`, the source line and a
caret under the column (`--format text`, the default: VS Code's and most editors'
problem matchers read it). `--format json`, `github` (GitHub Actions annotations) and
`sarif` (SARIF 2.1.0 for code scanning) are for CI (docs/ci.md). Scenario files
(`.toml`) given among the sources are checked as `uitamr verify` would read them.
Exit status: 1 if any error, 0 otherwise (warnings allowed), 2 for usage errors
(missing file, a pattern that matches none, not a regular file, bad option). Every file is read and checked even when
another one is broken; POUs may use POUs from the other files given.

`--platform fx3u|fx3g|fx5u|q` also checks every device and instruction against that CPU,
with the simulator's own rules (verifier.sim.cpucheck): what `uitamr verify` on that
platform would refuse (SM400 on an FX3U, D9000, Z8, CRC on a Q ...) is reported here, each
at its file:line:col under the rule UITAMR-ST-CPU. Without it nothing is asked of the CPU.
"""
from __future__ import annotations

import sys
from pathlib import Path

import click

from verifier.commands.check_formats import PLATFORM_RULES, RULES, Finding, to_github, to_json, to_sarif
from verifier.sim.cpu import EDITOR_NAMES, PROFILES, TARGET_CPUS
from verifier.st import TARGETS
from verifier.st.ast import Diagnostic, SourceFile
from verifier.textfile import real_path, shown_name, text_lines

EXIT_OK, EXIT_ERRORS, EXIT_USAGE = 0, 1, 2


def _named(name: str) -> list[Path]:
    """The files one name on the command line stands for: a folder its .st files
    (recursive, as `uitamr verify` reads it), a pattern what it stands for as `uitamr
    verify` expands one (cmd and PowerShell hand `verify/*.toml` over as it is; a pattern
    that stands for no file stays as named, for the caller to report), anything else itself."""
    from verifier.verify.sources import is_pattern, pattern_files, st_files_in

    path = Path(name)
    if is_pattern(name):
        return pattern_files(name) or [path]
    return st_files_in(path) if path.is_dir() else [path]


def expand_sources(sources: tuple[str, ...]) -> list[Path]:
    """Files named on the command line (`_named`). A file named twice (itself and through
    its folder or a pattern) is read once, where first named."""
    paths: list[Path] = []
    seen: set[Path] = set()
    for s in sources:
        for path in _named(s):
            key = real_path(path)
            if key not in seen:
                seen.add(key)
                paths.append(path)
    return paths


#: the toolkit's other files, which check would read as ST ("1:1: unexpected ';'"): what
#: each is and what reads it
_OTHER_KINDS = {
    ".il": "an instruction list (the ladder program), not ST: `python -m verifier.export.ladder FILE.il` "
           "reads it and names its mistakes (docs/plc-library.md)",
    ".csv": "a GX Works import file (generated), not ST source: check the .st or .il it was made from",
    ".jsonl": "a trace (JSON Lines), not ST: `uitamr replay` reads it",
    ".json": "a report, not ST: give the .st sources it reports on",
    ".html": "a report, not ST: give the .st sources it reports on",
    ".xml": "a report, not ST: give the .st sources it reports on",
}


def _capture_kind(path: Path) -> str | None:
    """What `path` is when it reads as a capture of `uitamr monitor` or a trace (a .txt, told
    by its content: an editor may export ST as .txt too), or None."""
    from verifier.monitor.capture import capture_kind
    from verifier.textfile import UnreadableText, read_utf8

    try:
        what = capture_kind(read_utf8(path), str(path))
    except UnreadableText:  # not a capture: ST (or a mistake) to be read as ST
        return None
    return None if what is None else f"{what}, not ST: `uitamr replay {path}` judges its frames (docs/commissioning.md)"


def _scenario_kind(path: Path) -> str | None:
    """What `path` is when it reads as a scenario (TOML with a scenario's keys) though not
    named .toml (Windows may save `s.toml` as `s.toml.txt`), or None."""
    import tomllib

    from verifier.textfile import UnreadableText, read_utf8
    from verifier.verify.scenario import TOP_KEYS

    try:  # read_utf8: a pipe or a device (/dev/zero) is not read, which waited or filled the memory
        data = tomllib.loads(read_utf8(path))
    except (UnreadableText, ValueError, RecursionError):  # not TOML: ST, or a mistake to place
        return None
    if not set(data) & set(TOP_KEYS):  # ST is no TOML; TOML without a scenario's key is no scenario
        return None
    renamed = path.stem if path.stem.lower().endswith(".toml") else f"{path.stem}.toml"
    return (f"a scenario (TOML), not ST: name it {renamed} (`uitamr check` reads scenarios by that name); "
            f"`uitamr verify --scenario {path}` runs it as it is")


def not_st(path: Path) -> str | None:
    """What the file `path` is when it is one of the toolkit's other files rather than ST
    (by its suffix, or for a name that says neither .st nor .toml, by its content), or None."""
    suffix = path.suffix.lower()
    if suffix in _OTHER_KINDS:
        return _OTHER_KINDS[suffix]
    if suffix == ".st":
        return _exported_body(path)
    return None if suffix == ".toml" else _capture_kind(path) or _scenario_kind(path)


def _exported_body(path: Path) -> str | None:
    """What `path` is when `uitamr export` wrote it: a body without its declarations, beside
    its label table and the folder's IMPORT_ORDER.txt. Checked, each such file was 'a
    statement outside a POU' at its first statement."""
    from verifier.export.writer import IMPORT_ORDER

    table = path.with_name(path.stem + ".labels.tsv")
    if not (table.is_file() and (path.parent / IMPORT_ORDER).is_file()):
        return None
    return (f"a body written by `uitamr export` (its declarations are in {table.name}), not ST source: "
            "check the .st files it was exported from, with the same --platform")


def not_a_source(path: Path) -> str | None:
    """Why `path` cannot be checked (or exported) at all (missing, a device, a pipe, another
    kind of the toolkit's files ...), or None: a usage error (exit 2) of either command. Files that exist but hold no text are diagnosed with
    file:line:col instead."""
    from verifier.st import read_source
    from verifier.verify.sources import DANGLING_LINK, is_pattern

    if path.is_file():
        return not_st(path)
    if is_pattern(str(path)):
        return "matches no file"
    if not path.exists() and not path.is_symlink():
        return "no such file"
    try:
        path.stat()
    except FileNotFoundError:  # a symbolic link whose target is missing (a loop: read_source names it)
        return DANGLING_LINK
    except OSError:
        pass
    problems = read_source(path)[1]
    return problems[0].message if problems else None


def check_findings(paths: list[Path], target: str,
                   platform: str | None = None) -> tuple[list[SourceFile], list[Finding]]:
    """Every finding about `paths` (ST files and scenario .toml files), in file order, each
    under the rule it comes from (see check_formats). With `platform` (a CPU profile name),
    also the devices and instructions that CPU does not have."""
    from verifier.st import check, parse, read_source
    from verifier.st.collector import collector_held

    files: list[SourceFile] = []
    findings: list[Finding] = []
    with collector_held():
        for p in paths:
            if p.suffix.lower() == ".toml":
                findings += [Finding(d, "UITAMR-SCENARIO") for d in check_scenario(p, platform)]
                continue
            text, problems = read_source(p)
            findings += [Finding(d, "UITAMR-ST-SOURCE") for d in problems]
            if not problems:  # an unreadable file is reported once, not also as empty
                files.append(parse(text, str(p), target))
        findings += [Finding(d, "UITAMR-ST-SYNTAX") for f in files for d in f.diagnostics]
        findings += [Finding(d, "UITAMR-ST-CHECK" if d.is_error else "UITAMR-ST-WARNING")
                     for d in check(files, target, platform)]
        if platform is not None:
            from verifier.sim.cpucheck import on_cpu

            standing, found = on_cpu(files, PROFILES[platform], [f.diagnostic for f in findings])
            kept = {id(d) for d in standing}
            findings = [f for f in findings if id(f.diagnostic) in kept] + [Finding(d, "UITAMR-ST-CPU") for d in found]
    order = {str(p): i for i, p in enumerate(paths)}
    findings.sort(key=lambda f: (order.get(f.diagnostic.file, len(order)), f.diagnostic.line, f.diagnostic.col))
    return files, findings


def platform_target(platform: str, target: str | None, command: str = "check") -> str:
    """The dialect to check `platform`'s sources in: `target` when given and its editor
    programs that CPU, else the editor that does (TARGET_CPUS, as `verifier.load` reads
    it). A contradictory pair is a usage error of `uitamr <command>` (SystemExit 2)."""
    editor = next(t for t, cpus in TARGET_CPUS.items() if platform in cpus)
    if target is not None and target != editor:
        click.echo(f"uitamr {command}: --platform {platform} and --target {target} disagree: the {platform.upper()} "
                   f"is programmed in {EDITOR_NAMES[editor]} (--target {editor}), not {EDITOR_NAMES[target]}; "
                   f"drop --target (--platform {platform} implies {editor}) or name a CPU {EDITOR_NAMES[target]} "
                   f"programs: --platform {'|'.join(TARGET_CPUS[target])}", err=True)
        sys.exit(EXIT_USAGE)
    return editor


def check_scenario(path: Path, platform: str | None = None) -> list[Diagnostic]:
    """A scenario file read as `uitamr verify` reads it: its TOML, keys, values and the
    sources it names (not the labels it uses: those need the program loaded, which
    `uitamr verify` does). `platform` (--platform): the CPU its devices are judged for, as
    `uitamr verify --platform` runs it, also a file that names its own (verify runs that on
    --platform's CPU too: `check --platform fx3g` of a `platform = "fx3u"` file with X200
    said 0 errors where verify refused X200 at its key), and the channel it names."""
    from verifier.plcfacts import channel_problem
    from verifier.verify.scenario import ScenarioError, load_scenario

    try:
        scenario = load_scenario(path, platform)  # --platform: a CPU verify runs (PLATFORMS)
    except ScenarioError as exc:  # every mistake of the file, each at its place (ScenarioErrors: several)
        return [Diagnostic(str(path), error.place.line if error.place else 0, error.place.col if error.place else 0,
                           "error", f"{error.key}: {error.message}" if error.key else error.message)
                for error in getattr(exc, "errors", [exc])]
    found = []
    place = scenario.key_lines.get("channel")
    if platform is not None and scenario.channel is not None and place is not None:
        # the file's channel on --platform's CPU, which verify --platform attaches it to
        # (check said 0 errors for a platform = "fx3u" file on fx3:2 where verify --platform q
        # refused fx3:2 at its key)
        problem = channel_problem(scenario.channel, platform)
        if problem is not None:
            found.append(Diagnostic(str(path), place.line, place.col, "error", f"channel: {problem}"))
    return found + _scenario_devices(scenario, platform or scenario.platform)


def _scenario_devices(scenario, cpu_name: str) -> list[Diagnostic]:
    """The devices of [initial] and [[inputs]] that CPU `cpu_name` (--platform's, else the
    scenario's platform) does not have, each at its key, as
    `uitamr verify` refuses them (exit 2) before the first scan."""
    from verifier.sim.cpu import PROFILES
    from verifier.sim.devices import device_problem, device_warning
    from verifier.verify.scenario import BUFFER_MEMORY, DEVICE_NAME

    cpu = PROFILES[cpu_name]
    named = [(f"initial.{name}", name, f"initial.{name}") for name, _ in scenario.initial
             if not BUFFER_MEMORY.match(name)]
    named += [(f"{step.key}.set", name, f"{step.key}.set.{name}") for step in scenario.inputs for name in step.values
              if DEVICE_NAME.match(name)]
    found = []
    for key, name, at in named:
        problem = device_problem(name, cpu)
        severity = "error"
        if problem is None:
            problem, severity = device_warning(name, cpu), "warning"  # M8402 on an FX5U: sets nothing
        if problem:
            place = scenario.key_lines.get(at)
            found.append(Diagnostic(str(scenario.path), place.line if place else 0, place.col if place else 0,
                                    severity, f"{key}: {problem}"))
    return found


def render(diag: Diagnostic, lines: list[str] | None) -> str:
    """The diagnostic line, then the source line and a caret (when the line exists)."""
    out = str(diag)
    if lines is not None and 1 <= diag.line <= len(lines):
        src = lines[diag.line - 1].rstrip("\r\n").expandtabs(1)
        width = 1
        if diag.end_line == diag.line and diag.end_col and diag.end_col > diag.col:
            width = diag.end_col - diag.col
        out += f"\n    {src}\n    {' ' * max(diag.col - 1, 0)}{'^' * min(width, max(1, len(src) - diag.col + 1))}"
    return out


@click.command(name="check")
@click.argument("sources", nargs=-1, required=True, type=click.Path())
@click.option("--target", type=click.Choice(TARGETS), default=None,
              help="Which engineering tool's dialect to accept. Default: the editor of --platform's "
                   "CPU (gxworks3 for fx5u, gxworks2 for the others), else gxworks2.")
@click.option("--platform", type=click.Choice(sorted(PROFILES), case_sensitive=False), default=None,
              help="Also check every device (name, range, index register) and instruction against "
                   "this CPU, as `uitamr verify --platform` loads it (fx3g: the FX3G CPU profile, "
                   "its smaller X/Y and R ranges); errors under rule UITAMR-ST-CPU. Implies the "
                   "dialect; a --target whose editor does not program the CPU is refused. Default: "
                   "no CPU check.")
@click.option("--format", "fmt", type=click.Choice(["text", "json", "github", "sarif"]), default="text",
              show_default=True,
              help="text: file:line:col: error: message (editors); json; github: GitHub Actions "
                   "annotations; sarif: SARIF 2.1.0 for code scanning (docs/ci.md).")
def command(sources: tuple[str, ...], target: str | None, platform: str | None, fmt: str) -> None:
    """Parse and type-check GX Works structured text (files, directories of .st, or glob
    patterns, which check expands itself as verify does), and scenario files (.toml) as
    `uitamr verify` reads them. With --platform, also check the
    devices and instructions against that CPU."""
    target_given = target is not None
    target = platform_target(platform, target) if platform else target or "gxworks2"
    paths = expand_sources(sources)
    refuse_what_is_not_st("uitamr check", sources, paths)
    files, findings = check_findings(paths, target, platform)
    diagnostics = [f.diagnostic for f in findings]
    errors = sum(d.is_error for d in diagnostics)
    warnings = len(diagnostics) - errors
    if fmt == "json":
        click.echo(to_json(findings, target, [str(p) for p in paths], platform))
    elif fmt == "github":
        annotations = to_github(findings)
        if annotations:
            click.echo(annotations)
        click.echo(f"{_summary(paths, target, target_given, platform)}: {errors} error(s), "
                   f"{warnings} warning(s)")
    elif fmt == "sarif":
        from verifier import __version__

        click.echo(to_sarif(findings, __version__, {**RULES, **PLATFORM_RULES} if platform else RULES))
    else:
        texts = {f.filename: text_lines(f.text) for f in files}
        for p in paths:
            if p.suffix.lower() == ".toml" and str(p) not in texts:
                texts[str(p)] = _lines_of(p)
        for d in diagnostics:
            click.echo(render(d, texts.get(d.file)))
        click.echo(f"{_summary(paths, target, target_given, platform)}: {errors} error(s), "
                   f"{warnings} warning(s)")
    sys.exit(EXIT_ERRORS if errors else EXIT_OK)


def refuse_what_is_not_st(command: str, sources, paths: list[Path]) -> None:
    """Exit 2 when a path is no ST source (`not_a_source`: an .il, a capture, a pipe, an
    exported body, each named with why) or when the sources hold none: what `uitamr check`
    and `uitamr export` refuse alike."""
    unusable = [(p, why) for p in paths if (why := not_a_source(p))]
    if unusable:
        for p, why in unusable:
            click.echo(f"{command}: {shown_name(str(p))}: {why}", err=True)
        sys.exit(EXIT_USAGE)
    say_folders_without_st(command, sources, fatal=not paths)
    if not paths:
        sys.exit(EXIT_USAGE)


def say_folders_without_st(command: str, sources, fatal: bool) -> None:
    """Each folder of `sources` that holds no .st file (plc/scenarios), on stderr with what it
    holds: said, not passed over in silence ("20 file(s) checked" read as if its scenarios
    were among them); a warning unless nothing at all was found (`fatal`)."""
    from verifier.verify.sources import is_pattern, st_files_in

    for folder in dict.fromkeys(s for s in sources if not is_pattern(s) and Path(s).is_dir()):
        if not st_files_in(Path(folder)):
            click.echo(f"{command}: {'' if fatal else 'warning: '}{folder}: {_no_st_in(Path(folder))}", err=True)


def _no_st_in(folder: Path) -> str:
    """What a folder that holds no .st file holds instead, and what to run on it: a folder
    of scenarios (plc/scenarios) is for `uitamr verify --scenario`, which reads a folder's
    .toml files, or for check itself when they are named (check reads a folder for .st only)."""
    from collections import Counter

    from verifier.verify.sources import files_below

    files = files_below(folder)
    if not files:
        return "no .st file in it: the folder is empty"
    kinds = Counter(p.suffix.lower() or "(no suffix)" for p in files).most_common()
    held = " and ".join(f"{n} {kind}" for kind, n in kinds[:3]) + " file(s)"
    held += f" and {sum(n for _, n in kinds[3:])} other(s)" if kinds[3:] else ""
    text = f"no .st file in it or below it: it holds {held}"
    scenarios = sorted(folder.glob("*.toml"))
    if not scenarios:
        return text + "; name the folders or files that hold the program's .st files"
    # double quotes: a pattern check expands itself, so cmd and PowerShell may pass it on too
    return (text + f"; its {len(scenarios)} .toml file(s) are scenarios: run them with `uitamr verify --scenario "
            f"\"{folder}\"` (on the sources they name, or on .st files given as arguments), or check them by name "
            f"with `uitamr check \"{folder / '*.toml'}\"`")


def _lines_of(path: Path) -> list[str] | None:
    try:
        return text_lines(path.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError):
        return None


def _checked_for(target: str, platform: str | None) -> str:
    return f"{target} on the {platform} CPU" if platform else target


def _summary(paths: list[Path], target: str, target_given: bool, platform: str | None) -> str:
    """'N file(s) checked for <dialect>': a run of scenario files only, with no dialect asked
    for, names none (each file is read for its own platform: an FX5U scenario said 'checked
    for gxworks2')."""
    if not platform and not target_given and all(p.suffix.lower() == ".toml" for p in paths):
        return f"{len(paths)} file(s) checked"
    return f"{len(paths)} file(s) checked for {_checked_for(target, platform)}"
