"""``uitamr emulate`` on real ports: a socat pty pair driven by mbpoll (libmodbus, an
independent master), and TCP driven by a pymodbus client and a raw socket.

Every subprocess has a timeout and is always cleaned up; TCP binds 127.0.0.1 port 0.
No wall-clock time is asserted: waits are bounded polls for what must appear.
"""
from __future__ import annotations

import errno
import os
import queue
import random
import re
import shutil
import signal
import socket
import subprocess
import sys
import threading
import time
import warnings
from pathlib import Path

import pytest
import serial
from pymodbus.client import ModbusTcpClient
from pymodbus.framer import FramerType

from linebus import LineBus, pty_cable
from verifier.protocol import STOP_FRAME, ControlRequest, Query, StatusRequest, encode, with_crc
import procs

pytestmark = pytest.mark.serial

STATUS_TASK = encode(StatusRequest(1, Query.TASK))
STATUS_REQUEST_HEAD = "01 01 00"  # how the emulator logs an FC01 status request of address 1
RUN_POINT_3 = encode(ControlRequest(1, 1, 3))
WAIT_S = 15  # upper bound for anything to show up; never a measured time


class EmulatorProcess:
    """``python -m verifier.cli emulate ...`` with its log lines collected as they come."""

    def __init__(self, *args: str) -> None:
        self.proc = procs.spawn(
            [sys.executable, "-m", "verifier.cli", "emulate", *args],
            stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, bufsize=1,
            env={**os.environ, "PYTHONUNBUFFERED": "1"},
        )
        self.lines: list[str] = []
        self.came_at: list[float] = []  # when each of `lines` reached this process (monotonic s)
        self.matched_came_at = 0.0  # when the line wait_for last found did
        self.resent = 0  # status requests read_status sent again after a host stall
        self._queue: queue.Queue[tuple[float, str] | None] = queue.Queue()
        threading.Thread(target=self._pump, daemon=True).start()

    def _pump(self) -> None:
        for line in self.proc.stdout:
            self._queue.put((time.monotonic(), line.rstrip("\n")))
        self._queue.put(None)

    def wait_for(self, pattern: str, timeout: float = WAIT_S, since: float = 0.0) -> re.Match:
        """The first log line (old or new) matching ``pattern``; with `since`, the first that
        reached the test at or after that time (monotonic s) (`matched_came_at` says when)."""
        regex = re.compile(pattern)
        for line, came in zip(self.lines, self.came_at):
            if came >= since and (m := regex.search(line)):
                self.matched_came_at = came
                return m
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            try:
                item = self._queue.get(timeout=0.1)
            except queue.Empty:
                continue
            if item is None:
                break
            self.came_at.append(item[0])
            self.lines.append(item[1])
            if item[0] >= since and (m := regex.search(item[1])):
                self.matched_came_at = item[0]
                return m
        raise AssertionError(f"no log line matching {pattern!r}; log so far:\n" + "\n".join(self.lines))

    def test_clock(self, dated_s: float) -> float:
        """The test's clock (monotonic s) when the emulator's clock read `dated_s` (the time
        its log lines begin with), by the line that reached the test soonest after the
        emulator dated it: later by that line's trip through the pipe (ms), never earlier,
        whatever stalled this test's process when other lines came."""
        offsets = [came - float(m.group(1)) for line, came in zip(self.lines, self.came_at)
                   if (m := re.match(r" *(\d+\.\d{3}) s  ", line))]
        return dated_s + min(offsets)

    def stop(self, sig: int = signal.SIGTERM) -> tuple[int, str]:
        """Signal it, wait for it to exit; (exit code, last line)."""
        if self.proc.poll() is None:
            self.proc.send_signal(sig)
        try:
            code = self.proc.wait(timeout=WAIT_S)
        finally:
            self.kill()
        self.wait_for(r"uitamr emulate: stopped", timeout=5)
        return code, self.lines[-1]

    def kill(self) -> None:
        if self.proc.poll() is None:
            procs.kill_group(self.proc)
            self.proc.wait(timeout=WAIT_S)


@pytest.fixture
def start_emulator():
    started: list[EmulatorProcess] = []

    def start(*args: str) -> EmulatorProcess:
        process = EmulatorProcess(*args)
        started.append(process)
        process.wait_for(r"listening on")
        return process

    yield start
    for process in started:
        process.kill()


@pytest.fixture
def pty_pair(tmp_path: Path):
    """Two linked ptys from socat: (robot side, master side)."""
    assert shutil.which("socat"), "socat is required (apt-get install socat)"
    robot_end, master_end = tmp_path / "robot", tmp_path / "master"
    proc = procs.spawn(
        ["socat", f"pty,raw,echo=0,link={robot_end}", f"pty,raw,echo=0,link={master_end}"],
        stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
    )
    try:
        deadline = time.monotonic() + WAIT_S
        while not (robot_end.exists() and master_end.exists()):
            assert proc.poll() is None, "socat exited"
            assert time.monotonic() < deadline, "socat made no ptys"
            time.sleep(0.02)
        yield str(robot_end), str(master_end)
    finally:
        proc.terminate()
        try:
            proc.wait(timeout=WAIT_S)
        except subprocess.TimeoutExpired:
            procs.kill_group(proc)
            proc.wait(timeout=WAIT_S)


def mbpoll(port: str, *args: str, values: tuple[str, ...] = ()) -> subprocess.CompletedProcess:
    """mbpoll once against ``port``; written values come after the device name."""
    assert shutil.which("mbpoll"), "mbpoll is required (apt-get install mbpoll)"
    return procs.run(
        ["mbpoll", "-m", "rtu", "-b", "9600", "-P", "none", "-a", "1", "-o", "3", "-1", *args, port, *values],
        capture_output=True, text=True, timeout=WAIT_S,
    )


def coils(result: subprocess.CompletedProcess, first: int) -> list[int]:
    """The 22 coil values from mbpoll's ``[ref]: v`` lines (mbpoll labels them by reference,
    ``first`` to ``first + 21``)."""
    found = {int(n): int(v) for n, v in re.findall(r"^\[(\d+)\]:\s+(\d+)", result.stdout, re.M)}
    assert sorted(found) == list(range(first, first + 22)), result.stdout
    return [found[first + i] for i in range(22)]


#: mbpoll's reply time-out in `mbpoll` (its -o)
MBPOLL_TIMEOUT_S = 3


def read_status(port: str, query: int, emulator: EmulatorProcess) -> tuple[int, int]:
    """(error, value) read by mbpoll from the `emulator` that answers on `port`: coils 9-16
    of the 22 carry the error byte, 17-22 the value.

    mbpoll's -r is 1-based, so query parameter P is ``-r P+1``.

    A read that timed out because the host held the emulator back runs again (3 reads at
    most): the emulator's own log dates its reply to the request more than mbpoll's time-out
    after mbpoll started (`EmulatorProcess.test_clock`, so a stall of this test's process
    does not count). Such a late reply is then read off the line, or the next exchange would
    take it for its own, and `emulator.resent` counts the request sent again. (Seen: the
    emulator SIGSTOPped 3.5 s as a test read the status: 'Connection timed out'.) A request
    the emulator did not answer, or answered in time, fails at once; so do three stalled
    reads (a host too loaded, or an emulator that answers late every time).
    """
    stalled = []
    for _attempt in range(3):
        started = time.monotonic()
        result = mbpoll(port, "-t", "0", "-r", str(query + 1), "-c", "22")
        if result.returncode == 0:
            break
        assert "timed out" in result.stderr, result.stdout + result.stderr + "\n".join(stalled)
        late = _late_reply(emulator, started)
        if late is None:
            break
        late_s, reply = late
        stalled.append(f"the emulator's reply is dated {late_s * 1000:.0f} ms after mbpoll started")
        with serial.Serial(port, 9600, timeout=WAIT_S) as line:  # the late reply: not the next exchange's
            line.read(len(reply))
        emulator.resent += 1
    else:
        pytest.fail("every status read timed out while the host held the emulator back (or the emulator "
                    "answers late every time): " + "; ".join(stalled))
    assert result.returncode == 0, (result.stdout + result.stderr + "\n".join(stalled) + "\nthe emulator's log:\n"
                                    + "\n".join(emulator.lines[-12:]))
    if stalled:  # shown in the run's warnings summary: how often the host got in the way
        warnings.warn("host stalls before the status read: " + "; ".join(stalled))
    bits = coils(result, query + 1)
    assert not any(bits[:8])
    error = sum(bits[8 + i] << i for i in range(8))
    value = sum(bits[16 + i] << i for i in range(6))
    return error, value


def _late_reply(emulator: EmulatorProcess, started: float) -> tuple[float, bytes] | None:
    """When (s after `started`, this test's clock) the emulator dated its reply to the status
    request mbpoll sent at `started`, and the reply, if after mbpoll's time-out; None when it
    read none, did not answer it or answered in time (a failure that is not the host's).
    Waits for the emulator to have read the request and settled it: a stalled emulator reads
    it late."""
    try:
        emulator.wait_for(rf"<- {STATUS_REQUEST_HEAD}", since=started)
        answer = emulator.wait_for(r"^ *(\d+\.\d{3}) s  (-> ((?:[0-9A-F]{2} )+)|\*\* fault)",
                                   since=emulator.matched_came_at)
    except AssertionError:  # nothing read, or read and never settled: what the log says is the failure's
        return None
    if answer.group(3) is None:
        return None
    dated = emulator.test_clock(float(answer.group(1))) - started
    return (dated, bytes.fromhex(answer.group(3))) if dated > MBPOLL_TIMEOUT_S else None


def write_command(port: str, code: int, command: int) -> subprocess.CompletedProcess:
    """FC06 with the command in the register address: register 0xCCDD is ``-r`` 0xCCDD+1."""
    return mbpoll(port, "-t", "4", "-r", str((code << 8 | command) + 1), values=("0",))


# ---- serial: mbpoll over a socat pty pair ------------------------------------------------------

def test_mbpoll_writes_stop_and_reads_every_status(pty_pair, start_emulator):
    robot_end, master_end = pty_pair
    emulator = start_emulator("--serial", robot_end)
    result = write_command(master_end, 0x01, 0xA0)
    assert result.returncode == 0 and "Written 1 references" in result.stdout
    emulator.wait_for(r"<- 01 06 01 A0 00 00 88 14  stop \(01/A0\)")
    emulator.wait_for(r"-> 01 06 01 A0 00 00 88 14")
    assert read_status(master_end, Query.TASK, emulator) == (0, 0)
    emulator.wait_for(r"<- 01 01 00 00 00 16 BD C4  read task status")
    assert read_status(master_end, Query.SPEED, emulator) == (0, 0)
    assert write_command(master_end, 0x02, 3).returncode == 0  # trackless speed stage 4
    assert read_status(master_end, Query.SPEED, emulator) == (0, 3)
    code, summary = emulator.stop()
    assert code == 0
    frames = 5 + emulator.resent  # a status request the host stalled was sent again
    assert f"{frames} frames in, {frames} replies out" in summary, summary


def test_a_second_emulator_on_the_same_port_is_refused(pty_pair, start_emulator):
    """Two emulators on one port took turns at the requests; the second now refuses."""
    robot_end, master_end = pty_pair
    first = start_emulator("--serial", robot_end)
    second = run_cli("--serial", robot_end, "--exit-after", "5")
    assert second.returncode == 2  # a mistake on the command line, as monitor's on a held port
    assert f"cannot open serial port {robot_end}: another program has it locked" in second.stderr
    assert "Traceback" not in second.stderr
    assert read_status(master_end, Query.TASK, first) == (0, 0)  # the first still answers
    assert first.stop()[0] == 0


def test_a_port_a_monitor_holds_is_refused_naming_the_monitor(pty_pair):
    """On the bench a `uitamr monitor` left on the adapter holds the port as a second
    emulator would; the refusal used to ask only "another uitamr emulate?", sending the
    user to look for an emulator that was not running."""
    robot_end, _ = pty_pair
    monitor = procs.spawn([sys.executable, "-m", "verifier.cli", "monitor", "--serial", robot_end,
                                "--duration", "60s", "--quiet"],
                          stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                          env={**os.environ, "PYTHONUNBUFFERED": "1"})
    try:
        assert "listening on" in monitor.stdout.readline()
        refused = run_cli("--serial", robot_end, "--exit-after", "5")
        assert refused.returncode == 2
        assert (f"cannot open serial port {robot_end}: another program has it locked (another uitamr "
                "emulate, or a uitamr monitor?)") in refused.stderr, refused.stderr
    finally:
        monitor.send_signal(signal.SIGINT)
        try:
            monitor.wait(timeout=WAIT_S)
        except subprocess.TimeoutExpired:
            procs.kill_group(monitor)
            monitor.wait(timeout=WAIT_S)


def test_mbpoll_sees_a_task_run_and_an_anti_collision_stop(pty_pair, start_emulator):
    robot_end, master_end = pty_pair
    emulator = start_emulator("--serial", robot_end, "--point-duration-s", "600")
    assert write_command(master_end, 0x01, 0xA0).returncode == 0
    assert write_command(master_end, 0x01, 3).returncode == 0
    assert read_status(master_end, Query.TASK, emulator) == (0, 1)
    emulator.stop()
    emulator = start_emulator("--serial", robot_end, "--anti-collision-at", "0")
    assert read_status(master_end, Query.VEHICLE, emulator) == (1, 1)
    assert emulator.stop()[0] == 0


def test_a_manual_stop_taken_as_the_power_on_stop_is_logged_as_such(pty_pair, start_emulator):
    """With --manual-stop-counts-as-stop the first 05/00 is the power-on stop, and the robot
    then obeys motion commands; the log said only "ignored: ... not in manual mode", so the
    point run that followed seemed to start without any stop."""
    robot_end, master_end = pty_pair
    emulator = start_emulator("--serial", robot_end, "--manual-stop-counts-as-stop")
    assert write_command(master_end, 0x05, 0x00).returncode == 0
    emulator.wait_for(r"\*\* command: manual move stop moving: the power-on stop; not in manual mode, "
                      r"nothing to stop$")
    assert not [line for line in emulator.lines if "** ignored" in line], emulator.lines
    assert write_command(master_end, 0x01, 3).returncode == 0
    emulator.wait_for(r"\*\* task: run point/script 3: started")
    assert emulator.stop()[0] == 0


def test_mbpoll_gets_illegal_function_and_the_next_request_is_still_answered(pty_pair, start_emulator):
    robot_end, master_end = pty_pair
    emulator = start_emulator("--serial", robot_end)
    result = mbpoll(master_end, "-t", "3", "-r", "1", "-c", "1")  # FC04: not the robot's
    assert "Illegal function" in result.stdout + result.stderr
    emulator.wait_for(r"-> 01 84 01 ")
    assert read_status(master_end, Query.TASK, emulator) == (0, 0)


def test_mbpoll_times_out_on_a_scripted_no_reply_then_recovers(pty_pair, start_emulator):
    robot_end, master_end = pty_pair
    emulator = start_emulator("--serial", robot_end, "--no-reply-on", "1")
    result = mbpoll(master_end, "-t", "0", "-r", "1", "-c", "22")
    assert "timed out" in (result.stdout + result.stderr).lower()
    emulator.wait_for(r"\*\* fault: request 1: no_reply")
    assert read_status(master_end, Query.TASK, emulator) == (0, 0)


def test_a_status_read_the_host_stalls_past_mbpolls_time_out_is_read_again(pty_pair, start_emulator):
    """The host stops the emulator (SIGSTOP) longer than mbpoll's 3 s time-out while mbpoll
    reads the status: the read is the host's, not the emulator's, so it runs again; and the
    reply the emulator then gives late is not taken by the next exchange (mbpoll read it:
    the run command failed, and the status read after it got the command's echo)."""
    robot_end, master_end = pty_pair
    emulator = start_emulator("--serial", robot_end, "--point-duration-s", "600")
    assert write_command(master_end, 0x01, 0xA0).returncode == 0
    os.kill(emulator.proc.pid, signal.SIGSTOP)
    resume = threading.Timer(MBPOLL_TIMEOUT_S + 1, os.kill, (emulator.proc.pid, signal.SIGCONT))
    resume.start()
    try:
        with pytest.warns(UserWarning, match="host stalls before the status read"):
            assert read_status(master_end, Query.TASK, emulator) == (0, 0)
    finally:
        resume.cancel()
        os.kill(emulator.proc.pid, signal.SIGCONT)
    ran = write_command(master_end, 0x01, 3)
    assert ran.returncode == 0, ran.stdout + ran.stderr
    assert read_status(master_end, Query.TASK, emulator) == (0, 1)
    assert emulator.resent == 1
    code, summary = emulator.stop()
    assert code == 0 and "5 frames in, 5 replies out" in summary, summary


def test_a_status_read_the_emulator_leaves_unanswered_fails_though_reads_are_run_again(pty_pair, start_emulator):
    """A read that timed out is run again only when the emulator's own log dates its reply
    past mbpoll's time-out: a request it read in time and did not answer fails at once."""
    robot_end, master_end = pty_pair
    emulator = start_emulator("--serial", robot_end, "--no-reply-on", "1")
    with pytest.raises(AssertionError, match="Connection timed out"):
        read_status(master_end, Query.TASK, emulator)
    assert emulator.resent == 0
    emulator.wait_for(r"\*\* fault: request 1: no_reply")


def test_serial_survives_noise_truncated_frames_and_floods(pty_pair, start_emulator):
    robot_end, master_end = pty_pair
    emulator = start_emulator("--serial", robot_end)
    rng = random.Random(7)
    with serial.Serial(master_end, 9600, timeout=WAIT_S) as port:
        port.write(b"\xff")  # one noise byte, then a silence, then a request
        port.flush()
        emulator.wait_for(r"<- FF  invalid frame")
        port.write(STOP_FRAME)
        assert port.read(8) == STOP_FRAME
        port.write(STATUS_TASK[:5])  # truncated frame: ended by the silence, ignored
        port.flush()
        time.sleep(0.1)
        port.write(bytes(rng.randrange(256) for _ in range(20_000)))  # flood
        port.flush()
        emulator.wait_for(r"!! \d+ bytes without a silence")
        time.sleep(0.1)
        port.reset_input_buffer()
    assert read_status(master_end, Query.TASK, emulator) == (0, 0)
    code, _ = emulator.stop(signal.SIGINT)
    assert code == 0


def test_serial_answers_a_request_after_t3_5_of_quiet_that_ends_a_flood(pty_pair, start_emulator):
    """300 bytes without a silence, then 0.3 s of quiet (over t3.5, under the 2 s frame gap
    set here: a pty delivers bytes up to some 15 ms late, so a gap under the default 20 ms
    does not survive it), then a request: the request was dropped with the flood."""
    robot_end, master_end = pty_pair
    emulator = start_emulator("--serial", robot_end, "--frame-gap-ms", "2000")
    with serial.Serial(master_end, 9600, timeout=WAIT_S) as port:
        port.write(bytes(300))
        port.flush()
        time.sleep(0.3)
        port.write(STATUS_TASK)
        assert port.read(8) == with_crc(bytes.fromhex("010103000000"))
    emulator.wait_for(r"!! 300 bytes without a silence")
    assert emulator.stop()[0] == 0


def test_pacing_late_logs_how_far_apart_the_requests_came(pty_pair, start_emulator):
    """--pacing late, three reads sent together: the third was logged as coming -250 ms
    after the second (counted from the second's delayed answer, not from when it came)."""
    robot_end, master_end = pty_pair
    emulator = start_emulator("--serial", robot_end, "--pacing", "late")
    with serial.Serial(master_end, 9600, timeout=WAIT_S) as port:
        port.write(STATUS_TASK * 3)
        assert port.read(24) == with_crc(bytes.fromhex("010103000000")) * 3
    for n, late in ((2, "250.0"), (3, "500.0")):
        emulator.wait_for(rf"\*\* pacing: request {n} came 0\.0 ms after the previous one "
                          rf"\(must be > 250 ms\): answered {late} ms late$")
    assert emulator.stop()[0] == 0


@pytest.mark.parametrize("request_body, exception", [
    # a quantity Modbus itself refuses (not 1-2000) is exception 03 before the address is
    # looked at (Modbus Application Protocol V1.1b3 §6.1, the Read Coils state diagram): these
    # two were answered 02 for the query parameter 4 / 01 00
    ("01 01 00 04 00 00", 3), ("01 01 01 00 07 D1", 3),
    ("01 01 00 04 00 16", 2), ("01 01 00 04 00 01", 2),  # a quantity Modbus allows: the address
    ("01 01 00 00 00 00", 3), ("01 01 00 00 00 17", 3),  # query 0, quantity not 22
])
def test_fc01_out_of_range_gets_the_exception_modbus_checks_first(pty_pair, start_emulator, request_body, exception):
    robot_end, master_end = pty_pair
    start_emulator("--serial", robot_end)
    with serial.Serial(master_end, 9600, timeout=WAIT_S) as port:
        port.write(with_crc(bytes.fromhex(request_body)))
        assert port.read(5) == with_crc(bytes((1, 0x81, exception)))


@pytest.mark.parametrize("function", [0x00, 0x80, 0x83, 0xFF])
def test_a_function_code_no_master_sends_gets_silence_and_the_log_says_why(pty_pair, start_emulator, function):
    """Function 00 is not valid and 80-FF are exception replies (Modbus Application Protocol
    V1.1b3 §4.1): no exception reply can answer them (80 | 80 is 80 again). The robot stays
    silent, and the log said only "unknown function code" and "no reply", while another
    unknown function code (03) gets exception 01."""
    robot_end, master_end = pty_pair
    emulator = start_emulator("--serial", robot_end)
    with serial.Serial(master_end, 9600, timeout=WAIT_S) as port:
        port.write(with_crc(bytes((1, function, 0, 0, 0, 1))))
        emulator.wait_for(rf"\*\* silent: request 1: byte 1: function code 0x{function:02X} is not one a master "
                          r"sends \(00 is not a Modbus function code, 80-FF are exception replies\): no reply$")
        port.write(STATUS_TASK)  # nothing came before the reply to this one
        assert port.read(8) == with_crc(bytes.fromhex("010103000000"))


def test_an_adapter_that_echoes_the_robots_replies_does_not_set_it_answering_itself(tmp_path, start_emulator):
    """A 2-wire adapter with local echo hands the emulator back every byte it sends. An FC06
    echo is the request again, so the emulator answered its own reply, and that reply's
    echo, some 70 times a second, for ever; the robot's transceiver does not hear itself."""
    bus = LineBus(tmp_path, robot_hears_itself=True)
    try:
        emulator = start_emulator("--serial", bus.robot)
        with serial.Serial(bus.plc, 9600, timeout=WAIT_S) as port:
            port.write(STOP_FRAME)
            assert port.read(8) == STOP_FRAME
            emulator.wait_for(r"-- serial .* echoes what the emulator sends")
            port.write(STATUS_TASK)  # the next request is still answered, and only it
            assert port.read(8) == with_crc(bytes.fromhex("010103000000"))
        code, summary = emulator.stop()
    finally:
        bus.close()
    assert code == 0 and "2 frames in, 2 replies out, 0 unanswered" in summary, "\n".join(emulator.lines)


def log_time(line: str) -> float:
    return float(line.split()[0])


def test_serial_reply_waits_for_t3_5_at_the_port_speed(pty_pair, start_emulator):
    """--turnaround-ms 0 at 1200 bit/s: the reply still waits t3.5 (29.2 ms) after the
    request, as a slave must; it went out at once. Judged on the emulator's own log, which
    says at the start that the turnaround asked is raised."""
    robot_end, master_end = pty_pair
    emulator = start_emulator("--serial", robot_end, "--baud", "1200", "--turnaround-ms", "0")
    with serial.Serial(master_end, 1200, timeout=WAIT_S) as port:
        port.write(STOP_FRAME)
        assert port.read(8) == STOP_FRAME
    # and the log says so before the first request (it said nothing of the 0 ms asked)
    emulator.wait_for(r"-- replies start 29.167 ms after a request, not 0 ms: never sooner than t3.5 at 1200 bit/s")
    request = emulator.wait_for(r"<- 01 06 01 A0").string
    reply = emulator.wait_for(r"-> 01 06 01 A0").string
    # t3.5 = 29.167 ms; the log counts whole ms, compared as whole ms (0.030 - 0.001 is
    # 0.028999... in floating point, and failed when the request was logged at 1 ms)
    assert round((log_time(reply) - log_time(request)) * 1000) >= 29
    assert emulator.stop()[0] == 0


def test_two_replies_owed_at_once_leave_t3_5_of_silence_between_them(pty_pair, start_emulator):
    """A master that sends two requests together (no silence between them) is owed two
    replies; they went out back to back, one 16-byte run a Modbus master reads as one
    frame with a bad CRC. Each reply now starts at least t3.5 after the previous one has
    left the line (8 bytes at 9600: 8.33 ms + 3.65 ms). Judged on the emulator's own log."""
    robot_end, master_end = pty_pair
    emulator = start_emulator("--serial", robot_end)
    with serial.Serial(master_end, 9600, timeout=WAIT_S) as port:
        port.write(STOP_FRAME + STATUS_TASK)
        assert port.read(16) == STOP_FRAME + with_crc(bytes.fromhex("010103000000"))
    first = emulator.wait_for(r"-> 01 06 01 A0").string
    second = emulator.wait_for(r"-> 01 01 03 00 00 00").string
    # 11.98 ms apart at least; the log counts whole ms, so at least 11 on its clock
    assert round((log_time(second) - log_time(first)) * 1000) >= 11, emulator.lines
    assert emulator.stop()[0] == 0


# ---- TCP: pymodbus client and raw sockets -----------------------------------------------------

def tcp_emulator(start_emulator, *args: str) -> tuple[EmulatorProcess, int]:
    emulator = start_emulator("--tcp", "127.0.0.1:0", *args)
    port = int(emulator.wait_for(r"listening on tcp 127\.0\.0\.1:(\d+)").group(1))
    return emulator, port


def exchange(sock: socket.socket, request: bytes, expect: int) -> bytes:
    sock.sendall(request)
    reply = b""
    while len(reply) < expect:
        chunk = sock.recv(expect - len(reply))
        assert chunk, "emulator closed the connection"
        reply += chunk
    return reply


def test_pymodbus_client_over_tcp_with_rtu_framing(start_emulator):
    emulator, port = tcp_emulator(start_emulator, "--point-duration-s", "600")
    client = ModbusTcpClient("127.0.0.1", port=port, framer=FramerType.RTU, timeout=10, retries=0)
    try:
        assert client.connect()
        stop = client.write_register(0x01A0, 0, device_id=1)
        assert not stop.isError() and stop.address == 0x01A0
        run = client.write_register(0x0103, 0, device_id=1)
        assert not run.isError()
        task = client.read_coils(0, count=22, device_id=1)
        assert not task.isError()
        assert task.bits[16] is True and not any(task.bits[:16])
        bad = client.write_register(0x0199, 0, device_id=1)  # no command 0x99: illegal value
        assert bad.isError() and bad.exception_code == 3
    finally:
        client.close()
    emulator.wait_for(r"-> 01 86 03 ")
    assert emulator.stop()[0] == 0


def test_raw_socket_faults_and_noise_over_tcp(start_emulator):
    emulator, port = tcp_emulator(start_emulator, "--wrong-address-on", "2", "--bad-crc-on", "3",
                                  "--garbage-on", "4")
    with socket.create_connection(("127.0.0.1", port), timeout=5) as sock:
        assert exchange(sock, STOP_FRAME, 8) == STOP_FRAME
        wrong = exchange(sock, STATUS_TASK, 8)
        assert wrong[0] == 2 and wrong[1:6] == bytes.fromhex("0103000000")
        assert exchange(sock, STATUS_TASK, 8)[:-2] == bytes.fromhex("010103000000")
        assert exchange(sock, STATUS_TASK, 3) == bytes.fromhex("A55AFF")
        # unknown function code with a good CRC: exception 01, and nothing is swallowed
        assert exchange(sock, with_crc(bytes((1, 3, 0, 0, 0, 1))), 5) == with_crc(bytes((1, 0x83, 1)))
        assert exchange(sock, STATUS_TASK, 8) == with_crc(bytes.fromhex("010103000000"))
        # noise glued to a request loses it; after a silence the next request is answered
        sock.sendall(b"\x00" + STATUS_TASK)
        emulator.wait_for(r"<- 00 01 01 00 00 00 16 BD C4")
        assert exchange(sock, STATUS_TASK, 8) == with_crc(bytes.fromhex("010103000000"))
        # a flood, then silence, then a request
        rng = random.Random(11)
        sock.sendall(bytes(rng.randrange(256) for _ in range(50_000)))
        emulator.wait_for(r"!! \d+ bytes without a silence")
        assert exchange(sock, STATUS_TASK, 8) == with_crc(bytes.fromhex("010103000000"))
    emulator.wait_for(r"client 127\.0\.0\.1:\d+ disconnected")
    code, summary = emulator.stop()
    assert code == 0 and "3 fault events" in summary and "50000 flood bytes dropped" in summary


def test_a_modbus_tcp_client_is_told_the_route_is_rtu_over_tcp(start_emulator):
    """mbpoll -m tcp, or a converter left in 'Modbus TCP gateway' mode, sends MBAP frames:
    the log says so and what to set (tcp-converter.md), instead of only 'too long for an
    FC01 request' about a frame that is no FC01 request."""
    emulator, port = tcp_emulator(start_emulator)
    done = procs.run(["mbpoll", "-m", "tcp", "-a", "1", "-t", "4", "-r", "417", "-1", "-o", "1",
                           "-p", str(port), "127.0.0.1", "0"], capture_output=True, text=True, timeout=WAIT_S)
    assert done.returncode != 0  # no reply: the robot stays silent
    line = emulator.wait_for(r"<- 00 01 00 00 00 06 01 06 01 A0 00 00 .*").group(0)
    assert ("this is a Modbus TCP frame (MBAP header 00 01 00 00 00 06, unit 1; as RTU: stop (01/A0)): the "
            "robot's route carries Modbus RTU frames with their CRC inside TCP: set the master or the converter "
            "to RTU over TCP (transparent mode), not Modbus TCP (docs/tcp-converter.md)") in line
    assert emulator.stop()[0] == 0


def test_tcp_serves_two_clients_on_one_robot(start_emulator):
    emulator, port = tcp_emulator(start_emulator)
    with socket.create_connection(("127.0.0.1", port), timeout=5) as first, \
            socket.create_connection(("127.0.0.1", port), timeout=5) as second:
        assert exchange(first, STOP_FRAME, 8) == STOP_FRAME
        assert exchange(second, RUN_POINT_3, 8) == RUN_POINT_3
        assert exchange(first, STATUS_TASK, 8) == with_crc(bytes.fromhex("010103000001"))
    assert emulator.stop()[0] == 0


def test_tcp_answers_a_client_that_shut_its_sending_side(start_emulator):
    """A client may send its request and shut its side (SHUT_WR): the reply is still owed
    and was dropped with the connection ("1 reply not sent")."""
    emulator, port = tcp_emulator(start_emulator)
    with socket.create_connection(("127.0.0.1", port), timeout=5) as sock:
        sock.sendall(STOP_FRAME)
        sock.shutdown(socket.SHUT_WR)
        got = b""
        while chunk := sock.recv(64):
            got += chunk
    assert got == STOP_FRAME  # then the emulator closed its side
    emulator.wait_for(r"client 127\.0\.0\.1:\d+ disconnected")
    code, summary = emulator.stop()
    assert code == 0 and "1 reply out" in summary and "not sent" not in summary


def test_quiet_still_says_which_port_it_listens_on(start_emulator):
    emulator = start_emulator("--tcp", "0", "--quiet")
    assert re.search(r"listening on tcp 127\.0\.0\.1:\d+", "".join(emulator.lines))
    assert emulator.stop()[0] == 0


# ---- the command's own errors ------------------------------------------------------------------

def run_cli(*args: str) -> subprocess.CompletedProcess:
    return procs.run([sys.executable, "-m", "verifier.cli", "emulate", *args],
                     capture_output=True, text=True, timeout=WAIT_S)


@pytest.mark.parametrize("text, message", [
    ('[[faults]]\nkind = "no_reply"\non_request = 1\n\n[[faults]]\nkind = "x"\nat_s = 1\n',
     "6:8: faults[1].kind: unknown fault 'x'; expected one of anti_collision"),
    ('[robot]\npacing = "sometimes"\n', "2:10: robot.pacing: unknown pacing policy 'sometimes'"),
])
def test_bad_fault_file_names_file_and_key(tmp_path, text, message):
    path = tmp_path / "faults.toml"
    path.write_text(text)
    result = run_cli("--tcp", "0", "--faults", str(path))
    assert result.returncode == 2
    assert f"{path}:{message}" in result.stderr
    assert "Traceback" not in result.stderr


def test_a_fault_file_that_is_not_utf8_is_named_at_its_byte_as_a_scenario_is(tmp_path):
    """A fault file saved in Latin-1 or Shift-JIS on the bench PC (a comment "café"): the
    message was "faults.toml: line 2, column 24 (byte 31): not UTF-8 text", where every other
    mistake in it, and the same file as a scenario, is named `file:line:col:`."""
    path = tmp_path / "faults.toml"
    path.write_bytes(b"[robot]\nturnaround_ms = 8 # caf\xe9\n")
    result = run_cli("--tcp", "0", "--faults", str(path))
    assert result.returncode == 2 and "Traceback" not in result.stderr
    assert f"{path}:2:24: not UTF-8 text (byte 31): save the file as UTF-8" in result.stderr, result.stderr
    verify = procs.run([sys.executable, "-m", "verifier.cli", "verify", "--scenario", str(path)],
                       capture_output=True, text=True, timeout=WAIT_S)
    assert verify.returncode == 2
    assert f"{path}:2:24: not UTF-8 text (byte 31): save the file as UTF-8" in verify.stdout + verify.stderr


def test_a_wrong_address_fault_on_the_robots_own_address_is_refused(tmp_path):
    path = tmp_path / "faults.toml"
    path.write_text('[[faults]]\nkind = "wrong_address"\non_request = 1\naddress = 5\n')
    result = run_cli("--tcp", "0", "--address", "5", "--faults", str(path))
    assert result.returncode == 2
    assert f"{path}:4:11: faults[0].address: 5 is the robot's own address" in result.stderr
    assert "Traceback" not in result.stderr


def test_the_log_says_what_a_closing_tcp_client_left_behind(start_emulator):
    # A long frame gap and turnaround keep the half request and the reply waiting until the
    # client has gone, whatever the machine's speed.
    emulator, port = tcp_emulator(start_emulator, "--frame-gap-ms", "60000", "--turnaround-ms", "60000")
    with socket.create_connection(("127.0.0.1", port), timeout=5) as sock:
        sock.sendall(STATUS_TASK[:5])
    emulator.wait_for(r"disconnected; 5 received bytes that were not yet a whole request dropped "
                      r"\(01 01 00 00 00\)$")
    with socket.create_connection(("127.0.0.1", port), timeout=5) as sock:
        sock.sendall(STOP_FRAME)
        emulator.wait_for(r"<- 01 06 01 A0 00 00 88 14")
    emulator.wait_for(r"disconnected; 1 reply not sent$")
    with socket.create_connection(("127.0.0.1", port), timeout=5):
        pass
    emulator.wait_for(r"disconnected$")  # nothing left behind: nothing more said
    code, summary = emulator.stop()
    # the reply owed to the client that left is counted (the summary used to lose it)
    assert code == 0 and "1 frame in, 0 replies out, 0 unanswered, 1 reply not sent," in summary


def test_replies_still_owed_when_the_emulator_stops_are_logged_and_counted(pty_pair, start_emulator):
    """SIGTERM while a (late) reply waits: it was dropped without a word, and the summary's
    frames in (1) did not add up to replies out + unanswered (0 + 0)."""
    robot_end, master_end = pty_pair
    emulator = start_emulator("--serial", robot_end, "--late-reply-on", "1:60000")
    with serial.Serial(master_end, 9600, timeout=WAIT_S) as port:
        port.write(STOP_FRAME)
        port.flush()
        emulator.wait_for(r"\*\* fault: request 1: late_reply")
        code, summary = emulator.stop()
    assert code == 0
    assert "1 frame in, 0 replies out, 0 unanswered, 1 reply not sent, 1 fault event," in summary
    emulator.wait_for(rf"-- serial {re.escape(robot_end)} closed; 1 reply not sent$")

    emulator, port = tcp_emulator(start_emulator, "--turnaround-ms", "60000")
    with socket.create_connection(("127.0.0.1", port), timeout=5) as sock:
        sock.sendall(STATUS_TASK)
        emulator.wait_for(r"<- 01 01 00 00 00 16 BD C4")
        code, summary = emulator.stop()
    assert code == 0 and "1 frame in, 0 replies out, 0 unanswered, 1 reply not sent," in summary
    emulator.wait_for(r"-- client 127\.0\.0\.1:\d+ closed: the emulator stops; 1 reply not sent$")


def test_fault_file_is_applied(tmp_path, start_emulator):
    path = tmp_path / "faults.toml"
    path.write_text('[robot]\nturnaround_ms = 2\n\n[[faults]]\nkind = "exception"\non_request = 1\ncode = 6\n')
    emulator, port = tcp_emulator(start_emulator, "--faults", str(path))
    with socket.create_connection(("127.0.0.1", port), timeout=5) as sock:
        assert exchange(sock, STOP_FRAME, 5) == with_crc(bytes((1, 0x86, 6)))


def test_the_scripted_fault_line_says_count_duration_and_filter_together(tmp_path, start_emulator):
    """count = 2 with duration_s and requests = "status": the log said only "for 600 s",
    as if every request for 600 s were hit; two status requests are."""
    path = tmp_path / "faults.toml"
    path.write_text('[[faults]]\nkind = "no_reply"\non_request = 1\ncount = 2\nduration_s = 600\n'
                    'requests = "status"\n')
    emulator, port = tcp_emulator(start_emulator, "--faults", str(path))
    emulator.wait_for(r"-- scripted fault: no_reply on request 1 ×2 within 600 s, status requests only$")
    with socket.create_connection(("127.0.0.1", port), timeout=5) as sock:
        sock.sendall(STATUS_TASK)
        assert exchange(sock, STOP_FRAME, 8) == STOP_FRAME  # FC06: not a status request
        sock.sendall(STATUS_TASK)
        emulator.wait_for(r"request 3: no_reply")
        assert exchange(sock, STATUS_TASK, 8) == with_crc(bytes.fromhex("010103000000"))  # the third: answered


@pytest.mark.parametrize("args, message, code", [
    ((), "give exactly one of --serial PORT or --tcp HOST:PORT", 2),
    (("--tcp", "0", "--serial", "/dev/ttyUSB0"), "give exactly one of", 2),
    (("--tcp", "here"), "expected HOST:PORT or PORT", 2),
    # was read as host ':' port 1, and failed (status 1) with "Name or service not known"
    (("--tcp", "::1"), "--tcp: an IPv6 address goes in brackets, e.g. [::1]:4001, got '::1'", 2),
    (("--tcp", "fe80::1:4001"), "an IPv6 address goes in brackets", 2),
    # in brackets already: was told to put it in brackets; the port is what it lacks
    (("--tcp", "[::1]"), "--tcp: the port is missing after the address, e.g. [::1]:4001, got '[::1]'", 2),
    (("--tcp", "0", "--late-reply-on", "3"), "expected N:MS", 2),
    (("--tcp", "0", "--no-reply-on", "0"), "request numbers start at 1", 2),
    # N:VALUE where only N is taken: the :VALUE was silently dropped
    (("--tcp", "0", "--wrong-address-on", "3:7"),
     "--wrong-address-on: expected a request number N, got '3:7'; its other settings go in a fault file "
     '([[faults]] kind = "wrong_address", on_request = 3, ...)', 2),
    (("--tcp", "0", "--garbage-on", "2:FF"), "--garbage-on: expected a request number N, got '2:FF'", 2),
    (("--tcp", "0", "--no-reply-on", "2:"), "--no-reply-on: expected a request number N, got '2:'", 2),
    (("--tcp", "0", "--address", "300"), "'--address': 300 is not in the range 1<=x<=247", 2),
    (("--tcp", "0", "--anti-collision-at", "-1"), "--anti-collision-at: must be at least 0.0", 2),
    (("--tcp", "0", "--turnaround-ms", "-3"), "--turnaround-ms: must be at least 0.0", 2),
    (("--tcp", "0", "--exception-on", "2:300"), "--exception-on: must be at most 255", 2),
    # was exit 1 (monitor said 2 of the same port) and pyserial's "[Errno 2] could not open port
    # /nonexistent/ttyUSB9: [Errno 2] No such file or directory: ...", with nothing to do
    (("--serial", "/nonexistent/ttyUSB9"), "uitamr emulate: cannot open serial port /nonexistent/ttyUSB9: no such port: "
     "check its name and that the adapter is plugged in (Linux: `ls /dev/ttyUSB*", 2),
    (("--serial", "loop://"), "loop:// sends every byte back", 2),
    (("--serial", "spy://loop://?logging=debug"), "loop:// sends every byte back", 2),
    (("--serial", "/nonexistent/ttyUSB9", "--baud", "0"), "0 is not a standard serial speed", 2),
    (("--serial", "/nonexistent/ttyUSB9", "--baud", "-9600"), "-9600 is not a standard serial speed", 2),
    (("--serial", "/nonexistent/ttyUSB9", "--baud", "9601"), "9601 is not a standard serial speed", 2),
    (("--tcp", "0", "--baud", "19200"), "--baud sets the speed of a --serial port", 2),
    (("--tcp", "0", "--exit-after", "-1"), "--exit-after': must be a number of seconds greater than 0", 2),
    (("--tcp", "0", "--exit-after", "0"), "--exit-after': must be a number of seconds greater than 0", 2),
    (("--tcp", "0", "--exit-after", "inf"), "--exit-after': 'inf' is not a finite number", 2),
    (("--tcp", "0", "--frame-gap-ms", "nan"), "--frame-gap-ms': 'nan' is not a finite number", 2),
    # rounded to 0 µs: the first TCP client crashed the command with a traceback
    (("--tcp", "0", "--frame-gap-ms", "0.0001"), "--frame-gap-ms: must be at least 0.001 (1 µs), got 0.0001", 2),
    (("--tcp", "0", "--frame-gap-ms", "0"), "--frame-gap-ms: must be at least 0.001", 2),
    (("--tcp", "0", "--turnaround-ms", "1e300"), "--turnaround-ms': '1e300' is out of range", 2),
    (("--serial", "socket://127.0.0.1"), "socket://127.0.0.1 needs a host and a port: socket://HOST:PORT", 2),
    (("--serial", "socket://127.0.0.1:http"), "the port 'http' is not a number from 1 to 65535", 2),
    # '²' passed str.isdigit() and failed int(); 5000 digits failed int() too: tracebacks
    (("--serial", "socket://127.0.0.1:²"), "the port '²' is not a number from 1 to 65535", 2),
    (("--serial", "socket://127.0.0.1:" + "9" * 5000), "is not a number from 1 to 65535", 2),
    # `--serial "$PORT"` with PORT unset: was exit 1, "cannot open serial port : ... ''"
    (("--serial", ""), "the port name is empty: give the serial port", 2),
    # was pyserial's "Could not configure port: (25, 'Inappropriate ioctl for device')"
    (("--serial", "/dev/null"), "uitamr emulate: cannot open serial port /dev/null: not a serial port (a file or "
     "another kind of device): give the adapter's port", 2),
    # a folder (Tab completion stops at /dev/serial/by-id/): was pyserial's "[Errno 21] could not
    # open port /tmp: [Errno 21] Is a directory: '/tmp'"
    (("--serial", "/tmp"), "uitamr emulate: cannot open serial port /tmp: a folder, not a serial port: give the "
     "adapter's port, e.g. /dev/ttyUSB0 or a name in /dev/serial/by-id/", 2),
    # was "[Errno -2] Name or service not known (while attempting to bind on address ('nosuch.invalid', 4001))"
    (("--tcp", "nosuch.invalid:4001"), "uitamr emulate: cannot listen on nosuch.invalid:4001: nosuch.invalid is not "
     "an address, nor a name this PC can look up", 2),
    # TEST-NET-1 (RFC 5737), on no PC: was "[Errno 99] Cannot assign requested address (while attempting ...)"
    (("--tcp", "192.0.2.7:4001"), "uitamr emulate: cannot listen on 192.0.2.7:4001: 192.0.2.7 is not an address "
     "of this PC: give one of its own", 2),
])
def test_cli_mistakes_get_a_clear_message(args, message, code):
    result = run_cli(*args)
    assert result.returncode == code
    assert message in result.stderr
    assert "Traceback" not in result.stderr
    assert "stopped after" not in result.stdout  # it never ran: no summary as if it had


def test_a_port_that_cannot_be_opened_says_what_to_check_on_site():
    """The mistakes at the adapter: a wrong name (or the adapter not plugged in), a user not in
    the port's group, a port another program has open. Both commands repeated pyserial's
    "[Errno 2] could not open port X: [Errno 2] No such file or directory: 'X'"; emulate
    exited 1 where monitor exited 2."""
    from verifier.emulate.ports import why_not_opened

    monitor = procs.run([sys.executable, "-m", "verifier.cli", "monitor", "--serial", "/nonexistent/ttyUSB9",
                              "--duration", "1s"], capture_output=True, text=True, timeout=WAIT_S)
    assert monitor.returncode == 2
    assert "uitamr monitor: cannot open /nonexistent/ttyUSB9: no such port: check its name" in monitor.stderr
    assert "Errno" not in monitor.stderr
    folder = procs.run([sys.executable, "-m", "verifier.cli", "monitor", "--serial", "/tmp", "--duration", "1s"],
                       capture_output=True, text=True, timeout=WAIT_S)
    assert folder.returncode == 2 and "uitamr monitor: cannot open /tmp: a folder, not a serial port" in folder.stderr
    assert "Errno" not in folder.stderr
    # root (the test runner) opens any port: pyserial's own exceptions for the other two
    denied = serial.SerialException(13, "could not open port /dev/ttyUSB0: [Errno 13] Permission denied")
    assert why_not_opened(denied).startswith("permission denied: your user may not open it; add it to the port's "
                                             "group (`ls -l` names the group, dialout on Debian and Ubuntu")
    busy = serial.SerialException(16, "could not open port /dev/ttyUSB0: [Errno 16] Device or resource busy")
    assert why_not_opened(busy).startswith("the port is busy: another program has it open")
    # nor can this bench make a converter that does not answer, one on no route, or a port
    # below 1024 refused (root binds any): the socket's own exceptions for them
    from verifier.serialports import why_not_connected, why_not_listening  # the port advice in one module

    assert why_not_connected(TimeoutError("timed out")).startswith("no answer: check the address, that the "
                                                                   "converter is on and on this PC's network")
    unreachable = OSError(errno.EHOSTUNREACH, "No route to host")
    assert why_not_connected(unreachable).startswith("no route to it: this PC is not on the converter's network")
    denied = PermissionError(errno.EACCES, "Permission denied (while attempting to bind on address ('0.0.0.0', 502))")
    assert why_not_listening(denied, "0.0.0.0", 502) == ("permission denied: ports below 1024 need root; give a "
                                                          "port from 1024 up, e.g. 4001")


def test_a_tcp_port_in_use_or_refused_says_what_to_do(start_emulator):
    """The bench mistakes with TCP: an emulator started earlier still holds the port (Python
    said "[Errno 98] Address already in use (while attempting to bind on address
    ('127.0.0.1', 4001))"); a serial server (socket://) that refuses (pyserial said "Could
    not open port socket://...: [Errno 111] Connection refused"); rfc2217:// to a converter
    in raw mode (pyserial: "Remote does not seem to support RFC2217 or BINARY mode
    [we-BINARY:False(INACTIVE), ...]"). Each exits 2 and says what to check."""
    first, port = tcp_emulator(start_emulator)
    taken = run_cli("--tcp", f"127.0.0.1:{port}")
    assert taken.returncode == 2 and "stopped after" not in taken.stdout
    assert taken.stderr.strip() == (f"uitamr emulate: cannot listen on 127.0.0.1:{port}: the port is in use: another "
                                    f"program listens on {port} (an emulator started earlier?); stop it, or give "
                                    "another port (--tcp 0 picks a free one)")
    assert first.stop()[0] == 0
    with socket.create_server(("127.0.0.1", 0)) as probe:  # a port nothing listens on once it is closed
        free = probe.getsockname()[1]
    with socket.create_server(("127.0.0.1", 0)) as raw:  # a converter in raw TCP mode: it never negotiates
        rfc2217 = run_cli("--serial", f"rfc2217://127.0.0.1:{raw.getsockname()[1]}")
    assert rfc2217.returncode == 2
    assert ("the server does not speak RFC 2217 (telnet COM port control): for a converter or ser2net that passes "
            "the bytes as they are (raw TCP), give socket://HOST:PORT") in rfc2217.stderr, rfc2217.stderr
    refused = run_cli("--serial", f"socket://127.0.0.1:{free}")
    assert refused.returncode == 2 and "Errno" not in refused.stderr
    assert refused.stderr.startswith(f"uitamr emulate: cannot open serial port socket://127.0.0.1:{free}: refused: "
                                     "nothing accepts connections on that port; check the address and port"), \
        refused.stderr


@pytest.mark.serial
def test_an_adapter_unplugged_mid_run_ends_with_the_summary_and_what_happened(tmp_path):
    """The USB adapter pulled out (here: socat, which made the pty pair, ended) with three bytes
    of a request still arriving: the emulator ends by itself with status 1 (emulator.md,
    "Testing without hardware"), after saying what it dropped and its summary; the reason
    was pyserial's "device reports readiness to read but returned no data (device
    disconnected or multiple access on port?)" after "Error:" - the port is locked, so nobody
    else read it."""
    robot, plc = tmp_path / "robot", tmp_path / "plc"
    emulator = None
    with pty_cable(tmp_path, "robot", "plc") as socat:
        try:
            emulator = EmulatorProcess("--serial", str(robot), "--frame-gap-ms", "60000")  # the 3 bytes wait
            emulator.wait_for("listening on")
            with serial.Serial(str(plc), 9600, timeout=WAIT_S) as port:
                # in one write: the stop is answered at once, the three bytes after it wait for
                # more (the PLC's end stays open: closing it made socat end before passing them on)
                port.write(STOP_FRAME + STOP_FRAME[:3])
                assert port.read(8) == STOP_FRAME
                socat.terminate()
                socat.wait(timeout=WAIT_S)
            assert emulator.proc.wait(timeout=WAIT_S) == 1
        finally:
            if emulator is not None:
                emulator.kill()
    emulator.wait_for(f"-- serial {robot} closed; 3 received bytes that were not yet a whole request dropped "
                      r"\(01 06 01\)")
    # frames in = replies out + unanswered + not sent: a reply whose drain failed (the port
    # gone while it was going out) was counted nowhere
    emulator.wait_for(r"uitamr emulate: stopped after .* 1 frame in, (1 reply out, 0 unanswered|"
                      r"0 replies out, 0 unanswered, 1 reply not sent), ")
    # the port is gone at the next read, or (the emulator late) at the reply's drain
    emulator.wait_for(re.escape(f"uitamr emulate: serial port {robot} failed") + "( while writing)?"
                      + re.escape(": the port went away: the USB adapter was unplugged or lost power (or the "
                                  "program that made the pty ended); plug it back in and start again"))
    assert not any("multiple access" in line or line.startswith("Error:") for line in emulator.lines)


@pytest.mark.serial
def test_a_reply_whose_drain_meets_an_unplugged_port_ends_the_run_not_in_a_traceback(tmp_path):
    """An adapter pulled out between the reply's write and its drain (pyserial's flush(),
    termios.tcdrain): termios.error, no OSError, went past the emulator's handler - a
    traceback, exit 1 and no summary (seen 1 run in 3 with socat killed as the reply came,
    on a loaded PC). Here that moment for sure: the reply's bytes written (none left), the
    drain on the port gone."""
    from verifier.emulate.ports import PortError, send_reply

    robot = tmp_path / "robot"
    with pty_cable(tmp_path, "robot", "plc") as socat, serial.Serial(str(robot), 9600, timeout=0) as port:
        socat.terminate()
        socat.wait(timeout=WAIT_S)
        with pytest.raises(PortError) as raised:
            send_reply(port, str(robot), b"")
    assert raised.value.in_use  # said after the summary, exit 1
    assert str(raised.value) == (f"serial port {robot} failed while writing: the port went away: the USB adapter was "
                                 "unplugged or lost power (or the program that made the pty ended); plug it back in "
                                 "and start again")  # not termios' "(5, 'Input/output error')"


def test_an_ipv6_listener_is_logged_as_tcp_takes_it_back(start_emulator):
    """The log's address pastes back into --tcp: [::1]:PORT, not ::1:PORT."""
    emulator = start_emulator("--tcp", "[::1]:0")
    port = int(emulator.wait_for(r"listening on tcp \[::1\]:(\d+)").group(1))
    with socket.create_connection(("::1", port), timeout=WAIT_S):
        pass
    assert emulator.stop()[0] == 0


def test_serial_pyserial_socket_url_reaches_a_serial_server(start_emulator):
    """``--serial socket://...``: the emulator dials a serial device server (here a listening
    socket standing in for one) and answers what comes through it."""
    with socket.create_server(("127.0.0.1", 0)) as server:
        server.settimeout(WAIT_S)
        port = server.getsockname()[1]
        emulator = start_emulator("--serial", f"socket://127.0.0.1:{port}")
        conn, _ = server.accept()
        with conn:
            conn.settimeout(WAIT_S)
            assert exchange(conn, STOP_FRAME, 8) == STOP_FRAME
            assert exchange(conn, STATUS_TASK, 8) == with_crc(bytes.fromhex("010103000000"))
    # the serial server went away: the emulator says so, sums up and exits with status 1
    emulator.wait_for(r"uitamr emulate: stopped after .* 2 frames in, 2 replies out")
    assert emulator.proc.wait(timeout=WAIT_S) == 1
    emulator.wait_for(r"uitamr emulate: serial port socket://\S+ failed: the serial server closed the connection$")


def test_a_log_reader_that_leaves_does_not_take_the_robot_off_the_line():
    """`uitamr emulate ... | head -1`: the reader closes the pipe after the first line.
    The robot keeps answering (a bench test goes on), and at the stop the summary goes to
    stderr with status 0, instead of exit 1 and no summary at all."""
    read_end, write_end = os.pipe()
    proc = procs.spawn([sys.executable, "-m", "verifier.cli", "emulate", "--tcp", "127.0.0.1:0"],
                       stdout=write_end, stderr=subprocess.PIPE, text=True)
    os.close(write_end)
    try:
        with os.fdopen(read_end, "rb") as reader:  # the first line, then the reader is gone
            first = reader.readline().decode()
        port = int(re.search(r"listening on tcp 127\.0\.0\.1:(\d+)", first).group(1))
        with socket.create_connection(("127.0.0.1", port), timeout=5) as sock:
            for _ in range(3):  # each exchange writes log lines into the closed pipe
                assert exchange(sock, STOP_FRAME, 8) == STOP_FRAME
            assert exchange(sock, STATUS_TASK, 8) == with_crc(bytes.fromhex("010103000000"))
        proc.send_signal(signal.SIGTERM)
        _, err = procs.finish(proc, WAIT_S)
    finally:
        if proc.poll() is None:
            procs.kill_group(proc)
            proc.wait(timeout=WAIT_S)
    assert proc.returncode == 0, err
    assert "Traceback" not in err
    assert re.search(r"uitamr emulate: stopped after [\d.]+ s: 4 frames in, 4 replies out, .*"
                     r"\(the log's reader closed stdout; the robot kept serving until the stop\)", err), err


def test_the_same_command_sent_again_soon_after_a_late_reply_is_answered_not_taken_for_an_echo(
        pty_pair, start_emulator):
    """An FC06 reply is its request byte for byte, so the echo filter for 2-wire adapters must
    not take a master's next request for the echo. A reply 150 ms late, then the same stop
    100 ms after it (266 ms after the first: within the pacing) went unanswered when any
    copy within 200 ms of the reply was dropped as an echo; an echo comes back within the
    adapter's latency (ECHO_GRACE_US)."""
    robot_end, master_end = pty_pair
    emulator = start_emulator("--serial", robot_end, "--turnaround-ms", "150")
    with serial.Serial(master_end, 9600, timeout=WAIT_S) as port:
        port.write(STOP_FRAME)
        assert port.read(8) == STOP_FRAME
        time.sleep(0.1)
        port.write(STOP_FRAME)
        assert port.read(8) == STOP_FRAME, "\n".join(emulator.lines)
    code, summary = emulator.stop()
    assert code == 0 and "2 frames in, 2 replies out, 0 unanswered" in summary, "\n".join(emulator.lines)


def test_a_port_error_raised_while_handling_one_without_words_is_no_traceback():
    """why_not_opened read the first argument of the error pyserial raised its own from
    (termios.error(25, ...) for a file that is no serial port) as `args[0]`: an error raised
    while handling one with no arguments (KeyError(), NotImplementedError()) ended emulate and
    monitor in an IndexError traceback instead of pyserial's words."""
    from verifier.serialports import why_not_opened

    try:
        try:
            raise NotImplementedError()
        except NotImplementedError:
            raise serial.SerialException("could not open port /dev/ttyS9: no custom baud rate")
    except serial.SerialException as err:
        assert why_not_opened(err) == "could not open port /dev/ttyS9: no custom baud rate"
