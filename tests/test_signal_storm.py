"""Ctrl-C pressed again and again while `uitamr monitor` or `uitamr emulate` stops (an
impatient user, or a supervisor that repeats its signal).

Their handlers set a `threading.Event`, whose `set` takes a lock: a signal that came while
an earlier handler held it ran a handler that waited for that lock for ever (the earlier one
cannot go on under it), and each further signal nested one more. Under a burst of SIGINT the
monitor hung or died of RecursionError before writing its report in 10 runs of 10, the
emulator hung in 1 of 10. The stop flag they set now takes no lock (verifier/stopflag.py).

Signals that came after the command had put the interpreter's handlers back (its reports
written) ended the process during its shutdown: by SIGINT (status 130) in 19 runs of 20 for
the monitor and 20 of 20 for the emulator, some with "Exception ignored in atexit callback
... KeyboardInterrupt ... lost sys.stderr", so the exit status that says the verdict
(the monitor's 3 for a silent line, the emulator's 0) was lost with nothing left to stop.
The `uitamr` program now ignores Ctrl-C once its handlers are put back (stopflag.put_back):
the tests hold each run to the command's own exit status and a stderr without a traceback.
"""
from __future__ import annotations

import json
import signal
import socket
import subprocess
import sys
import time

from monitor_helpers import WAIT_S
import procs

ATTEMPTS = 3
BURST_S = 0.5
#: a moment for the command to wait in its read, where a user's Ctrl-C finds it: each
#: signal then interrupts the wait and runs the handler (a burst ends the loop at once, and
#: with it the burst, if the first signal comes before the loop has started)
LISTENING_S = 0.3


def _burst_of_ctrl_c(process: subprocess.Popen) -> None:
    """SIGINT as fast as the test can send it, for BURST_S or until the process ends."""
    end = time.monotonic() + BURST_S
    while process.poll() is None and time.monotonic() < end:
        process.send_signal(signal.SIGINT)


def _ended(process: subprocess.Popen) -> str:
    """The process's stderr once it ended; a hang fails the test after WAIT_S."""
    try:
        _out, err = procs.finish(process, WAIT_S)
    except subprocess.TimeoutExpired as hung:  # its process group is killed
        raise AssertionError(f"still running {WAIT_S} s after a burst of Ctrl-C: {hung.stderr[-2000:]}") from None
    for noise in ("RecursionError", "Traceback", "KeyboardInterrupt", "Exception ignored"):
        assert noise not in err, err[-2000:]
    return err


def test_the_monitor_stops_under_a_burst_of_ctrl_c_and_writes_its_report(tmp_path):
    with socket.create_server(("127.0.0.1", 0)) as server:
        server.settimeout(WAIT_S)
        port = server.getsockname()[1]
        for attempt in range(ATTEMPTS):
            report = tmp_path / f"m{attempt}.json"
            monitor = procs.spawn(
                [sys.executable, "-m", "verifier.cli", "monitor", "--tcp", f"127.0.0.1:{port}", "--json", str(report)],
                stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
            connection, _ = server.accept()
            with connection:
                assert "Ctrl-C stops" in monitor.stdout.readline()  # its handlers are in place
                time.sleep(LISTENING_S)
                _burst_of_ctrl_c(monitor)
                err = _ended(monitor)
            assert json.loads(report.read_text())["verdict"] == "no-traffic"
            assert monitor.returncode == 3, err  # its verdict's status, NO TRAFFIC, not SIGINT's


def test_the_emulator_stops_under_a_burst_of_ctrl_c():
    for _attempt in range(ATTEMPTS):
        emulator = procs.spawn([sys.executable, "-m", "verifier.cli", "emulate", "--tcp", "127.0.0.1:0"],
                               stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        assert "listening on tcp" in emulator.stdout.readline()  # its handlers are in place
        time.sleep(LISTENING_S)
        _burst_of_ctrl_c(emulator)
        err = _ended(emulator)
        assert emulator.returncode == 0, err  # emulator.md: Ctrl-C stops it with status 0


def test_a_command_run_in_process_gives_the_caller_its_ctrl_c_back():
    """Only the `uitamr` program ignores Ctrl-C once its reports are written: a Python caller
    (click's CliRunner here) gets its own handler back, or Ctrl-C would stop nothing after."""
    from click.testing import CliRunner

    from verifier.cli import main

    before = signal.getsignal(signal.SIGINT)
    with socket.create_server(("127.0.0.1", 0)) as server:
        port = server.getsockname()[1]
        result = CliRunner().invoke(main, ["monitor", "--tcp", f"127.0.0.1:{port}", "--duration", "200ms"])
    assert result.exit_code == 3, result.output
    assert signal.getsignal(signal.SIGINT) is before
