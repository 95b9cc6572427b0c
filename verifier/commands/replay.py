"""`uitamr replay CAPTURE...`: the verifier's rules on a saved capture.

Reads our JSONL trace (`uitamr verify --trace`, `uitamr monitor --trace`) or a plain
capture (timestamped hex lines, docs/commissioning.md), runs it through the monitor's
framing and the eight rules, and writes the same reports. Exit status: 0 no finding,
1 findings, 2 a capture that cannot be read (named with file, line and column), 3 a
capture that holds no bytes (nothing was verified), 4 a monitor's trace whose end record
says its port went away (cut short: not the whole session).
"""
from __future__ import annotations

import sys
from dataclasses import replace
from pathlib import Path

import click

from verifier.commands.monitor import EXIT_UNUSABLE, _finish, exit_status, line_options, line_timing
from verifier.commands.protocol_options import given_settings, protocol_settings
from verifier.commands.report_files import (JudgingCommand, ReportError, check_folders, check_not_inputs,
                                             mistakes_junit, refused_report_junit, report_options, text_console)
from verifier.monitor.capture import CaptureError, read_capture
from verifier.monitor.framer import DEFAULT_TOLERANCE_US
from verifier.monitor.session import CaptureInfo, MonitorSession
from verifier.textfile import is_char_device
from verifier.verify.evidence import RuleOptions
from verifier.verify.result import CAPTURED_FROM_FILE, mistakes_of


@click.command("replay", cls=JudgingCommand, maker="uitamr replay",
               inputs_of=lambda params: params.get("captures") or ())
@click.argument("captures", nargs=-1, required=True, type=click.Path())
@line_options
@protocol_settings
@report_options
def command(captures, baud, line_format, tolerance, joined, reply_timeout, settings,
            json_path, junit_path, trace_path, html_path):
    """Re-check a saved trace or capture with the rules of `uitamr verify`."""
    console = text_console()
    try:
        check_folders(json_path, junit_path, trace_path, html_path)
        check_not_inputs(captures, json_path, junit_path, trace_path, html_path)
    except ReportError as exc:
        refused_report_junit(junit_path, exc, "uitamr replay", captures)
        raise click.UsageError(str(exc)) from None
    results = []
    for name in captures:
        path = Path(name)
        try:
            loaded = read_capture(path)
        except CaptureError as exc:
            if is_char_device(path):  # `uitamr replay /dev/ttyUSB0`: the port, not what was captured on it
                exc = CaptureError(exc.place, "", message=f"{exc}: a serial port, not a capture; `uitamr monitor --serial "
                                                     f"{name}` listens on it (replay reads the file its --capture wrote)")
            click.echo(f"uitamr replay: {exc}", err=True)
            mistakes_junit(junit_path, mistakes_of(exc), "uitamr replay")  # the CI server shows the mistake
            sys.exit(EXIT_UNUSABLE)
        is_trace = any(chunk.direction is not None for chunks in loaded.values() for chunk in chunks)
        # a monitor's trace says the tolerance its host times were judged with; other frames
        # that say their side (a verify trace, tx/rx lines) are exactly timed
        recorded = [chunk.tolerance_us for chunks in loaded.values() for chunk in chunks
                    if chunk.tolerance_us is not None]
        default = DEFAULT_TOLERANCE_US if not is_trace else max(recorded, default=0)
        verify_trace = is_trace and not recorded
        timing = line_timing(baud, line_format, tolerance, default)
        for capture_name, chunks in loaded.items():
            # a verify trace names its one run as its JUnit did, after the scenario; a monitor's
            # trace and a plain capture are named after their file
            info = CaptureInfo(capture_name if len(loaded) > 1 or verify_trace else path.name, str(path), CAPTURED_FROM_FILE,
                               line=f"{baud} {line_format}")
            recorded = chunks[-1].settings if chunks else None  # the end record's: overridden by options given
            run_settings = settings if recorded is None else replace(recorded, **given_settings(settings))
            session = MonitorSession(info, run_settings, _rule_options(chunks, reply_timeout), timing,
                                     from_power_on=not joined, signal_held=chunks[-1].signal_held if chunks else None,
                                     events=chunks[-1].events if chunks else ())
            for chunk in chunks:
                session.feed(chunk)
            if chunks and not chunks[-1].data:  # an end record, or a capture's `end` line: the run's end
                session.end_at(chunks[-1].t_us, chunks[-1].cut_short)
            session.close()
            results.append(session.result())
    _finish(results, console, json_path, junit_path, trace_path, html_path, "uitamr replay", captures)
    sys.exit(exit_status(results))


def _rule_options(chunks: list, reply_timeout_us: int | None) -> RuleOptions:
    """The rules' settings for one run of a capture: those its trace's end record says the
    run was judged with (a scenario's [rules] and [response_handling] within, a monitor's
    --reply-timeout), else the defaults; --reply-timeout, when given, over both."""
    recorded = dict(chunks[-1].rules) if chunks else {}
    if reply_timeout_us is not None:
        recorded["reply_timeout_us"] = reply_timeout_us
    return RuleOptions(**recorded)
