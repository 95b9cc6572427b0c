"""The `uitamr` command: a thin click face over the verifier package.

Each sub-command lives in its own module `verifier.commands.<name>` and exposes a click
command object called `command`; modules are imported only when their command runs, so
`uitamr frame` does not pay for the ST parser or the simulator.
"""
from __future__ import annotations

import importlib
import io
import sys

import click

from verifier import __version__
from verifier.stopflag import AS_PROGRAM
from verifier.textfile import UNENCODABLE

SUBCOMMANDS = {
    "verify": "Run PLC programs against the emulated robot and check the traffic.",
    "check": "Parse and type-check GX Works structured text.",
    "frame": "Print or decode the exact bytes of a robot command.",
    "emulate": "Run the emulated robot on a real serial port or TCP socket.",
    "monitor": "Listen on a real line and check its traffic against the rules, live.",
    "replay": "Check a saved trace or capture against the rules.",
    "export": "Write paste-ready ST bodies and label tables for GX Works.",
}


#: the exit status of a command stopped by Ctrl-C before it finished (128 + SIGINT); the
#: program's entry point says it of a Ctrl-C during this module's own import
from verifier.entry import EXIT_INTERRUPTED, interrupted  # noqa: E402


class UnusablePath(click.ClickException):
    """A path given on the command line that cannot be used; exit status 2, as for
    every other unusable input."""

    exit_code = 2

    @classmethod
    def of(cls, exc: OSError) -> UnusablePath:
        """The error of an OSError about a path the user gave: the path and what is wrong."""
        return cls(f"{exc.filename}: {exc.strerror or exc}")


class LazyGroup(click.Group):
    def __call__(self, *args, **kwargs):
        # `uitamr` as a program (its console script, python -m verifier.cli); click's CliRunner
        # and other in-process callers call .main() and keep their own Ctrl-C handling
        AS_PROGRAM.set()
        return super().__call__(*args, **kwargs)

    def list_commands(self, ctx: click.Context) -> list[str]:
        return list(SUBCOMMANDS)

    def get_command(self, ctx: click.Context, name: str) -> click.Command | None:
        if name not in SUBCOMMANDS:
            return None
        module = importlib.import_module(f"verifier.commands.{name}")
        return module.command

    def make_context(self, info_name, args, parent=None, **extra):
        given = list(args)  # the parser uses up the list it reads
        try:
            return super().make_context(info_name, args, parent, **extra)
        except click.UsageError as error:  # `uitamr --bogus verify --junit report.xml`
            if not extra.get("resilient_parsing"):
                self._junit_of_mistake(error, info_name, given, parent)
            raise

    def resolve_command(self, ctx: click.Context, args: list[str]):
        # the name as typed, for the Ctrl-C message of `invoke`: `ctx.invoked_subcommand` is
        # set only once the command's module is imported (`get_command`), and Ctrl-C in that
        # import (a loaded PC takes a second or more) said `uitamr None: interrupted`
        ctx.meta["uitamr.command"] = args[0] if args else None
        try:
            return super().resolve_command(ctx, args)
        except click.UsageError as error:  # `uitamr verfy --junit report.xml`
            if not ctx.resilient_parsing:
                self._junit_of_mistake(error, ctx.info_name, args, ctx.parent)
            raise

    def _junit_of_mistake(self, error: click.UsageError, info_name, args: list[str], parent) -> None:
        """A mistake in `uitamr`'s own part of the command line (an option it does not have, a
        command it does not know) exits 2 with click's usage message, as ever; when the
        sub-command's arguments name a --junit file, the mistake is also written there as the
        judging commands write their own (`JudgingCommand`): CI publishes that file, and
        showed an earlier run's report or none. The sub-command is the first word click's
        resilient parse leaves after `uitamr`'s options; one that `uitamr` does not know is
        read for the report options alone (all three judging commands spell --junit so),
        and its JUnit is named after it as typed."""
        from verifier.commands.report_files import JudgingCommand, report_options

        ctx = self.context_class(self, info_name=info_name, parent=parent, resilient_parsing=True,
                                 ignore_unknown_options=True)
        with ctx:
            try:
                rest = click.Command.parse_args(self, ctx, list(args))  # not Group's: keeps the name in
            except click.ClickException:
                return
            # `uitamr` has flags only: each word click let through before the command's name is an
            # option it does not know (`--bogus`), not a value
            words = iter(rest)
            name = next((word for word in words if not word.startswith("-")), None)
            if name is None:
                return
            command = self.get_command(ctx, name) if name in SUBCOMMANDS else \
                click.command(name, cls=JudgingCommand, maker=f"uitamr {name}")(report_options(lambda **_: None))
            if isinstance(command, JudgingCommand):
                command.usage_error_junit(error, name, list(words), ctx)

    def invoke(self, ctx: click.Context):
        try:
            return super().invoke(ctx)
        except KeyboardInterrupt:
            # Ctrl-C in `uitamr replay` of a long capture (or a verify) was click's "Aborted!"
            # and exit 1, which these commands' callers read as "findings". 130 = 128 + SIGINT,
            # as the shell reports a program that Ctrl-C stopped. (monitor and emulate take
            # Ctrl-C as their stop and finish their reports or summary.)
            name = ctx.invoked_subcommand or ctx.meta.get("uitamr.command")
            click.echo(interrupted(name), err=True)
            sys.exit(EXIT_INTERRUPTED)
        except OSError as exc:
            # A path the file system refuses (a name too long, a folder that cannot be read,
            # a symlink loop) is the user's to fix: say which, never a traceback. An OSError
            # without a file name is not about a path the user gave, and stays one.
            if exc.filename is None:
                raise
            raise UnusablePath.of(exc) from None

    def format_commands(self, ctx: click.Context, formatter: click.HelpFormatter) -> None:
        with formatter.section("Commands"):
            formatter.write_dl(list(SUBCOMMANDS.items()))


@click.group(cls=LazyGroup, context_settings={"help_option_names": ["-h", "--help"]})
@click.version_option(__version__, prog_name="uitamr")
def main() -> None:
    """UITAMR PLC toolkit: verify, check, frame, emulate, monitor, replay and export."""
    # A file name that is not UTF-8 (b"\xfe.st" from a Shift-JIS or Big5 share) holds lone
    # surrogates, which a UTF-8 stdout with strict errors (a UTF-8 locale other than C, a
    # pipe, PYTHONIOENCODING) cannot print: `uitamr check` ended in a traceback. Such
    # characters are printed as stderr prints them ("\udcfe"), in the reports too.
    for stream in (sys.stdout, sys.stderr):
        if isinstance(stream, io.TextIOWrapper) and stream.errors == "strict":
            stream.reconfigure(errors=UNENCODABLE)


if __name__ == "__main__":  # pragma: no cover
    main()
