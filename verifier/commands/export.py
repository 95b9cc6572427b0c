"""`uitamr export --target gxworks2|gxworks3 --out DIR [SOURCES...]`: paste-ready ST bodies
and label tables for GX Works (docs/import-gxworks2.md, docs/import-gxworks3.md).

With no SOURCES it exports the bundled library (plc/core, the platform ports and the
examples of that editor's platforms). Exit status: 0 written, 1 the sources have errors
(listed as file:line:col), 2 usage errors (no such file, one that is no regular file: a
pipe, a device; a file with no POU in it), as `uitamr check` has them.
An initial value the target's label table cannot carry is never dropped silently: one
note line per value (file:line:col) and DROPPED_INITIAL_VALUES.txt in the output folder.
An --out folder inside a source folder is left out of the sources (an earlier export there
is bodies without declarations), with a note.

`--platform fx3u|fx3g|fx5u|q` also checks what is written (with --program, the POUs
written) against that CPU, with `uitamr check --platform`'s own rules
(verifier.sim.cpucheck): a device or instruction the CPU does not have is an error at its
file:line:col, as the check prints it, and nothing is written (exit 1); a warning (an FX3
special relay number on a Q) is printed and the export goes on. The platform implies the
target (its CPU's editor); a --target whose editor does not program it is refused (exit 2).
With no SOURCES, the bundled library of that platform is exported.
"""
from __future__ import annotations

import sys
from pathlib import Path

import click

from verifier.bundled import PLC_DIR
from verifier.commands.check import expand_sources, platform_target, refuse_what_is_not_st
from verifier.sim.cpu import PROFILES
from verifier.textfile import real_path, shown_name

EXIT_OK, EXIT_ERRORS, EXIT_USAGE = 0, 1, 2
#: the bundled folders each editor gets by default
BUNDLED = {
    "gxworks2": ("core", "fx3", "q", "examples/common", "examples/fx3", "examples/q"),
    "gxworks3": ("core", "fx5", "examples/common", "examples/fx5"),
}


def bundled_sources(target: str, platform: str | None = None) -> list[Path]:
    """The bundled files `target` gets; for `platform`, only the folders of its CPU family
    (the core, the common example, its port and examples, not another family's)."""
    folders = BUNDLED[target]
    if platform is not None:
        family, families = PROFILES[platform].family, {cpu.family for cpu in PROFILES.values()}
        folders = [f for f in folders if f.rpartition("/")[2] not in families - {family}]
    return [p for folder in folders for p in sorted((PLC_DIR / folder).glob("*.st"))]


def _folder(ctx, param, value: str) -> str:
    """--out's folder: a blank one (`--out "$OUT"` with OUT unset) wrote the export into the
    current folder, among whatever is there."""
    if not value.strip():
        raise click.BadParameter("the folder is empty: give the folder to write into, e.g. --out gx2")
    return value


@click.command(name="export")
@click.argument("sources", nargs=-1, type=click.Path())
@click.option("--target", type=click.Choice(["gxworks2", "gxworks3"]), default=None,
              help="The engineering tool that will import the files. Required, unless --platform "
                   "names the CPU (its editor: gxworks3 for fx5u, gxworks2 for the others).")
@click.option("--out", "out_dir", type=click.Path(file_okay=False), required=True, callback=_folder,
              help="Folder for <POU>.st, <POU>.labels.tsv, GlobalLabels.labels.tsv, <Type>.struct.tsv and IMPORT_ORDER.txt.")
@click.option("--program", "programs", multiple=True, metavar="NAME",
              help="Write only this POU (usually your PROGRAM) and every function block, function and "
                   "structure it needs, with the global labels; repeat for more. Every source is still "
                   "checked. Default: every POU of the sources.")
@click.option("--platform", type=click.Choice(sorted(PROFILES), case_sensitive=False), default=None,
              help="Also check what is written against this CPU, as `uitamr check --platform` does "
                   "(devices, index registers, instructions): on an error nothing is written. Implies "
                   "--target; a --target whose editor does not program the CPU is refused. With no "
                   "SOURCES: the bundled library of this platform. Default: no CPU check.")
def command(sources: tuple[str, ...], target: str | None, out_dir: str, programs: tuple[str, ...],
            platform: str | None) -> None:
    """Write, per POU, the ST body and a tab-separated label table for GX Works.

    With no SOURCES: the bundled library (plc/core, the ports and the examples of the
    target editor's platforms, or of --platform's)."""
    from verifier.export import ExportError, NothingToExport, export_sources
    from verifier.export.needed import UnknownProgram
    from verifier.export.writer import DROPPED_TABLE, IMPORT_ORDER

    if platform is not None:
        target = platform_target(platform, target, "export")
    elif target is None:
        # click's own "Missing option '--target'. Choose from: gxworks2, gxworks3" hid that
        # naming the CPU will do
        raise click.UsageError("Missing option '--target' or '--platform': name the editor (--target gxworks2 "
                               "for FX3U/FX3G and Q, gxworks3 for FX5U) or the CPU, which implies it "
                               f"(--platform {', '.join(sorted(PROFILES))})")
    if sources:
        from verifier.verify.sources import is_pattern, pattern_files, pattern_matches

        # a pattern is expanded as `uitamr verify` expands it (cmd and PowerShell do not)
        unmatched = [s for s in sources if is_pattern(s) and not pattern_files(s)]
        # a symbolic link to nothing is not missing: it is refused below, as check refuses it
        missing = [s for s in sources if not Path(s).exists() and not Path(s).is_symlink() and not is_pattern(s)]
        if unmatched or missing:
            said = [f"{s!r} matches no file" for s in unmatched]  # as check and verify say it
            said += [f"no such file or folder: {', '.join(map(shown_name, missing))}"] if missing else []
            click.echo(f"uitamr export: {'; '.join(said)}", err=True)
            sys.exit(EXIT_USAGE)
        paths = expand_sources(sources)
        scenarios = [str(p) for p in paths if p.suffix.lower() == ".toml"]
        if scenarios:  # read as ST, a scenario's first key was "unexpected 'name'"
            more = f" and {len(scenarios) - 3} more" if len(scenarios) > 3 else ""
            click.echo(f"uitamr export: {', '.join(scenarios[:3])}{more}: a scenario (.toml), not ST source: "
                       "export writes the POUs of .st files; run scenarios with uitamr verify --scenario", err=True)
            sys.exit(EXIT_USAGE)
        # a folder that holds --out: the files of an earlier export there are not sources (bodies
        # without declarations: the second run of the same command failed on them)
        out = real_path(out_dir)
        folders = [real_path(f) for s in sources for f in (pattern_matches(s) if is_pattern(s) else [Path(s)])
                   if f.is_dir()]
        earlier = [p for p in paths if real_path(p).is_relative_to(out)] \
            if any(out != f and out.is_relative_to(f) for f in folders) else []
        if earlier:
            click.echo(f"uitamr export: {len(earlier)} file(s) in the --out folder {out_dir} left out of the "
                       "sources (an earlier export)", err=True)
            paths = [p for p in paths if p not in earlier]
        # refused as check refuses them: read as ST, an .il was "1:1: unexpected ';'", a capture
        # "'#' must follow a radix"; a pipe or a device was "1 unreadable file(s)", exit 1
        refuse_what_is_not_st("uitamr export", sources, paths)
    else:
        paths = bundled_sources(target, platform)
    if not paths:
        click.echo("uitamr export: no .st files to export", err=True)
        sys.exit(EXIT_USAGE)
    from verifier.st import read_source  # the one ST reader (UTF-8, else Shift-JIS)

    texts, unreadable = {}, []
    for p in paths:
        texts[p], problems = read_source(p)
        unreadable += problems
    if unreadable:
        for d in unreadable:
            click.echo(str(d), err=True)
        click.echo(f"uitamr export: nothing written, {len(unreadable)} unreadable file(s)", err=True)
        sys.exit(EXIT_ERRORS)
    notes: list = []
    warnings: list = []  # the CPU's (--platform), printed before whatever follows
    removed: list[Path] = []
    try:
        written = export_sources(paths, target, Path(out_dir), texts, notes=notes, programs=list(programs),
                                 cpu=PROFILES[platform] if platform else None, warnings=warnings,
                                 removed=removed)
    except NothingToExport as e:
        for d in e.diagnostics:
            click.echo(str(d), err=True)
        click.echo(f"uitamr export: nothing written, {len(e.diagnostics)} file(s) without a POU", err=True)
        sys.exit(EXIT_USAGE)
    except ExportError as e:
        for d in warnings + e.diagnostics:  # with --platform, the CPU's warnings among the errors
            click.echo(str(d), err=True)
        click.echo(f"uitamr export: nothing written, {sum(d.is_error for d in e.diagnostics)} error(s)", err=True)
        sys.exit(EXIT_ERRORS)
    except UnknownProgram as e:
        hint = "" if sources else _bundled_elsewhere(programs, paths)
        click.echo(f"uitamr export: nothing written: --program: {e}{hint}", err=True)
        sys.exit(EXIT_USAGE)
    except OSError as e:
        click.echo(f"uitamr export: cannot write {e.filename or out_dir}: {e.strerror or e}", err=True)
        sys.exit(EXIT_USAGE)
    for note in warnings + notes:
        click.echo(str(note), err=True)
    if sources:
        _warn_of_another_editor(tuple(paths), target)
    if removed:
        names = ", ".join(p.name for p in removed[:4]) + (f" and {len(removed) - 4} more" if len(removed) > 4 else "")
        click.echo(f"uitamr export: note: removed {len(removed)} file(s) of an earlier export into {out_dir} "
                   f"that this one does not hold: {names}", err=True)
    pous = sum(1 for p in written if p.suffix == ".st")
    click.echo(f"{pous} POU(s) exported for {target} into {out_dir} (import order: "
               f"{Path(out_dir) / IMPORT_ORDER})")
    if notes:
        click.echo(f"{len(notes)} initial value(s) not carried by the {target} label tables: "
                   f"see {Path(out_dir) / DROPPED_TABLE}")


def _bundled_elsewhere(programs: tuple[str, ...], exported: list[Path]) -> str:
    """For a --program of the bundled library that the chosen target or platform does not
    export (`--target gxworks2 --program UITAMR_ExampleFx5`, copied from the other import
    page), the platforms whose export holds it."""
    from verifier.bundled import library_file

    hints = []
    for name in programs:
        path = library_file(name)
        if path is None or path in exported:
            continue
        where = sorted((cpu for cpu in PROFILES if path in bundled_sources(platform_target(cpu, None, "export"), cpu)),
                       key=lambda cpu: (cpu == "fx3g", cpu))  # the FX3U, the library's first FX3
        if where:
            hints.append(f"{path.stem} is bundled for {', '.join(where)}: export it with "
                         f"--platform {where[0]}" + (f" (or {', '.join(where[1:])})" if where[1:] else ""))
    return "; " + "; ".join(hints) if hints else ""


def _warn_of_another_editor(paths: tuple[Path, ...], target: str) -> None:
    """A warning when the sources load only on CPUs another editor programs (FX5U sources,
    SM8561 and RS2, exported with --target gxworks2): the files are written, but their label
    tables are in the wrong editor's type names and that editor cannot open such a project."""
    from verifier.sim.cpu import EDITOR_NAMES, TARGET_CPUS
    from verifier.verify.platform import platforms_that_load

    fits, _ = platforms_that_load(paths)
    if not fits or any(platform in TARGET_CPUS[target] for platform in fits):
        return
    editors = sorted({editor for editor, cpus in TARGET_CPUS.items() for platform in fits if platform in cpus})
    click.echo(f"uitamr export: warning: the sources load on {', '.join(fits)} only, which "
               f"{' and '.join(EDITOR_NAMES[e] for e in editors)} programs, not {EDITOR_NAMES[target]}: "
               f"export them with --target {editors[0]}", err=True)
