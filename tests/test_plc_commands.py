"""Command FBs as an integrator wires them: the library on an FX3U (RS2 channel 1) against
the emulated robot, with the engine's call under the test's control."""
from __future__ import annotations

from pathlib import Path

import pytest

import verifier
from verifier.amr import Robot
from verifier.amr.config import RobotConfig
from verifier.link import Line
from verifier.protocol import ControlRequest, Settings, encode

PLC = Path(__file__).resolve().parents[1] / "plc"
SETTINGS = Settings()

HARNESS = """
PROGRAM T_Commands
VAR
    fbPort : UITAMR_PortFx3;
    fbEngine : UITAMR_Engine;
    fbRun : UITAMR_RunPoint;
    fbSpeed : UITAMR_SetSpeed;
    fbJog : UITAMR_Jog;
    fbJogStop : UITAMR_Jog;
    uMbx : ARRAY[0..15] OF WORD;
    uPort : ARRAY[0..39] OF WORD;
    bCallEngine : BOOL;
    bCmdOff : BOOL;
    bRun : BOOL;
    wPoint : INT;
    bSpeed : BOOL;
    bJog : BOOL;
    wJogDir : INT;
    bJogStop : BOOL;
END_VAR
fbPort(i_bEN := TRUE, i_wChannel := 1, i_bRs232 := FALSE, io_uPort := uPort);
IF bCallEngine THEN
    fbEngine(i_bEN := NOT M8002, i_wAddress := 1, i_bMonitor := FALSE, io_uMbx := uMbx, io_uPort := uPort);
END_IF;
fbRun(i_bEN := NOT bCmdOff, i_bExecute := bRun, i_wPoint := wPoint, io_uMbx := uMbx);
fbSpeed(i_bEN := TRUE, i_bExecute := bSpeed, i_bMagnetic := FALSE, i_wStage := 2, io_uMbx := uMbx);
fbJog(i_bEN := TRUE, i_bExecute := bJog, i_wDirection := wJogDir, io_uMbx := uMbx);
fbJogStop(i_bEN := TRUE, i_bExecute := bJogStop, i_wDirection := 0, io_uMbx := uMbx);
END_PROGRAM
"""


def rig(point_duration_s=1.0):
    project = verifier.load(PLC / "core", PLC / "fx3", sources={"T_Commands.st": HARNESS})
    line = Line(Robot(config=RobotConfig(point_duration_s=point_duration_s)))
    project.attach_serial("fx3:1", line)
    h = project.program("T_Commands")
    h.bCallEngine = True
    return project, h, line


def run(project, ms, until=None):
    stop = project.now_us + ms * 1000
    while project.now_us < stop:
        project.run_programs(["T_Commands"], scans=1)
        if until is not None and until(project.program("T_Commands")):
            return


def sent(line):
    return [f.data for f in line.trace if f.direction == "tx"]


def test_a_request_the_engine_never_takes_ends_with_0303_and_is_withdrawn():
    """docs/plc-library.md: 16#0303 'command not taken by the engine within 30 s - is the
    engine called every scan?'. With the mailbox free the request was posted at once and,
    with no engine to take it, the FB stayed busy for ever."""
    project, h, line = rig()
    run(project, 1500, until=lambda x: x.fbEngine.o_bInitDone)
    assert h.fbEngine.o_bInitDone
    h.bCallEngine = False                             # e.g. the engine's call is skipped
    h.wPoint, h.bRun = 2, True
    run(project, 29_000)
    assert h.fbRun.o_bBusy and not h.fbRun.o_bErr
    run(project, 1_100, until=lambda x: x.fbRun.o_bErr)
    assert h.fbRun.o_bErr and h.fbRun.o_uErrId == 0x0303 and not h.fbRun.o_bBusy
    assert h.uMbx[0] == 0                             # the request is withdrawn
    h.bCallEngine = True                              # the engine is back: nothing stale is sent
    run(project, 2000)
    assert encode(ControlRequest(1, 1, 2), SETTINGS) not in sent(line)
    h.bRun = False
    run(project, 50)
    h.wPoint, h.bRun = 3, True
    run(project, 5000, until=lambda x: x.fbRun.o_bOK)
    assert h.fbRun.o_bOK and encode(ControlRequest(1, 1, 3), SETTINGS) in sent(line)


def test_an_edge_when_en_returns_is_served_after_the_discarded_command():
    """i_bEN off while the engine serves a command discards its result. When i_bEN came
    back with a rising edge of i_bExecute in the same scan, the FB still showed o_bBusy for
    the discarded command, ignored the edge, then dropped o_bBusy with neither o_bOK nor
    o_bErr: the new command was lost while i_bExecute stayed TRUE."""
    project, h, line = rig()
    run(project, 1500, until=lambda x: x.fbEngine.o_bInitDone)
    h.wPoint, h.bRun = 2, True
    run(project, 400)                                 # sent; the engine polls the task
    assert encode(ControlRequest(1, 1, 2), SETTINGS) in sent(line)
    h.bCmdOff, h.bRun = True, False
    run(project, 100)
    h.bCmdOff, h.wPoint, h.bRun = False, 3, True      # EN back and a new edge, same scan
    states = []

    def record(x):
        states.append((x.fbRun.o_bBusy, x.fbRun.o_bOK, x.fbRun.o_bErr))
        return x.fbRun.o_bOK or x.fbRun.o_bErr
    run(project, 8000, until=record)
    assert h.fbRun.o_bOK and not h.fbRun.o_bErr
    busy = [s[0] for s in states]
    assert all(busy[:-1]) and not busy[-1]            # busy from the edge until it ends ok
    frames = sent(line)
    assert frames.index(encode(ControlRequest(1, 1, 3), SETTINGS)) > frames.index(
        encode(ControlRequest(1, 1, 2), SETTINGS))
    assert h.uMbx[0] == 0 and h.uMbx[8] == 0


def test_a_command_queued_behind_a_long_task_waits_for_it_and_is_sent():
    """Found writing a station program: the speed button pressed during a 45 s run to a
    point ended after 30 s with 16#0303 ('is the engine called every scan?') and was never
    sent, though the page says requests of several FBs are served one after the other and
    none is lost. A task may run up to TASK_TIMEOUT (10 min): the time a command ahead
    runs (the engine serving it) does not count against QUEUE_TIMEOUT."""
    project, h, line = rig(point_duration_s=40.0)
    run(project, 1500, until=lambda x: x.fbEngine.o_bInitDone)
    h.wPoint, h.bRun = 2, True
    run(project, 1000)
    h.bSpeed = True
    run(project, 500)
    assert h.fbRun.o_bBusy and h.fbSpeed.o_bBusy
    run(project, 45_000, until=lambda x: x.fbSpeed.o_bOK or x.fbSpeed.o_bErr)
    assert h.fbSpeed.o_bOK and not h.fbSpeed.o_bErr, hex(h.fbSpeed.o_uErrId)
    assert h.fbRun.o_bOK
    assert encode(ControlRequest(1, 2, 1), SETTINGS) in sent(line)


JOG_FORWARD = encode(ControlRequest(1, 5, 1), SETTINGS)
JOG_STOP = encode(ControlRequest(1, 5, 0), SETTINGS)


def test_hold_to_jog_needs_a_second_instance_for_the_stop():
    """Found writing a station's hold-to-jog buttons: with ONE UITAMR_Jog, direction 1 on
    the press and 0 on the release, a short tap released while the move command was still
    busy (its status read, ~0.3 s) gave an edge the FB ignored - the stop never went out
    and the robot kept moving. Pinned here as the page now says it, with the pattern it
    gives (a second instance for direction 0, as UITAMR_PanelFx3 has), which loses nothing."""
    project, h, line = rig()
    run(project, 1500, until=lambda x: x.fbEngine.o_bInitDone)
    h.wJogDir, h.bJog = 1, True                       # press
    run(project, 100)
    h.bJog = False
    run(project, 20)
    h.wJogDir, h.bJog = 0, True                       # release: a new edge while busy
    run(project, 3000)
    assert JOG_FORWARD in sent(line) and JOG_STOP not in sent(line)
    h.bJog = False
    run(project, 50)
    h.wJogDir, h.bJogStop = 1, False
    h.bJog = True                                     # press again
    run(project, 100)
    h.bJog, h.bJogStop = False, True                  # release: the second instance
    run(project, 3000, until=lambda x: x.fbJogStop.o_bOK or x.fbJogStop.o_bErr)
    assert h.fbJogStop.o_bOK
    frames = sent(line)
    assert frames.count(JOG_FORWARD) == 2 and frames[::-1].index(JOG_STOP) < frames[::-1].index(JOG_FORWARD)
    header = (PLC / "core" / "UITAMR_Jog.st").read_text()
    page = (PLC.parent / "docs" / "plc-library.md").read_text()
    for text in (header, page):
        assert "second instance" in text and "UITAMR_PanelFx3" in text


def test_one_button_hold_to_jog_as_the_library_page_wires_it():
    """A station with one hold-to-jog button (journey32b) wired the second instance's
    execute as `NOT X3`, the obvious release: a rising edge in the first scan too, so a jog
    stop went out after every power-on stop. plc-library.md now shows the wiring; its
    snippet, run as printed on an FX3U with the button on X3: nothing but the stop and the
    engine's reads until the press, then jog forward, and jog stop after the release, also
    after a tap released while the forward command is still busy."""
    import re

    page = (PLC.parent / "docs" / "plc-library.md").read_text(encoding="utf-8")
    section = page.split("**Hold-to-jog with `UITAMR_Jog`**", 1)[1].split("### The port interface", 1)[0]
    snippet = re.search(r"```iecst\n(.*?)```", section, re.S).group(1)
    program = ("PROGRAM T_Jog\nVAR\n    fbPort : UITAMR_PortFx3;\n    fbEngine : UITAMR_Engine;\n"
               "    fbJogFwd : UITAMR_Jog;\n    fbJogStop : UITAMR_Jog;\n    uMbx : ARRAY[0..15] OF WORD;\n"
               "    uPort : ARRAY[0..39] OF WORD;\n    bJogged : BOOL;\nEND_VAR\n"
               "fbPort(i_bEN := TRUE, i_wChannel := 1, i_bRs232 := FALSE, io_uPort := uPort);\n"
               "fbEngine(i_bEN := NOT M8002, i_wAddress := 1, i_bMonitor := TRUE, io_uMbx := uMbx, io_uPort := uPort);\n"
               + snippet + "END_PROGRAM\n")
    project = verifier.load(PLC / "core", PLC / "fx3", sources={"T_Jog.st": program})
    line = Line(Robot())
    project.attach_serial("fx3:1", line)
    jog_forward = encode(ControlRequest(1, 5, 1), SETTINGS)
    jog_stop = encode(ControlRequest(1, 5, 0), SETTINGS)

    def controls():
        return [f.data for f in line.trace if f.direction == "tx" and f.data[1] == 0x06]

    project.run_programs(["T_Jog"], ms=3000)
    assert controls() == [encode(ControlRequest(1, 1, 0xA0), SETTINGS)]        # the power-on stop only
    for hold_ms in (1500, 100):                                              # a hold, then a tap
        project.devices["X3"] = True
        project.run_programs(["T_Jog"], ms=hold_ms)
        project.devices["X3"] = False
        project.run_programs(["T_Jog"], ms=3000)
    assert controls()[1:] == [jog_forward, jog_stop, jog_forward, jog_stop]
    assert not project.program("T_Jog").bJogged


def post_once(cases):
    """One instance per (FB, its input assignments) with its own mailbox and no engine, all
    given one rising edge of i_bExecute: the program after that scan (fb<i>, uMbx<i>)."""
    decls = "".join(f"    fb{i} : {fb};\n    uMbx{i} : ARRAY[0..15] OF WORD;\n" for i, (fb, _) in enumerate(cases))
    calls = "".join(f"fb{i}(i_bEN := TRUE, i_bExecute := bGo, {arg + ', ' if arg else ''}io_uMbx := uMbx{i});\n"
                    for i, (_, arg) in enumerate(cases))
    harness = f"PROGRAM T_Wrappers\nVAR\n    bGo : BOOL;\n{decls}END_VAR\n{calls}END_PROGRAM\n"
    project = verifier.load(PLC / "core", sources={"T_Wrappers.st": harness})
    h = project.program("T_Wrappers")
    project.run_programs(["T_Wrappers"], scans=1)
    h.bGo = True
    project.run_programs(["T_Wrappers"], scans=1)
    return h


def test_every_table_2_command_has_a_wrapper_as_uitamr_command_says():
    """UITAMR_Command's header sent integrators to it "for commands without a wrapper, e.g.
    coordinate reset or manual mode" while UITAMR_SetMode wraps both. Each wrapper of code 1
    is run here (own mailbox, no engine) and what it posts is read back: every table-2
    command of the manual is posted by one, and the header now says so and names the
    wrapper of those two."""
    from verifier.protocol.catalogue import RobotCommand

    cases = [("UITAMR_Tape", f"i_wAction := {a}") for a in range(1, 9)]
    cases += [("UITAMR_SetMode", f"i_wMode := {m}") for m in (1, 2)]
    cases += [("UITAMR_Pause", ""), ("UITAMR_Stop", "")]
    h = post_once(cases)
    posted = set()
    for i, _ in enumerate(cases):
        mbx = getattr(h, f"uMbx{i}")
        slot = 8 if mbx[8] == 1 else 0  # UITAMR_Stop posts to the priority slot
        assert mbx[slot] == 1, cases[i]  # requested
        posted.add((mbx[slot + 2], mbx[slot + 3]))
    assert {(1, int(c)) for c in RobotCommand} <= posted
    header = " ".join((PLC / "core" / "UITAMR_Command.st").read_text(encoding="utf-8").split("*)", 1)[0].split())
    assert "without a wrapper" not in header
    assert "every command of the manual has one (coordinate reset and manual mode: UITAMR_SetMode)" in header


DIRECT = """
PROGRAM T_Direct
VAR
    fbPort : UITAMR_PortFx3;
    fbEngine : UITAMR_Engine;
    fbCmd : UITAMR_Command;
    uMbx : ARRAY[0..15] OF WORD;
    uPort : ARRAY[0..39] OF WORD;
    bGo : BOOL;
    wKind : INT;
    wCode : INT;
    wCommand : INT;
END_VAR
fbPort(i_bEN := TRUE, i_wChannel := 1, i_bRs232 := FALSE, io_uPort := uPort);
fbEngine(i_bEN := NOT M8002, i_wAddress := 1, i_bMonitor := FALSE, io_uMbx := uMbx, io_uPort := uPort);
fbCmd(i_bEN := TRUE, i_bExecute := bGo, i_wKind := wKind, i_wCode := wCode, i_wCommand := wCommand,
      i_bParamErr := FALSE, i_bPriority := FALSE, io_uMbx := uMbx);
END_PROGRAM
"""


def test_the_0301_detail_of_a_direct_uitamr_command_is_what_the_table_says():
    """plc-library.md gave 16#0301 no detail, but the engine sets one when UITAMR_Command is
    called directly with values it does not check: the kind when that is out of range, else
    the control code given - also when the command or the query is the culprit (a query of
    9 with i_wCode 7 shows detail 7). The table now says so; held here by running it."""
    import re

    project = verifier.load(PLC / "core", PLC / "fx3", sources={"T_Direct.st": DIRECT})
    line = Line(Robot())
    project.attach_serial("fx3:1", line)
    h = project.program("T_Direct")
    project.run_programs(["T_Direct"], until_us=1_500_000)
    for kind, code, command, detail in [(5, 1, 3, 5), (2, 14, 0, 14), (2, 1, 300, 1), (3, 7, 9, 7)]:
        h.wKind, h.wCode, h.wCommand, h.bGo = kind, code, command, True
        project.run_programs(["T_Direct"], until_us=project.now_us + 100_000)
        assert (h.fbCmd.o_bErr, h.fbCmd.o_uErrId, h.fbCmd.o_uErrDetail) == (True, 0x0301, detail)
        h.bGo = False
        project.run_programs(["T_Direct"], until_us=project.now_us + 50_000)
    doc = (PLC.parent / "docs" / "plc-library.md").read_text(encoding="utf-8")
    row = " ".join(re.search(r"^\| 16#0301 \|(.*)$", doc, flags=re.M).group(1).split())
    assert ("the kind (outside 1..3), else the `i_wCode` given - also when the command (0..255) or, "
            "for kind 3, the query (0..3) is the one out of range") in row.replace("—", "-")


def test_a_relative_move_is_accepted_while_it_rounds_into_the_command_byte():
    """UITAMR_MoveRelative rounds |i_eValue| / 0.1 m (0.01 rad) to the nearest unit but
    refused anything above 255.0 units before rounding: 25.54 m, which rounds to 255 (the
    byte's largest value, 25.5 m), ended with 16#0301 while 25.46 m, which rounds to 255
    too, was sent. It now refuses only what rounds above 255 (255.5 units or more, in
    REAL: 25.55 m is 255.49998 and 2.555 rad 255.50002), as its header says."""
    cases = [(1, "25.54", 6, 255), (3, "-25.54", 11, 255), (4, "2.554", 12, 255), (2, "25.549", 8, 255),
             (2, "-25.46", 9, 255), (1, "25.55", 6, 255),
             (1, "25.56", None, None), (4, "-2.556", None, None), (1, "25.551", None, None),
             (4, "2.555", None, None)]
    h = post_once([("UITAMR_MoveRelative", f"i_wAxis := {axis}, i_eValue := {value}")
                   for axis, value, _, _ in cases])
    for i, (axis, value, code, units) in enumerate(cases):
        fb, mbx = getattr(h, f"fb{i}"), getattr(h, f"uMbx{i}")
        if code is None:      # refused: 16#0301 at once, nothing posted
            assert (fb.o_bErr, fb.o_uErrId, mbx[0]) == (True, 0x0301, 0), (axis, value)
        else:                 # posted: requested, that code and that distance
            assert (fb.o_bErr, mbx[0], mbx[2], mbx[3]) == (False, 1, code, units), (axis, value)
    header = " ".join((PLC / "core" / "UITAMR_MoveRelative.st").read_text(encoding="utf-8").split("*)", 1)[0].split())
    assert "25.54 m sends 255; at 255.5 or more (25.56 m, 2.556 rad) 16#0301, nothing sent" in header


PAUSE_FRAME = encode(ControlRequest(1, 1, 0x80), SETTINGS)
POINT_3 = encode(ControlRequest(1, 1, 3), SETTINGS)


def _cell(declarations: str, body: str, point_duration_s: float = 8.0, faults=()):
    """A cell program on an FX3U (RS2 ch1) around `body`, the robot's point run taking
    `point_duration_s`: (project, robot, line, run(ms))."""
    program = ("PROGRAM T_Cell\nVAR\n    fbPort : UITAMR_PortFx3;\n    fbEngine : UITAMR_Engine;\n"
               "    uMbx : ARRAY[0..15] OF WORD;\n    uPort : ARRAY[0..39] OF WORD;\n" + declarations + "END_VAR\n"
               "fbPort(i_bEN := TRUE, i_wChannel := 1, i_bRs232 := FALSE, io_uPort := uPort);\n" + body + "END_PROGRAM\n")
    project = verifier.load(PLC / "core", PLC / "fx3", sources={"T_Cell.st": program})
    robot = Robot(config=RobotConfig(point_duration_s=point_duration_s), faults=faults)
    line = Line(robot)
    project.attach_serial("fx3:1", line)
    return project, robot, line, lambda ms: project.run_programs(["T_Cell"], ms=ms)


def _press(project, run, device, at_ms_from_now):
    run(at_ms_from_now)
    project.devices[device] = True
    run(300)
    project.devices[device] = False


def _controls_at(line):
    return [(round(f.t_start_us / 1e6, 2), f.data) for f in line.trace if f.direction == "tx" and f.data[1] == 0x06]


def _run_point_cell(declarations: str, body: str):
    """_cell with the engine (monitor on) and fbRun : UITAMR_RunPoint of point 3 on X0, a
    fbPause : UITAMR_Pause declared, and `body` after them."""
    return _cell("    fbRun : UITAMR_RunPoint;\n    fbPause : UITAMR_Pause;\n" + declarations,
                 "fbEngine(i_bEN := NOT M8002, i_wAddress := 1, i_bMonitor := TRUE, io_uMbx := uMbx, io_uPort := uPort);\n"
                 "fbRun(i_bEN := TRUE, i_bExecute := X0, i_wPoint := 3, io_uMbx := uMbx);\n" + body)


def test_a_pause_overtakes_a_run_point_and_a_second_run_point_is_no_resume():
    """journey33b: a cell wired from the page (start X0 -> UITAMR_RunPoint, pause X3 ->
    UITAMR_Pause) paused nothing: the pause pressed 3 s into an 8 s point went out after
    the point had ended (the run held the engine). The pause now overtakes the run: it is
    the next frame the pace allows, the robot pauses and the run stays busy without error.
    A second UITAMR_RunPoint of the same point is still no resume (kind 1: it queues behind
    the paused run); the stop ends both."""
    project, robot, line, run = _run_point_cell(
        "    fbResume : UITAMR_RunPoint;\n"
        "    fbStop : UITAMR_Stop;\n",
        "fbPause(i_bEN := TRUE, i_bExecute := X3, io_uMbx := uMbx);\n"
        "fbResume(i_bEN := TRUE, i_bExecute := X4, i_wPoint := 3, io_uMbx := uMbx);\n"
        "fbStop(i_bEN := TRUE, i_bExecute := X1, io_uMbx := uMbx);\n")
    h = project.program("T_Cell")
    _press(project, run, "X0", 2000)                          # point 3 from ~2.4 s, 8 s long
    run(2700)                                                 # 5.0 s
    pressed_at = project.now_us / 1e6
    _press(project, run, "X3", 0)                             # pause at 5 s
    run(500)
    (run_at, _), (pause_at, pause) = [c for c in _controls_at(line) if c[1] != _controls_at(line)[0][1]]
    assert pause == PAUSE_FRAME and pause_at < pressed_at + 0.35   # within one pace of the button
    assert robot.mode == "paused" and h.fbEngine.o_bPaused
    assert h.fbRun.o_bBusy and not h.fbRun.o_bOK and not h.fbRun.o_bErr
    _press(project, run, "X4", 2000)                          # "resume" with a second RunPoint at ~8 s
    run(8000)                                                 # 16 s: the point would long have ended
    assert robot.mode == "paused" and h.fbRun.o_bBusy and h.fbResume.o_bBusy
    assert [c[1] for c in _controls_at(line)][1:] == [POINT_3, PAUSE_FRAME]    # nothing else sent
    _press(project, run, "X1", 0)
    run(1000)
    assert robot.mode == "idle" and not h.fbRun.o_bBusy and h.fbRun.o_uErrId == 0x0305
    assert not h.fbResume.o_bBusy and h.fbResume.o_uErrId == 0x0305 and not h.fbEngine.o_bPaused
    assert [c[1] for c in _controls_at(line)][-1] == encode(ControlRequest(1, 1, 0xA0), SETTINGS)
    page = (PLC.parent / "docs" / "plc-library.md").read_text(encoding="utf-8")
    assert "A second `UITAMR_RunPoint` of\nthe same point is no resume" in page


def test_pause_and_resume_of_a_running_point_as_the_library_page_wires_it():
    """The page's wiring (plc-library.md, 'Pause and resume while a point runs'), run as
    printed: UITAMR_RunPoint runs the point, the pause overtakes it and the robot pauses,
    the run stays busy (no o_bOK, no o_bErr) and o_bPaused is on while paused, the resume
    (UITAMR_Command kind 2 of the same point) overtakes it too, the robot finishes the
    point (paused time not counted) and the run ends with o_bOK."""
    import re

    page = (PLC.parent / "docs" / "plc-library.md").read_text(encoding="utf-8")
    section = page.split("### Pause and resume while a point runs", 1)[1].split("\n## ", 1)[0]
    snippet = re.search(r"```iecst\n(.*?)```", section, re.S).group(1)
    declarations = ("    fbRun : UITAMR_RunPoint;\n    fbPause : UITAMR_Pause;\n    fbResume : UITAMR_Command;\n"
                    "    fbStop : UITAMR_Stop;\n    bPaused : BOOL;\n    bDone : BOOL;\n")
    project, robot, line, run = _cell(declarations, snippet + "IF fbRun.o_bOK THEN\n    bDone := TRUE;\nEND_IF;\n")
    h = project.program("T_Cell")
    _press(project, run, "X0", 2000)                          # point 3 from ~2.4 s, 8 s long
    run(700)
    assert robot.mode == "running" and h.fbRun.o_bBusy and not h.bPaused
    _press(project, run, "X3", 2000)                          # pause ~3 s into the run
    run(700)
    assert robot.mode == "paused" and h.bPaused and h.fbEngine.o_bTaskRunning   # paused, still reported running
    assert h.fbRun.o_bBusy and not h.fbRun.o_bErr and not h.bDone
    _press(project, run, "X4", 5000)                           # resume after 5 s of pause (11 s)
    run(700)
    assert robot.mode == "running" and not h.bPaused and h.fbRun.o_bBusy
    assert [c[1] for c in _controls_at(line)][1:] == [POINT_3, PAUSE_FRAME, POINT_3]
    run(3000)                                                   # 15 s: unpaused it would have ended at ~10.4 s
    assert robot.mode == "running" and h.fbRun.o_bBusy and not h.bDone
    run(5000)                                                   # 20 s
    assert robot.mode == "idle" and h.bDone and not h.fbRun.o_bBusy and not h.fbRun.o_bErr
    assert not h.fbEngine.o_bErr and not h.bPaused


def test_a_stop_during_a_point_lights_no_lamp_wired_as_the_page_shows():
    """journey33b: a cell's error lamp latched every o_bErr of its command FBs, as
    UITAMR_PanelFx3's fault lamp does; the operator's stop during a point lit it (the run
    ended with 16#0305), and no page said that a stop ends the command it overtakes with an
    error. The page's lamp, run as printed: the run ends with 16#0305, the lamp stays off;
    a robot that stops answering lights it with 16#0101, and X2 clears it."""
    import re

    from verifier.amr.faults import Fault

    page = (PLC.parent / "docs" / "plc-library.md").read_text(encoding="utf-8")
    section = page.split("**A stop is not a fault of the command it ends.**", 1)[1].split("\n### ", 1)[0]
    snippet = re.search(r"```iecst\n(.*?)```", section, re.S).group(1)
    body = ("fbEngine(i_bEN := NOT M8002, i_wAddress := 1, i_bMonitor := TRUE, io_uMbx := uMbx, io_uPort := uPort);\n"
            "fbRun(i_bEN := TRUE, i_bExecute := X0, i_wPoint := 3, io_uMbx := uMbx);\n"
            "fbStop(i_bEN := TRUE, i_bExecute := X1, io_uMbx := uMbx);\n" + snippet
            + "IF fbRun.o_bErr THEN\n    bNaive := TRUE;\nEND_IF;\n")          # a lamp of every o_bErr
    project, robot, line, run = _cell(
        "    fbRun : UITAMR_RunPoint;\n    fbStop : UITAMR_Stop;\n    bLamp : BOOL;\n    uLampErr : WORD;\n"
        "    bNaive : BOOL;\n",
        body, faults=[Fault(kind="no_reply", at_s=12.0, duration_s=5.0)])
    h = project.program("T_Cell")
    _press(project, run, "X0", 2000)
    _press(project, run, "X1", 2000)                          # the stop during the move, at 4 s
    run(2000)
    assert h.fbRun.o_uErrId == 0x0305 and h.fbStop.o_uErrId == 0 and robot.mode == "idle"  # kept after o_bErr
    assert not h.bLamp and h.uLampErr == 0 and h.bNaive       # the page's lamp stays off, a naive one lit
    _press(project, run, "X0", 4000)                          # again at ~10.3 s; silent from 12 s
    run(6000)
    assert h.bLamp and h.uLampErr == 0x0101
    _press(project, run, "X2", 1000)
    assert not h.bLamp and h.uLampErr == 0


def test_a_paused_point_outlasts_the_task_timeout_and_ends_ok_after_the_resume():
    """TASK_TIMEOUT (10 min) bounds a run's travel, not an operator's pause: a point paused
    for 11 min is still busy, without 16#0106, and after the resume the timer starts from 0:
    the run ends with o_bOK when the robot has finished the point."""
    project, robot, line, run = _run_point_cell(
        "    fbResume : UITAMR_Command;\n"
        "    bDone : BOOL;\n",
        "fbPause(i_bEN := TRUE, i_bExecute := X3, io_uMbx := uMbx);\n"
        "fbResume(i_bEN := TRUE, i_bExecute := X4, i_wKind := 2, i_wCode := 1, i_wCommand := 3,\n"
        "         i_bParamErr := FALSE, i_bPriority := FALSE, io_uMbx := uMbx);\n"
        "IF fbRun.o_bOK THEN\n    bDone := TRUE;\nEND_IF;\n")
    h = project.program("T_Cell")
    _press(project, run, "X0", 2000)
    _press(project, run, "X3", 2000)                          # paused ~2 s into the 8 s point
    run(11 * 60_000)
    assert robot.mode == "paused" and h.fbEngine.o_bPaused
    assert h.fbRun.o_bBusy and not h.fbRun.o_bErr and h.fbRun.o_uErrId == 0
    _press(project, run, "X4", 0)
    run(8000)
    assert robot.mode == "idle" and h.bDone and not h.fbRun.o_bErr and not h.fbEngine.o_bPaused


def test_a_pause_pressed_with_the_start_goes_after_the_point_and_pauses_it():
    """A pause asked in the scan the point is asked (start and pause buttons together, or the
    pause while the run still waits in the mailbox) went out first, the priority slot being
    served first: it paused nothing and the point then ran unpaused. The point's control
    command now goes first and the pause right after it, pausing the point."""
    project, robot, line, run = _run_point_cell(
        "",
        "fbPause(i_bEN := TRUE, i_bExecute := X0, io_uMbx := uMbx);\n")
    h = project.program("T_Cell")
    _press(project, run, "X0", 2000)
    run(1000)
    assert [c[1] for c in _controls_at(line)][1:] == [POINT_3, PAUSE_FRAME]
    assert robot.mode == "paused" and h.fbEngine.o_bPaused and h.fbRun.o_bBusy


@pytest.mark.parametrize("stop_first", [False, True], ids=["pause-called-first", "stop-called-first"])
def test_a_stop_pressed_while_a_pause_is_served_goes_out_right_after_it(stop_first):
    """The pause holds the priority slot while it is served (its control command and its
    status read): a stop pressed 20 ms after the pause is the next control command after
    it, one pace after the pause's status read (plc-library.md: about 600 ms after the
    pause), and ends the paused run with 16#0305. The stop takes over only a result that
    was already there, uncollected, at its call in the scan before: a pause called on
    every scan collects its own (o_bOK, not 16#0316), also one called after the stop in
    the program, which sees the pause's result first."""
    calls = ["fbPause(i_bEN := TRUE, i_bExecute := X3, io_uMbx := uMbx);\n",
             "fbStop(i_bEN := TRUE, i_bExecute := X1, io_uMbx := uMbx);\n"]
    project, robot, line, run = _run_point_cell(
        "    fbStop : UITAMR_Stop;\n    bPauseOk : BOOL;\n",
        "".join(calls[::-1] if stop_first else calls) + "IF fbPause.o_bOK THEN\n    bPauseOk := TRUE;\nEND_IF;\n")
    h = project.program("T_Cell")
    _press(project, run, "X0", 2000)
    run(2700)
    project.devices["X3"] = True
    run(20)
    _press(project, run, "X1", 0)
    project.devices["X3"] = False
    run(2000)
    (pause_at, pause), (stop_at, stop) = _controls_at(line)[2:]
    assert pause == PAUSE_FRAME and stop == encode(ControlRequest(1, 1, 0xA0), SETTINGS)
    assert 0.55 <= stop_at - pause_at <= 0.7
    assert robot.mode == "idle" and h.fbRun.o_uErrId == 0x0305 and h.fbPause.o_uErrId == 0 and h.bPauseOk
    page = " ".join((PLC.parent / "docs" / "plc-library.md").read_text(encoding="utf-8").split())
    assert ("(the pause's control command and status read: about 600 ms; with a silent robot, after the pause's "
            "three attempts: about 2.3 s)") in page


def test_the_resume_button_moves_nothing_when_no_point_runs():
    """review34: UITAMR_CellFx3's resume (X4: UITAMR_Command kind 2 of the point) and the
    page's wiring sent the point whenever pressed: with nothing paused - before X0, or after
    the operator's stop had ended the paused point - the robot drove to the point with fbGo
    idle (nobody following it, no 'reached', no fault from the run). The resume is now
    asked only while the point's run is busy; while it is, it resumes as before."""
    import re

    from verifier.amr.config import RobotConfig as Config

    page = (PLC.parent / "docs" / "plc-library.md").read_text(encoding="utf-8")
    section = page.split("### Pause and resume while a point runs", 1)[1].split("\n## ", 1)[0]
    snippet = re.search(r"```iecst\n(.*?)```", section, re.S).group(1)
    page_project = _cell("    fbRun : UITAMR_RunPoint;\n    fbPause : UITAMR_Pause;\n    fbResume : UITAMR_Command;\n"
                         "    fbStop : UITAMR_Stop;\n    bPaused : BOOL;\n", snippet)
    cell = verifier.load(PLC / "core", PLC / "fx3", PLC / "examples" / "fx3" / "UITAMR_CellFx3.st")
    robot = Robot(config=Config(point_duration_s=8.0))
    line = Line(robot)
    cell.attach_serial("fx3:1", line)
    cell_project = (cell, robot, line, lambda ms: cell.run_programs(["UITAMR_CellFx3"], ms=ms))
    for project, robot, line, run in (page_project, cell_project):
        _press(project, run, "X4", 2000)                      # resume with nothing run yet
        run(2000)
        assert robot.mode == "idle" and len(_controls_at(line)) == 1      # the power-on stop only
        _press(project, run, "X0", 0)                         # the point ...
        _press(project, run, "X3", 2000)                      # ... paused ...
        _press(project, run, "X1", 2000)                      # ... and stopped
        run(1000)
        assert robot.mode == "idle"
        _press(project, run, "X4", 1000)                      # resume after the stop
        run(2000)
        assert robot.mode == "idle"
        assert [c[1] for c in _controls_at(line)][1:] == [POINT_3, PAUSE_FRAME, encode(ControlRequest(1, 1, 0xA0), SETTINGS)]


def test_a_pause_that_comes_after_the_point_has_ended_waits_for_the_resume():
    """review34: a pause pressed in the last 300 ms of a point reaches the robot after the
    task has ended: the robot ignores it and reports idle, and the engine (which does not
    let an 'idle' answer end a paused run, in case a robot reports a paused task idle)
    keeps the run busy with o_bPaused on, TASK_TIMEOUT stopped. plc-library.md says so and
    how it ends: the resume (the point again, already reached) ends it with o_bOK."""
    project, robot, line, run = _run_point_cell(
        "    fbResume : UITAMR_Command;\n    bDone : BOOL;\n",
        "fbPause(i_bEN := TRUE, i_bExecute := X3, io_uMbx := uMbx);\n"
        "fbResume(i_bEN := TRUE, i_bExecute := X4 AND fbRun.o_bBusy, i_wKind := 2, i_wCode := 1, i_wCommand := 3,\n"
        "         i_bParamErr := FALSE, i_bPriority := FALSE, io_uMbx := uMbx);\n"
        "IF fbRun.o_bOK THEN\n    bDone := TRUE;\nEND_IF;\n")
    h = project.program("T_Cell")
    _press(project, run, "X0", 2000)                          # point 3 at 2.4 s, ends at ~10.4 s
    _press(project, run, "X3", 8000)                          # pause at 10.3 s: sent at 10.46 s
    run(20_000)
    assert [c[1] for c in _controls_at(line)][1:] == [POINT_3, PAUSE_FRAME]
    assert robot.mode == "idle" and h.fbEngine.o_bPaused and not h.fbEngine.o_bTaskRunning
    assert h.fbRun.o_bBusy and not h.bDone and not h.fbRun.o_bErr
    _press(project, run, "X4", 0)
    run(10_000)
    assert h.bDone and not h.fbRun.o_bBusy and not h.fbEngine.o_bPaused
    page = " ".join((PLC.parent / "docs" / "plc-library.md").read_text(encoding="utf-8").split())
    assert "a pause that reaches the robot after the point has ended" in page


def test_a_pause_during_a_relative_move_is_a_pause_too():
    """review34: the pause overtakes every command that waits for its task, and the robot
    pauses a relative move as it pauses a point (UITAMR_PanelFx3: X15 then X21). But the
    engine counted a pause only over a code-1 command: o_bPaused stayed FALSE while the
    robot stood paused, and TASK_TIMEOUT ran on, so an operator's pause of 10 min ended the
    move with 16#0106 (the fault lamp). Now it is paused as a point is: o_bPaused, no
    TASK_TIMEOUT; the stop ends it with 16#0305."""
    project, robot, line, run = _cell(
        "    fbMove : UITAMR_MoveRelative;\n    fbPause : UITAMR_Pause;\n    fbStop : UITAMR_Stop;\n",
        "fbEngine(i_bEN := NOT M8002, i_wAddress := 1, i_bMonitor := TRUE, io_uMbx := uMbx, io_uPort := uPort);\n"
        "fbMove(i_bEN := TRUE, i_bExecute := X0, i_wAxis := 1, i_eValue := 2.0, io_uMbx := uMbx);\n"
        "fbPause(i_bEN := TRUE, i_bExecute := X3, io_uMbx := uMbx);\n"
        "fbStop(i_bEN := TRUE, i_bExecute := X1, io_uMbx := uMbx);\n")
    h = project.program("T_Cell")
    _press(project, run, "X0", 2000)
    _press(project, run, "X3", 500)
    run(1000)
    assert robot.mode == "paused" and h.fbEngine.o_bPaused and h.fbMove.o_bBusy
    run(11 * 60_000)
    assert robot.mode == "paused" and h.fbMove.o_bBusy and h.fbMove.o_uErrId == 0 and not h.fbEngine.o_bErr
    _press(project, run, "X1", 0)
    run(1000)
    assert robot.mode == "idle" and not h.fbMove.o_bBusy and h.fbMove.o_uErrId == 0x0305
    assert not h.fbEngine.o_bPaused


_FORGOTTEN_PAUSE = (
    "IF X7 THEN                                        (* manual mode: skipped when X7 is off *)\n"
    "    fbPause(i_bEN := TRUE, i_bExecute := X3, io_uMbx := uMbx);\n"
    "END_IF;\n"
    "fbPauseB(i_bEN := TRUE, i_bExecute := X5, io_uMbx := uMbx);\n"
    "fbStop(i_bEN := TRUE, i_bExecute := X1, io_uMbx := uMbx);\n"
    "IF fbPause.o_bOK THEN\n    bPauseOk := TRUE;\nEND_IF;\n"
    "IF fbPause.o_bErr THEN\n    uPauseErr := fbPause.o_uErrId;\nEND_IF;\n"
    "IF fbPauseB.o_bOK THEN\n    bPauseBOk := TRUE;\nEND_IF;\n"
    "IF fbPauseB.o_bErr THEN\n    uPauseBErr := fbPauseB.o_uErrId;\nEND_IF;\n"
    "IF fbStop.o_bOK THEN\n    bStopOk := TRUE;\nEND_IF;\n"
    "IF fbStop.o_bErr THEN\n    uStopErr := fbStop.o_uErrId;\nEND_IF;\n")
_FORGOTTEN_LABELS = ("    fbPauseB : UITAMR_Pause;\n    fbStop : UITAMR_Stop;\n    bPauseOk : BOOL;\n"
                     "    uPauseErr : WORD;\n    bPauseBOk : BOOL;\n    uPauseBErr : WORD;\n    bStopOk : BOOL;\n"
                     "    uStopErr : WORD;\n")
STOP_FRAME = encode(ControlRequest(1, 1, 0xA0), SETTINGS)


def _pause_forgotten_then_stop(project, robot, line, run):
    """Point 3 runs; the manual-mode pause (X3 while X7) is pressed and X7 drops before its
    result comes: the robot pauses, the result stays uncollected in the priority slot. Then
    the stop (X1) is pressed: -> the time of the press and of the stop's frame, just sent."""
    h = project.program("T_Cell")
    _press(project, run, "X0", 2000)                          # point 3 from ~2.4 s, 8 s long
    run(1000)
    project.devices["X7"] = project.devices["X3"] = True
    run(30)
    project.devices["X7"] = project.devices["X3"] = False     # the section is skipped from now on
    run(1500)
    assert robot.mode == "paused" and h.fbEngine.o_bPaused
    assert h.uMbx[8] == 3 and h.fbPause.o_bBusy               # its result waits, nobody collects it
    pressed_at = project.now_us / 1e6
    project.devices["X1"] = True
    stops = []
    while not stops and project.now_us / 1e6 < pressed_at + 1.0:
        run(10)
        stops = [t for t, frame in _controls_at(line) if frame == STOP_FRAME and t > pressed_at]
    assert stops, "the stop was not sent"
    assert h.fbStop.o_bBusy                                   # its status read is still to come
    return pressed_at, stops[0]


def test_a_pause_not_called_when_its_result_comes_does_not_block_the_stop():
    """review34/s35: UITAMR_Pause posts to the stop's priority slot. Called in a manual-mode IF
    that went false before its result came, it left the result there, and UITAMR_Stop pressed
    afterwards never got the slot: it ended with 16#0303 after 30 s WITHOUT SENDING THE STOP.
    The stop now takes over a result its owner did not collect within a scan: its frame
    goes out at the next pace and it ends with o_bOK, the run with 16#0305."""
    project, robot, line, run = _run_point_cell(_FORGOTTEN_LABELS, _FORGOTTEN_PAUSE)
    h = project.program("T_Cell")
    pressed_at, stop_at = _pause_forgotten_then_stop(project, robot, line, run)
    assert stop_at <= pressed_at + 0.35                       # within one pace of the button
    project.devices["X1"] = False
    run(1000)
    assert h.bStopOk and h.uStopErr == 0 and robot.mode == "idle"
    assert h.fbRun.o_uErrId == 0x0305 and not h.fbRun.o_bBusy and not h.fbEngine.o_bPaused
    assert h.uMbx[8] == 0



@pytest.mark.parametrize("while_served", ["the stop", "a newer pause"])
def test_a_forgotten_pause_called_again_does_not_take_another_request_s_result(while_served):
    """The priority slot of a forgotten pause is reused (by the stop, then by any pause or
    resume): called again while that other request is served, the old UITAMR_Pause must
    not collect its result as its own - a pause writes the same kind and command as the
    one before it. It ends with o_bErr 16#0316 (its result was taken over), and the owner
    of the request gets its own result."""
    project, robot, line, run = _run_point_cell(_FORGOTTEN_LABELS, _FORGOTTEN_PAUSE)
    h = project.program("T_Cell")
    _pause_forgotten_then_stop(project, robot, line, run)
    if while_served == "a newer pause":
        project.devices["X1"] = False
        run(1000)
        assert h.bStopOk and robot.mode == "idle"
        _press(project, run, "X0", 0)                         # the point again
        run(1000)
        assert robot.mode == "running"
        pressed_at = project.now_us / 1e6
        project.devices["X5"] = True                          # the other pause (called every scan)
        for _ in range(100):
            run(10)
            if [t for t, frame in _controls_at(line) if frame == PAUSE_FRAME and t > pressed_at]:
                break
    project.devices["X7"] = True                              # the old pause is called again while the
    run(2000)                                                 # other is served, ahead of its owner
    assert h.uPauseErr == 0x0316 and not h.bPauseOk and not h.fbPause.o_bBusy
    if while_served == "the stop":
        assert h.bStopOk and h.uStopErr == 0 and robot.mode == "idle"
    else:
        assert h.bPauseBOk and h.uPauseBErr == 0 and robot.mode == "paused" and h.fbEngine.o_bPaused
        assert h.fbRun.o_bBusy and not h.fbRun.o_bErr
    assert h.uMbx[8] == 0


def test_a_priority_request_of_a_kind_out_of_range_is_refused_without_ending_the_run():
    """In the priority slot the kind shares its word with the request's tag (bits 4..14):
    UITAMR_Command refuses a kind outside 1..4 there itself, with the engine's 16#0301 and
    the kind as detail, nothing posted. Before, the engine refused it only after taking it
    as a stop: the running point ended with 16#0305."""
    project, robot, line, run = _run_point_cell(
        "    fbOdd : UITAMR_Command;\n    uOddErr : WORD;\n    uOddDetail : WORD;\n",
        "fbOdd(i_bEN := TRUE, i_bExecute := X6, i_wKind := 17, i_wCode := 1, i_wCommand := 3,\n"
        "      i_bParamErr := FALSE, i_bPriority := TRUE, io_uMbx := uMbx);\n"
        "IF fbOdd.o_bErr THEN\n    uOddErr := fbOdd.o_uErrId;\n    uOddDetail := fbOdd.o_uErrDetail;\nEND_IF;\n")
    h = project.program("T_Cell")
    _press(project, run, "X0", 2000)
    run(1000)
    _press(project, run, "X6", 0)
    run(1000)
    assert (h.uOddErr, h.uOddDetail) == (0x0301, 17)
    assert robot.mode == "running" and h.fbRun.o_bBusy and h.fbRun.o_uErrId == 0
    assert [c[1] for c in _controls_at(line)][1:] == [POINT_3]


def test_a_stop_pressed_while_a_pause_waits_untaken_sends_nothing_asked_before_it():
    """review s35: a pause waits untaken in the priority slot while a point waits in the
    normal one (the engine sends the point's control command first, the pause after it).
    A stop pressed in that moment could not post: the point went out after the stop was
    pressed (the robot drove off), then the pause, and the stop ~940 ms after its button -
    against UITAMR_Stop's 'nothing asked before the stop moves the robot after it'. A stop
    now takes the place of a pause or a resume the engine has not taken yet: it goes out
    first, the point ends with 16#0305 unsent, and the pause (never sent: the stop stops
    the robot anyway) ends with 16#0305 as a normal request waiting does - no fault for
    UITAMR_CellFx3's lamp, which leaves 16#0305 out."""
    project, robot, line, run = _run_point_cell(
        "    fbStop : UITAMR_Stop;\n    uPauseErr : WORD;\n    bStopOk : BOOL;\n",
        "fbPause(i_bEN := TRUE, i_bExecute := X3, io_uMbx := uMbx);\n"
        "fbStop(i_bEN := TRUE, i_bExecute := X1, io_uMbx := uMbx);\n"
        "IF fbPause.o_bErr THEN\n    uPauseErr := fbPause.o_uErrId;\nEND_IF;\n"
        "IF fbStop.o_bOK THEN\n    bStopOk := TRUE;\nEND_IF;\n")
    h = project.program("T_Cell")
    run(3000)
    polls = len(line.trace)
    while len(line.trace) == polls:                          # a monitor poll just went out:
        run(10)                                              # the next frame waits for the pace
    project.devices["X0"] = project.devices["X3"] = True     # start and pause together
    run(10)
    assert h.uMbx[0] == 1 and h.uMbx[8] == 1                 # both wait, untaken
    pressed_at = project.now_us / 1e6
    project.devices["X1"] = True                             # the stop, 10 ms later
    run(2000)
    after = [(t, frame) for t, frame in _controls_at(line) if t >= pressed_at]
    assert [frame for _t, frame in after] == [STOP_FRAME]    # no point, no pause: the stop
    assert after[0][0] <= pressed_at + 0.35                  # within one pace of the button
    assert robot.mode == "idle" and h.bStopOk
    assert h.fbRun.o_uErrId == 0x0305 and not h.fbRun.o_bBusy
    assert h.uPauseErr == 0x0305 and not h.fbPause.o_bBusy
    assert h.uMbx[0] == 0 and h.uMbx[8] == 0
