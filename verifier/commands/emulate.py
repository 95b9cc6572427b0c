"""``uitamr emulate``: the emulated robot on a real serial port or TCP socket, for bench
tests of a real PLC (docs/emulator.md)."""
from __future__ import annotations

import math
import os
import signal
import sys
import threading

import click

from verifier.amr import ConfigError, Fault, Robot, RobotConfig
from verifier.amr.config import BEFORE_STOP_POLICIES, PACING_POLICIES
from verifier.amr.schema import LARGEST
from verifier.emulate.assembler import DEFAULT_SILENCE_US
from verifier.emulate.core import Emulator
from verifier.emulate.faultfile import FaultFileError, load_fault_file
from verifier.emulate.ports import PortError, serve_serial, serve_tcp, t3_5_at
from verifier.commands.numbers import INT
from verifier.commands.protocol_options import protocol_settings
from verifier.digits import digit_problem
from verifier.serialports import serial_url_problem
from verifier.stopflag import StopFlag, put_back


def _tcp_endpoint(value: str) -> tuple[str, int]:
    if value.startswith("[") and value.endswith("]"):  # "[::1]" would read as host "[:" port "1]"
        raise click.BadParameter(f"the port is missing after the address, e.g. {value}:4001, got {value!r}",
                                 param_hint="--tcp")
    host, sep, port = value.rpartition(":")
    if not sep:
        host, port = "127.0.0.1", value
    if ":" in host and not (host.startswith("[") and host.endswith("]")):
        raise click.BadParameter(f"an IPv6 address goes in brackets, e.g. [::1]:4001, got {value!r}",
                                 param_hint="--tcp")
    host = host.strip("[]") or "127.0.0.1"
    if problem := digit_problem(port):
        raise click.BadParameter(f"the port {port!r}: {problem}", param_hint="--tcp")
    try:
        number = int(port)
    except ValueError:
        raise click.BadParameter(f"expected HOST:PORT or PORT, got {value!r}", param_hint="--tcp") from None
    if not 0 <= number <= 65535:
        raise click.BadParameter(f"port must be 0-65535, got {number}", param_hint="--tcp")
    return host, number


#: Serial speeds the emulator accepts: the standard rates from 300 to 230400 bit/s that
#: USB-RS-485 adapters offer (for a PLC set to another speed by mistake). The robot uses 9600.
STANDARD_BAUD_RATES = (300, 600, 1200, 2400, 4800, 9600, 19200, 38400, 57600, 115200, 230400)


def _baud(ctx: click.Context, param: click.Parameter, value: int) -> int:
    if value not in STANDARD_BAUD_RATES:
        raise click.BadParameter(
            f"{value} is not a standard serial speed; use one of "
            f"{', '.join(map(str, STANDARD_BAUD_RATES))} (the robot uses 9600)")
    return value


def _serial_url(ctx: click.Context, param: click.Parameter, value: str | None) -> str | None:
    if value is not None and "loop://" in value.lower():
        raise click.BadParameter(
            "loop:// sends every byte back to the port itself, so the robot would read its own "
            "replies as new requests (an FC06 reply echoes the request) and never hear a PLC; "
            "give a real port, a pty (socat) or socket://HOST:PORT")
    problem = serial_url_problem(value) if value is not None else None
    if problem:
        raise click.BadParameter(problem)
    return value


class _FiniteFloat(click.ParamType):
    """A number of seconds or milliseconds: finite (click's float takes "nan" and "inf")
    and within the range every setting keeps (verifier.amr.schema.LARGEST)."""

    name = "number"

    def convert(self, value, param, ctx):
        if isinstance(value, str) and (problem := digit_problem(value)):
            self.fail(problem, param, ctx)
        try:
            number = float(value)
        except (TypeError, ValueError):
            self.fail(f"{value!r} is not a number", param, ctx)
        if not math.isfinite(number):
            self.fail(f"{value!r} is not a finite number", param, ctx)
        if abs(number) > LARGEST:
            self.fail(f"{value!r} is out of range (at most {LARGEST:g} either way)", param, ctx)
        return number


FINITE = _FiniteFloat()
MIN_FRAME_GAP_MS = 0.001


def _exit_after(ctx: click.Context, param: click.Parameter, value: float | None) -> float | None:
    if value is not None and not 0 < value <= threading.TIMEOUT_MAX:
        raise click.BadParameter(f"must be a number of seconds greater than 0 "
                                 f"(and at most {threading.TIMEOUT_MAX:.0f}), got {value:g}")
    return value


def _request_number(value: str, option: str) -> tuple[int, str]:
    number, _, rest = value.partition(":")
    if problem := digit_problem(value):
        raise click.BadParameter(f"{value!r}: {problem}", param_hint=option)
    try:
        n = int(number)
    except ValueError:
        raise click.BadParameter(f"expected a request number, got {value!r}", param_hint=option) from None
    if n < 1:
        raise click.BadParameter(f"request numbers start at 1, got {n}", param_hint=option)
    return n, rest


def _only_request_number(value: str, option: str, kind: str) -> int:
    """N alone: these options take no :VALUE (3:7 would silently lose the 7)."""
    n, rest = _request_number(value, option)
    if rest or ":" in value:
        raise click.BadParameter(
            f"expected a request number N, got {value!r}; its other settings go in a fault "
            f"file ([[faults]] kind = \"{kind}\", on_request = {n}, ...)", param_hint=option)
    return n


def _fault(option: str, table: dict) -> Fault:
    try:
        return Fault.from_dict(table, option)
    except ConfigError as err:
        raise click.BadParameter(err.message, param_hint=option) from None


def _flag_faults(no_reply, bad_crc, garbage, wrong_address, exception, late,
                 anti_collision, off_tape, low_battery) -> list[Fault]:
    faults = []
    for option, kind, values in (("--no-reply-on", "no_reply", no_reply), ("--bad-crc-on", "bad_crc", bad_crc),
                                 ("--garbage-on", "garbage", garbage),
                                 ("--wrong-address-on", "wrong_address", wrong_address)):
        faults += [_fault(option, {"kind": kind, "on_request": _only_request_number(v, option, kind)})
                   for v in values]
    for value in exception:
        n, code = _request_number(value, "--exception-on")
        try:
            number = int(code or "4", 0)
        except ValueError:
            raise click.BadParameter(f"expected N[:CODE], got {value!r}", param_hint="--exception-on") from None
        faults.append(_fault("--exception-on", {"kind": "exception", "on_request": n, "code": number}))
    for value in late:
        n, ms = _request_number(value, "--late-reply-on")
        try:
            delay = float(ms)
        except ValueError:
            raise click.BadParameter(f"expected N:MS (request number and delay), got {value!r}",
                                     param_hint="--late-reply-on") from None
        faults.append(_fault("--late-reply-on", {"kind": "late_reply", "on_request": n, "delay_ms": delay}))
    for option, kind, values in (("--anti-collision-at", "anti_collision", anti_collision),
                                 ("--off-tape-at", "off_tape", off_tape),
                                 ("--low-battery-at", "low_battery", low_battery)):
        faults += [_fault(option, {"kind": kind, "at_s": s}) for s in values]
    return faults


def bare_arguments(args: list[str], port_given: bool) -> str | None:
    """What is wrong with words given without an option (this command takes options only),
    or None: a port typed without its option (`uitamr monitor /dev/ttyUSB0`, which click
    calls an "unexpected extra argument") is named with the option it needs."""
    if not args:
        return None
    if len(args) == 1 and not port_given:
        try:
            _tcp_endpoint(args[0])  # what --tcp takes (HOST:PORT, PORT), else a serial port's name
            option = "--tcp"
        except click.BadParameter:
            option = "--serial"
        return f"{args[0]!r} is given without its option: {option} {args[0]}"
    return f"unexpected argument{'s' if len(args) > 1 else ''} {' '.join(map(repr, args))}: the command takes options only"


@click.command("emulate", context_settings={"allow_extra_args": True})
@click.option("--serial", "serial_url", metavar="PORT", callback=_serial_url,
              help="Serial port or pyserial URL: /dev/ttyUSB0, COM3, socket://HOST:PORT, rfc2217://HOST:PORT "
                   "(not loop://).")
@click.option("--tcp", "tcp", metavar="HOST:PORT",
              help="Listen for raw RTU frames over TCP (PORT alone binds 127.0.0.1; port 0 = any free port).")
@click.option("--baud", type=INT, default=9600, show_default=True, callback=_baud,
              help="Serial speed, a standard rate 300-230400 (the robot uses 9600 8N1); --serial only.")
@protocol_settings
@click.option("--faults", "faults_file", type=click.Path(dir_okay=False), metavar="FILE.toml",
              help="Scripted faults ([[faults]]) and robot settings ([robot]).")
@click.option("--turnaround-ms", type=FINITE, help="Delay from the end of a request to the reply [5].")
@click.option("--point-duration-s", type=FINITE, help="How long a point/script run takes [8].")
@click.option("--pacing", type=click.Choice(PACING_POLICIES),
              help="Requests 250 ms or less apart: answer (default), ignore, or answer late.")
@click.option("--before-stop", type=click.Choice(BEFORE_STOP_POLICIES),
              help="Motion before the power-on stop command: ignore (default) or obey.")
@click.option("--no-reply-on", multiple=True, metavar="N", help="No reply to request N (repeatable).")
@click.option("--bad-crc-on", multiple=True, metavar="N", help="Corrupt the CRC of the reply to request N.")
@click.option("--garbage-on", multiple=True, metavar="N", help="Answer request N with garbage bytes.")
@click.option("--wrong-address-on", multiple=True, metavar="N", help="Answer request N from another address.")
@click.option("--exception-on", multiple=True, metavar="N[:CODE]", help="Answer request N with exception CODE [4].")
@click.option("--late-reply-on", multiple=True, metavar="N:MS", help="Answer request N MS milliseconds late.")
@click.option("--anti-collision-at", multiple=True, type=FINITE, metavar="S", help="Obstacle at S seconds (error 01).")
@click.option("--off-tape-at", multiple=True, type=FINITE, metavar="S", help="Leave the tape at S seconds (error 02).")
@click.option("--low-battery-at", multiple=True, type=FINITE, metavar="S", help="Battery warning from S seconds (error 03).")
@click.option("--frame-gap-ms", type=FINITE, default=DEFAULT_SILENCE_US / 1000, show_default=True,
              help="Silence that ends an incomplete frame on the wall clock (USB adapters deliver in chunks).")
@click.option("--exit-after", type=FINITE, metavar="S", callback=_exit_after,
              help="Stop by itself after S seconds (S > 0).")
@click.option("--quiet", is_flag=True, help="No live log, only the summary line.")
def command(serial_url, tcp, baud, settings, faults_file, turnaround_ms, point_duration_s, pacing,
            before_stop, no_reply_on, bad_crc_on, garbage_on, wrong_address_on, exception_on,
            late_reply_on, anti_collision_at, off_tape_at, low_battery_at, frame_gap_ms,
            exit_after, quiet):
    """Run the emulated robot on a serial port or a TCP socket until Ctrl-C.

    Every frame is logged with its time, direction (<- request, -> reply), hex bytes and
    meaning; robot events (tasks, faults, ignored commands) are marked **.
    """
    if problem := bare_arguments(click.get_current_context().args, serial_url is not None or tcp is not None):
        raise click.UsageError(problem)
    if (serial_url is None) == (tcp is None):
        raise click.UsageError("give exactly one of --serial PORT or --tcp HOST:PORT")
    context = click.get_current_context()
    if tcp is not None and context.get_parameter_source("baud") is not click.core.ParameterSource.DEFAULT:
        raise click.UsageError("--baud sets the speed of a --serial port; --tcp carries bytes without one")
    robot_table: dict = {}
    faults: list[Fault] = []
    if faults_file == "":  # `--faults "$FAULTS"` with FAULTS unset ran the bench test without its faults
        raise click.BadParameter("the file's name is empty (a variable of the script that is not set?): give "
                                 "the fault file", param_hint="--faults")
    if faults_file:
        try:
            loaded = load_fault_file(faults_file, settings.address)
        except FaultFileError as err:
            raise click.BadParameter(str(err), param_hint="--faults") from None
        robot_table, faults = dict(loaded.robot), list(loaded.faults)
    flags = (("turnaround_ms", "--turnaround-ms", turnaround_ms),
             ("point_duration_s", "--point-duration-s", point_duration_s),
             ("pacing", "--pacing", pacing), ("before_stop", "--before-stop", before_stop))
    for key, option, value in flags:
        if value is None:
            continue
        try:
            RobotConfig.from_dict({key: value})
        except ConfigError as err:
            raise click.BadParameter(err.message, param_hint=option) from None
        robot_table[key] = value
    # Every key was checked on its own (file keys with their line, options with their
    # name); together they cannot fail.
    config = RobotConfig.from_dict(robot_table)
    faults += _flag_faults(no_reply_on, bad_crc_on, garbage_on, wrong_address_on, exception_on,
                           late_reply_on, anti_collision_at, off_tape_at, low_battery_at)
    if frame_gap_ms < MIN_FRAME_GAP_MS:  # the assemblers count whole µs: less rounds to none
        raise click.BadParameter(f"must be at least {MIN_FRAME_GAP_MS:g} (1 µs), got {frame_gap_ms:g}; "
                                 f"the default is {DEFAULT_SILENCE_US / 1000:g}", param_hint="--frame-gap-ms")
    endpoint = _tcp_endpoint(tcp) if tcp is not None else None

    log_closed = False

    def log_anyway(line: str) -> None:
        # A reader that leaves (`uitamr emulate ... | head`) must not take the robot off
        # the line in the middle of a bench test, nor lose the summary: the log goes to
        # /dev/null from then on and the summary to stderr.
        nonlocal log_closed
        if log_closed:
            return
        try:
            click.echo(line)
            sys.stdout.flush()
        except BrokenPipeError:
            log_closed = True
            devnull = os.open(os.devnull, os.O_WRONLY)
            os.dup2(devnull, sys.stdout.fileno())
            os.close(devnull)

    def log(line: str) -> None:
        if not quiet:
            log_anyway(line)

    # no reply before t3.5 at the line's speed (TCP: the robot's 9600 line behind the converter);
    # a serial port is opened 8N1 at --baud (ports.serve_serial)
    t3_5_us = t3_5_at(baud)
    emulator = Emulator(Robot(settings, config, faults), log, t3_5_us=t3_5_us, read_at=f"{baud} 8N1")
    if config.turnaround_us < t3_5_us:  # raised without a word, the bench's timings puzzled
        emulator.note(f"replies start {t3_5_us / 1000:g} ms after a request, not {config.turnaround_ms:g} ms: "
                      f"never sooner than t3.5 at {baud} bit/s")
    for fault in faults:
        emulator.note(f"scripted fault: {fault.describe()}")
    stop = StopFlag()  # set in a signal handler: no lock (verifier/stopflag.py)

    def on_signal(signum, _frame) -> None:
        stop.set()

    previous = {sig: signal.signal(sig, on_signal) for sig in (signal.SIGINT, signal.SIGTERM)}
    timer = threading.Timer(exit_after, stop.set) if exit_after is not None else None
    if timer is not None:
        timer.daemon = True
        timer.start()
    silence_us = round(frame_gap_ms * 1000)
    try:
        if endpoint is None:
            serve_serial(serial_url, emulator, stop, silence_us, baud)
        else:
            # with --quiet the live log is off, but a client needs the port (port 0 = any)
            serve_tcp(endpoint[0], endpoint[1], emulator, stop, silence_us,
                      on_listening=(lambda host, port: log_anyway(f"listening on tcp {host}:{port}")) if quiet else None)
    except PortError as err:
        if err.in_use:
            log_anyway(emulator.summary())  # what it did before the port failed
        click.echo(f"uitamr emulate: {err}", err=True)
        # a mistake on the command line (the port's name, one in use): exit 2, as monitor's;
        # a port that failed while serving (the adapter unplugged): 1
        sys.exit(1 if err.in_use else 2)
    finally:
        if timer is not None:
            timer.cancel()
        put_back(previous)
    log_anyway(emulator.summary())
    if log_closed:
        click.echo(f"{emulator.summary()} (the log's reader closed stdout; the robot kept serving "
                   "until the stop)", err=True)
