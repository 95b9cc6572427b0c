"""Q + QJ71C24N: short replies (a 5-byte exception) only reach the engine when the C24's
no-reception monitoring time ends the message; with it set, the exception is reported as
16#0103 and the following replies stay aligned. The scenario format has no C24 key yet,
so this test wires robot, line and simulator itself."""
from __future__ import annotations

import re

import pytest
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


def test_a_reception_error_is_read_and_the_line_stays_aligned():
    """Timer 0 in format 0 ends a short message with a reception error: the module turns on
    the reception abnormal detection X4, not X3 (C24 (Application) 6.1), and the data up to
    the error wait for G_INPUT (C24 (Basic) 6.1.5). The port read only on X3, so the error
    message was never taken off the module and every reply after it waited behind it: the
    link stayed dead. Now X4 starts a read too; the engine sees a transport error for that
    attempt and the replies after it are read in step."""
    fault = Fault(kind="exception", on_request=5, count=1, code=2)   # request 5 = run point 1
    project, line, robot = rig([fault], no_reception_ms=5)
    project.configure_c24(0, 1, no_reception_format=0)
    prog = project.program("UITAMR_ExampleQ")
    seen = set()

    def watch(p):
        seen.add((p.program("UITAMR_ExampleQ").fbPort.o_uErrId, p.devices["X4"]))
    run(project, 12000, pulse(project, "X20", 1000), watch)
    assert any(x4 for _, x4 in seen)                         # X4 came on ...
    assert any(err == 0x0307 for err, _ in seen)             # ... and the read ended in error
    assert prog.fbEngine.o_wRetryCount > 0                   # that attempt was repeated
    assert prog.fbEngine.o_wCommErrCount == 1 and not project.devices["X3"]   # nothing after it misread
    done = [e for e in robot.events if e.kind == "task" and e.message.endswith("done")]
    assert len(done) >= 2 and not prog.fbCycle.o_bErr       # the cycle ran on


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
    ("i_bReadReq := X3,", "i_bReadReq := X23,"), ("i_bRecvErr := X4,", "i_bRecvErr := X24,"),
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
    for place in ("C24_UNIT", "i_bReadReq", "i_bRecvErr", "U0\\G", "C24_CHANNEL", "G310 / G324 / G325"):
        assert place in header
    guide = (PLC.parent / "docs" / "import-gxworks2.md").read_text()
    for place in ("`C24_UNIT`", "X(start + 3)", "X(start + 4)", "`U0\\G150`", "`G310`", "`C24_CHANNEL`"):
        assert place in guide


def test_forgetting_the_buffer_memory_writes_breaks_the_link():
    """Why the U\\G writes are on the list: with them left at U0 the module at X/Y020 keeps
    word units and an end code, and the stop is never seen as answered."""
    prog, _ = run_at_x020(moved_example(MOVE_TO_X020[:3]))
    assert not prog.fbEngine.o_bInitDone


# ------------------------------------------------------- a program of one's own in another slot
USER_MAIN = """PROGRAM Main
VAR
    fbPort : UITAMR_PortQC24;
    fbEngine : UITAMR_Engine;
    uMbx : ARRAY[0..15] OF WORD;
    uPort : ARRAY[0..39] OF WORD;
END_VAR
IF SM402 THEN
    U2\\G310 := 1;
    U2\\G324 := 8;
    U2\\G325 := 16#FFFF;
END_IF;
fbPort(i_bEN := TRUE, i_uUnit := 16#2, i_wChannel := 2, i_bReadReq := X2A, io_uPort := uPort);
fbEngine(i_bEN := NOT SM402, i_wAddress := 1, i_bMonitor := TRUE, io_uMbx := uMbx, io_uPort := uPort);
"""
LIBRARY = [PLC / "core", PLC / "q" / "UITAMR_PortQC24.st"]


def load_main(main, faults=()):
    """LIBRARY and a program Main (text main) on a Q CPU, its C24 CH2 at U2 on a line to a robot."""
    project = verifier.load(*LIBRARY, sources={"Main.st": main}, cpu="q")
    project.attach_serial("q:2", Line(Robot(Settings(), RobotConfig(), list(faults))))
    return project


def invoke_verify(*args):
    """`uitamr verify` with args (paths given as Path or str)."""
    from click.testing import CliRunner

    from verifier.commands.verify import command

    return CliRunner().invoke(command, [*map(str, args)], catch_exceptions=False)


def verify_main(tmp_path, main, *args):
    """`uitamr verify` of LIBRARY and a Main.st in tmp_path holding main."""
    (tmp_path / "Main.st").write_text(main)
    return invoke_verify(*LIBRARY, tmp_path / "Main.st", *args)


def test_matrix_runs_a_program_whose_c24_sits_in_another_slot_on_ch2(tmp_path):
    """The bundled q-exception.toml sets timer 0 for the example's module (U0, CH1). Under
    --matrix those settings once made a module at U0 that took the robot's replies off the
    line, so a program driving its C24 at U2 on CH2 never saw an answer and failed
    (UITAMR-CYCLE: stop after stop). The settings now go to the module the program drives."""
    import json

    report = tmp_path / "m.json"
    result = verify_main(tmp_path, USER_MAIN, "--matrix", "--channel", "q:2", "--duration", "8s", "--json", str(report))
    assert result.exit_code == 0, result.output
    runs = {s["name"]: s for s in json.loads(report.read_text())["scenarios"]}
    exception = next(s for name, s in runs.items() if "exception" in name)
    assert exception["verdict"] == "pass" and not exception["violations"]
    assert any("C24 settings (on the module your program drives)" in n for n in exception["notes"])


def test_c24_settings_for_the_module_the_program_drives():
    """configure_c24(None, ...) sets timer 0 on whichever module the program addresses: the
    5-byte exception to a status read at U2/CH2 is reported as such, and the replies after
    it stay aligned."""
    fault = Fault(kind="exception", at_s=2.0, count=1, code=3, requests="status")
    project = load_main(USER_MAIN, [fault])
    project.configure_c24(None, 2, no_reception_ms=5)
    errors = set()
    project.run_programs(["Main"], ms=6000,
                         on_scan=lambda p: errors.add(p.program("Main").fbEngine.o_uErrId))
    assert project.c24_addressed() == [2]
    assert 0x0103 in errors
    assert project.program("Main").fbEngine.o_wCommErrCount == 0


def test_a_c24_setting_for_a_slot_the_program_does_not_drive_is_noted(tmp_path):
    """A [[c24]] for U0 while the program drives its module at U2: before, the setting
    made a phantom module that swallowed the replies (the run failed with no hint why);
    now the run goes on, and a note at the [[c24]]'s line says the settings were not in
    force and which unit to give."""
    scenario = tmp_path / "s.toml"
    scenario.write_text('program = "Main"\nplatform = "q"\nchannel = "q:2"\nduration = "3s"\n\n'
                        '[[c24]]\nunit = 0\nchannel = 2\nno_reception = "5ms"\n')
    result = verify_main(tmp_path, USER_MAIN, "--scenario", str(scenario))
    assert result.exit_code == 0, result.output
    assert f"{scenario}:6:1: c24[0]: unit = 0 (U0) is not the QJ71C24N the program drives" in result.output
    assert "give unit = 2" in result.output


def test_replies_left_in_the_module_are_noted_with_the_signal_to_read_on(tmp_path):
    """Moving the C24 to U2/CH2 but leaving i_bReadReq at X3: every reply stayed in the
    module and the report only said UITAMR-CYCLE (stop after stop), far from the cause.
    Now a note names the unread messages and the module's own read request, X2A."""
    result = verify_main(tmp_path, USER_MAIN.replace("i_bReadReq := X2A", "i_bReadReq := X3"),
                         "--channel", "q:2", "--duration", "5s")
    assert result.exit_code == 1
    assert ("note: QJ71C24N U2 CH2: 5 received message(s) never read by G_INPUT, the oldest since 0.252 s; "
            "the module's reception data read request for CH2 is X2A (reception abnormal detection X2B)") in result.output
    fixed = verify_main(tmp_path, USER_MAIN, "--channel", "q:2", "--duration", "5s")
    assert fixed.exit_code == 0 and "never read" not in fixed.output


TCP_MAIN = """PROGRAM TcpMain
VAR
    fbPort : UITAMR_PortE71;
    fbEngine : UITAMR_Engine;
    uMbx : ARRAY[0..15] OF WORD;
    uPort : ARRAY[0..39] OF WORD;
END_VAR
fbPort(i_bEN := TRUE, i_sUnit := 'U2', i_wConnection := 3, i_udIpAddress := 16#C0A8010A,
       i_uTcpPort := 502, i_uLocalPort := 5000,
       i_uOpenSignal := U2\\G20480, i_uRecvSignal := U2\\G20485, io_uPort := uPort);
fbEngine(i_bEN := NOT SM402, i_wAddress := 1, i_bMonitor := TRUE, io_uMbx := uMbx, io_uPort := uPort);
"""


def test_an_e71_program_reading_another_modules_open_signal_is_told_which_words_to_pass(tmp_path):
    """E71 at U2 but the open and reception signals still read from U0\\G20480 / U0\\G20485:
    the module opened, the port never saw it open and closed it again, over and over, and
    the report said only that nothing reached the robot. The note now says the program
    closed every open connection unused and names the module's words to pass."""
    (tmp_path / "TcpMain.st").write_text(TCP_MAIN.replace("U2\\G2048", "U0\\G2048"))
    sources = [PLC / "core", PLC / "q" / "UITAMR_PortE71.st", tmp_path / "TcpMain.st"]
    result = invoke_verify(*sources, "--duration", "5s")
    assert result.exit_code == 1
    assert ("the QJ71E71 at U2 opened the connection (10 open(s)) and the program closed it again each time "
            "without sending") in result.output
    assert "does the program pass U2\\G20480 (and U2\\G20485 as i_uRecvSignal)?" in result.output
    (tmp_path / "TcpMain.st").write_text(TCP_MAIN)
    fixed = invoke_verify(*sources, "--duration", "5s")
    assert fixed.exit_code == 0, fixed.output


def test_the_e71_split_reply_scan_limit_is_what_tcp_converter_md_says():
    """tcp-converter.md: the E71 reads one segment per receive and receives every other
    scan, so a two-segment reply needs four scans; at 125 ms that is the 500 ms reply
    time-out. The bundled q-tcp-split passes at 120 ms and fails at 125 ms."""
    from dataclasses import replace

    from verifier.commands.verify import bundled_plc_dir
    from verifier.verify.runner import run_scenario
    from verifier.verify.scenario import load_scenario

    split = load_scenario(bundled_plc_dir() / "scenarios" / "q-tcp-split.toml")
    assert "`--scan 120ms` and fails at `--scan 125ms`" in (PLC.parent / "docs" / "tcp-converter.md").read_text()
    assert run_scenario(replace(split, scan_us=120_000)).passed
    assert not run_scenario(replace(split, scan_us=125_000)).passed


def test_the_q_example_says_where_automatic_io_assignment_puts_the_output_module():
    """Slot 0 C24 (32 points) + slot 1 input + slot 2 output: by automatic assignment the
    output module starts at Y40 only if the input module has 32 points; the guide said
    'an input module at X20-X2F and an output module at Y40-Y4F', which automatic
    assignment never gives. Both the guide and the example's header now say so."""
    guide = (PLC.parent / "docs" / "import-gxworks2.md").read_text()
    assert "it is at Y30" in guide and "q00cpu/manual?p=166" in guide
    assert "else it is at Y30" in EXAMPLE_Q.read_text().split("PROGRAM UITAMR_ExampleQ", 1)[0]


@pytest.mark.parametrize("no_reception_ms, recovers", [(None, False), (5, True)])
def test_one_stray_byte_breaks_the_link_for_good_without_timer_0(no_reception_ms, recovers):
    """plc-library.md, Q notes: without the no-reception monitoring time one stray byte
    after a reply shifts every later 8-byte message by one byte, for as long as the CPU
    runs - the robot answering perfectly. With timer 0 (format 1) the stray byte ends as
    a message of its own and the next exchanges are whole again - now that the port reads
    while X3 is ON: reading on its rising edge only, the stray byte waited behind the
    reply, X3 never went OFF, and nothing was read again (30 failed exchanges in 20 s)."""
    fault = Fault(kind="garbage", on_request=3, count=1, data=b"\xA5", position="after")
    project, line, robot = rig([fault], no_reception_ms=no_reception_ms)
    prog = project.program("UITAMR_ExampleQ")
    run(project, 3000)
    errors_before = prog.fbEngine.o_wCommErrCount
    run(project, 20000)
    assert robot.requests > 40                                  # polled all along, answered all along
    assert (prog.fbEngine.o_wCommErrCount == errors_before) == recovers


def test_the_unread_note_dates_the_oldest_message_still_waiting():
    """`c24_unread` (the note's "the oldest since ...") gave, after a G_INPUT had taken one
    of several waiting messages, the time of that read instead of when the oldest message
    still waiting arrived: a reply left unread for a second looked one scan old."""
    main = USER_MAIN.replace("i_bReadReq := X2A", "i_bReadReq := bRead").replace(
        "uPort : ARRAY[0..39] OF WORD;", "uPort : ARRAY[0..39] OF WORD;\n    bRead : BOOL;")
    project = load_main(main)
    project.run_programs(["Main"], ms=2000)
    ((unit, channel, waiting, oldest),) = project.c24_unread()
    assert (unit, channel) == (2, 2) and waiting >= 2 and oldest < 500_000
    project.program("Main").bRead = True  # one G_INPUT, at 2 s: the first message is read
    project.run_programs(["Main"], ms=10)
    project.program("Main").bRead = False
    project.run_programs(["Main"], ms=100)
    ((_, _, _, since),) = project.c24_unread()
    assert oldest < since < 1_900_000, since  # the second message's arrival, not the read at 2 s


@pytest.mark.parametrize("un", [2, None])
def test_the_programs_own_c24_setting_stands_over_one_for_the_module_it_drives(un):
    """A program that sets word units itself (U2\\G310 := 0, wrong for the library) fails
    to link whether the scenario's byte-units setting names its module (un=2, made before
    the first scan) or is for "the module the program drives" (un=None): the latter was
    applied at the first G_OUTPUT, after the program's own write, and hid the mistake."""
    main = USER_MAIN.replace("U2\\G310 := 1;", "U2\\G310 := 0;")
    project = load_main(main)
    project.configure_c24(un, 2, byte_units=True)
    project.run_programs(["Main"], ms=3000)
    assert not project.program("Main").fbEngine.o_bInitDone
    # control: with the program's byte-units write, the same setting links
    project = load_main(USER_MAIN)
    project.configure_c24(un, 2, byte_units=True)
    project.run_programs(["Main"], ms=3000)
    assert project.program("Main").fbEngine.o_bInitDone


def test_a_c24_setting_for_the_module_the_program_drives_made_mid_run_leaves_the_programs_word():
    """configure_c24(None, ...) made after the program's first G_OUTPUT: the program's own
    U2\\G310 := 0 stands there too, as at the first call (it was written over, and the
    word-units mistake linked)."""
    main = USER_MAIN.replace("U2\\G310 := 1;", "U2\\G310 := 0;")
    project = load_main(main)
    project.run_programs(["Main"], ms=1000)
    assert project.c24_addressed() == [2]
    project.configure_c24(None, 2, byte_units=True)
    project.run_programs(["Main"], ms=3000)
    assert not project.program("Main").fbEngine.o_bInitDone


def test_a_c24_setting_for_the_module_the_program_drives_fills_a_word_it_leaves_alone():
    """The other half: a word the program does not write (here the receive count, G324)
    takes the setting made for the module it drives."""
    main = USER_MAIN.replace("    U2\\G324 := 8;\n", "")
    project = load_main(main)
    project.configure_c24(None, 2, receive_count=8)
    project.run_programs(["Main"], ms=3000)
    assert project.program("Main").fbEngine.o_bInitDone


def test_a_c24_left_in_word_units_is_named_with_the_setting_to_make(tmp_path):
    """Found writing a Q program of one's own: the receive settings left to "the module
    parameters" (no U0\\G writes) and none made, the module kept its default word units,
    G_OUTPUT sent the 8-byte stop as 16 bytes, and the report said only 'byte 8: too long
    for an FC06 request: 16 bytes' - nothing about the word/byte units. The note names the
    buffer-memory word, its value and the three places to set byte units."""
    text = USER_MAIN.replace("    U2\\G310 := 1;\n", "")
    assert "G310" not in text
    result = verify_main(tmp_path, text, "--channel", "q:2", "--duration", "3s")
    assert result.exit_code == 1
    assert "UITAMR-FORMAT" in result.output
    assert ("note: QJ71C24N U2 CH2 is in word units (buffer memory 136H = 0, the module's default): G_OUTPUT "
            "sent a count of 8 as 16 bytes. UITAMR_PortQC24 counts bytes: set byte units (136H = 1) in the "
            "module's parameters, or in the first scan (U2\\G310 := 1, as UITAMR_ExampleQ does); in a "
            "scenario, [[c24]] byte_units = true") in " ".join(result.output.split())
    fixed = verify_main(tmp_path, USER_MAIN, "--channel", "q:2", "--duration", "3s")
    assert fixed.exit_code == 0 and "word units" not in fixed.output


def test_replies_waiting_for_a_count_they_never_reach_are_named_with_the_settings(tmp_path):
    """The next step of the same newcomer: byte units set, but the received data count
    (511) and the end code (0D0AH) left at the module's defaults. Every reply stayed in
    the module as an unfinished message, and the report said only UITAMR-CYCLE (stop
    after stop). The note names the bytes waiting and the two settings."""
    text = USER_MAIN.replace("    U2\\G324 := 8;\n    U2\\G325 := 16#FFFF;\n", "")
    assert "G324" not in text and "G325" not in text
    result = verify_main(tmp_path, text, "--channel", "q:2", "--duration", "5s")
    assert result.exit_code == 1
    out = " ".join(result.output.split())
    assert ("note: QJ71C24N U2 CH2: 40 received byte(s) wait in the module as an unfinished message since "
            "0.244 s:") in out
    assert ("it ends at the received data count (144H = 511) or the receive end code (145H = 0D0AH). "
            "UITAMR_PortQC24 needs a count of 8 bytes and no end code: set 144H = 8 and 145H = FFFFH in the "
            "module's parameters, or in the first scan (U2\\G324 := 8; U2\\G325 := 16#FFFF, as UITAMR_ExampleQ "
            "does); in a scenario, [[c24]] receive_count = 8, end_code = \"none\"") in out
    fixed = verify_main(tmp_path, USER_MAIN, "--channel", "q:2", "--duration", "5s")
    assert fixed.exit_code == 0 and "unfinished message" not in fixed.output


def test_matrix_runs_a_program_that_leaves_the_receive_settings_to_the_module_parameters(tmp_path):
    """docs/import-gxworks2.md §5 says to prefer the module's parameters for byte units,
    the received data count and the end code over the example's first-scan U0\\G writes. A
    program that followed it failed every bundled Q scenario under --matrix (UITAMR-FORMAT,
    16-byte frames): the bundled scenarios did not make those settings, only the example's
    writes did. They are now the bundled scenarios' [[c24]], as an installation makes them."""
    import json

    text = USER_MAIN.replace("    U2\\G310 := 1;\n    U2\\G324 := 8;\n    U2\\G325 := 16#FFFF;\n", "")
    assert "\\G" not in text
    report = tmp_path / "m.json"
    result = verify_main(tmp_path, text, "--matrix", "--channel", "q:2", "--duration", "8s", "--json", str(report))
    assert result.exit_code == 0, result.output
    runs = json.loads(report.read_text())["scenarios"]
    assert runs and all(s["verdict"] == "pass" and not s["violations"] for s in runs)


def test_the_bundled_q_garbage_scenario_needs_timer_0():
    """plc/scenarios/q-garbage.toml sets the no-reception monitoring time, as its description
    and plc-library.md (fault coverage) say every Q installation must: with it the 3 garbage
    bytes end as a message, cost one retry, and the engine's 16#0105 of the 4 s of garbage
    clears once the robot answers again. The same scenario without it fails for good: the
    bytes wait in the module for 5 more, every later reply is read out of step, and the
    engine still reports 16#0102 at the end of the run, long after the garbage stopped."""
    from dataclasses import replace

    from verifier.verify.runner import run_scenario
    from verifier.verify.scenario import load_scenario

    scenario = load_scenario(PLC / "scenarios" / "q-garbage.toml")
    assert [c.no_reception_us for c in scenario.c24] == [5_000]
    assert run_scenario(scenario).passed
    without = replace(scenario, c24=tuple(replace(c, no_reception_us=None) for c in scenario.c24))
    result = run_scenario(without)
    assert not result.passed
    engine = result.watched["fbEngine.o_uErrId"]
    first = next(t for t, code in engine if code == 0x0102)
    assert first < 10_000_000                                   # the single garbage at request 10
    assert all(code != 0 for t, code in engine if t > first)    # never healthy again
    assert engine[-1][1] == 0x0102
    cycle = result.watched["fbCycle.o_uErrId"]
    assert cycle[-1][1] == 0x0102 and cycle[-1][0] > 38_000_000     # failed again after the acknowledge


def test_a_send_the_module_ends_with_an_error_fails_the_attempt_at_once():
    """plc-library.md's 16#0108 row named 16#0306 among the port codes the engine gets, but
    UITAMR_PortQC24 kept a G_OUTPUT error to its own o_uErrId: the engine waited 500 ms for
    a reply to a frame that never went out, three times, and reported 16#0101 - a silent
    robot, though the module refused the send. Now the attempt fails at once with 16#0108,
    detail 16#0306, as the TCP ports do for a failed send. The simulator has no model of
    when the module ends OUTPUT with an error, so the module's G_OUTPUT is made to end that
    way (error code 7F20H, an arbitrary module code) for every frame from 1 s on."""
    project, line, _ = rig([], no_reception_ms=5)
    prog = project.program("UITAMR_ExampleQ")
    run(project, 1000)
    assert prog.fbEngine.o_bInitDone
    module = project._instructions().c24(0)
    refused = []

    def output(s1, s2, d, loc_id):  # the module's completion with an error: d + 1 ON, code in s1 + 1
        refused.append(project.now_us)
        s1.set(1, 0x7F20)
        module._finish(d, ok=False)
        return True

    module.output = output
    run(project, 1500)
    engine = prog.fbEngine
    assert (engine.o_uErrId, engine.o_uErrDetail) == (0x0108, 0x0306)
    assert (prog.fbPort.o_uErrId, prog.fbPort.o_uErrDetail) == (0x0306, 0x7F20)
    # three attempts paced 310 ms apart, none waiting out the 500 ms reply time-out (then
    # the monitor's polls fail the same way)
    assert len(refused) >= 3 and refused[2] - refused[0] < 2 * 500_000
    assert [f for f in line.trace if f.direction == "tx" and f.t_start_us > 1_000_000] == []
    doc = (PLC.parent / "docs" / "plc-library.md").read_text(encoding="utf-8")
    assert re.search(r"^\| 16#0108 \|[^|]*\| port code \(16#0306/", doc, flags=re.M)


def test_a_send_error_is_signalled_when_a_stray_message_was_read_during_the_send():
    """The known gap: a G_OUTPUT that ended with an error failed the attempt only when no
    message was held (IF NOT bRecvHeld). A stray message (a second device's chatter, a
    reply given up on) that ended while the send was under way was read and held, the send
    error went only to the port's o_uErrId, and the engine took the stray message as the
    reply to a frame that never went out. Now the send error replaces it: the attempt
    fails (16#0108 / 16#0306 for that attempt) and is repeated. The module's G_OUTPUT is
    made to end with an error (7F20H) two scans after one send from 1 s on, and a
    well-formed status reply (battery normal) is put in the module's receive area in the
    scan after that send started."""
    project, line, _ = rig([], no_reception_ms=5)
    prog = project.program("UITAMR_ExampleQ")
    run(project, 1000)
    assert prog.fbEngine.o_bInitDone and prog.fbEngine.o_wCommErrCount == 0
    module = project._instructions().c24(0)
    normal_output = module.output
    refused = []

    def output(s1, s2, d, loc_id):
        refused.append([s1, d, 0])
        module.output = normal_output           # one send only
        return True

    def during_the_send(p):
        for item in refused:
            s1, d, scans = item
            item[2] = scans + 1
            if scans == 0:                      # a stray message ends in the module
                chan = module.channels[1]
                chan.frames.append((bytes.fromhex("0101030000003C4E"), 0, p.now_us))
                module._signals(chan)
            elif scans == 1:                    # the send ends with an error
                s1.set(1, 0x7F20)
                module._finish(d, ok=False)
    module.output = output
    seen = []
    run(project, 1500, during_the_send, lambda p: seen.append(
        ((prog.fbPort.o_uErrId, prog.fbPort.o_uErrDetail), prog.fbEngine.o_wCommErrCount)))
    assert len(refused) == 1 and refused[0][2] >= 2
    assert (0x0306, 0x7F20) in {port for port, _ in seen}   # the port saw the error ...
    # ... and so does the engine: the attempt failed and was repeated
    assert prog.fbEngine.o_wCommErrCount == 1 and prog.fbEngine.o_wRetryCount == 1
    assert not prog.fbEngine.o_bErr                          # the repeat got the robot's reply


def test_a_pause_called_only_in_manual_mode_loses_its_result_and_blocks_no_stop():
    """The examples' headers said that a pause whose FB is not called when its result comes
    "blocks the stop". An integrator who moved fbPause into a manual-mode IF (left before
    the pause's answer) sees otherwise, as docs/plc-library.md says: the stop takes the
    priority slot over and goes out at the next pace; fbPause, called again, ends with
    16#0316 (its result lost). The headers now say that."""
    text = (PLC / "examples" / "q" / "UITAMR_ExampleQ.st").read_text(encoding="utf-8")
    call = "fbPause(i_bEN := TRUE, i_bExecute := X23, io_uMbx := uMbx);"
    assert call in text
    text = text.replace(call, f"IF X25 THEN\n    {call}\nEND_IF;")
    robot = Robot(Settings(), RobotConfig(point_duration_s=6.0), [])
    line = Line(robot)
    project = verifier.load(*SOURCES[:3], cpu="q", sources={"UITAMR_ExampleQ.st": text})
    project.attach_serial("q:1", line)
    prog = project.program("UITAMR_ExampleQ")

    def manual(p):
        now_ms = p.now_us // 1000
        p.devices["X25"] = 1000 <= now_ms < 4010 or now_ms >= 9000
    run(project, 12000, manual, pulse(project, "X20", 2000), pulse(project, "X23", 4000),
        pulse(project, "X21", 7000))
    sent = [(f.t_start_us, bytes(f.data).hex()) for f in line.trace if f.direction == "tx"]
    assert any(4_000_000 <= t < 4_350_000 and data == "0106018000008" "9de" for t, data in sent)  # the pause
    assert any(7_000_000 <= t < 7_350_000 and data == "010601a000008814" for t, data in sent)  # the stop
    assert prog.fbPause.o_uErrId == 0x0316 and not prog.fbPause.o_bBusy
    for example in sorted((PLC / "examples").glob("*/UITAMR_Example*.st")):
        header = example.read_text(encoding="utf-8").split("*)", 1)[0]
        if "fbPause" in example.read_text(encoding="utf-8"):
            assert "blocks the stop" not in " ".join(header.split()), example.name


def test_the_q_example_says_its_buttons_move_when_the_c24_takes_x020():
    """review s35: with the pause (X23) and resume (X24) the example's buttons are the very
    inputs its own relocation list gives the C24 at X/Y020 (read request X23, reception
    abnormal detection X24; its X20..X22 are the start, stop and acknowledge). Following
    the list alone, fbPause reads the read request: on a CPU whose inputs are refreshed
    at END it sees it on with every reply and pauses the robot. The header and
    import-gxworks2.md now say the buttons are the input module's and move with it."""
    edited = moved_example(MOVE_TO_X020)
    body = edited.split("PROGRAM UITAMR_ExampleQ", 1)[1]
    port_inputs = set(re.findall(r"i_b(?:ReadReq|RecvErr) := (X\w+)", body))
    buttons = set(re.findall(r"i_b(?:Execute|Start|Stop|Ack) := (X\w+)", body))
    assert port_inputs == {"X23", "X24"} and port_inputs <= buttons       # the clash the note is for
    note = "The buttons X20..X24 are the input module's: with the C24 at X/Y020 move them with it"
    header = " ".join(EXAMPLE_Q.read_text().split("PROGRAM UITAMR_ExampleQ", 1)[0].split())
    assert note in header
    tcp = " ".join((PLC / "examples" / "q" / "UITAMR_ExampleTcpQ.st").read_text().split("PROGRAM", 1)[0].split())
    assert "The buttons X20..X24 are the input module's: with the E71 at X/Y020 move them with it" in tcp
    guide = " ".join((PLC.parent / "docs" / "import-gxworks2.md").read_text().split())
    assert "The buttons `X20`–`X24` are the input module's" in guide
