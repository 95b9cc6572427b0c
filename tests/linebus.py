"""A two-wire RS-485 line made of real ptys, for the monitor's tests.

Three socat pty pairs: the PLC's end, the robot's end and a tap (a receive-only USB
adapter). A relay joins the far ends of the pairs the way the twisted pair joins devices:
whatever the PLC end writes reaches the robot end and the tap, whatever the robot end
writes reaches the PLC end and the tap. `noise` puts bytes on the line from nowhere.
"""
from __future__ import annotations

import contextlib
import os
import select
import subprocess
import threading
import time
from pathlib import Path

OPEN_TIMEOUT_S = 10


class LineBus:
    def __init__(self, folder: Path, robot_hears_itself: bool = False):
        """``robot_hears_itself``: what the robot end writes comes back to it too, as on a
        2-wire USB adapter with local echo (its receiver stays on while it sends)."""
        self.folder = folder
        self._robot_echo = ("robot",) if robot_hears_itself else ()
        self.plc = str(folder / "plc")
        self.robot = str(folder / "robot")
        self.tap = str(folder / "tap")
        self._socats = []
        self._fds: dict[str, int] = {}
        for name in ("plc", "robot", "tap"):
            device, bus = folder / name, folder / f"{name}-bus"
            self._socats.append(subprocess.Popen(
                ["socat", f"pty,raw,echo=0,link={device}", f"pty,raw,echo=0,link={bus}"],
                stdout=subprocess.DEVNULL, stderr=subprocess.PIPE))
            deadline = time.monotonic() + OPEN_TIMEOUT_S
            while not (device.exists() and bus.exists()):
                assert time.monotonic() < deadline, "socat did not create its pty pair"
                time.sleep(0.01)
            self._fds[name] = os.open(bus, os.O_RDWR | os.O_NOCTTY | os.O_NONBLOCK)
        self._lock = threading.Lock()
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._relay, daemon=True)
        self._thread.start()

    def _write(self, name: str, data: bytes) -> None:
        view = memoryview(data)
        while view:
            try:
                written = os.write(self._fds[name], view)
            except BlockingIOError:
                select.select([], [self._fds[name]], [], 0.05)
                continue
            view = view[written:]

    def from_plc(self, data: bytes) -> None:
        """Bytes the PLC end puts on the line, straight to the tap and the robot from the
        caller's thread (tests.monitor_helpers.Master): not through the PLC end's socat and
        the relay thread, two more programs the host could stall on the way (seen: a
        request 530 ms late on the wire, so 170 ms before the next one, a PACING finding
        the PLC stand-in had not made). The tap first: it hears a request before the robot
        can answer it."""
        with self._lock:
            self._write("tap", data)
            self._write("robot", data)

    def from_robot(self, data: bytes) -> None:
        """Bytes the robot end puts on the line, straight to the tap and the PLC end from the
        caller's thread: a robot answered in-process (tests.monitor_helpers.Master with a
        `robot`), so that a reply goes out right after its request whatever the host does.
        The tap first, as in the relay."""
        with self._lock:
            for name in ("tap", "plc", *self._robot_echo):
                self._write(name, data)

    def _relay(self) -> None:
        # the tap first: what it hears before the PLC end does (a reply the PLC stand-in
        # hears is on the tap before its next request can be)
        sources = {self._fds["plc"]: ("tap", "robot"), self._fds["robot"]: ("tap", "plc", *self._robot_echo),
                   self._fds["tap"]: ()}  # the tap only listens: what it writes goes nowhere
        while not self._stop.is_set():
            ready, _, _ = select.select(list(sources), [], [], 0.05)
            for fd in ready:
                try:
                    data = os.read(fd, 4096)
                except (BlockingIOError, OSError):
                    continue
                with self._lock:
                    for name in sources[fd]:
                        self._write(name, data)

    def noise(self, data: bytes) -> None:
        """Bytes on the line that nobody sent (a disturbance): the tap and the robot hear them."""
        with self._lock:
            self._write("tap", data)
            self._write("robot", data)

    def close(self) -> None:
        self._stop.set()
        self._thread.join(timeout=2)
        for fd in self._fds.values():
            os.close(fd)
        for socat in self._socats:
            socat.terminate()
            socat.wait(timeout=5)


@contextlib.contextmanager
def pty_cable(folder: Path, one: str, other: str):
    """A socat pty pair, the cable between two ends named `folder/one` and `folder/other`:
    yields socat's process, so that a test can pull the cable out (terminate it) while a
    command has a port open; the process is ended at the end if it still runs."""
    ends = folder / one, folder / other
    socat = subprocess.Popen(["socat", *(f"pty,raw,echo=0,link={end}" for end in ends)],
                             stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        deadline = time.monotonic() + OPEN_TIMEOUT_S
        while not all(end.exists() for end in ends):
            assert socat.poll() is None and time.monotonic() < deadline, "socat made no pty pair"
            time.sleep(0.02)
        yield socat
    finally:
        if socat.poll() is None:
            socat.kill()
            socat.wait(timeout=OPEN_TIMEOUT_S)
