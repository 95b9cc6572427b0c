"""`uitamr monitor --serial PORT | --tcp HOST:PORT`: the verifier's rules on a real line.

Listens (never transmits), splits the bytes into RTU frames, tells requests from replies,
decodes them and applies the eight rules of `uitamr verify` while the line runs; Ctrl-C
or `--duration` stops it and writes the same reports as `verify` (and `--capture FILE`,
the plain capture `uitamr replay` reads). Exit status: 0 no finding, 1 findings, 2 the
port or an option is unusable, 3 no traffic: not a byte was seen, so nothing was verified,
4 cut short: the port went away before the session's end, and its frames broke no rule.
docs/commissioning.md.
"""
from __future__ import annotations

import signal
import sys
import time
from pathlib import Path

import click
from rich.console import Console
from rich.markup import escape

from verifier import protocol
from verifier.commands.emulate import STANDARD_BAUD_RATES, _tcp_endpoint, bare_arguments
from verifier.commands.protocol_options import protocol_settings
from verifier.commands.report_files import (JudgingCommand, ReportError, ReportPath, check_folders,
                                             check_not_inputs, mistakes_junit, refused_report_junit, report_options,
                                             text_console, usage_error_junit, write_reports)
from verifier.commands.verify import _Duration
from verifier.monitor.capture import format_plain, tolerance_hides_pacing
from verifier.monitor.framer import DEFAULT_TOLERANCE_US, LineTiming
from verifier.monitor.session import CaptureInfo, MonitorSession
from verifier.monitor.sources import SerialSource, SourceError, TcpSource, now_us
from verifier.monitor.view import MonitorView
from verifier.serialports import serial_url_problem
from verifier.stopflag import StopFlag, put_back
from verifier.verify.evidence import RuleOptions
from verifier.verify.result import CUT_SHORT, NO_TRAFFIC, Mistake, overall_verdict

EXIT_CLEAN, EXIT_FINDINGS, EXIT_UNUSABLE, EXIT_NO_TRAFFIC, EXIT_CUT_SHORT = 0, 1, 2, 3, 4
#: how often the rules judge what the line has settled since the last time
CHECK_EVERY_S = 0.5


class _Tolerance(_Duration):
    """--tolerance: below the pacing period. At 250 ms or more UITAMR-PACING cannot find a
    violation at all (a period plus the tolerance must be 250 ms or less), nor the other
    timing rules most: a mistyped unit (`20s` for `20ms`) would pass a PLC pacing at 100 ms."""

    def convert(self, value, param, ctx):
        us = super().convert(value, param, ctx)
        if tolerance_hides_pacing(us):
            self.fail(f"{value!r} is not below the pacing period of {protocol.MIN_PERIOD_US // 1000} ms: with it no "
                      "UITAMR-PACING violation could be found. A USB adapter needs its latency timer "
                      f"(16 ms by default: the default {DEFAULT_TOLERANCE_US // 1000}ms covers it); was the unit "
                      "mistyped?", param, ctx)
        return us


def line_options(command):
    """Options shared by monitor and replay: the line's timing, the tolerance, power-on."""
    options = (
        click.option("--baud", type=click.Choice([str(b) for b in STANDARD_BAUD_RATES]), default="9600",
                     show_default=True, help="Line speed (the robot uses 9600)."),
        click.option("--framing", "line_format", type=click.Choice(["8N1", "8E1", "8O1", "8N2"]), default="8N1",
                     show_default=True, help="Data bits, parity, stop bits (the robot uses 8N1)."),
        click.option("--tolerance", type=_Tolerance(zero_ok=True),
                     help="How far host timestamps may be off (USB adapter latency): timing rules "
                          f"blame only what is beyond it. Default {DEFAULT_TOLERANCE_US // 1000}ms "
                          "(replay of a capture whose frames say their side - a verify trace, tx/rx lines: 0; "
                          "of a monitor trace: the tolerance it was recorded with)."),
        click.option("--joined", is_flag=True,
                     help="The capture began after the PLC's power-on: do not judge UITAMR-POWERON-STOP."),
        click.option("--reply-timeout", type=_Duration(),
                     help="The PLC's reply time-out (UITAMR-ONE-AT-A-TIME, UITAMR-RESPONSE-HANDLING). "
                          f"Default {protocol.DEFAULT_REPLY_TIMEOUT_US // 1000}ms (replay of a trace: the time-out "
                          "its end record says the run was judged with)."),
    )
    for option in reversed(options):
        command = option(command)
    return command


def line_timing(baud: str, line_format: str, tolerance_us: int | None, default_tolerance_us: int) -> LineTiming:
    bits = 1 + 8 + (0 if line_format[1] == "N" else 1) + int(line_format[2])
    return LineTiming(int(baud), bits, default_tolerance_us if tolerance_us is None else tolerance_us)


@click.command("monitor", cls=JudgingCommand, maker="uitamr monitor", context_settings={"allow_extra_args": True})
@click.option("--serial", "serial_url", metavar="PORT",
              help="Serial port or pyserial URL to listen on: /dev/ttyUSB0, COM3, socket://HOST:PORT, rfc2217://...")
@click.option("--tcp", "tcp", metavar="HOST:PORT", help="A TCP server that streams the line's bytes (converter route).")
@line_options
@protocol_settings
@click.option("--duration", type=_Duration(), help="Stop by itself after this long, e.g. 10min (default: Ctrl-C).")
@click.option("--capture", "capture_path", type=ReportPath(),
              help="Also write the raw chunks as a plain capture (for `uitamr replay` and tickets).")
@report_options
@click.option("--quiet", is_flag=True, help="Findings only, not every frame.")
def command(serial_url, tcp, baud, line_format, tolerance, joined, reply_timeout, settings, duration,
            capture_path, json_path, junit_path, trace_path, html_path, quiet):
    """Listen on the robot's line and check every frame and gap against the manual, live."""
    # refused as click refuses an option (its usage message, exit 2), and in --junit's file too
    ctx = click.get_current_context()
    if problem := bare_arguments(ctx.args, serial_url is not None or tcp is not None):
        raise usage_error_junit(junit_path, click.UsageError(problem, ctx), "uitamr monitor")
    if (serial_url is None) == (tcp is None):
        mistake = click.UsageError("give exactly one of --serial PORT or --tcp HOST:PORT", ctx)
        raise usage_error_junit(junit_path, mistake, "uitamr monitor")
    problem = serial_url_problem(serial_url) if serial_url is not None else None
    if problem:
        raise usage_error_junit(junit_path, click.BadParameter(problem, ctx, param_hint="--serial"), "uitamr monitor")
    try:  # `--capture /dev/ttyUSB0`: the capture's text went out onto the robot's line
        check_not_inputs([serial_url] if serial_url is not None else [], junit_path, capture_path, json_path,
                         trace_path, html_path, what="the port the monitor listens on, and the monitor never writes "
                                                     "to the line: give a file for the report or the capture")
    except ReportError as exc:  # --junit first: when it is the port, the mistake is not written there
        junit = None if junit_path in exc.paths else junit_path
        raise usage_error_junit(junit, click.UsageError(str(exc), ctx), "uitamr monitor") from None
    console = text_console()
    try:
        check_folders(json_path, junit_path, trace_path, html_path, capture_path)
    except ReportError as exc:
        refused_report_junit(junit_path, exc, "uitamr monitor")
        raise click.UsageError(str(exc)) from None
    timing = line_timing(baud, line_format, tolerance, DEFAULT_TOLERANCE_US)
    try:
        if serial_url is not None:
            parity = {"N": "N", "E": "E", "O": "O"}[line_format[1]]
            source = SerialSource(serial_url, int(baud), 8, parity, int(line_format[2]))
            channel = "rs485"
        else:
            host, port = _tcp_endpoint(tcp)
            source = TcpSource(host, port)
            channel = "tcp"
    except SourceError as exc:  # the line cannot be opened: the JUnit says so, not the last run's results
        click.echo(f"uitamr monitor: {exc}", err=True)
        mistakes_junit(junit_path, [Mistake(str(exc))], "uitamr monitor")
        sys.exit(EXIT_UNUSABLE)
    info = CaptureInfo(f"monitor {source.description}", source.description, channel, line=f"{baud} {line_format}")
    if reply_timeout is None:
        reply_timeout = protocol.DEFAULT_REPLY_TIMEOUT_US
    session = MonitorSession(info, settings, RuleOptions(reply_timeout_us=reply_timeout), timing,
                             from_power_on=not joined)
    stop, said_stopping = StopFlag(), StopFlag()  # set in a signal handler: no lock (verifier/stopflag.py)

    def on_signal(_signum, _frame) -> None:
        # a second Ctrl-C while the reports were being written (a moment, on a long session)
        # lost them all but the capture, in a KeyboardInterrupt: it waits for them instead
        if stop.is_set() and not said_stopping.is_set():
            said_stopping.set()
            click.echo("uitamr monitor: stopping: the reports and the capture are being written", err=True)
        stop.set()

    previous = {sig: signal.signal(sig, on_signal) for sig in (signal.SIGINT, signal.SIGTERM)}
    started = time.monotonic()
    deadline = None if duration is None else started + duration / 1_000_000
    lost: str | None = None
    # a serial port is listened on; a TCP stream is read from a server it connected to
    doing = "reading, connected to" if channel == "tcp" else "listening on"
    console.print(f"[dim]{doing} {escape(source.description)} ({baud} {line_format}, tolerance "
                  f"{timing.tolerance_us / 1000:g} ms); Ctrl-C stops[/]")
    console.file.flush()
    try:
        try:
            with MonitorView(console, settings, source.description, quiet) as view:
                next_check = time.monotonic() + CHECK_EVERY_S
                while not stop.is_set() and (deadline is None or time.monotonic() < deadline):
                    try:
                        chunk = source.read()
                    except SourceError as exc:
                        lost = str(exc)
                        break
                    view.frames(session.feed(chunk) if chunk is not None else session.poll(now_us()))
                    if time.monotonic() >= next_check:
                        view.findings(session.check())
                        next_check = time.monotonic() + CHECK_EVERY_S
                view.frames(session.close())
                view.findings(session.check())
        finally:
            source.close()
        if lost:
            console.print(f"[yellow]stopped: {escape(lost)}[/]")
        listened_us = round((time.monotonic() - started) * 1_000_000)
        if deadline is not None and not stop.is_set() and not lost:
            # ended by --duration: it listened that long. A host that ran the monitor late
            # (a loaded PC) let it notice the deadline late; that delay was no listening, and
            # "no bytes were seen in 1.1 s" for --duration 1s told the engineer otherwise
            listened_us = duration
        if lost:
            session.went_away(listened_us, duration)
        result = session.result(listened_us=listened_us)
        if lost:
            result.notes.append(f"the capture ended early: {lost}")
        failed: list[ReportError] = []
        try:
            failed += _reports([result], console, json_path, junit_path, trace_path, html_path, "uitamr monitor")
        finally:
            # the capture is the line's only record (the reports can be made again from it by
            # `uitamr replay`): it is written even when a report cannot be
            if capture_path:
                comment = f"uitamr monitor capture of {source.description}, {baud} {line_format}"
                if lost:
                    comment += f"\nthe capture ended early: {lost}"
                text = format_plain(session.chunks, comment, end_us=session.last_us if session.chunks else None)
                try:
                    Path(capture_path).write_text(text, encoding="utf-8")
                except OSError as exc:
                    failed.append(ReportError(f"cannot write the capture {capture_path}: {exc.strerror or exc}",
                                              capture_path))
                    click.echo(f"uitamr monitor: {failed[-1]}", err=True)
                else:
                    console.print(f"[dim]wrote {escape(str(capture_path))}[/]")
        if failed:  # exit 2: --junit's file says why, after the session's test case
            refused_report_junit(junit_path, failed, "uitamr monitor", (), [result])
            sys.exit(EXIT_UNUSABLE)
        sys.exit(exit_status([result]))
    finally:  # the handlers stay until the reports and the capture are written
        put_back(previous)


def exit_status(results) -> int:
    """The exit status of the overall verdict: findings first (1); else a capture that saw
    nothing (3): it verified nothing; else one cut short (4): not the whole session; else 0."""
    return {"fail": EXIT_FINDINGS, NO_TRAFFIC: EXIT_NO_TRAFFIC, CUT_SHORT: EXIT_CUT_SHORT,
            "pass": EXIT_CLEAN}[overall_verdict(results)]


def _finish(results, console: Console, json_path, junit_path, trace_path, html_path, command: str,
            inputs=()) -> None:
    """The console report, then the report files, which name `command` as their maker; exit 2
    when one cannot be written, with that mistake in --junit's file."""
    failed = _reports(results, console, json_path, junit_path, trace_path, html_path, command)
    if failed:
        refused_report_junit(junit_path, failed, command, inputs, results)
        sys.exit(EXIT_UNUSABLE)


def _reports(results, console: Console, json_path, junit_path, trace_path, html_path,
             command: str) -> list[ReportError]:
    """The console report, then the report files; the report that could not be written (said
    on stderr), if one could not."""
    from verifier.verify import report_console

    report_console.render(results, console)
    try:
        write_reports(results, console, json_path, junit_path, trace_path, html_path, command)
    except ReportError as exc:
        click.echo(f"{command}: {exc}", err=True)
        return [exc]
    return []
