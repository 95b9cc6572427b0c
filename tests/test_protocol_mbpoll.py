"""libmodbus (mbpoll) as an independent Modbus master agrees with our frames.

Over a real socat pty pair: the request bytes mbpoll puts on the line (from the command
line `uitamr frame --mbpoll` prints) must equal `encode(request)`, and mbpoll must accept
our replies (FC06 echo, FC01 22-coil status) and read back the coil bits we meant.
"""
from __future__ import annotations

import os
import re
import select
import subprocess
import time
import warnings
from pathlib import Path

import pytest

from verifier.commands.frame import mbpoll_command
from verifier.protocol import (
    ControlReply,
    RobotError,
    Settings,
    StatusReply,
    command_from_words,
    encode,
)
import procs

pytestmark = pytest.mark.serial

IO_TIMEOUT_S = 10  # generous upper bound for a loaded machine; not a timing assertion


@pytest.fixture
def pty_pair(tmp_path: Path):
    master_end, robot_end = tmp_path / "master", tmp_path / "robot"
    socat = procs.spawn(
        ["socat", f"pty,raw,echo=0,link={master_end}", f"pty,raw,echo=0,link={robot_end}"],
        stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
    )
    deadline = time.monotonic() + IO_TIMEOUT_S
    while not (master_end.exists() and robot_end.exists()):
        assert socat.poll() is None, socat.stderr.read().decode()
        assert time.monotonic() < deadline, "socat did not create the pty pair"
        time.sleep(0.02)
    fd = os.open(robot_end, os.O_RDWR | os.O_NOCTTY)
    try:
        yield str(master_end), fd
    finally:
        os.close(fd)
        socat.terminate()
        socat.wait(timeout=IO_TIMEOUT_S)


def read_exactly(fd: int, count: int) -> bytes:
    data = b""
    deadline = time.monotonic() + IO_TIMEOUT_S
    while len(data) < count:
        ready, _, _ = select.select([fd], [], [], max(0.0, deadline - time.monotonic()))
        assert ready, f"only {data.hex(' ')} arrived, expected {count} bytes"
        data += os.read(fd, count - len(data))
    return data


#: mbpoll's reply time-out (its -o, 1 s when not given, as mbpoll_command leaves it)
MBPOLL_TIMEOUT_S = 1.0
ATTEMPTS = 3


def exchange(device_fd: int, argv: list[str], expected_request: bytes, reply: bytes) -> str:
    """mbpoll's output once it got `reply` to its request (checked to be `expected_request`).

    This test answers as soon as the request is read, so a reply that reached mbpoll after
    its 1 s time-out was the host's doing: the test process was not run (a pytest process
    SIGSTOPped 1.5 s once mbpoll started: 'Connection timed out', the test failed). Such an
    attempt, when the reply went out more than the time-out after mbpoll was started (its
    request cannot have gone out before), runs again; any other failure fails at once, and
    so do three such attempts."""
    stalled = []
    for _attempt in range(ATTEMPTS):
        started = time.monotonic()
        process = procs.spawn(argv, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
        try:
            request = read_exactly(device_fd, len(expected_request))
            os.write(device_fd, reply)
            answered_s = time.monotonic() - started
            output, _ = procs.finish(process, IO_TIMEOUT_S)
        finally:
            if process.poll() is None:
                procs.kill_group(process)
                process.wait()
        assert request == expected_request, f"mbpoll sent {request.hex(' ')}, we encode {expected_request.hex(' ')}"
        if process.returncode != 0 and answered_s > MBPOLL_TIMEOUT_S:
            said = [line for line in output.splitlines() if "failed" in line] or output.splitlines()[-1:]
            stalled.append(f"answered {answered_s * 1000:.0f} ms after mbpoll started: {' '.join(said)}")
            continue
        assert process.returncode == 0, output
        if stalled:  # shown in the run's warnings summary: how often the host got in the way
            warnings.warn("host stalls before the clean mbpoll exchange: " + " | ".join(stalled))
        return output
    pytest.fail("every mbpoll timed out while the host held this test's reply back past its time-out: "
                + " | ".join(stalled))


@pytest.mark.parametrize("settings", [Settings(), Settings(field_order="code-low"),
                                      Settings(codes_10_13="hex", address=7)])
@pytest.mark.parametrize("words", ["stop", "move y -0.3", "rotate +2.55", "follow-tape right"])
def test_mbpoll_writes_the_same_fc06_frame(pty_pair, settings, words):
    device, fd = pty_pair
    request = command_from_words(words.split(), address=settings.address)
    frame = encode(request, settings)
    output = exchange(fd, mbpoll_command(request, settings, device), frame,
                      encode(ControlReply.echo(request), settings))
    assert "Written 1 references" in output


@pytest.mark.parametrize("query, error, value", [("task", RobotError.NONE, 1), ("vehicle", RobotError.OFF_TAPE, 2),
                                                 ("battery", RobotError.BATTERY_LOW, 1), ("speed", RobotError.NONE, 3)])
def test_mbpoll_reads_our_status_reply_as_22_coils(pty_pair, query, error, value):
    device, fd = pty_pair
    settings = Settings(status_order="return")
    request = command_from_words(["read", query])
    reply = StatusReply(1, error, value, request.query)
    output = exchange(fd, mbpoll_command(request, settings, device), encode(request, settings),
                      encode(reply, settings))
    coils = {}
    for line in output.splitlines():
        if line.startswith("[") and "]:" in line:
            reference, bit = line.split("]:")
            coils[int(reference.strip("[ "))] = int(bit.strip())
    start = int.from_bytes(encode(request, settings)[2:4], "big")
    assert sorted(coils) == list(range(start, start + 22))
    bits = [coils[start + i] for i in range(22)]
    assert bits[0:8] == [0] * 8
    assert sum(bit << i for i, bit in enumerate(bits[8:16])) == error
    assert sum(bit << i for i, bit in enumerate(bits[16:22])) == value


def _set_labels(output: str) -> set[int]:
    """The coil numbers mbpoll shows as 1."""
    return {int(ref.strip("[ ")) for ref, bit in (line.split("]:") for line in output.splitlines()
                                                    if line.startswith("[") and "]:" in line) if bit.strip() == "1"}


@pytest.mark.parametrize("query, page, sentence", [
    ("task", "protocol.md", r"for `read task` coils (\d+)–(\d+) and (\d+)–(\d+)"),
    ("battery", "protocol.md", r"for `read battery` \(`-r 3`\) (\d+)–(\d+) and (\d+)–(\d+)"),
    ("task", "emulator.md", r"coils (\d+)–(\d+) carry the error byte and (\d+)–(\d+) the value"),
    ("battery", "emulator.md", r"\(`-r 4`, battery: the error byte in coils (\d+)–(\d+), the value in (\d+)–(\d+)\)"),
])
def test_the_coil_numbers_the_pages_give_are_the_ones_mbpoll_shows(pty_pair, query, page, sentence):
    """mbpoll numbers the coils it shows from its start reference, the query parameter: the
    pages gave the error code as coils 8-15 and the value as 16-21 for every query, so a
    battery read (-r 3) was read three coils off. Error 03 and value 1 show where they are."""
    device, fd = pty_pair
    text = " ".join((Path(__file__).resolve().parents[1] / "docs" / page).read_text(encoding="utf-8").split())
    error_first, error_last, value_first, value_last = map(int, re.search(sentence, text).groups())
    request = command_from_words(["read", query])
    argv = mbpoll_command(request, Settings(), device)
    if page == "emulator.md":  # its recipe counts from 1: -r P+1 without -0
        assert "-t 0 -r 1 -c 22 -1 /tmp/plc" in text.split("## Testing without hardware", 1)[1]
        argv = [word for word in argv if word != "-0"]
        argv[argv.index("-r") + 1] = str(int(request.query) + 1)
    output = exchange(fd, argv, encode(request), encode(StatusReply(1, RobotError.BATTERY_LOW, 1, request.query)))
    assert _set_labels(output) == {error_first, error_first + 1, value_first}
    assert (error_last - error_first, value_last - value_first) == (7, 5)
