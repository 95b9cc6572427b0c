"""Helpers for the simulator tests: load ST from text, a fake serial endpoint, a scenario
result to compare with another run's."""
from __future__ import annotations

from dataclasses import asdict

import verifier.sim


#: indices of the port interface io_uPort of UITAMR_Engine (its PORT_<name> constants,
#: docs/plc-library.md "The port interface"): request and reply flags and lengths, the port's
#: error code, and where the frame to send and the reply received start (one byte per word)
TX_REQ, TX_LEN, RX_DONE, RX_LEN, PORT_ERR, TX_BASE, RX_BASE = 0, 1, 2, 3, 4, 8, 24


#: a function block with a TON (done 3 s after i_bExecute rises), as an integrator's first
#: test of docs/testing-st.md loads it
FB_DELAY = """
FUNCTION_BLOCK FB_Delay
VAR_INPUT i_bExecute : BOOL; END_VAR
VAR_OUTPUT o_bDone : BOOL; END_VAR
VAR fbTimer : TON; END_VAR
fbTimer(IN := i_bExecute, PT := T#3s);
o_bDone := fbTimer.Q;
END_FUNCTION_BLOCK
"""


def load_st(text: str, name: str = "t.st", **options) -> verifier.sim.Project:
    return verifier.sim.load(sources={name: text}, **options)


def fb_source(body: str, decls: str, name: str = "FB_T") -> str:
    """A FUNCTION_BLOCK wrapping `body` with the given VAR declarations."""
    return f"FUNCTION_BLOCK {name}\nVAR\n{decls}\nEND_VAR\n{body}\nEND_FUNCTION_BLOCK\n"


def run_fb(body: str, decls: str, scans: int = 1, **options):
    project = load_st(fb_source(body, decls), **options)
    fb = project.instance("FB_T")
    fb.scan(scans)
    return project, fb


def run_program(src: str, scans: int = 1, name: str = "P", **options):
    """Load `src`, run its PROGRAM `name` for `scans` scans; the PROGRAM instance."""
    project = load_st(src, **options)
    project.run_programs([name], scans=scans)
    return project.program(name)


class FakeEndpoint:
    """The Line master interface with scripted replies: bytes are delivered at the times
    given to `reply_at`."""

    def __init__(self):
        self.sent: list[tuple[bytes, int, str | None]] = []
        self._incoming: list[tuple[int, int]] = []

    def send(self, data: bytes, t_us: int, origin: str | None = None) -> int:
        self.sent.append((bytes(data), t_us, origin))
        return t_us

    def reply_at(self, t_us: int, data: bytes, byte_us: int = 1042) -> None:
        for k, b in enumerate(data):
            self._incoming.append((b, t_us + (k + 1) * byte_us))
        self._incoming.sort(key=lambda x: x[1])

    def receive_until(self, t_us: int) -> list[tuple[int, int]]:
        out = [x for x in self._incoming if x[1] <= t_us]
        self._incoming = [x for x in self._incoming if x[1] > t_us]
        return out


def comparable(result) -> dict:
    """A scenario result as a dict without its wall-clock time: two runs meant to give the
    same result compare equal field for field."""
    data = asdict(result)
    data.pop("wall_s")
    return data
