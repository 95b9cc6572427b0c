"""UITAMR_Engine and the command FBs, run in the simulator against a fake port written
here in Python: the port interface (io_uPort) is served directly, the robot's answers come
from verifier.protocol, and every request is timed in virtual microseconds.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings as hsettings, strategies as st

import verifier
from sim_helpers import RX_BASE, RX_DONE, RX_LEN, TX_BASE, TX_LEN, TX_REQ
from verifier.protocol import (
    ControlReply, ControlRequest, ExceptionReply, Settings, StatusReply, StatusRequest,
    decode_request, encode,
)

ROOT = Path(__file__).resolve().parents[1]
CORE = ROOT / "plc" / "core"
SETTINGS = Settings()

HARNESS = """
PROGRAM T_Engine
VAR
    fbEngine : UITAMR_Engine;
    fbRun : UITAMR_RunPoint;
    fbStop : UITAMR_Stop;
    fbSpeed : UITAMR_SetSpeed;
    fbRead : UITAMR_ReadStatus;
    fbMove : UITAMR_MoveRelative;
    fbRange : UITAMR_SetCollisionRange;
    fbRunB : UITAMR_RunPoint;
    uMbx : ARRAY[0..15] OF WORD;
    uPort : ARRAY[0..39] OF WORD;
    bEnable : BOOL;
    bMonitor : BOOL;
    bCmdOff : BOOL;
    bRun : BOOL;
    bStop : BOOL;
    bSpeed : BOOL;
    bRead : BOOL;
    bMove : BOOL;
    bRange : BOOL;
    wPoint : INT;
    wStage : INT;
    wQuery : INT;
    wAxis : INT;
    eValue : REAL;
    eRange : REAL;
    bRunB : BOOL;
    wPointB : INT;
    wAddress : INT;
END_VAR
fbEngine(i_bEN := bEnable, i_wAddress := wAddress, i_bMonitor := bMonitor, io_uMbx := uMbx, io_uPort := uPort);
fbRun(i_bEN := NOT bCmdOff, i_bExecute := bRun, i_wPoint := wPoint, io_uMbx := uMbx);
fbStop(i_bEN := NOT bCmdOff, i_bExecute := bStop, io_uMbx := uMbx);
fbSpeed(i_bEN := NOT bCmdOff, i_bExecute := bSpeed, i_bMagnetic := FALSE, i_wStage := wStage, io_uMbx := uMbx);
fbRead(i_bEN := NOT bCmdOff, i_bExecute := bRead, i_wQuery := wQuery, io_uMbx := uMbx);
fbMove(i_bEN := NOT bCmdOff, i_bExecute := bMove, i_wAxis := wAxis, i_eValue := eValue, io_uMbx := uMbx);
fbRange(i_bEN := NOT bCmdOff, i_bExecute := bRange, i_eRange := eRange, io_uMbx := uMbx);
fbRunB(i_bEN := TRUE, i_bExecute := bRunB, i_wPoint := wPointB, io_uMbx := uMbx);
END_PROGRAM
"""


@dataclass
class FakePort:
    """Plays port and robot: takes the engine's frame, answers after `turnaround_us`."""

    h: object
    project: object
    turnaround_us: int = 15_000
    running_polls: int = 2          # task status 'running' answers after a point command
    silent: bool = False            # no reply at all
    exception_code: int | None = None
    corrupt: bool = False
    robot_error: int = 0
    requests: list = field(default_factory=list)   # (t_us, bytes)
    overlaps: list = field(default_factory=list)   # requests while a reply was due
    due: tuple | None = None
    busy_polls: int = 0

    def step(self) -> None:
        now = self.project.now_us
        port = self.h.uPort
        if port[TX_REQ]:
            data = bytes(port[TX_BASE + i] for i in range(port[TX_LEN]))
            port[TX_REQ] = 0
            if self.due is not None:
                self.overlaps.append((now, data))
            self.requests.append((now, data))
            reply = self.answer(data)
            if reply is not None:
                self.due = (now + self.turnaround_us, reply)
        if port[5]:                      # flush request
            port[5] = 0
            port[RX_DONE] = 0
        if self.due and now >= self.due[0] and not port[RX_DONE]:
            reply = self.due[1]
            for i in range(16):
                port[RX_BASE + i] = reply[i] if i < len(reply) else 0
            port[RX_LEN] = len(reply)
            port[RX_DONE] = 1
            self.due = None

    def answer(self, data: bytes) -> bytes | None:
        if self.silent:
            return None
        request = decode_request(data, SETTINGS)
        if self.exception_code is not None:
            function = 6 if isinstance(request, ControlRequest) else 1
            return encode(ExceptionReply(1, function, self.exception_code), SETTINGS)
        if isinstance(request, ControlRequest):
            if request.code == 1 and 1 <= request.command <= 21:     # a point run takes time
                self.busy_polls = self.running_polls
            elif request.code == 1 and request.command == 0xA0:     # stop: at rest at once
                self.busy_polls = 0
            reply = encode(ControlReply.echo(request), SETTINGS, strict=False)
        else:
            value = 0
            if request.query == 0 and self.busy_polls > 0:
                self.busy_polls -= 1
                value = 1
            reply = encode(StatusReply(request.address, self.robot_error, value), SETTINGS, strict=False)
        if self.corrupt:
            reply = reply[:-1] + bytes([reply[-1] ^ 0xFF])
        return reply

    def run(self, ms: float, until=None) -> None:
        stop = self.project.now_us + round(ms * 1000)
        while self.project.now_us < stop:
            self.h.scan()
            self.step()
            if until is not None and until(self.h):
                return

    def kinds(self) -> list[bytes]:
        return [data for _, data in self.requests]


@pytest.fixture()
def rig():
    project = verifier.load(CORE, sources={"T_Engine.st": HARNESS})
    h = project.program("T_Engine")
    port = FakePort(h, project)
    h.wAddress = 1
    h.bEnable = True
    return h, port


STOP = encode(ControlRequest(1, 1, 0xA0), SETTINGS)
READ_TASK = encode(StatusRequest(1, 0), SETTINGS)


def start_point(h, port, point=3):
    port.run(1500, until=lambda x: x.fbEngine.o_bInitDone)
    h.wPoint, h.bRun = point, True


def start_long_point(h, port):
    """Point 3 run, 1 s on: its task answers 'running' to 50 polls, so it is still running and polled."""
    port.running_polls = 50
    start_point(h, port)
    port.run(1000)


def test_the_stop_command_goes_first_and_is_followed_by_a_task_poll(rig):
    h, port = rig
    port.run(1500)
    assert port.kinds()[0] == STOP
    assert port.kinds()[1] == READ_TASK
    assert h.fbEngine.o_bInitDone and h.fbEngine.o_bOK and not h.fbEngine.o_bErr


def test_requests_are_paced_at_least_300_ms_start_to_start(rig):
    h, port = rig
    port.running_polls = 20
    start_point(h, port)
    port.run(4000)
    starts = [t for t, _ in port.requests]
    assert len(starts) >= 8
    assert min(b - a for a, b in zip(starts, starts[1:])) >= 300_000


def test_run_point_polls_until_idle_then_ends_ok(rig):
    h, port = rig
    start_point(h, port, point=5)
    port.run(5000, until=lambda x: x.fbRun.o_bOK or x.fbRun.o_bErr)
    assert h.fbRun.o_bOK and not h.fbRun.o_bErr
    sent = port.kinds()
    run = encode(ControlRequest(1, 1, 5), SETTINGS)
    i = sent.index(run)
    assert sent[i + 1:] == [READ_TASK] * (port.running_polls + 1)


def test_never_transmits_while_a_reply_is_due(rig):
    h, port = rig
    port.turnaround_us = 280_000          # slow robot: the reply comes after the pacing period
    start_point(h, port)
    port.run(6000)
    assert port.requests and port.overlaps == []


def test_no_reply_three_attempts_then_0101(rig):
    h, port = rig
    start_point(h, port)
    port.silent = True
    before = len(port.requests)
    port.run(5000, until=lambda x: x.fbRun.o_bErr)
    assert h.fbRun.o_bErr and h.fbRun.o_uErrId == 0x0101
    attempts = port.requests[before:]
    assert len(attempts) == 3 and len({d for _, d in attempts}) == 1
    gaps = [b[0] - a[0] for a, b in zip(attempts, attempts[1:])]
    assert all(g >= 500_000 + 200_000 for g in gaps)      # time-out + guard time


def test_bad_crc_is_retried_and_reported_after_the_last_attempt(rig):
    h, port = rig
    start_point(h, port)
    port.corrupt = True
    port.run(5000, until=lambda x: x.fbRun.o_bErr)
    assert h.fbRun.o_uErrId == 0x0102
    assert h.fbEngine.o_wRetryCount >= 2


def test_exception_reply_is_not_retried(rig):
    h, port = rig
    start_point(h, port)
    port.exception_code = 4
    before = len(port.requests)
    port.run(3000, until=lambda x: x.fbRun.o_bErr)
    assert h.fbRun.o_uErrId == 0x0103 and h.fbEngine.o_uErrDetail == 4
    assert len(port.requests) - before == 1


def test_robot_anti_collision_fails_the_waiting_command(rig):
    h, port = rig
    start_point(h, port)
    port.robot_error = 1
    port.run(3000, until=lambda x: x.fbRun.o_bErr)
    assert h.fbRun.o_uErrId == 0x0201


def test_commands_requested_together_are_queued_not_lost(rig):
    h, port = rig
    port.run(1500, until=lambda x: x.fbEngine.o_bInitDone)
    h.wStage, h.wQuery, h.wPoint = 3, 3, 2
    h.bSpeed = h.bRead = h.bRun = True            # the same scan
    port.run(8000, until=lambda x: x.fbSpeed.o_bOK and x.fbRead.o_bOK and x.fbRun.o_bOK)
    assert h.fbSpeed.o_bOK and h.fbRead.o_bOK and h.fbRun.o_bOK
    controls = [d for d in port.kinds() if d[1] == 6][1:]
    # served one after the other, in the order the FBs are called (fbRun before fbSpeed)
    assert controls == [encode(ControlRequest(1, 1, 2), SETTINGS), encode(ControlRequest(1, 2, 2), SETTINGS)]
    assert encode(StatusRequest(1, 3), SETTINGS) in port.kinds()


def test_stop_overtakes_a_running_point(rig):
    h, port = rig
    port.running_polls = 50
    start_point(h, port)
    port.run(1500)
    assert h.fbRun.o_bBusy
    count = len(port.requests)
    h.bStop = True
    port.run(2000, until=lambda x: x.fbStop.o_bOK)
    assert h.fbRun.o_bErr and h.fbRun.o_uErrId == 0x0305
    assert h.fbStop.o_bOK
    assert port.kinds()[count] == STOP            # the very next frame


def test_a_stop_also_ends_a_command_still_waiting_in_the_mailbox(rig):
    """Found writing a station program: start pressed while the robot was silent (the
    monitor's status read being retried), then the emergency stop. The run-point request
    waited in the mailbox, the engine had not taken it yet; the stop was sent, and then
    the run point: the robot drove off after the emergency stop."""
    h, port = rig
    h.bMonitor = True
    port.run(1500, until=lambda x: x.fbEngine.o_bInitDone)
    port.run(400)
    port.silent = True                     # the monitor's next poll gets no reply
    port.run(350)
    h.wPoint, h.bRun = 4, True             # start: the request waits behind the poll
    port.run(100)
    assert h.uMbx[0] == 1                  # requested, not taken by the engine
    h.bStop = True                         # emergency stop
    port.run(100)
    port.silent = False
    count = len(port.requests)
    port.run(4000)
    run4 = encode(ControlRequest(1, 1, 4), SETTINGS)
    assert run4 not in port.kinds()[count - 1:], "run point 4 was sent after the stop"
    assert h.fbStop.o_bOK
    assert h.fbRun.o_bErr and h.fbRun.o_uErrId == 0x0305 and not h.fbRun.o_bBusy


def test_a_stop_also_ends_the_commands_queued_behind_the_running_one(rig):
    """A speed command queued (o_bBusy) behind a running point, then the stop: the point
    ends with 16#0305, and the speed command, which would have been posted as the point's
    slot came free, must not go out after the stop either."""
    h, port = rig
    start_long_point(h, port)
    h.wStage, h.bSpeed = 2, True
    port.run(100)
    assert h.fbRun.o_bBusy and h.fbSpeed.o_bBusy
    count = len(port.requests)
    h.bStop = True
    port.run(3000, until=lambda x: x.fbStop.o_bOK)
    port.run(1000)
    assert port.kinds()[count] == STOP
    assert not [d for d in port.kinds()[count:] if d[1] == 6 and d != STOP]
    assert h.fbRun.o_uErrId == 0x0305
    assert h.fbSpeed.o_bErr and h.fbSpeed.o_uErrId == 0x0305 and not h.fbSpeed.o_bBusy


def test_a_command_a_stop_ends_shows_no_value_of_an_earlier_command(rig):
    """A status read the stop ended while it waited for a retry showed o_wRobotErr 3 - the
    battery warning of the read before it, left in the slot - while one the stop ended
    still unsent in the mailbox showed 0: the stop's 16#0305 carries no status value."""
    h, port = rig
    port.run(1500, until=lambda x: x.fbEngine.o_bInitDone)
    port.robot_error = 3                              # battery warning: the read ends ok
    h.wQuery, h.bRead = 3, True
    port.run(2000, until=lambda x: x.fbRead.o_bOK)
    assert h.fbRead.o_wRobotErr == 3
    h.bRead = False
    port.run(50)
    port.robot_error, port.silent = 0, True           # the next read waits for a retry
    h.wQuery, h.bRead = 0, True
    port.run(600)
    assert h.uMbx[0] == 2 and h.fbRead.o_bBusy
    h.bStop = True
    port.run(20)
    port.silent = False
    port.run(3000, until=lambda x: x.fbStop.o_bOK)
    assert h.fbRead.o_bErr and h.fbRead.o_uErrId == 0x0305
    assert h.fbRead.o_wValue == 0 and h.fbRead.o_wRobotErr == 0


def test_a_command_started_after_the_stop_ended_is_sent(rig):
    h, port = rig
    start_long_point(h, port)
    h.bStop = True
    port.run(3000, until=lambda x: x.fbStop.o_bOK)
    h.bRun = False
    port.run(50)
    port.running_polls = 1
    h.wPoint, h.bRun = 6, True
    port.run(3000, until=lambda x: x.fbRun.o_bOK or x.fbRun.o_bErr)
    assert h.fbRun.o_bOK
    assert encode(ControlRequest(1, 1, 6), SETTINGS) in port.kinds()


def test_out_of_range_parameters_send_nothing(rig):
    h, port = rig
    port.run(1500, until=lambda x: x.fbEngine.o_bInitDone)
    count = len(port.requests)
    h.wPoint, h.bRun = 22, True
    h.wAxis, h.eValue, h.bMove = 1, 30.0, True
    h.eRange, h.bRange = 0.3, True
    port.run(100)
    assert h.fbRun.o_uErrId == h.fbMove.o_uErrId == h.fbRange.o_uErrId == 0x0301
    assert len(port.requests) == count


# 1.3 m / 0.1 and 0.59 m / 0.2 are 12.999999 and 2.9499998 in REAL: an FX3 CPU's
# REAL_TO_INT drops the fraction (docs/instructions.md §3), the FBs must still send 13 and 3
# (25.54 m rounds to 255, the byte's largest value: sent, not refused)
@pytest.mark.parametrize("axis,value,code,units", [(1, 1.5, 6, 15), (1, -2.0, 7, 20), (2, 0.3, 8, 3),
                                                   (3, -25.5, 11, 255), (4, -0.25, 13, 25), (4, 2.55, 12, 255),
                                                   (1, 1.3, 6, 13), (1, -1.3, 7, 13), (4, 0.29, 12, 29),
                                                   (1, 25.54, 6, 255)])
def test_relative_moves_in_engineering_units(rig, axis, value, code, units):
    h, port = rig
    port.run(1500, until=lambda x: x.fbEngine.o_bInitDone)
    h.wAxis, h.eValue, h.bMove = axis, value, True
    port.run(2000, until=lambda x: x.fbMove.o_bOK)
    assert encode(ControlRequest(1, code, units), SETTINGS, strict=False) in port.kinds()


@pytest.mark.parametrize("metres,step", [(0.0, 0), (0.2, 1), (0.4, 2), (0.61, 3), (0.59, 3), (0.39, 2),
                                         (-0.04, 0)])
def test_collision_range_steps(rig, metres, step):
    h, port = rig
    port.run(1500, until=lambda x: x.fbEngine.o_bInitDone)
    h.eRange, h.bRange = metres, True
    port.run(2000, until=lambda x: x.fbRange.o_bOK)
    assert encode(ControlRequest(1, 4, step), SETTINGS) in port.kinds()


def test_disabling_the_engine_fails_pending_commands_and_reenabling_stops_first(rig):
    h, port = rig
    start_long_point(h, port)
    h.bEnable = False
    port.run(100)
    assert h.fbRun.o_bErr and h.fbRun.o_uErrId == 0x0302
    h.bEnable = True
    count = len(port.requests)
    port.run(1500)
    assert port.kinds()[count] == STOP


def test_monitor_polls_the_four_statuses(rig):
    h, port = rig
    h.bMonitor = True
    port.run(3000)
    queries = [d[3] for d in port.kinds() if d[1] == 1]
    assert {0, 1, 2, 3} <= set(queries)


def test_silent_robot_at_power_on_refuses_commands_then_recovers(rig):
    h, port = rig
    port.silent = True
    port.run(2300)                                   # three attempts of the stop have failed
    assert not h.fbEngine.o_bInitDone and h.fbEngine.o_uErrId == 0x0101
    assert {d for d in port.kinds()} == {STOP}       # nothing but the stop was ever sent
    h.wPoint, h.bRun = 1, True
    port.run(500, until=lambda x: x.fbRun.o_bErr)
    assert h.fbRun.o_uErrId == 0x0107
    port.silent = False
    port.run(6000, until=lambda x: x.fbEngine.o_bInitDone)
    assert h.fbEngine.o_bInitDone
    h.bRun = False
    port.run(50)
    h.bRun = True
    port.run(3000, until=lambda x: x.fbRun.o_bOK)
    assert h.fbRun.o_bOK


def test_stray_bytes_keep_the_line_quiet_before_a_retry(rig):
    h, port = rig
    start_point(h, port)
    port.silent = True
    port.run(520)                                     # the attempt has timed out: guard time runs
    before = len(port.requests)
    for _ in range(3):                                # a late reply trickles in every 100 ms
        port.run(100)
        h.uPort[RX_LEN], h.uPort[RX_DONE] = 3, 1
    port.run(150)
    assert len(port.requests) == before               # still quiet: guard restarted each time
    port.run(300)
    assert len(port.requests) == before + 1


def test_idle_polls_to_end_is_one_constant():
    text = (CORE / "UITAMR_Engine.st").read_text().replace(
        "IDLE_POLLS_TO_END : INT := 1;", "IDLE_POLLS_TO_END : INT := 2;")
    project = verifier.load(CORE, sources={str(CORE / "UITAMR_Engine.st"): text, "T_Engine.st": HARNESS})
    h = project.program("T_Engine")
    port = FakePort(h, project, running_polls=0)      # the robot never reports 'running'
    h.bEnable = True
    start_point(h, port, point=4)
    port.run(3000, until=lambda x: x.fbRun.o_bOK)
    sent = port.kinds()
    after = sent[sent.index(encode(ControlRequest(1, 1, 4), SETTINGS)) + 1:]
    assert after == [READ_TASK, READ_TASK]                # two 'idle' answers in a row


COMMANDS = {"bRun": "fbRun", "bStop": "fbStop", "bSpeed": "fbSpeed", "bRead": "fbRead",
            "bMove": "fbMove", "bRange": "fbRange"}


@hsettings(max_examples=12, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(st.lists(st.tuples(st.sampled_from(sorted(COMMANDS)), st.integers(0, 1500)), min_size=1, max_size=5),
       st.lists(st.sampled_from(["ok", "ok", "silent", "corrupt", "exception", "error"]), min_size=8, max_size=8))
def test_every_command_ends_in_ok_or_err_whatever_the_line_does(commands, behaviours):
    project = verifier.load(CORE, sources={"T_Engine.st": HARNESS})
    h = project.program("T_Engine")
    port = FakePort(h, project)
    h.bEnable = True
    h.wPoint, h.wStage, h.wQuery, h.wAxis, h.eValue, h.eRange = 2, 2, 1, 3, 0.5, 0.2
    port.run(1500)
    started = []
    for step, (flag, delay_ms) in enumerate(commands):
        mode = behaviours[step % len(behaviours)]
        port.silent, port.corrupt = mode == "silent", mode == "corrupt"
        port.exception_code = 3 if mode == "exception" else None
        port.robot_error = 2 if mode == "error" else 0
        setattr(h, flag, True)
        started.append(COMMANDS[flag])
        port.run(delay_ms)
    port.silent, port.corrupt, port.exception_code, port.robot_error = False, False, None, 0

    def all_ended(x):
        return all(getattr(x, fb).o_bOK or getattr(x, fb).o_bErr for fb in set(started))
    port.run(40_000, until=all_ended)
    assert all_ended(h), {fb: (getattr(h, fb).o_bBusy, getattr(h, fb).o_uErrId) for fb in set(started)}
    assert port.overlaps == []
    starts = [t for t, _ in port.requests]
    assert all(b - a >= 300_000 for a, b in zip(starts, starts[1:]))


# ---------------------------------------------------------------------------- latching (PLCopen)
def test_inputs_are_latched_on_the_execute_edge_not_when_the_request_is_posted(rig):
    """QA finding 4: a queued command must send what its inputs were at its rising edge."""
    h, port = rig
    port.running_polls = 6
    start_point(h, port, point=1)                     # fbRun keeps the engine busy
    port.run(400)
    assert h.fbRun.o_bBusy
    h.wPointB, h.bRunB = 2, True                      # queued behind fbRun
    h.wStage, h.bSpeed = 2, True
    h.wAxis, h.eValue, h.bMove = 1, 1.5, True
    h.wQuery, h.bRead = 1, True
    port.run(50)
    assert h.fbRunB.o_bBusy and h.fbSpeed.o_bBusy and h.fbMove.o_bBusy and h.fbRead.o_bBusy
    h.wPointB = 192                                   # 16#C0: coordinate reset if read late
    h.wStage = 4
    h.wAxis, h.eValue = 4, -0.25
    h.wQuery = 7                                      # out of range if checked late
    port.run(15_000, until=lambda x: all(getattr(x, fb).o_bOK or getattr(x, fb).o_bErr
                                         for fb in ("fbRunB", "fbSpeed", "fbMove", "fbRead")))
    assert h.fbRunB.o_bOK and h.fbSpeed.o_bOK and h.fbMove.o_bOK and h.fbRead.o_bOK
    sent = port.kinds()
    latched = [encode(ControlRequest(1, 1, 2), SETTINGS), encode(ControlRequest(1, 2, 1), SETTINGS),
               encode(ControlRequest(1, 6, 15), SETTINGS), encode(StatusRequest(1, 1), SETTINGS)]
    assert all(frame in sent for frame in latched)
    late = [encode(ControlRequest(1, 1, 0xC0), SETTINGS), encode(ControlRequest(1, 2, 3), SETTINGS),
            encode(ControlRequest(1, 13, 25), SETTINGS)]
    assert not any(frame in sent for frame in late)


def test_a_new_value_needs_a_new_edge(rig):
    h, port = rig
    port.run(1500, until=lambda x: x.fbEngine.o_bInitDone)
    h.wPointB, h.bRunB = 4, True
    port.run(3000, until=lambda x: x.fbRunB.o_bOK)
    h.wPointB = 6                                     # held Execute: nothing new is sent
    port.run(1000)
    assert encode(ControlRequest(1, 1, 6), SETTINGS) not in port.kinds()
    h.bRunB = False
    port.run(50)
    h.bRunB = True
    port.run(3000, until=lambda x: x.fbRunB.o_bOK)
    assert encode(ControlRequest(1, 1, 6), SETTINGS) in port.kinds()


def test_a_rising_edge_while_busy_is_ignored_as_the_library_page_says(rig):
    """A second rising edge on the same FB while o_bBusy sends nothing: the running command
    goes on and its o_bOK follows. plc-library.md said only "send the new value with a new
    rising edge", which an integrator reads as "re-trigger at once"; it now says the edge
    must come after the command has ended, as UITAMR_Command's header does."""
    h, port = rig
    port.running_polls = 8
    start_point(h, port, point=1)
    port.run(500)
    assert h.fbRun.o_bBusy
    h.bRun = False
    port.run(50)
    h.wPoint, h.bRun = 2, True                        # re-triggered while busy
    port.run(8000, until=lambda x: x.fbRun.o_bOK or x.fbRun.o_bErr)
    assert h.fbRun.o_bOK
    assert encode(ControlRequest(1, 1, 2), SETTINGS) not in port.kinds()
    page = " ".join((ROOT / "docs" / "plc-library.md").read_text(encoding="utf-8").split())
    assert ("a new rising edge once the command has ended (`o_bOK` or `o_bErr`): a rising edge "
            "while `o_bBusy` is ignored") in page


# ---------------------------------------------------------------------------- i_bEN / o_bENO
def test_eno_mirrors_en_on_command_fbs_and_engine(rig):
    h, port = rig
    port.run(100)
    assert h.fbEngine.o_bENO and h.fbRun.o_bENO and h.fbStop.o_bENO
    h.bCmdOff, h.bEnable = True, False
    port.run(20)
    assert not h.fbEngine.o_bENO
    assert not any(getattr(h, fb).o_bENO for fb in ("fbRun", "fbStop", "fbSpeed", "fbRead", "fbMove", "fbRange"))


def test_a_command_fb_without_en_ignores_execute(rig):
    h, port = rig
    port.run(1500, until=lambda x: x.fbEngine.o_bInitDone)
    count = len(port.requests)
    h.bCmdOff = True
    h.wPoint, h.bRun = 3, True
    port.run(1000)
    assert not (h.fbRun.o_bBusy or h.fbRun.o_bOK or h.fbRun.o_bErr)
    assert all(d[1] == 1 or d == STOP for d in port.kinds()[count:])   # no control frame
    h.bCmdOff = False                                 # EN back with Execute held: needs a new edge
    port.run(500)
    assert not h.fbRun.o_bBusy


def test_en_off_withdraws_a_queued_request_and_frees_the_mailbox(rig):
    h, port = rig
    port.running_polls = 6
    h.wPointB = 1
    port.run(1500, until=lambda x: x.fbEngine.o_bInitDone)
    h.bRunB = True                                    # fbRunB keeps the engine busy (EN always on)
    port.run(400)
    h.wPoint, h.bRun = 9, True                        # queued behind it
    port.run(50)
    assert h.fbRun.o_bBusy
    h.bCmdOff = True                                  # withdrawn before the engine took it
    port.run(50)
    assert not h.fbRun.o_bBusy and not h.fbRun.o_bOK and not h.fbRun.o_bErr
    port.run(6000, until=lambda x: x.fbRunB.o_bOK)
    assert encode(ControlRequest(1, 1, 9), SETTINGS) not in port.kinds()
    h.bCmdOff, h.bRun = False, False
    port.run(50)
    h.wPoint, h.bRun = 7, True                        # the mailbox is usable again
    port.run(6000, until=lambda x: x.fbRun.o_bOK)
    assert h.fbRun.o_bOK


def test_en_off_while_the_engine_serves_the_command_discards_the_result_and_frees_the_slot(rig):
    h, port = rig
    port.running_polls = 4
    start_point(h, port, point=5)
    port.run(400)                                     # sent, the engine polls its task
    assert encode(ControlRequest(1, 1, 5), SETTINGS) in port.kinds()
    h.bCmdOff = True
    port.run(4000)
    assert not (h.fbRun.o_bOK or h.fbRun.o_bErr or h.fbRun.o_bBusy)
    assert h.uMbx[0] == 0                             # slot freed once the engine was done
    h.bCmdOff, h.bRun = False, False
    port.run(50)
    h.wPoint, h.bRun = 8, True
    port.run(6000, until=lambda x: x.fbRun.o_bOK)
    assert h.fbRun.o_bOK and encode(ControlRequest(1, 1, 8), SETTINGS) in port.kinds()


# ---------------------------------------------------------------------------- parameters at type limits
@pytest.mark.parametrize("metres", [7000.0, -7000.0, 1.0e30, -3.0e38])
def test_a_collision_range_beyond_int_is_0301_without_an_operation_error(metres):
    """REAL_TO_INT of i_eRange / 0.2 beyond INT is an operation error, which stops a Q CPU;
    the FB evaluates its range on every scan, so a bad HMI value alone used to stop it."""
    project = verifier.load(CORE, sources={"T_Engine.st": HARNESS}, target="gxworks2:q")
    h = project.program("T_Engine")
    port = FakePort(h, project)
    h.bEnable = True
    port.run(1500, until=lambda x: x.fbEngine.o_bInitDone)
    count = len(port.requests)
    h.eRange = metres                                 # no Execute yet: the value alone
    port.run(100)
    h.bRange = True
    port.run(100)
    assert h.fbRange.o_bErr and h.fbRange.o_uErrId == 0x0301
    assert all(d[1] == 1 for d in port.kinds()[count:])   # no control frame
    assert project.diagnostics == []
    h.bRange, h.eRange = False, 0.4
    port.run(50)
    h.bRange = True
    port.run(2000, until=lambda x: x.fbRange.o_bOK)
    assert h.fbRange.o_bOK and encode(ControlRequest(1, 4, 2), SETTINGS) in port.kinds()


# ---------------------------------------------------------------------------- the robot address
ERR_ADDRESS = 0x0315


def rising_edges(samples):
    return sum(1 for a, b in zip([False] + samples, samples) if b and not a)


@pytest.mark.parametrize("address", [300, -5, 248, -32768])
def test_an_address_out_of_range_is_one_error_and_nothing_is_sent(rig, address):
    """Before: the engine tried the power-on stop every INIT_RETRY_TIME, the frame builder
    refused it each time (16#0301, detail 1 = the control code) and every command ended with
    16#0107 'stop not acknowledged'. Now: one 16#0315 naming the address, held."""
    h, port = rig
    h.wAddress = address
    errs, ids = [], set()
    for _ in range(500):                                   # 5 s: two INIT_RETRY_TIMEs
        port.run(10)
        errs.append(h.fbEngine.o_bErr)
        ids.add((h.fbEngine.o_uErrId, h.fbEngine.o_uErrDetail))
    assert port.requests == []
    assert rising_edges(errs) == 1 and all(errs[1:])
    assert ids == {(ERR_ADDRESS, address & 0xFFFF)}
    assert not (h.fbEngine.o_bOK or h.fbEngine.o_bReady or h.fbEngine.o_bBusy or h.fbEngine.o_bInitDone)
    assert h.fbEngine.o_bENO
    h.wPoint, h.bRun, h.bStop, h.wQuery, h.bRead = 3, True, True, 0, True
    port.run(30)                                           # each command ends at once, with the same error
    for fb in (h.fbRun, h.fbStop, h.fbRead):                # the wrappers show no detail
        assert fb.o_bErr and not fb.o_bBusy and fb.o_uErrId == ERR_ADDRESS
    h.bMonitor = True
    port.run(2000)
    assert port.requests == []
    assert h.uMbx[0] == 0 and h.uMbx[8] == 0               # the mailbox is free again


def test_fixing_the_address_recovers_with_the_stop_first(rig):
    h, port = rig
    h.wAddress = 300
    port.run(3000)
    h.wAddress = 1
    port.run(20)
    assert not h.fbEngine.o_bErr and h.fbEngine.o_uErrId == 0   # cleared as by a rising edge
    port.run(1500, until=lambda x: x.fbEngine.o_bInitDone)
    assert h.fbEngine.o_bInitDone
    assert port.kinds()[0] == STOP                          # the first frame is the stop
    h.wPoint, h.bRun = 3, True
    port.run(5000, until=lambda x: x.fbRun.o_bOK)
    assert h.fbRun.o_bOK and encode(ControlRequest(1, 1, 3), SETTINGS) in port.kinds()
    assert not h.fbEngine.o_bErr


def test_an_address_going_out_of_range_ends_the_running_command_and_needs_the_stop_again(rig):
    h, port = rig
    start_long_point(h, port)
    h.wAddress = 0x1000
    port.run(600)                                           # a reply still due is discarded
    count = len(port.requests)
    assert h.fbRun.o_bErr and h.fbRun.o_uErrId == ERR_ADDRESS
    assert (h.fbEngine.o_uErrId, h.fbEngine.o_uErrDetail) == (ERR_ADDRESS, 0x1000)
    assert not h.fbEngine.o_bInitDone
    port.run(3000)
    assert len(port.requests) == count                      # nothing more on the line
    h.wAddress = 0                                          # 0: the default address 1
    port.run(1500, until=lambda x: x.fbEngine.o_bInitDone)
    assert port.kinds()[count] == STOP


def test_reenabling_with_the_address_still_out_of_range_raises_it_again_and_sends_nothing(rig):
    h, port = rig
    h.wAddress = 300
    port.run(200)
    h.bEnable = False
    h.wPoint, h.bRun = 3, True
    port.run(50)
    assert h.fbRun.o_bErr and h.fbRun.o_uErrId == 0x0302    # disabled wins: the engine does not run
    h.bEnable, h.bRun = True, False
    port.run(1000)
    assert h.fbEngine.o_bErr and h.fbEngine.o_uErrId == ERR_ADDRESS
    assert port.requests == []


@pytest.mark.parametrize("address", [1, 247])
def test_the_limits_of_the_address_range_are_sent(rig, address):
    h, port = rig
    port.silent = True
    h.wAddress = address
    port.run(400)
    assert port.kinds() and port.kinds()[0][0] == address
    assert h.fbEngine.o_uErrId != ERR_ADDRESS


def test_another_valid_address_is_another_robot_the_stop_goes_first_to_it(rig):
    """Changing i_wAddress from 1 to 2 while a point runs: the robot at address 2 gets the
    stop before anything else (it may have just been powered on), the command asked of the
    robot at address 1 ends with 16#0305, and commands are served at address 2 after."""
    h, port = rig
    start_long_point(h, port)
    count = len(port.requests)
    h.wAddress = 2
    port.run(1500, until=lambda x: x.fbEngine.o_bInitDone)
    assert h.fbRun.o_bErr and h.fbRun.o_uErrId == 0x0305
    sent = port.kinds()[count:]
    assert sent and sent[0] == encode(ControlRequest(2, 1, 0xA0), SETTINGS)
    assert all(frame[0] == 2 for frame in sent)
    assert h.fbEngine.o_bInitDone and not h.fbEngine.o_bErr
    h.bRun = False
    port.run(50)
    port.running_polls = 2
    h.wPoint, h.bRun = 4, True
    port.run(5000, until=lambda x: x.fbRun.o_bOK or x.fbRun.o_bErr)
    assert h.fbRun.o_bOK and encode(ControlRequest(2, 1, 4), SETTINGS) in port.kinds()
    count = len(port.requests)
    h.wAddress = 0                                          # 0 is address 1: another robot again
    port.run(1500, until=lambda x: x.fbEngine.o_bInitDone)
    assert port.kinds()[count] == STOP


def test_the_same_robot_by_another_spelling_is_not_a_new_robot(rig):
    """0 and 1 name the same robot: switching between them sends no new stop."""
    h, port = rig
    port.run(1500, until=lambda x: x.fbEngine.o_bInitDone)
    stops = port.kinds().count(STOP)
    h.wAddress = 0
    port.run(2000)
    assert port.kinds().count(STOP) == stops and h.fbEngine.o_bInitDone


@pytest.mark.parametrize("scan_ms", [7, 10, 13])
def test_pacing_keeps_the_robots_250_ms_with_100_ms_timers(scan_ms):
    """An FX5 TON may count in 100 ms units (docs/instructions.md §4): the pace timer then
    ends up to a tick early, and start-to-start must still exceed the robot's 250 ms."""
    project = verifier.load(CORE, sources={"T_Engine.st": HARNESS}, timer_resolution_ms=100,
                            scan_ms=scan_ms)
    h = project.program("T_Engine")
    port = FakePort(h, project)
    h.wAddress, h.bEnable = 1, True
    port.running_polls = 20
    start_point(h, port)
    port.run(4000)
    starts = [t for t, _ in port.requests]
    assert len(starts) >= 8
    assert min(b - a for a, b in zip(starts, starts[1:])) > 250_000
