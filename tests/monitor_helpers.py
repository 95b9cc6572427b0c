"""Shared pieces of the monitor/replay tests: real processes on a pty line, a bad master."""
from __future__ import annotations

import json
import os
import select
import subprocess
import sys
import threading
import time
from collections import Counter
from pathlib import Path

from linebus import LineBus
from verifier import protocol
from verifier.amr import Robot
import procs

SETTINGS = protocol.DEFAULT_SETTINGS
WAIT_S = 20


def frame(*words: str) -> bytes:
    return protocol.encode(protocol.command_from_words(list(words), 1), SETTINGS)


def uitamr(*args) -> list[str]:
    return [sys.executable, "-m", "verifier.cli", *map(str, args)]


def start(*args, **kw) -> subprocess.Popen:
    return procs.spawn(uitamr(*args), stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, **kw)


def wait_for_line(proc: subprocess.Popen, words: str, timeout_s: float = WAIT_S, seen: list[str] | None = None) -> str:
    """Read the process's stdout until a line holds `words` (it has started, it has seen a
    frame). A process that shows no such line in `timeout_s` is killed, and the failure
    says what it printed. The lines read (the one found too) are added to `seen` if given.
    (This waited with select() on the pipe: lines that came in one write with the one read
    were already in the reader's buffer, not the pipe, and were never looked at; and its
    failure then read stderr to the end, so a process that ran on hung the test instead
    of failing it.)"""
    seen = [] if seen is None else seen
    watchdog = threading.Timer(timeout_s, procs.kill_group, (proc,))
    watchdog.start()
    try:
        for line in iter(proc.stdout.readline, ""):
            seen.append(line)
            if words in line:
                return line
    finally:
        watchdog.cancel()
    proc.wait(timeout=timeout_s)
    raise AssertionError(f"no line with {words!r} within {timeout_s} s (exit {proc.returncode}, killed when "
                         f"negative); got {''.join(seen)!r}, stderr {proc.stderr.read()!r}")


class Master:
    """A PLC stand-in on the line's PLC end: writes requests at chosen times, reads replies.

    Like the PLC it stands for it sends one request at a time: it waits for the reply (up
    to the reply time-out) before it sends the next. It waited 200 ms only: a robot the
    host stalled longer answered after the next request had gone out, and the monitor
    rightly found UITAMR-ONE-AT-A-TIME and UITAMR-HALF-DUPLEX on a line the test had
    not meant to make.

    It also notes when the host stalled the run (`stalls`): when it woke up late for a
    request (a reply that came late makes it late for the next one), or a reply it waited
    for did not come (the emulator was not run). `sent_at` holds when each request was
    written (monotonic seconds); `log` what it did and saw, with times, for a failure's
    message (`report`).

    With a `robot` (the emulator's own model, verifier.amr.Robot) the master answers for
    the robot itself: each reply goes on the line from the robot's end (LineBus.from_robot)
    right after its request, from this thread, so a host stall delays request and reply
    together and the gaps between requests are the ones the test wrote. A `uitamr emulate`
    process the host stalled 230 ms or more answered so late that the next request, sent
    after the reply, no longer broke the pacing: the wire was not the one the test meant."""

    LATE_S = 0.05  # what the tests allow the host (the monitor's --tolerance)
    REPLY_TIMEOUT_S = 0.5  # the rules' reply time-out (docs/verifier.md)

    def __init__(self, line: LineBus, robot: Robot | None = None):
        self.fd = os.open(line.plc, os.O_RDWR | os.O_NOCTTY)  # the replies come here
        self.write = line.from_plc  # the requests go on the line from here (LineBus.from_plc)
        self.line, self.robot = line, robot
        self.t0 = self.start = time.monotonic()
        self.sent_at: list[float] = []
        self.stalls: list[str] = []
        self.log: list[str] = []

    def report(self) -> str:
        """What the master did and measured, for an assertion's message."""
        return ("master (times from its start): " + "; ".join(self.log)
                + "\nhost stalls measured: " + ("; ".join(self.stalls) or "none"))

    def at(self, t_s: float) -> None:
        """Wait until `t_s` after the start. A master that is late (a loaded host) moves
        the rest of its schedule by as much, so the gaps it was given never shrink: a late
        request followed by one on time would break the pacing the test sets out to keep."""
        target = self.t0 + t_s
        now = time.monotonic()
        if now < target:
            time.sleep(target - now)
            now = time.monotonic()
        if now - target > self.LATE_S:
            self.stalls.append(f"woke {(now - target) * 1000:.0f} ms late for the request at {t_s:.3f} s")
        self.t0 += now - target if now > target else 0.0

    def send(self, data: bytes, reply_length: int | None = 8, timeout_s: float = REPLY_TIMEOUT_S) -> bytes:
        self.sent_at.append(time.monotonic())
        self.write(data)
        self.log.append(f"{self.sent_at[-1] - self.start:.3f} s wrote {data.hex(' ')}")
        if self.robot is not None:
            return self._answer(data)
        got = b""
        deadline = time.monotonic() + timeout_s
        while reply_length and len(got) < reply_length and time.monotonic() < deadline:
            ready, _, _ = select.select([self.fd], [], [], 0.01)
            if ready:
                got += os.read(self.fd, 64)
        if reply_length:
            self.log.append(f"{len(got)} reply bytes after {(time.monotonic() - self.sent_at[-1]) * 1000:.0f} ms")
        if reply_length and len(got) < reply_length:
            self.stalls.append(f"{len(got)} of {reply_length} reply bytes within {timeout_s * 1000:.0f} ms "
                               f"of request {len(self.sent_at)}")
        return got

    def _answer(self, request: bytes) -> bytes:
        """The in-process robot's reply to `request`, on the line at once (none: silence).
        Its clock is the line's: the request ended its time at 9600 baud after it was written."""
        end_us = round((self.sent_at[-1] - self.start) * 1_000_000) + protocol.frame_time_us(len(request))
        reply = self.robot.on_request(request, end_us)
        if reply is None:
            self.log.append("the robot stays silent")
            return b""
        self.line.from_robot(reply.data)
        self.log.append(f"{time.monotonic() - self.start:.3f} s the robot answered {reply.data.hex(' ')}")
        return reply.data

    def close(self) -> None:
        os.close(self.fd)


def bad_master(line: LineBus, robot: Robot | None = None) -> Master:
    """First command not stop, 100 ms pacing, one bad CRC: the findings of issue 10. The
    master, for what it measured (`Master.report`); with a `robot` it answers for it
    (`Master`), else a robot on the line does."""
    master = Master(line, robot)
    try:
        run_point = frame("run-point", "1")
        read = frame("read", "task")
        stop = frame("stop")
        bad_stop = stop[:-1] + bytes([stop[-1] ^ 0x01])
        master.at(0.0)
        master.send(run_point)      # not the stop command
        master.at(0.1)
        master.send(read)           # 100 ms after the previous request
        master.at(0.2)
        master.send(read)           # 100 ms again
        master.at(0.3)
        master.send(bad_stop, reply_length=None)  # 100 ms again, and a wrong CRC: no reply
        master.at(0.95)
        master.send(stop)
        master.at(1.6)  # 650 ms after the stop: a stalled relay must not make it a PACING finding
        master.send(read)
    finally:
        master.close()
    return master


BAD_MASTER_FINDINGS = {"UITAMR-POWERON-STOP": 1, "UITAMR-PACING": 3, "UITAMR-CRC": 1}


def diagnosis(out: str, err: str, capture: Path | None = None, master: Master | None = None) -> str:
    """All a failed real-time run can say, for an assertion's message: the monitor's output
    (every frame and finding with its time), its stderr (a traceback exits 1 too, as
    findings do), the chunks it read with their host times, and what the master measured."""
    parts = [out, f"--- monitor stderr ---\n{err or '(empty)'}"]
    if capture is not None:
        text = capture.read_text(encoding="utf-8") if capture.exists() else "(not written)"
        parts.append(f"--- capture {capture.name} ---\n{text}")
    if master is not None:
        parts.append(master.report())
    return "\n".join(parts)


def findings(report: Path) -> Counter:
    data = json.loads(report.read_text(encoding="utf-8"))
    return Counter(v["rule"] for scenario in data["scenarios"] for v in scenario["violations"])
