"""The report files every judging command writes (`verify`, `monitor`, `replay`): one set
of options, one writer loop, so a capture from site gives the same files as a CI run."""
from __future__ import annotations

import errno
import io
import os
import stat
import sys
from pathlib import Path

import click
from rich.console import Console
from rich.markup import escape

from verifier.textfile import real_path


class _ReportConsole(Console):
    """A console whose reader may go away (`uitamr verify --json r.json | head -1`): the
    rest of the text is dropped, and the command goes on to write its report files and
    exit with its verdict (rich's own console exits at once, and the reports were lost)."""

    def on_broken_pipe(self) -> None:
        self.quiet = True
        stream = sys.stderr if self.stderr else sys.stdout
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, stream.fileno())  # the interpreter's last flush finds nothing to fail on
        os.close(devnull)


def text_console(**options) -> Console:
    """The console the judging commands print on: no syntax highlighting, long lines kept
    whole, and no emoji codes (a location such as 'Main.st:100:9' holds one, ':100:')."""
    return _ReportConsole(highlight=False, soft_wrap=True, emoji=False, **options)


class ReportPath(click.Path):
    """A report's file: not a name that begins with '-', which is the next option taken for
    the file left out (`--junit --duration 5q` wrote a report named "--duration"), nor an
    empty one (`--junit "$REPORT"` with REPORT unset), which wrote no report and said nothing."""

    def __init__(self):
        super().__init__(dir_okay=False)

    def convert(self, value, param, ctx):
        if isinstance(value, str) and value.startswith("-"):
            self.fail(f"{value!r} is an option, not a file: give the report's file first "
                      f"(./{value} for a file of that name)", param, ctx)
        if value == "":
            self.fail("the file's name is empty (a variable of the CI script that is not set?): give the "
                      "file to write", param, ctx)
        return super().convert(value, param, ctx)


REPORT_OPTIONS = (
    click.option("--json", "json_path", type=ReportPath(), help="Write the verdict as JSON."),
    click.option("--junit", "junit_path", type=ReportPath(),
                 help="Write JUnit XML (one testcase per scenario or capture)."),
    click.option("--trace", "trace_path", type=ReportPath(), help="Write every frame as JSON Lines."),
    click.option("--html", "html_path", type=ReportPath(),
                 help="Write a self-contained HTML report with a timing diagram."),
)


def report_options(command):
    for option in reversed(REPORT_OPTIONS):
        command = option(command)
    return command


class ReportError(Exception):
    """A report file that cannot be written; the message names it, `paths` holds the report
    paths it refuses (both of two reports given one file)."""

    def __init__(self, message: str, *paths: str):
        super().__init__(message)
        self.paths = paths


def check_folders(*paths: str | None) -> None:
    """Refuse before any work when a report's folder does not exist, or when two reports
    are to go to the same file (the second would silently replace the first)."""
    seen: dict[Path, str] = {}
    for path in paths:
        if not path:
            continue
        try:
            os.stat(path)
        except OSError as exc:  # a name too long for the file system, a symlink loop: no file can be written there
            if exc.errno in (errno.ENAMETOOLONG, errno.ELOOP):
                raise ReportError(f"cannot write {path}: {exc.strerror}", path) from None
        resolved = real_path(path)
        if not resolved.parent.is_dir():
            what = "is a file, not a folder" if resolved.parent.exists() else "does not exist"
            raise ReportError(f"cannot write {path}: the folder {resolved.parent} {what}", path)
        if resolved in seen:
            raise ReportError(f"{seen[resolved]} and {path} are the same file: give each report a file of its own",
                              seen[resolved], path)
        seen[resolved] = path


def check_not_inputs(inputs, *paths: str | None,
                     what: str = "one of the run's input files: write the report to another file") -> None:
    """Refuse a report that would be written over one of the run's own input files (a
    scenario, an ST source, a capture): the input would be lost. `what` says what the
    inputs are and what to do ("PATH is WHAT"); the first path refused is the error's."""
    if not any(paths):
        return
    resolved = {real_path(p) for p in inputs}
    for path in paths:
        if path and real_path(path) in resolved:
            raise ReportError(f"{path} is {what}", path)


def _not_over_other_content(path: Path) -> None:
    """Refuse to replace a file that holds something else than XML: the input files of a
    run that could not start are known only as far as it got (the ST a broken scenario
    file names is not), so its JUnit report is never written over text that is no report."""
    try:
        if not stat.S_ISREG(path.stat().st_mode):
            # a folder, a device, a pipe (opened to read, it would wait for a writer: a hang): writing
            # it says what is wrong, or hands the report to the pipe's reader
            return
        with path.open("rb") as existing:
            head = existing.read(64).lstrip(b"\xef\xbb\xbf \t\r\n")
    except OSError:
        return  # no such file, or one that cannot be read: writing it says what is wrong
    if head and not head.startswith(b"<"):
        raise ReportError(f"{path} exists and holds no XML (an input file?): write the report to another file",
                          str(path))


def junit_of_mistakes(junit_path, mistakes: list, command: str, inputs=(), results=()) -> tuple[bool, str]:
    """For a run that cannot start (exit 2): its mistakes (`result.Mistake`, each with its
    place) written to --junit's file as errors (`report_junit.unusable_element`), so that a
    CI server shows what to fix rather than no report or the last run's; never over one of
    the run's input files (`inputs`, as far as they are known). `results`: the runs done
    before the mistake, kept in the file beside it. Returns whether it was written and the
    line that says so, or why not."""
    from verifier.verify import report_junit

    try:
        check_not_inputs(inputs, junit_path)
        _not_over_other_content(Path(junit_path))
        report_junit.write_unusable(mistakes, Path(junit_path), command, results)
    except ReportError as exc:
        return False, f"the JUnit report was not written: {exc}"
    except OSError as exc:
        return False, f"the JUnit report was not written: cannot write {junit_path}: {exc.strerror or exc}"
    if results:
        these = "this error as a test case" if len(mistakes) == 1 else "these errors as test cases"
        return True, f"wrote {junit_path} (the runs' results, and {these})"
    return True, f"wrote {junit_path} (these errors as test cases)"


def junit_of_refused_report(junit_path, errors: ReportError | list[ReportError], command: str, inputs=(),
                            results=()) -> tuple[bool, str] | None:
    """For a run that exits 2 because other reports than the JUnit cannot be written (a
    folder that does not exist, two reports given one file, a report over an input file, a
    full disk; `uitamr monitor`'s capture too): those mistakes written to --junit's file as
    errors, as `junit_of_mistakes` does, so that a CI server does not show an earlier run's
    file as this one's; `results` (reports that failed after the runs) stay in it beside the
    errors. None when there is no --junit or a refused path is its own; else what
    `junit_of_mistakes` returns."""
    from verifier.verify.result import Mistake

    errors = [errors] if isinstance(errors, ReportError) else list(errors)
    if not junit_path or any(real_path(path) == real_path(junit_path) for error in errors for path in error.paths):
        return None
    return junit_of_mistakes(junit_path, [Mistake(str(error)) for error in errors], command, inputs, results)


def mistakes_junit(junit_path, mistakes: list, command: str, inputs=()) -> None:
    """For exit 2 before a session (a line that cannot be opened, a capture that cannot be
    read, a mistake in the command line): the mistakes in --junit's file, when one is given
    (not over one of `inputs`), and a line on stderr that says so or why not."""
    if junit_path:
        click.echo(f"{command}: {junit_of_mistakes(junit_path, mistakes, command, inputs)[1]}", err=True)


def usage_mistake(error: click.UsageError):
    """A mistake in the command line as its JUnit test case says it: click's message (it
    names the option: "Invalid value for '--duration': ...") on the first line, then the
    usage and help lines click prints above it on stderr."""
    from verifier.verify.result import Mistake

    shown = io.StringIO()
    error.show(shown)
    usage = shown.getvalue().rstrip().removesuffix(f"Error: {error.format_message()}").rstrip()
    return Mistake(f"{error.format_message()}\n\n{usage}" if usage else error.format_message())


def usage_error_junit(junit_path, error: click.UsageError, command: str, inputs=()) -> click.UsageError:
    """`error`, for its caller to raise (click shows it and exits 2), after it was written to
    --junit's file as `usage_mistake` says it, when a file is given (not over `inputs`)."""
    mistakes_junit(junit_path, [usage_mistake(error)], command, inputs)
    return error


class JudgingCommand(click.Command):
    """A command that writes the judging reports (`verify`, `monitor`, `replay`). A mistake
    in its command line (an unknown option, `--duration 5q`, an option without its value, a
    --platform that is none) exits 2 with click's usage message as before, and is also
    written to --junit's file as an error test case when the arguments give one, as click
    reads them: a CI server shows the mistake, not an earlier run's report or none. `maker`:
    the command as the report names it; `inputs_of`: the input files the parsed values
    name (the JUnit is not written over them)."""

    def __init__(self, *args, maker: str, inputs_of=lambda params: (), **kwargs):
        super().__init__(*args, **kwargs)
        self.maker, self.inputs_of = maker, inputs_of

    def make_context(self, info_name, args, parent=None, **extra):
        given = list(args)  # the parser uses up the list it reads
        try:
            return super().make_context(info_name, args, parent, **extra)
        except click.UsageError as error:
            if not extra.get("resilient_parsing"):
                self.usage_error_junit(error, info_name, given, parent, extra)
            raise

    def invoke(self, ctx: click.Context):
        try:
            return super().invoke(ctx)
        except OSError as exc:
            # a path the file system refuses where the command did not expect it (a name too
            # long, a symlink loop): `uitamr`'s own message and exit 2 (UnusablePath), and the
            # JUnit of it, as for every other unusable input
            if exc.filename is None:
                raise
            from verifier.cli import UnusablePath
            from verifier.verify.result import Mistake

            error = UnusablePath.of(exc)
            mistakes_junit(ctx.params.get("junit_path"), [Mistake(error.message)], self.maker,
                           self.inputs_of(ctx.params))
            raise error from None

    def usage_error_junit(self, error: click.UsageError, info_name, args, parent, extra=None) -> None:
        """`error` (this command's, or that of `uitamr` before it: `uitamr --bogus verify`)
        written to the --junit file `args`, this command's arguments, give, when they give one."""
        params = self._values_despite_mistakes(info_name, list(args), parent, extra or {})
        usage_error_junit(params.get("junit_path"), error, self.maker, self.inputs_of(params))

    def _values_despite_mistakes(self, info_name, args, parent, extra) -> dict:
        """The values click reads from `args` when it passes over what it cannot use (click's
        resilient parsing, as for shell completion, with unknown options let through): an
        empty dict when even that fails (`--junit` without its file)."""
        try:
            ctx = super().make_context(info_name, args, parent,
                                       **{**extra, "resilient_parsing": True, "ignore_unknown_options": True})
        except click.UsageError:
            return {}
        return ctx.params


def refused_report_junit(junit_path, errors: ReportError | list[ReportError], command: str, inputs=(),
                         results=()) -> None:
    """For exit 2 from other reports than the JUnit (a refused path, one that cannot be
    written): those mistakes in --junit's file, and a line on stderr that says so or why not."""
    junit = junit_of_refused_report(junit_path, errors, command, inputs, results)
    if junit is not None:
        click.echo(f"{command}: {junit[1]}", err=True)


def write_reports(results, console: Console, json_path=None, junit_path=None, trace_path=None,
                  html_path=None, command: str = "uitamr verify") -> None:
    """The report files asked for; `command` (`uitamr monitor`, `uitamr replay`) is named
    in those that name their maker (JSON's tool, the JUnit suite, the page's heading)."""
    from functools import partial

    from verifier.verify import report_html, report_json, report_junit, report_trace

    writers = ((json_path, partial(report_json.write, command=command)),
               (junit_path, partial(report_junit.write, command=command)),
               (trace_path, report_trace.write),  # the frames alone: a trace names no maker
               (html_path, partial(report_html.write, command=command)))
    for path, write in writers:
        if path:
            try:
                write(results, Path(path))
            except OSError as exc:
                raise ReportError(f"cannot write {path}: {exc.strerror or exc}", path) from None
            console.print(f"[dim]wrote {escape(str(path))}[/]")
