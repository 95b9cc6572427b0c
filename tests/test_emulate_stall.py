"""The emulator's framing over TCP when its host stalls it (a loaded bench PC).

A frame ends after a silence, which the emulator measures on its own clock. It read a
client's bytes 4096 at a time, one read a round: a flood that had come whole was framed in
pieces, and a host that stopped the emulator between two of them for longer than the frame
gap made it take the stall for a silence. The flood was cut ("!! 4096 bytes without a
silence"), its tail taken for a frame of its own, and a request sent once the first "!!"
line showed was glued to that tail and went unanswered (seen once, flake31:
test_raw_socket_faults_and_noise_over_tcp timed out). What waits is now read in one piece.

The stall is made in the emulator's own process, through its clock, right after its first
read: the socket, the emulator and its framing are the real ones.
"""
from __future__ import annotations

import re
import socket
import threading
import time

from verifier.amr import Robot
from verifier.emulate import ports
from verifier.emulate.assembler import RequestAssembler
from verifier.emulate.core import Emulator
from verifier.protocol import STOP_FRAME
from verifier.stopflag import StopFlag

STALL_NS = 100_000_000  # longer than the 20 ms frame gap
FLOOD = bytes(range(256)) * 40  # 10,240 bytes, sent in one piece
WAIT_S = 10


class StallingClock:
    """The emulator's clock; once `stall_next` is called, the next reading comes after a
    stall of STALL_NS (the host stopped the emulator)."""

    def __init__(self) -> None:
        self.offset_ns = 0
        self.armed = False

    def stall_next(self) -> None:
        self.armed = True

    def __call__(self) -> int:
        if self.armed:
            self.armed = False
            self.offset_ns += STALL_NS
        return time.monotonic_ns() + self.offset_ns


def test_a_flood_that_came_whole_is_one_flood_though_the_host_stalls_the_emulator(monkeypatch):
    clock = StallingClock()
    lines: list[str] = []
    emulator = Emulator(Robot(), lines.append, clock_ns=clock)

    class StallAfterTheFirstRead(RequestAssembler):
        reads = 0

        def feed(self, data, t_us):
            StallAfterTheFirstRead.reads += 1
            if StallAfterTheFirstRead.reads == 1:
                clock.stall_next()
            return super().feed(data, t_us)

    monkeypatch.setattr(ports, "RequestAssembler", StallAfterTheFirstRead)
    listening = threading.Event()
    address: list[tuple[str, int]] = []
    stop = StopFlag()

    def on_listening(host, port):
        address.append((host, port))
        listening.set()

    server = threading.Thread(target=ports.serve_tcp, args=("127.0.0.1", 0, emulator, stop, 20_000),
                              kwargs={"on_listening": on_listening}, daemon=True)
    server.start()
    try:
        assert listening.wait(WAIT_S)
        with socket.create_connection(address[0], timeout=WAIT_S) as client:
            client.sendall(FLOOD)
            deadline = time.monotonic() + WAIT_S
            while not any(" !! " in line for line in lines) and time.monotonic() < deadline:
                time.sleep(0.01)
            client.sendall(STOP_FRAME)  # as a master does once the flood was refused
            reply = client.recv(64)
    finally:
        stop.set()
        server.join(WAIT_S)
    drops = [line for line in lines if " !! " in line]
    assert [re.search(r"!! (\d+) bytes", line).group(1) for line in drops] == [str(len(FLOOD))], lines
    assert reply == STOP_FRAME, lines
