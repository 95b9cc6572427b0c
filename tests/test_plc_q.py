"""Q + QJ71C24N: short replies (a 5-byte exception) only reach the engine when the C24's
no-reception monitoring time ends the message; with it set, the exception is reported as
16#0103 and the following replies stay aligned. The scenario format has no C24 key yet,
so this test wires robot, line and simulator itself."""
from __future__ import annotations

import re
from pathlib import Path

import verifier
from verifier.amr import Fault, Robot, RobotConfig
from verifier.link import Line
from verifier.protocol import Settings, crc_ok

PLC = Path(__file__).resolve().parents[1] / "plc"
SOURCES = [PLC / "core", PLC / "q", PLC / "examples" / "common", PLC / "examples" / "q"]


def rig(faults, no_reception_ms):
    robot = Robot(Settings(), RobotConfig(point_duration_s=3.0), faults)
    line = Line(robot)
    project = verifier.load(*SOURCES, cpu="q")
    project.attach_serial("q:1", line)
    project.configure_c24(0, 1, no_reception_ms=no_reception_ms)
    return project, line, robot


def pulse(project, device, at_ms):
    def on_scan(p):
        now_ms = p.now_us // 1000
        p.devices[device] = at_ms <= now_ms < at_ms + 300
    return on_scan


def run(project, ms, *hooks):
    def on_scan(p):
        for hook in hooks:
            hook(p)
    project.run_programs(["UITAMR_ExampleQ"], ms=ms, on_scan=on_scan)


def test_exception_reply_is_reported_and_the_line_stays_aligned():
    fault = Fault(kind="exception", on_request=5, count=1, code=2)   # request 5 = run point 1
    project, line, robot = rig([fault], no_reception_ms=5)
    prog = project.program("UITAMR_ExampleQ")
    run(project, 4000, pulse(project, "X20", 1000))
    assert prog.fbCycle.o_bErr and prog.fbCycle.o_uErrId == 0x0103
    assert prog.fbCycle.fbRun.fbCmd.o_uErrDetail == 2     # the exception code reaches the command
    run(project, 15000, pulse(project, "X22", 4500), pulse(project, "X20", 6000))
    replies = [f for f in line.trace if f.direction == "rx" and f.t_start_us > 6_000_000]
    assert replies and all(crc_ok(bytes(f.data)) for f in replies)
    assert prog.fbEngine.o_wCommErrCount == 0          # nothing after the exception was misread
    done = [e for e in robot.events if e.kind == "task" and e.message.endswith("done")]
    assert len(done) >= 2 and not prog.fbCycle.o_bErr       # the cycle ran on after the acknowledge


def test_requests_keep_the_pacing_on_q():
    project, line, _ = rig([], no_reception_ms=5)
    run(project, 8000, pulse(project, "X20", 1000))
    starts = [f.t_start_us for f in line.trace if f.direction == "tx"]
    assert len(starts) > 10
    assert min(b - a for a, b in zip(starts, starts[1:])) > 250_000


# ---------------------------------------------------------------------------- moving the module
EXAMPLE_Q = PLC / "examples" / "q" / "UITAMR_ExampleQ.st"
MOVE_TO_X020 = [   # the places the example's header and import-gxworks2.md §5 list
    ("C24_UNIT : WORD := 16#0;", "C24_UNIT : WORD := 16#2;"),
    ("i_bReadReq := X3,", "i_bReadReq := X23,"),
    ("U0\\G150", "U2\\G150"), ("U0\\G164", "U2\\G164"), ("U0\\G165", "U2\\G165"),
]


def moved_example(edits):
    text = EXAMPLE_Q.read_text()
    for old, new in edits:
        assert text.count(old) == 1, old
        text = text.replace(old, new)
    return text


def run_at_x020(text):
    robot = Robot(Settings(), RobotConfig(point_duration_s=1.0), [])
    line = Line(robot)
    project = verifier.load(*SOURCES[:-1], sources={"UITAMR_ExampleQ.st": text}, cpu="q")
    project.attach_serial("q:1", line)
    run(project, 5000, pulse(project, "X20", 1000))
    return project.program("UITAMR_ExampleQ"), line


def test_the_documented_edits_move_the_c24_to_x020():
    prog, line = run_at_x020(moved_example(MOVE_TO_X020))
    assert prog.fbEngine.o_bInitDone and prog.fbCycle.o_wPoint > 1
    assert [f for f in line.trace if f.direction == "rx"]


def test_the_example_lists_every_place_that_names_the_module():
    text = EXAMPLE_Q.read_text()
    body = text.split("PROGRAM UITAMR_ExampleQ", 1)[1]
    assert set(re.findall(r"U[0-9A-F]+\\G\d+", body)) == {"U0\\G150", "U0\\G164", "U0\\G165"}
    header = text.split("PROGRAM UITAMR_ExampleQ", 1)[0]
    for place in ("C24_UNIT", "i_bReadReq", "U0\\G", "C24_CHANNEL", "G310 / G324 / G325"):
        assert place in header
    guide = (PLC.parent / "docs" / "import-gxworks2.md").read_text()
    for place in ("`C24_UNIT`", "X(start + 3)", "`U0\\G150`", "`G310`", "`C24_CHANNEL`"):
        assert place in guide


def test_forgetting_the_buffer_memory_writes_breaks_the_link():
    """Why the U\\G writes are on the list: with them left at U0 the module at X/Y020 keeps
    word units and an end code, and the stop is never seen as answered."""
    prog, _ = run_at_x020(moved_example(MOVE_TO_X020[:2]))
    assert not prog.fbEngine.o_bInitDone
