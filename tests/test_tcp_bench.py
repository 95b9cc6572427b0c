"""Bench test of the TCP route: ``uitamr emulate --tcp`` as a real subprocess, driven by a
real TCP client that sends exactly the bytes the library's Ethernet port POU hands to its
send instruction (SP_SOCSND of UITAMR_PortTcpFx5, recorded in a simulated run of the
bundled FX5U TCP example), as raw Modbus RTU inside TCP (CRC included, no MBAP header) -
what a serial-to-TCP converter in transparent mode passes to the robot. Every request is
written in two TCP segments and every reply is read in pieces, as a converter may split
them.

Nothing wall-clock is asserted: each request waits at least the simulated spacing after
the previous one as it was really sent (sleeping can only make gaps longer; on a loaded
machine a late request once shortened the gap to the next, on time, one), waits are bounded, and the emulator runs each robot task for 600 s
so the robot's answers do not depend on how late a request arrives.
"""
from __future__ import annotations

import socket
import time
from dataclasses import replace
from pathlib import Path

import pytest

from verifier.link.converter import Converter
from verifier.protocol import crc16
from verifier.verify import runner
from verifier.verify.scenario import load_scenario

from test_emulate_ports import start_emulator, tcp_emulator  # noqa: F401  (fixture)

pytestmark = pytest.mark.serial

SCENARIO = Path(__file__).resolve().parents[1] / "plc" / "scenarios" / "fx5u-tcp-healthy.toml"
REPLAYED_US = 6_000_000  # connect, power-on stop, status polls, run point 1, polls while it runs
SEGMENT_PAUSE_S = 0.05  # between the two TCP segments of a request


class RecordingConverter(Converter):
    """The scenario's converter, keeping each TCP send of the PLC and each segment it gets."""

    sends: list[tuple[int, bytes]] = []
    segments: list[tuple[int, bytes]] = []

    def send(self, t_us, connection, data, origin=None):
        RecordingConverter.sends.append((t_us, bytes(data)))
        return super().send(t_us, connection, data, origin)

    def receive_until(self, t_us, connection):
        got = super().receive_until(t_us, connection)
        RecordingConverter.segments.extend(got)
        return got


@pytest.fixture(scope="module")
def port_pou_exchanges() -> list[tuple[int, bytes, bytes]]:
    """(send time, bytes SP_SOCSND sent, bytes the PLC received back) of the first seconds."""
    RecordingConverter.sends, RecordingConverter.segments = [], []
    patch = pytest.MonkeyPatch()
    patch.setattr(runner, "Converter", RecordingConverter)
    try:
        result = runner.run_scenario(replace(load_scenario(SCENARIO), duration_us=REPLAYED_US))
    finally:
        patch.undo()
    assert not result.all_violations()  # its later expectations lie beyond the replayed seconds
    sends, segments = RecordingConverter.sends, RecordingConverter.segments
    assert len(sends) >= 15 and sends[0][1] == bytes.fromhex("010601A000008814")
    assert any(data[1] == 0x06 and data[2:4] == b"\x01\x01" for _, data in sends), "no run-point command"
    # every send got its reply as one segment, before the next send
    exchanges = []
    for k, (t, data) in enumerate(sends):
        end = sends[k + 1][0] if k + 1 < len(sends) else REPLAYED_US
        replies = [seg for ts, seg in segments if t < ts <= end]
        assert len(replies) == 1, (t, data.hex(), replies)
        exchanges.append((t, data, replies[0]))
    # the POU's bytes are the frames on the robot's line, unchanged by the converter
    assert [d for _, d in sends] == [f.data for f in result.trace if f.direction == "tx"][:len(sends)]
    return exchanges


def read_in_pieces(sock: socket.socket, count: int) -> bytes:
    """``count`` bytes, one recv of at most 3 bytes at a time."""
    data = b""
    while len(data) < count:
        chunk = sock.recv(min(3, count - len(data)))
        assert chunk, "the emulator closed the connection"
        data += chunk
    return data


def test_tcp_client_sending_the_port_pous_bytes_gets_the_simulated_replies(start_emulator, port_pou_exchanges):
    emulator, port = tcp_emulator(start_emulator, "--point-duration-s", "600", "--frame-gap-ms", "5000")
    replies = []
    with socket.create_connection(("127.0.0.1", port), timeout=10) as sock:
        sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
        previous = None  # (simulated start in µs, wall time of its first half, of its second half)
        for start_us, request, reply in port_pou_exchanges:
            if previous is not None:
                # the simulated gap counted from the previous request as it was really sent,
                # whichever half the emulator dates it by: a late request (a loaded machine)
                # never shortens the gap to the next one
                gap_s = (start_us - previous[0]) / 1e6
                delay = max(previous[1] + gap_s, previous[2] + gap_s - SEGMENT_PAUSE_S) - time.monotonic()
                if delay > 0:
                    time.sleep(delay)
            first_half = time.monotonic()
            sock.sendall(request[:3])  # two TCP segments: the converter forwards both halves
            time.sleep(SEGMENT_PAUSE_S)
            previous = (start_us, first_half, time.monotonic())
            sock.sendall(request[3:])
            got = read_in_pieces(sock, len(reply))
            assert crc16(got[:-2]) == int.from_bytes(got[-2:], "little")
            replies.append(got)
    assert replies == [reply for _, _, reply in port_pou_exchanges]
    emulator.wait_for(r"client 127\.0\.0\.1:\d+ disconnected")
    code, _ = emulator.stop()
    assert code == 0
    assert not [line for line in emulator.lines if "pacing" in line], "a request came sooner than the library sends it"
