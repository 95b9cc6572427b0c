"""The whole chain: ST parsed and simulated scan by scan, bytes on the virtual RS-485 line,
the emulated robot, the rules and the expectations.

1. For each rule, a small ST program that keeps it and one that breaks it. The programs send
   fixed frames through the library's FX3 port FB (tx request / length / bytes in the port
   interface), so each test decides exactly what goes on the wire and when.
2. Deliberately broken variants of our own library, made by text substitution on the PLC
   engineer's ST files: the verifier must catch each one, and pass the unmodified library.
"""
from __future__ import annotations

import shutil
import sys
from dataclasses import replace
from pathlib import Path

import pytest

from verifier import protocol
from verifier.amr.config import RobotConfig
from verifier.amr.faults import Fault
from verifier.verify.conditions import parse_condition
from verifier.verify.evidence import RuleOptions
from verifier.verify.result import KEEP_ALL, Keep
from verifier.verify.runner import run_scenario
from verifier.verify.scenario import Scenario, parse_scenario
import procs

REPO = Path(__file__).resolve().parents[1]
PLC = REPO / "plc"
S = protocol.Settings()
STOP = protocol.ControlRequest(1, protocol.ControlCode.ROBOT, protocol.RobotCommand.STOP)
POINT3 = protocol.ControlRequest(1, protocol.ControlCode.ROBOT, 3)
READ = protocol.StatusRequest(1, protocol.Query.TASK)


# --- a frame sequencer in ST -------------------------------------------------------------------

SEQUENCER = """\
(* Test program: sends FRAME_COUNT fixed frames, one every PERIOD, through the FX3 port FB.
   Replies are received and dropped; bErr is the program's only error signal. *)
PROGRAM SeqTest
VAR
    fbPort : UITAMR_PortFx3;
    uPort : ARRAY[0..39] OF WORD;
    uFrames : ARRAY[0..63] OF WORD;
    tmrPeriod : TON;
    bLoaded : BOOL;
    bErr : BOOL;
    wNext : INT;
    wIndex : INT;
END_VAR
VAR CONSTANT
    FRAME_COUNT : INT := {count};
    FRAME_LEN : INT := 8;
END_VAR
IF NOT bLoaded THEN
{loads}
    bLoaded := TRUE;
END_IF;
fbPort(i_bEN := TRUE, i_wChannel := 1, io_uPort := uPort);
tmrPeriod(IN := NOT tmrPeriod.Q, PT := {period});
IF tmrPeriod.Q AND (wNext < FRAME_COUNT) AND (uPort[0] = 0) THEN
    FOR wIndex := 0 TO FRAME_LEN - 1 DO
        uPort[8 + wIndex] := uFrames[wNext * FRAME_LEN + wIndex];
    END_FOR;
    uPort[1] := INT_TO_WORD(FRAME_LEN);
    uPort[0] := 1;
    wNext := wNext + 1;
END_IF;
uPort[2] := 0;
"""


def sequencer(tmp_path: Path, frames: list[bytes], period: str = "T#300ms") -> Path:
    assert all(len(f) == 8 for f in frames) and len(frames) <= 8
    loads = "\n".join(
        f"    uFrames[{i * 8 + k}] := 16#{byte:02X};" for i, frame in enumerate(frames) for k, byte in enumerate(frame)
    )
    path = tmp_path / "SeqTest.st"
    path.write_text(SEQUENCER.format(count=len(frames), loads=loads, period=period))
    return path


def run_sequence(tmp_path: Path, frames: list, *, period: str = "T#300ms", robot: dict | None = None,
                 faults: list[dict] = (), duration_us: int | None = None, options: RuleOptions | None = None):
    data = [f if isinstance(f, bytes) else protocol.encode(f, S) for f in frames]
    sources = (PLC / "core" / "UITAMR_PortLink.st", PLC / "core" / "UITAMR_PortPacking.st",
               PLC / "fx3" / "UITAMR_PortFx3.st", sequencer(tmp_path, data, period))
    scenario = Scenario(
        name="sequence",
        sources=tuple(p for p in sources if p.exists()),
        program="SeqTest",
        duration_us=duration_us or (len(frames) + 2) * 400_000,
        robot=RobotConfig.from_dict(robot or {}),
        faults=tuple(Fault.from_dict(f) for f in faults),
        options=options or RuleOptions(response_signal=parse_condition("bErr")),
        response_signal_given=True,
    )
    result = run_scenario(scenario)
    assert result.aborted is None, result.aborted
    sent = [f.data for f in result.trace if f.direction == "tx"]
    assert sent == data, "the sequencer did not put the frames on the line as written"
    return result


def broken_rules(result) -> set[str]:
    return {rule for rule, found in result.violations.items() if found}


def test_a_compliant_sequence_passes_every_rule(tmp_path):
    result = run_sequence(tmp_path, [STOP, READ, POINT3, READ])
    assert broken_rules(result) == set() and result.passed
    assert all(f.origin and f.origin.endswith(".st:" + f.origin.rsplit(":", 2)[1] + ":" + f.origin.rsplit(":", 1)[1])
               for f in result.trace if f.direction == "tx")


def test_crc_rule_through_the_pipeline(tmp_path):
    bad = bytearray(protocol.encode(READ, S))
    bad[6] ^= 0x10
    result = run_sequence(tmp_path, [STOP, bytes(bad)])
    assert broken_rules(result) == {"UITAMR-CRC"}
    (violation,) = result.violations["UITAMR-CRC"]
    assert violation.origin and "UITAMR_PortFx3.st" in violation.origin  # the ST line that sent it


def test_format_rule_through_the_pipeline(tmp_path):
    wrong_quantity = protocol.with_crc(bytes.fromhex("010100000008"))
    result = run_sequence(tmp_path, [STOP, wrong_quantity, READ])
    assert "UITAMR-FORMAT" in broken_rules(result)
    assert "quantity" in result.violations["UITAMR-FORMAT"][0].message


def test_pacing_rule_through_the_pipeline(tmp_path):
    result = run_sequence(tmp_path, [STOP, READ, READ], period="T#200ms")
    assert broken_rules(result) == {"UITAMR-PACING"}
    assert len(result.violations["UITAMR-PACING"]) == 2


def test_power_on_stop_rule_through_the_pipeline(tmp_path):
    result = run_sequence(tmp_path, [READ, POINT3, READ, STOP])
    assert broken_rules(result) == {"UITAMR-POWERON-STOP"}
    assert run_sequence(tmp_path, [READ, STOP, READ, POINT3, READ]).passed


def test_cycle_rule_through_the_pipeline(tmp_path):
    result = run_sequence(tmp_path, [STOP, POINT3, READ])
    assert broken_rules(result) == {"UITAMR-CYCLE"}


def test_half_duplex_and_one_at_a_time_through_the_pipeline(tmp_path):
    # the robot takes 400 ms to answer (inside the 500 ms time-out); the program sends every 300 ms
    result = run_sequence(tmp_path, [STOP, READ, READ], robot={"turnaround_ms": 400.0})
    assert {"UITAMR-HALF-DUPLEX", "UITAMR-ONE-AT-A-TIME"} <= broken_rules(result)
    assert any(e.kind == "collision" or "discarded" in e.kind for e in result.events) or \
        "was due" in result.violations["UITAMR-HALF-DUPLEX"][0].message
    assert run_sequence(tmp_path, [STOP, READ, READ], period="T#600ms", robot={"turnaround_ms": 400.0}).passed


def test_response_handling_through_the_pipeline(tmp_path):
    reads = [STOP] + [READ] * 7
    faults = [{"kind": "no_reply", "at_s": 0.5, "duration_s": 10.0}]
    options = RuleOptions(response_signal=parse_condition("bErr"), response_within_us=1_000_000)
    result = run_sequence(tmp_path, reads, period="T#700ms", faults=faults, duration_us=8_000_000, options=options)
    assert broken_rules(result) == {"UITAMR-RESPONSE-HANDLING"}
    assert "'bErr' did not become true within 1 s" in result.violations["UITAMR-RESPONSE-HANDLING"][0].message


# --- the library and broken variants of it ---------------------------------------------------

FX3_EXAMPLE = """
name = "fx3 example"
sources = ["core/*.st", "fx3/*.st", "examples/common/*.st", "examples/fx3/UITAMR_ExampleFx3.st"]
program = "UITAMR_ExampleFx3"
platform = "fx3u"
duration = "{duration}"
[robot]
point_duration_s = 3.0
{robot}
[[inputs]]
at = "1s"
set = {{ X0 = true }}
pulse = "300ms"
{faults}
[[expect]]
reached_point = 1
within = "{point_within}"
[response_handling]
signal = "fbEngine.o_bErr"
within = "4s"
"""


def library_copy(tmp_path: Path, edits: dict[str, list[tuple[str, str]]]) -> Path:
    """A copy of plc/ with text substitutions applied (each must match exactly once)."""
    copy = tmp_path / "plc"
    shutil.copytree(PLC, copy, ignore=shutil.ignore_patterns("scenarios", "ladder"))
    for relative, substitutions in edits.items():
        path = copy / relative
        text = path.read_text(encoding="utf-8")
        for old, new in substitutions:
            assert text.count(old) == 1, f"{relative}: {old!r} found {text.count(old)} times; update the test"
            text = text.replace(old, new)
        path.write_text(text, encoding="utf-8")
    return copy


def broken_scenario(tmp_path: Path, variant: str) -> tuple[Scenario, Path]:
    """Thirty seconds of the FX3 example on a copy of the library broken as VARIANTS[variant]
    says, and an empty folder for the run's reports."""
    edits, options, _ = VARIANTS[variant]
    copy = library_copy(tmp_path, edits)
    text = FX3_EXAMPLE.format(duration="30s", robot=options.get("robot", ""), faults=options.get("faults", ""),
                              point_within="10s")
    folder = tmp_path / "out"
    folder.mkdir()
    return parse_scenario(text, copy / "scenario.toml"), folder


def run_library(tmp_path: Path, edits: dict, *, duration: str = "12s", robot: str = "", faults: str = "",
                point_within: str = "10s"):
    copy = library_copy(tmp_path, edits)
    text = FX3_EXAMPLE.format(duration=duration, robot=robot, faults=faults, point_within=point_within)
    scenario = parse_scenario(text, copy / "scenario.toml")
    return run_scenario(scenario)


def test_the_unmodified_library_passes(tmp_path):
    result = run_library(tmp_path, {})
    assert broken_rules(result) == set() and result.passed


NO_REPLY = '[[faults]]\nkind = "no_reply"\nat_s = 5.0\nduration_s = 20.0\n'

VARIANTS = {
    "crc-init-wrong": (
        {"core/UITAMR_CRC16.st": [("CRC_INIT : WORD := 16#FFFF;", "CRC_INIT : WORD := 16#0000;")]},
        {}, {"UITAMR-CRC"},
    ),
    "crc-polynomial-wrong": (
        {"core/UITAMR_CRC16.st": [("CRC_POLY : WORD := 16#A001;", "CRC_POLY : WORD := 16#8005;")]},
        {}, {"UITAMR-CRC"},
    ),
    "crc-bytes-swapped": (
        {
            "core/UITAMR_BuildControl.st": [(
                "io_uFrame[6] := uCrc AND BYTE_MASK;\n    io_uFrame[7] := SHR(uCrc, BITS_PER_BYTE);",
                "io_uFrame[7] := uCrc AND BYTE_MASK;\n    io_uFrame[6] := SHR(uCrc, BITS_PER_BYTE);",
            )],
            "core/UITAMR_BuildStatus.st": [(
                "io_uFrame[6] := uCrc AND BYTE_MASK;\n    io_uFrame[7] := SHR(uCrc, BITS_PER_BYTE);",
                "io_uFrame[7] := uCrc AND BYTE_MASK;\n    io_uFrame[6] := SHR(uCrc, BITS_PER_BYTE);",
            )],
        },
        {}, {"UITAMR-CRC"},
    ),
    "pacing-too-short": (
        {"core/UITAMR_Engine.st": [("PACE_TIME : TIME := T#300ms;", "PACE_TIME : TIME := T#200ms;")]},
        {}, {"UITAMR-PACING"},
    ),
    "no-power-on-stop": (
        {"core/UITAMR_Engine.st": [(
            "wJob := JOB_INIT;\n            wKind := KIND_WAIT;\n            wCode := CODE_ROBOT;\n            wCommand := CMD_STOP;",
            "wJob := JOB_INIT;\n            wKind := KIND_WAIT;\n            wCode := CODE_ROBOT;\n            wCommand := 1;",
        )]},
        {}, {"UITAMR-POWERON-STOP"},
    ),
    "sending-while-a-reply-is-due": (
        {"core/UITAMR_Engine.st": [
            ("REPLY_TIMEOUT : TIME := T#500ms;", "REPLY_TIMEOUT : TIME := T#100ms;"),
            ("GUARD_TIME : TIME := T#200ms;", "GUARD_TIME : TIME := T#0ms;"),
        ]},
        {"robot": "turnaround_ms = 400.0"}, {"UITAMR-HALF-DUPLEX", "UITAMR-ONE-AT-A-TIME"},
    ),
    "ignoring-time-outs": (
        {"core/UITAMR_Engine.st": [("ELSIF tmrReply.Q THEN", "ELSIF FALSE THEN")]},
        {"faults": NO_REPLY, "duration": "14s"}, {"UITAMR-RESPONSE-HANDLING"},
    ),
    "status-quantity-wrong": (
        {"core/UITAMR_BuildStatus.st": [("QUANTITY_LOW : WORD := 16#0016;", "QUANTITY_LOW : WORD := 16#0008;")]},
        {}, {"UITAMR-FORMAT"},
    ),
}


@pytest.mark.parametrize("variant", sorted(VARIANTS))
def test_the_verifier_catches_a_broken_library(tmp_path, variant):
    edits, options, expected = VARIANTS[variant]
    result = run_library(tmp_path, edits, **options)
    assert not result.passed
    assert expected <= broken_rules(result), f"{variant}: broke {broken_rules(result)}"



@pytest.mark.parametrize("word, passes", [("16#1C91", False), ("16#1C87", False), ("16#1C80", False),
                                          ("16#0C81", True), ("16#1C89", True)])
def test_a_port_at_another_line_format_than_the_robots_fails(tmp_path, word, passes):
    """D8400 = H1C81 (9600 8N1) is what the robot reads. A port set to 19200 8N1, 9600 8E1
    or 9600 7N1 puts its frames on the line in a form the robot's UART cannot read, so it
    never answers. The simulator used to note the format and let the robot answer anyway:
    the run PASSed. H0C81 is 9600 8N1 too (without the RS-485 control bit) and passes.
    H1C89 (9600 8N2) is reported too, but its frames are read: a second stop bit is only a
    longer idle before the next start bit to an 8N1 receiver (it failed the run as if not)."""
    edit = {"fx3/UITAMR_PortFx3.st": [("COMM_FORMAT : WORD := 16#1C81;", f"COMM_FORMAT : WORD := {word};")]}
    result = run_library(tmp_path, edit)
    assert result.passed is passes
    sent = [f for f in result.trace if f.direction == "tx"]
    assert sent and sent[0].data == protocol.encode(STOP, S)          # sent as the program wrote it
    answered = [f for f in result.trace if f.direction == "rx"]
    if passes:
        assert answered
        return
    assert answered == []
    assert any(e.kind == "discarded" and "its receiver cannot read it" in e.message for e in result.events)
    assert any(f"communication format D8400=H{word[3:]}" in d for d in result.diagnostics)

@pytest.mark.parametrize("scan, jitter", [("10ms", "4ms"), ("25ms", "10ms"), ("2ms", "1ms")])
def test_the_library_keeps_every_rule_whatever_the_scan_time(tmp_path, scan, jitter):
    copy = library_copy(tmp_path, {})
    text = FX3_EXAMPLE.format(duration="12s", robot="", faults="", point_within="10s")
    scenario = parse_scenario(f'scan = "{scan}"\nscan_jitter = "{jitter}"\nseed = 3\n' + text, copy / "s.toml")
    result = run_scenario(scenario)
    assert result.passed, (broken_rules(result), result.failed_expectations)


def test_the_unmodified_library_handles_the_same_silent_robot(tmp_path):
    result = run_library(tmp_path, {}, faults=NO_REPLY, duration="14s")
    assert broken_rules(result) == set()


def test_a_program_that_stops_the_cpu_fails_with_its_st_location(tmp_path):
    crash = tmp_path / "Crash.st"
    crash.write_text("PROGRAM Crash\nVAR\n    a : ARRAY[0..3] OF INT;\n    i : INT;\nEND_VAR\ni := i + 1;\na[i] := 1;\n")
    from verifier.verify.scenario import default_scenario

    result = run_scenario(replace(default_scenario(duration_us=1_000_000), sources=(crash,), program="Crash"))
    assert not result.passed and result.verdict == "fail"
    assert f"{crash.name}:7:" in result.aborted and result.ended_us < 1_000_000
    assert "simulation stopped" in result.failed_expectations[0].detail


def test_the_default_run_expects_the_power_on_stop(tmp_path):
    """A program that never talks to the robot must not pass by saying nothing."""
    quiet = tmp_path / "Quiet.st"
    quiet.write_text("PROGRAM Quiet\nVAR\n    n : INT;\nEND_VAR\nn := n + 1;\n")
    from verifier.verify.scenario import default_scenario

    result = run_scenario(replace(default_scenario(duration_us=6_000_000), sources=(quiet,), program="Quiet"))
    assert not result.passed and broken_rules(result) == set()
    (missed,) = result.failed_expectations
    assert missed.expectation.label == "sent stop within 5 s" and "was not sent" in missed.detail


def test_the_complete_example_in_the_scenario_docs_runs_and_passes():
    docs = (REPO / "docs" / "scenarios.md").read_text(encoding="utf-8")
    section = docs[docs.index("## A complete example"):]
    example = section[section.index("```toml") + len("```toml"):section.index("```\n", section.index("```toml") + 7)]
    scenario = parse_scenario(example, PLC / "scenarios" / "docs-example.toml")
    assert {e.kind for e in scenario.expectations} == {"sent", "that", "reached_point", "never"}
    result = run_scenario(scenario)
    assert result.passed, ([v.message for v in result.all_violations()], [e.detail for e in result.failed_expectations])


LATE_ECHO_PROGRAM = """PROGRAM P
VAR
    n : INT;
    k : INT;
    wLen : INT;
    uSend : ARRAY[0..3] OF WORD;
    uRecv : ARRAY[0..3] OF WORD;
    bInit : BOOL;
END_VAR
IF NOT bInit THEN
    D8400 := 16#1C81;
    D8409 := 5;
    bInit := TRUE;
ELSE
    n := n + 1;
    IF n >= 30 AND NOT M8402 AND k < 4 THEN
        n := 0;
        k := k + 1;
        wLen := 8;
        IF k = 1 THEN       (* stop: 01 06 01 A0 00 00 88 14 *)
            uSend[0] := 16#0601; uSend[1] := 16#A001; uSend[2] := 16#0000; uSend[3] := 16#1488;
        ELSIF k = 2 THEN    (* run-point 1: 01 06 01 01 00 00 D9 F6 *)
            uSend[0] := 16#0601; uSend[1] := 16#0101; uSend[2] := 16#0000; uSend[3] := 16#F6D9;
        ELSIF k = 3 THEN    (* read task: 01 01 00 00 00 16 BD C4 *)
            uSend[0] := 16#0101; uSend[1] := 16#0000; uSend[2] := 16#1600; uSend[3] := 16#C4BD;
        ELSE                (* stop with its CRC bytes swapped: 01 06 01 A0 00 00 14 88 *)
            uSend[0] := 16#0601; uSend[1] := 16#A001; uSend[2] := 16#0000; uSend[3] := 16#8814;
        END_IF;
        M8402 := TRUE;
    END_IF;
    M8403 := FALSE;
    M8409 := FALSE;
END_IF;
RS2(bInit, uSend[0], wLen, 8, 1, uRecv[0]);
END_PROGRAM
"""


@pytest.mark.parametrize("keep", [KEEP_ALL, Keep(frames=False, details=False)], ids=["whole", "streamed"])
def test_a_late_reply_paired_with_a_request_the_robot_ignores_is_no_crash(tmp_path, keep):
    """Stop, run point 1, read the task (its reply 700 ms late), then a stop with its CRC
    bytes swapped: the late reply lands after the bad request and counts as its answer,
    an exchange with no request the robot would read. reached_point used to stop with
    AttributeError on it; it is not a step towards the point."""
    (tmp_path / "P.st").write_text(LATE_ECHO_PROGRAM, encoding="utf-8")
    text = ('name = "late echo"\nsources = ["P.st"]\nprogram = "P"\nplatform = "fx3u"\nduration = "3s"\n'
            '[[faults]]\nkind = "late_reply"\non_request = 3\ndelay_ms = 700\n[[expect]]\nreached_point = 1\n')
    result = run_scenario(parse_scenario(text, tmp_path / "s.toml"), keep=keep)
    assert result.tx_count == 4
    outcome = result.expectations[0]
    assert not outcome.passed and "never reported the task running" in outcome.detail


def test_a_location_on_line_100_is_printed_as_it_is(tmp_path):
    """':100:' is an emoji code to rich: the console printed 'P.st💯9' for a frame sent
    from line 100 (the JSON had it right)."""
    lines = LATE_ECHO_PROGRAM.splitlines()
    sending = next(k for k, line in enumerate(lines) if "M8402 := TRUE" in line)  # starts each send
    padded = ["(* padding *)"] * (99 - sending) + lines
    assert "M8402 := TRUE" in padded[99]
    (tmp_path / "P.st").write_text("\n".join(padded).replace("n >= 30", "n >= 5") + "\n", encoding="utf-8")
    (tmp_path / "s.toml").write_text('name = "fast"\nsources = ["P.st"]\nprogram = "P"\nplatform = "fx3u"\n'
                                     'duration = "2s"\n', encoding="utf-8")
    done = procs.run([sys.executable, "-m", "verifier.cli", "verify", "--scenario", str(tmp_path / "s.toml")],
                     capture_output=True, text=True, timeout=120, cwd=tmp_path)
    assert done.returncode == 1, done.stdout + done.stderr
    assert "UITAMR-PACING" in done.stdout and "P.st:100:9" in done.stdout, done.stdout
    assert "\N{HUNDRED POINTS SYMBOL}" not in done.stdout


def test_a_program_that_stops_the_cpu_names_its_st_file_as_the_frames_do(tmp_path, monkeypatch):
    # the other reports name ST files relative to the working folder; the stop gave the
    # absolute path (/tmp/.../Crash.st:7:3)
    crash = tmp_path / "Crash.st"
    crash.write_text("PROGRAM Crash\nVAR\n    a : ARRAY[0..3] OF INT;\n    i : INT;\nEND_VAR\ni := i + 1;\na[i] := 1;\n")
    from verifier.verify.scenario import default_scenario

    monkeypatch.chdir(tmp_path)
    result = run_scenario(replace(default_scenario(duration_us=1_000_000), sources=(crash,), program="Crash"))
    assert result.aborted.startswith("Crash.st:7:"), result.aborted


@pytest.mark.parametrize("keep", [KEEP_ALL, Keep(frames=False, details=False)], ids=["whole", "as-it-goes"])
def test_an_expectation_met_before_the_cpu_stopped_is_met(tmp_path, keep):
    """The program stopped the CPU at 3 s (an index out of range); its stop command had
    been sent and answered at 0.23 s, yet `sent = "stop"` within 5 s failed with "the
    simulation stopped at 3.000 s, before the window closed at 5.000 s": a second failure
    that was none, beside the real one. What came before the stop is met; what had not
    come, and `never`, which needs the whole window, still fail and say why."""
    example = (PLC / "examples" / "fx3" / "UITAMR_ExampleFx3.st").read_text(encoding="utf-8")
    crash = tmp_path / "Crash.st"
    crash.write_text(example.replace("PROGRAM UITAMR_ExampleFx3", "PROGRAM Crash")
                     + "IF X5 THEN uMbx[D200] := 1; END_IF;\n", encoding="utf-8")
    sources = [*sorted((PLC / "core").glob("*.st")), *sorted((PLC / "fx3").glob("*.st")),
               *sorted((PLC / "examples" / "common").glob("*.st")), crash]
    listed = ", ".join(f'"{p.as_posix()}"' for p in sources)
    scenario = parse_scenario(
        f'name = "crash"\nsources = [{listed}]\nprogram = "Crash"\nduration = "10s"\n'
        '[initial]\nD200 = 99\n[[inputs]]\nat = "3s"\nset = { X5 = true }\n'
        '[[expect]]\nsent = "stop"\nwithin = "5s"\n'
        '[[expect]]\nthat = "fbEngine.o_bInitDone"\nwithin = "5s"\n'
        '[[expect]]\nthat = "fbCycle.o_bCycle"\nwithin = "5s"\n'
        '[[expect]]\nnever = "fbEngine.o_bErr"\nwithin = "5s"\n', tmp_path / "s.toml")
    result = run_scenario(scenario, keep=keep)
    assert "Crash.st" in result.aborted and result.ended_us == 3_000_000
    stop, init, cycle, never = result.expectations
    assert stop.passed and init.passed, (stop.detail, init.detail)
    for failed in (cycle, never):
        assert not failed.passed
        assert failed.detail == "the simulation stopped at 3.000 s, before the window closed at 5.000 s"
