"""The FX3U ladder program (plc/ladder/UITAMR_LadderFx3.il) is verified like the ST library:
each instruction is translated, one to one, into an ST statement with ladder semantics
(accumulator, block and MPS stacks, edge contacts, timers T200-T245 at 10 ms) and the
result runs under `uitamr verify` scenarios against the emulated robot. The CSV for
GX Works2 must be the one generated from the .il file."""
from __future__ import annotations

import re
from pathlib import Path

import pytest

from verifier.export.ladder import IlError, parse_il, to_csv
from verifier.protocol import ControlRequest, StatusRequest, encode
from verifier.verify.runner import run_scenario
from verifier.verify.scenario import load_scenario

LADDER = Path(__file__).resolve().parents[1] / "plc" / "ladder"
IL = LADDER / "UITAMR_LadderFx3.il"
COMPARE = {"=": "=", "<>": "<>", ">": ">", "<": "<", ">=": ">=", "<=": "<="}


def value(operand: str) -> str:
    if re.fullmatch(r"K-?\d+", operand):
        return operand[1:]
    if re.fullmatch(r"H[0-9A-F]+", operand):
        return "16#" + operand[1:]
    return operand


def word(operand: str) -> str:
    """A compared operand: an H constant is a 16-bit word, so H8001 is compared as -32767,
    the value MOV H8001 leaves in a D register (FX3U words are signed 16-bit)."""
    if re.fullmatch(r"H[0-9A-F]+", operand) and int(operand[1:], 16) >= 0x8000:
        return str(int(operand[1:], 16) - 0x10000)
    return value(operand)


def timer_ms(name: str, preset: str) -> int:
    unit = 10 if 200 <= int(name[1:]) <= 245 else 100     # FX3U: T200-T245 10 ms, T0-T199 100 ms
    return int(value(preset)) * unit


def timer_time(name: str, preset: str) -> str:
    return f"T#{timer_ms(name, preset)}ms"


def next_device(name: str) -> str:
    m = re.fullmatch(r"([A-Z]+)(\d+)", name)
    return f"{m.group(1)}{int(m.group(2)) + 1}"


def translate(program, name: str) -> str:
    """ST with the ladder's meaning, statement by statement."""
    presets = {i.operands[0]: timer_time(i.operands[0], i.operands[1])
               for i in program if i.op == "OUT" and i.operands[0].startswith("T")}
    body: list[str] = []
    block = mps = edges = 0
    after_output = True

    def contact(op: str) -> str:
        return f"tmr{op}.Q" if re.fullmatch(r"T\d+", op) else op

    for ins in program:
        op, args = ins.op, ins.operands
        cmp = re.fullmatch(r"(LD|AND|OR)(=|<>|>=|<=|>|<)", op)
        if op in ("LD", "LDI", "LDP") or (cmp and cmp.group(1) == "LD"):
            if not after_output:
                body.append(f"bBlk{block} := bAcc;")
                block += 1
            if op == "LDP":
                body += [f"bAcc := {args[0]} AND NOT bEdge{edges};", f"bEdge{edges} := {args[0]};"]
                edges += 1
            elif cmp:
                body.append(f"bAcc := ({word(args[0])} {COMPARE[cmp.group(2)]} {word(args[1])});")
            else:
                body.append(f"bAcc := {'NOT ' if op == 'LDI' else ''}{contact(args[0])};")
            after_output = False
            continue
        if cmp:
            joiner = "AND" if cmp.group(1) == "AND" else "OR"
            body.append(f"bAcc := bAcc {joiner} ({word(args[0])} {COMPARE[cmp.group(2)]} {word(args[1])});")
            continue
        simple = {"AND": "bAcc AND {}", "ANI": "bAcc AND NOT {}", "OR": "bAcc OR {}", "ORI": "bAcc OR NOT {}"}
        if op in simple:
            body.append("bAcc := " + simple[op].format(contact(args[0])) + ";")
        elif op in ("ANB", "ORB"):
            block -= 1
            body.append(f"bAcc := bBlk{block} {'AND' if op == 'ANB' else 'OR'} bAcc;")
        elif op == "MPS":
            body.append(f"bMps{mps} := bAcc;")
            mps += 1
        elif op == "MRD":
            body.append(f"bAcc := bMps{mps - 1};")
        elif op == "MPP":
            mps -= 1
            body.append(f"bAcc := bMps{mps};")
        elif op == "END":
            pass
        else:
            after_output = True
            d = args[0] if op in ("OUT", "SET", "RST", "INC") else (args[-1] if args else "")
            if op == "OUT" and d.startswith("T"):
                body.append(f"tmr{d}(IN := bAcc, PT := {presets[d]});")
            elif op == "OUT":
                body.append(f"{d} := bAcc;")
            elif op in ("SET", "RST") and d.startswith("T"):
                body.append(f"IF bAcc THEN tmr{d}(IN := FALSE, PT := {presets[d]}); END_IF;")
            elif op in ("SET", "RST"):
                body.append(f"IF bAcc THEN {d} := {'TRUE' if op == 'SET' else 'FALSE'}; END_IF;")
            elif op == "RS2":
                s, m, dd, n, n1 = args
                body.append(f"RS2(bAcc, {s}, {value(m)}, {value(n)}, {value(n1)}, {dd});")
            elif op == "CRC":
                s, dd, n = args
                body.append(f"CRC(bAcc, {s}, {value(n)}, {dd});")
            else:
                expr = {
                    "MOV": lambda a: value(a[0]),
                    "ADD": lambda a: f"{value(a[0])} + {value(a[1])}",
                    "MUL": lambda a: f"{value(a[0])} * {value(a[1])}",
                    "DIV": lambda a: f"{value(a[0])} / {value(a[1])}",
                    "WAND": lambda a: f"{value(a[0])} AND {value(a[1])}",
                    "INC": lambda a: f"{a[0]} + 1",
                }[op](args)
                extra = f" {next_device(d)} := {value(args[0])} MOD {value(args[1])};" if op == "DIV" else ""
                body.append(f"IF bAcc THEN {d} := {expr};{extra} END_IF;")
    decls = ["    bAcc : BOOL;"]
    decls += [f"    bBlk{i} : BOOL;" for i in range(4)] + [f"    bMps{i} : BOOL;" for i in range(4)]
    decls += [f"    bEdge{i} : BOOL;" for i in range(edges)] + [f"    tmr{t} : TON;" for t in presets]
    return (f"PROGRAM {name}\nVAR\n" + "\n".join(decls) + "\nEND_VAR\n" + "\n".join(body) + "\nEND_PROGRAM\n")


@pytest.fixture(scope="module")
def program():
    return parse_il(IL.read_text(), str(IL))


def test_committed_csv_is_generated_from_the_il(program):
    assert (LADDER / "UITAMR_LadderFx3.csv").read_bytes().decode("ascii") == to_csv(program, IL.stem)


def test_csv_layout(program):
    rows = to_csv(program, IL.stem).split("\r\n")
    assert rows[0] == '"UITAMR_LadderFx3"'
    assert rows[2].split("\t")[:4] == ['"Step Number"', '"Line Statement"', '"Instruction"', '"I/O(Device)"']
    assert rows[3].split("\t")[:4] == ['"0"', '"R1 first scan: line format, time-out, stop owed, first point"', '"LD"', '"M8002"']


def test_bad_il_names_its_line():
    with pytest.raises(IlError, match=r"x.il:2:"):
        parse_il("LD X0\n#? Y0\nEND\n", "x.il")
    with pytest.raises(IlError, match="END"):
        parse_il("LD X0\nOUT Y0\n", "x.il")


@pytest.mark.parametrize("text, message", [
    ("LD X0\nOUT\nEND\n", r"x.il:2:1: OUT takes 1 operand\(s\), got 0"),
    ("LD X0\nOUT T200\nEND\n", r"x.il:2:1: OUT takes 2 operand\(s\), got 1"),
    ("LD X0\n  MOVV D0 D1\nEND\n", r"x.il:2:3: 'MOVV' is not an instruction this converter knows"),
    ("LD= D0\nEND\n", r"x.il:1:1: LD= takes 2 operand\(s\), got 1"),
    # each was "x.il: the program must end with END", with no line or what to do
    ("LD X0\nOUT Y0\n", r"^x.il:2:1: the program must end with END: add END after this line \(OUT Y0\)$"),
    ("LD X0\nOUT Y0\nEND\nLD X1\n", r"^x.il:4:1: LD after END \(line 3\): END must be the last instruction, "
                                     r"the CPU runs nothing after it$"),
    ("; R1 nothing yet\n", r"^x.il: no instruction in it: an .il holds one instruction a line, the last one END$"),
    # was "got 3: 'OUT Y0 ; lamp'" without why
    ("LD X0\nOUT Y0 ; lamp\nEND\n", r"x.il:2:1: OUT takes 1 operand\(s\), got 3: 'OUT Y0 ; lamp' \(a comment "
                                    r"goes on a line of its own, starting with ';'\)$"),
])
def test_il_mistakes_are_named_with_line_and_column(text, message):
    """A mistyped instruction used to become a CSV row GX Works2 would refuse (with a step
    count of 1), and a missing operand a Python traceback."""
    with pytest.raises(IlError, match=message):
        parse_il(text, "x.il")


def test_the_regeneration_command_reports_mistakes_without_a_traceback(tmp_path):
    """`python -m verifier.export.ladder FILE.il` (docs/plc-library.md) on a missing file,
    a file that is not UTF-8 or no argument: one message, exit status, no traceback."""
    import subprocess
    import sys
    root = Path(__file__).resolve().parents[1]
    bad = tmp_path / "bad.il"
    bad.write_bytes(b"LD X0\nOUT Y0\xff\nEND\n")
    cases = [([str(tmp_path / "missing.il")], 2, "missing.il: cannot read"),
             ([str(bad)], 1, "bad.il:2:7: not UTF-8 text (byte 12): save the file as UTF-8"),
             ([], 2, "usage: python -m verifier.export.ladder FILE.il")]
    for args, status, message in cases:
        run = subprocess.run([sys.executable, "-m", "verifier.export.ladder", *args], cwd=root,
                             capture_output=True, text=True, env={"PYTHONPATH": str(root), "PATH": ""})
        assert run.returncode == status, run.stderr
        assert message in run.stderr and "Traceback" not in run.stderr, run.stderr
    ok = subprocess.run([sys.executable, "-m", "verifier.export.ladder", str(IL)], cwd=root,
                        capture_output=True, env={"PYTHONPATH": str(root), "PATH": ""})
    assert ok.returncode == 0 and ok.stdout == (LADDER / "UITAMR_LadderFx3.csv").read_bytes()


def test_the_regeneration_command_writes_its_file_only_when_the_il_converts(tmp_path):
    """`python -m verifier.export.ladder X.il > X.csv` left an empty X.csv when the .il had a
    mistake (the shell empties the file before the command runs), and GX Works2 then read a
    program of nothing. `-o X.csv` writes the file only once the conversion succeeded, whole
    (a temporary file renamed over it); on a mistake the CSV there stays as it was."""
    import subprocess
    import sys
    root = Path(__file__).resolve().parents[1]
    env = {"PYTHONPATH": str(root), "PATH": ""}
    csv = tmp_path / "out.csv"
    csv.write_bytes(b"the previous CSV\r\n")
    bad = tmp_path / "bad.il"
    bad.write_text("LD X0\nOUTT Y0\nEND\n", encoding="utf-8")
    run = subprocess.run([sys.executable, "-m", "verifier.export.ladder", str(bad), "-o", str(csv)], cwd=root,
                         capture_output=True, text=True, env=env)
    assert run.returncode == 1 and "bad.il:2:1" in run.stderr and "Traceback" not in run.stderr, run.stderr
    assert csv.read_bytes() == b"the previous CSV\r\n" and run.stdout == ""
    assert sorted(p.name for p in tmp_path.iterdir()) == ["bad.il", "out.csv"]  # no temporary file left
    ok = subprocess.run([sys.executable, "-m", "verifier.export.ladder", str(IL), "--out", str(csv)], cwd=root,
                        capture_output=True, env=env)
    assert ok.returncode == 0 and ok.stdout == b"", ok.stderr
    assert csv.read_bytes() == (LADDER / "UITAMR_LadderFx3.csv").read_bytes()
    # the .il itself as the output is refused: it would be overwritten by its own CSV
    same = subprocess.run([sys.executable, "-m", "verifier.export.ladder", str(bad), "-o", str(bad)], cwd=root,
                          capture_output=True, text=True, env=env)
    assert same.returncode == 2 and "is the .il itself" in same.stderr
    assert bad.read_text(encoding="utf-8") == "LD X0\nOUTT Y0\nEND\n"


def test_frame_constants_match_the_protocol(program):
    """The words the ladder writes are the protocol's frames, two bytes per word, low first."""
    words = lambda frame: [frame[i] | frame[i + 1] << 8 for i in range(0, 6, 2)]
    movs = {(i.operands[1], value(i.operands[0])) for i in program if i.op == "MOV"}
    stop = words(encode(ControlRequest(1, 1, 0xA0)))
    read = words(encode(StatusRequest(1, 0)))
    assert ("D200", f"16#{stop[0]:04X}") in movs and ("D227", f"16#{stop[1]:04X}") in movs
    assert {("D200", f"16#{read[0]:04X}"), ("D202", f"16#{read[2]:04X}")} <= movs
    assert ("D8400", "16#1C81") in movs


SCENARIO = """
name = "{name}"
sources = ["UITAMR_LadderFx3.st"]
program = "UITAMR_LadderFx3"
platform = "fx3u"
duration = "{duration}"
scan = "{scan}"

[robot]
point_duration_s = 6.0
"""


def table(section: str, **keys) -> str:
    """One TOML array-of-tables entry: [[section]] with its keys (strings quoted, inline tables kept)."""
    def shown(v):
        if isinstance(v, bool):
            return "true" if v else "false"
        if isinstance(v, (int, float)) or (isinstance(v, str) and v.startswith("{")):
            return str(v)
        return f'"{v}"'
    return f"\n[[{section}]]\n" + "".join(f"{k} = {shown(v)}\n" for k, v in keys.items())


def press(device: str, at: str) -> str:
    return table("inputs", at=at, set=f"{{ {device} = true }}", pulse="500ms")


def run_ladder(tmp_path, program, name, *parts, duration="45s", signal=None, scan="10ms"):
    (tmp_path / "UITAMR_LadderFx3.st").write_text(translate(program, "UITAMR_LadderFx3"))
    text = SCENARIO.format(name=name, duration=duration, scan=scan) + press("X0", "2s")
    text += table("expect", sent="stop", within="1s") + "".join(parts)
    if signal:
        text += f'\n[response_handling]\nsignal = "{signal}"\nwithin = "5s"\n'
    path = tmp_path / "ladder.toml"
    path.write_text(text)
    result = run_scenario(load_scenario(path))
    problems = [f"{v.rule} at {v.t_us / 1e6:.3f} s: {v.message}" for v in result.all_violations()[:5]]
    problems += [str(getattr(e, "message", e)) for e in result.failed_expectations]
    return result, problems


def test_ladder_runs_the_point_cycle(tmp_path, program):
    result, problems = run_ladder(
        tmp_path, program, "ladder: cycle over points 1-3",
        table("expect", reached_point=3, within="40s"), table("expect", never="Y3"),
        table("expect", that="Y0 AND Y1", within="3s"))
    assert result.passed, "\n".join(problems)


def test_ladder_reports_no_reply_and_recovers_after_acknowledge(tmp_path, program):
    result, problems = run_ladder(
        tmp_path, program, "ladder: no reply",
        table("faults", kind="no_reply", at_s=4.0, duration_s=4.0),
        press("X2", "10s"), press("X0", "12s"),
        table("expect", that="Y3 AND D225 = 16#0101", after="4s", within="4s"),
        table("expect", reached_point=2, after="12s", within="30s"), signal="Y3")
    assert result.passed, "\n".join(problems)


def test_ladder_stops_the_cycle_on_anti_collision(tmp_path, program):
    result, problems = run_ladder(
        tmp_path, program, "ladder: anti-collision",
        table("faults", kind="anti_collision", at_s=5.0),
        table("expect", that="Y3 AND D225 = 16#0201", after="5s", within="2s"), duration="10s")
    assert result.passed, "\n".join(problems)


def test_ladder_does_not_send_into_a_late_reply_it_is_receiving(tmp_path, program):
    """R9 sends only when no byte of an unfinished reception is counted in D8403: with a
    5 ms scan a reply 680 ms late was still arriving when the retry fell due, and the retry
    went out 3.3 ms after its last byte (UITAMR-HALF-DUPLEX: t3.5 is 3.65 ms)."""
    result, problems = run_ladder(
        tmp_path, program, "ladder: late reply", table("faults", kind="late_reply", on_request=9, delay_ms=680),
        duration="20s", scan="5ms")
    assert result.passed, "\n".join(problems)


def test_ladder_rejects_a_bad_crc_and_retries(tmp_path, program):
    result, problems = run_ladder(
        tmp_path, program, "ladder: bad CRC",
        table("faults", kind="bad_crc", on_request=6),
        table("expect", reached_point=2, within="30s"), table("expect", never="Y3"), duration="30s")
    assert result.passed, "\n".join(problems)


def test_ladder_sends_the_stop_next_when_x1_comes_during_a_retry(tmp_path, program):
    """X1 while the point command waits for a reply that never comes: the ladder used to
    send the point command again after the stop button, so a robot that answered it drove
    off. Now the retry becomes a task-status read and the stop follows it (R24, R19): no
    control command after the button but the stop, and UITAMR-CYCLE's read in between."""
    result, problems = run_ladder(
        tmp_path, program, "ladder: stop during a retry",
        table("faults", kind="no_reply", at_s=2.0, count=1, requests="control"),
        press("X1", "2.3s"), table("expect", that="NOT Y1", after="2.3s", within="1s"), duration="8s")
    assert result.passed, "\n".join(problems)
    stop = encode(ControlRequest(1, 1, 0xA0))
    after = [f.data for f in result.trace if f.direction == "tx" and f.t_start_us > 2_300_000]
    read_task = encode(StatusRequest(1, 0))
    assert after[:2] == [read_task, stop], [a.hex(" ") for a in after[:3]]
    run_point = [f for f in result.trace if f.direction == "tx" and f.data[1] == 6 and f.data != stop]
    assert len(run_point) == 1, [(f.t_start_us, f.data.hex(" ")) for f in run_point]


def test_ladder_waits_for_the_reply_time_out_after_three_failed_power_on_stops(tmp_path, program):
    """A robot silent for the first 3 s: after three unanswered stops the ladder starts the
    stop again at once (M100 still owed). T201, the reply timer, stayed ON across that
    back-to-back restart (its coil never saw step 30 left at R10), so the new stop timed out
    in the same scan: the retry went out 300 ms later while its reply could still come
    (UITAMR-ONE-AT-A-TIME), and an echo arriving then was flushed and the stop sent again
    (UITAMR-CYCLE). R9 now resets T201 with every frame it sends."""
    result, _ = run_ladder(
        tmp_path, program, "ladder: silent at power-on",
        table("faults", kind="no_reply", at_s=0.0, duration_s=3.0),
        table("expect", that="M100 = FALSE", within="6s"), duration="8s")
    assert [f"{v.rule} at {v.t_us / 1e6:.3f} s: {v.message}" for v in result.all_violations()] == []
    sent = [f.t_start_us for f in result.trace if f.direction == "tx"]
    answered = {f.t_start_us for f in result.trace if f.direction == "rx"}
    assert all(b - a >= 500_000 for a, b in zip(sent, sent[1:]) if b < 3_000_000), sent
    assert answered


def test_ladder_on_the_rs232_route_with_h0081(tmp_path, program):
    """plc-library.md: on the RS-232 route change R1's H1C81 to H0081 and nothing else."""
    guide = " ".join((Path(__file__).resolve().parents[1] / "docs" / "plc-library.md").read_text(encoding="utf-8").split())
    assert "change R1's `MOV H1C81 D8400` to `MOV H0081 D8400`; nothing else changes" in guide
    from dataclasses import replace
    rs232 = [replace(i, operands=("H0081", "D8400")) if i.operands == ("H1C81", "D8400") else i for i in program]
    assert rs232 != program
    result, problems = run_ladder(
        tmp_path, rs232, "ladder: RS-232 route",
        table("expect", reached_point=3, within="40s"), table("expect", never="Y3"),
        table("expect", that="D8400 = 16#0081", within="20ms"))
    assert result.passed, "\n".join(problems)
    assert result.diagnostics == []


def test_ladder_reports_a_silent_robot_when_the_stop_was_pressed(tmp_path, program):
    """The robot goes silent and the operator presses stop during the retries: R24 turned
    every retry into a task-status read (step 15) and R8 set the attempt count back to 0
    with each one, so the ladder polled for ever: no fault, no Y3, no 16#0101 (the ST engine
    reports 16#0101 after three attempts). A failed status read is resent as before; only a
    failed control command becomes the read."""
    result, problems = run_ladder(
        tmp_path, program, "ladder: silent robot, stop pressed",
        table("faults", kind="no_reply", at_s=4.0, duration_s=30.0),
        press("X1", "4.3s"),
        table("expect", that="Y3 AND D225 = 16#0101", after="4s", within="5s"), duration="12s",
        signal="Y3")
    assert result.passed, "\n".join(problems)


def test_ladder_error_id_is_the_code_of_the_fault_it_shows(tmp_path, program):
    """D225 kept the code of a failed attempt after its retry had succeeded (R12 and R15
    wrote it on every failed attempt: a bad CRC left 16#0102 with no fault), and the code of
    an acknowledged fault for good: an HMI read a stale error. It now behaves as the ST
    example's cycle error (UITAMR_PointCycle's o_uErrId, D101 of UITAMR_ExampleFx3): written
    when the fault M103 / Y3 is set, kept while it stands (a stop with X1 in the fault keeps
    both), cleared by the acknowledge X2; a failed attempt that a retry makes good shows
    nothing, as the engine reports a job's code only when the job ends."""
    result, problems = run_ladder(
        tmp_path, program, "ladder: error id follows the fault",
        table("faults", kind="bad_crc", on_request=6),
        table("faults", kind="no_reply", at_s=9.0, count=1),
        table("faults", kind="no_reply", at_s=16.0, duration_s=4.0),
        press("X1", "21s"), press("X2", "24s"), press("X0", "26s"),
        table("expect", never="(D225 <> 0) <> Y3"),
        table("expect", that="Y3 AND D225 = 16#0101", after="16s", within="5s"),
        table("expect", always="Y3 AND D225 = 16#0101", after="21s", within="2900ms"),
        table("expect", that="NOT Y3 AND D225 = 0", after="24s", within="1s"),
        table("expect", reached_point=2, after="26s", within="30s"), duration="60s")
    assert result.passed, "\n".join(problems)
    tx = [f for f in result.trace if f.direction == "tx"]
    assert len({f.data for f in tx if 8_000_000 < f.t_start_us < 15_000_000}) < len(
        [f for f in tx if 8_000_000 < f.t_start_us < 15_000_000]), "no retry was exercised"


def test_the_regeneration_command_keeps_a_link_and_the_file_s_mode(tmp_path, monkeypatch):
    """`-o X.csv` renamed its temporary file over X.csv: a link X.csv (to the CSV kept in the
    project folder) became a file of its own and the project's CSV stayed old, where the
    shell's `> X.csv` writes through the link. And it set the mode with os.chmod on a file
    descriptor, which Windows' Python before 3.13 refuses (TypeError: a traceback, the
    temporary file left open): here os.chmod refuses descriptors as it does there."""
    import os
    import stat

    from verifier.export import ladder

    real_chmod = os.chmod

    def chmod_without_descriptors(path, mode, *args, **kwargs):
        if isinstance(path, int):
            raise TypeError("chmod: path should be string, bytes or os.PathLike, not int")
        return real_chmod(path, mode, *args, **kwargs)

    monkeypatch.setattr(os, "chmod", chmod_without_descriptors)
    kept = tmp_path / "project" / "UITAMR_LadderFx3.csv"
    kept.parent.mkdir()
    kept.write_bytes(b"the previous CSV\r\n")
    real_chmod(kept, 0o640)
    link = tmp_path / "out.csv"
    link.symlink_to(kept)
    assert ladder.main([str(IL), "-o", str(link)]) == 0
    assert link.is_symlink() and kept.read_bytes() == (LADDER / "UITAMR_LadderFx3.csv").read_bytes()
    assert stat.S_IMODE(kept.stat().st_mode) == 0o640
    assert sorted(p.name for p in kept.parent.iterdir()) == ["UITAMR_LadderFx3.csv"]  # no temporary file left


def test_an_il_named_with_a_newline_keeps_its_mistakes_on_one_line():
    """The converter's mistakes built 'file:line:col' by hand from the raw name: `b<LF>ad.il`
    broke each into two lines, where every other message shows the name escaped (Place)."""
    for text, message in (("LD X0\nOUTT Y0\nEND\n", "b\\x0aad.il:2:1: 'OUTT' is not an instruction"),
                          ("LD X0 X1\nEND\n", "b\\x0aad.il:1:1: LD takes 1 operand(s)"),
                          ("LD X0\n", "b\\x0aad.il:1:1: the program must end with END")):
        with pytest.raises(IlError) as caught:
            parse_il(text, "b\nad.il")
        assert str(caught.value).startswith(message), str(caught.value)


def test_the_regeneration_command_s_own_messages_keep_a_name_with_a_newline_on_one_line(tmp_path, capsys):
    """The command's messages about its files (a .il that cannot be read, a CSV that cannot be
    written, -o naming the .il) printed the raw name: `b<LF>ad.il` broke each in two."""
    from verifier.export import ladder

    missing = tmp_path / "b\nad.il"
    assert ladder.main([str(missing)]) == 2
    assert capsys.readouterr().err.startswith(f"{tmp_path}/b\\x0aad.il: ")
    assert ladder.main([str(IL), "-o", str(tmp_path / "no\nfolder" / "x.csv")]) == 2
    assert capsys.readouterr().err.startswith(f"{tmp_path}/no\\x0afolder/x.csv: cannot write: ")
    il = tmp_path / "c\nd.il"
    il.write_text("END\n", encoding="utf-8")
    assert ladder.main([str(il), "-o", str(il)]) == 2
    assert capsys.readouterr().err == f"{tmp_path}/c\\x0ad.il: is the .il itself: name the .csv to write (-o {tmp_path}/c\\x0ad.csv)\n"


def test_the_regeneration_command_writes_into_a_pipe_and_leaves_it_one(tmp_path):
    """`-o` renamed its temporary file over whatever the path named: `-o` a pipe (or, run as
    root, `-o /dev/null`) replaced it with a regular file. A pipe or a device is now written
    to, as `> FILE` writes to it."""
    import os
    import stat
    import threading

    from verifier.export import ladder

    pipe = tmp_path / "csv.pipe"
    os.mkfifo(pipe)
    received = []
    reader = threading.Thread(target=lambda: received.append(pipe.read_bytes()), daemon=True)
    reader.start()
    assert ladder.main([str(IL), "-o", str(pipe)]) == 0
    assert stat.S_ISFIFO(pipe.stat().st_mode)  # (replaced, the reader waits on a pipe no one opens)
    reader.join(10)
    assert received == [(LADDER / "UITAMR_LadderFx3.csv").read_bytes()]


def test_devices_written_in_lower_case_reach_the_csv_in_upper_case():
    """`ld x0` gave the CSV row "LD" "x0": the instruction was upper-cased, its device not;
    GX Works2 writes devices in upper case in its own CSV (ASSUMPTION: that its reader wants
    them so is not confirmed; upper case is what it writes)."""
    csv = to_csv(parse_il("ld x0\nout t200 k30\nmov h1c81 d8400\nend\n", "x.il"), "x")
    rows = [line.split("\t")[2:4] for line in csv.splitlines()[3:]]
    assert rows == [['"LD"', '"X0"'], ['"OUT"', '"T200"'], ['""', '"K30"'], ['"MOV"', '"H1C81"'], ['""', '"D8400"'],
                    ['"END"', '""']]


@pytest.mark.parametrize("name, text", [
    ("UITAMR_Command.st", "LD X0\nEND\n"),  # named .st: whatever it holds
    ("fb.txt", "(* UITAMR_Command *)\nFUNCTION_BLOCK UITAMR_Command\nEND_FUNCTION_BLOCK\n"),
    ("main.il", "\ufeff  program Main\nVAR x : BOOL; END_VAR\nEND_PROGRAM\n"),
    ("fb.il", "FUNCTION_BLOCK Fb\nEND_FUNCTION_BLOCK\n"),
])
def test_the_regeneration_command_names_an_st_file_as_one(tmp_path, capsys, name, text):
    """Given an ST file, the converter said "'(*' is not an instruction this converter knows"
    (exit 1), as if an .il had a typo: it now says the file is structured text and what reads
    it, with the exit status of other unusable input (2), and writes no CSV."""
    from verifier.export import ladder

    source = tmp_path / name
    source.write_text(text, encoding="utf-8")
    csv = tmp_path / "out.csv"
    assert ladder.main([str(source), "-o", str(csv)]) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"{source}: is structured text (ST), not an instruction list"), err
    assert "`uitamr check`" in err and "`uitamr export`" in err and "not an instruction this" not in err
    assert not csv.exists()


@pytest.mark.parametrize("text, message", [
    # each was converted without a word into a CSV GX Works2 refuses, or a program that does not run
    ("LD X8\nOUT Y0\nEND\n", r"^x.il:1:4: device X8: X numbers are base 8 on the fx3u"),
    ("LD X0\nOUT Y19\nEND\n", r"^x.il:2:5: device Y19: Y numbers are base 8 on the fx3u"),
    ("LD X0\nMOV K1 D9000\nEND\n", r"^x.il:2:8: device D9000 does not exist on the fx3u: D runs D0..D8511"),
    ("LD SM400\nOUT Y0\nEND\n", r"^x.il:1:4: device SM400: the fx3u has no SM devices; .* use M8000"),
    ("LD X0\nOUT T600 K10\nEND\n", r"^x.il:2:5: device T600 does not exist on the FX3U: T runs T0..T511"),
    ("LD X0\nOUT D0\nEND\n", r"^x.il:2:5: OUT takes a bit device \(Y, M, S\) or a timer or counter with its "
                             r"preset; D0 is a word device"),
    ("LD D0\nOUT Y0\nEND\n", r"^x.il:1:4: LD takes a bit device \(X, Y, M, S, T, C\); D0 is a word device: "
                             r"compare a word with LD= D0 K\.\.\."),
    ("LD X0\nMOV K1 K2\nEND\n", r"^x.il:2:8: MOV stores its result in K2, a constant: give a word device "
                                r"\(D, R\) there"),
    ("LD X0\nRS2 D200 K8 K0 K8 K1\nEND\n", r"^x.il:2:13: RS2 stores its result in K0, a constant"),
])
def test_an_operand_the_fx3u_does_not_have_or_of_the_wrong_kind_is_named_at_its_column(text, message):
    """A technician who changed the example's devices (X8 for the ninth input, a D past
    D8511, a word on OUT, a constant as MOV's destination) got a CSV without a word: the
    converter only counted operands. The device rules are `uitamr check --platform fx3u`'s."""
    with pytest.raises(IlError, match=message):
        parse_il(text, "x.il")


def test_the_operands_of_the_bundled_ladder_and_ordinary_ones_are_accepted(program):
    parse_il("LD X0\nLDP X17\nORB\nOUT T0 K10\nOUT C255 K5\nRST D0\nRST T0\nMOV H1C81 D8400\nMOV K4M0 D0\n"
             "LD= D0 K1\nMOV D0Z1 R100\nINC D0\nOUT M8000\nEND\n", "x.il")


def test_a_comment_before_an_instruction_that_is_not_carried_into_the_csv_is_noted(tmp_path):
    """`; 啟動按鈕` over a rung (no R and number) vanished from the CSV without a word: only
    `; R5 ...` comments become line statements. The converter writes the CSV and says so at
    the comment; comments that are not directly over an instruction (the file's header),
    and one that continues an R comment, are not noted."""
    import subprocess
    import sys

    il = tmp_path / "cell.il"
    il.write_text("; my cell\n; devices: X10 start\n; R1 first scan\nLD M8002\nSET M100\n; 啟動按鈕\nLD X10\n"
                  "SET M101\n; R2 停止\n; 第二行\nLD X11\nRST M101\nEND\n", encoding="utf-8")
    notes: list[str] = []
    program = parse_il(il.read_text(encoding="utf-8"), str(il), notes)
    assert [i.statement for i in program if i.statement] == ["R1 first scan", "R2 停止"]
    assert notes == [f"{il}:6:3: note: this comment is not carried into the CSV: only a comment that starts "
                     f"with R and a number (; R5 ...) becomes the line statement of the instruction after it"]
    run = subprocess.run([sys.executable, "-m", "verifier.export.ladder", str(il), "-o", str(tmp_path / "cell.csv")],
                         cwd=Path(__file__).resolve().parents[1], capture_output=True, text=True, encoding="utf-8")
    assert (run.returncode, run.stderr) == (0, notes[0] + "\n"), run


def test_an_il_saved_as_utf16_or_big5_says_to_save_it_as_utf8(tmp_path, capsys):
    """Notepad on a Traditional Chinese Windows saves "Unicode" (UTF-16) or "ANSI" (Big5): the
    converter said "u16.il: line 1, column 1 (byte 0): not UTF-8 text", without what to do and
    not as file:line:col, where a scenario or fault file says "save the file as UTF-8"."""
    from verifier.export import ladder

    text = "; R1 啟動\r\nLD X0\r\nOUT Y0\r\nEND\r\n"
    u16, big5 = tmp_path / "u16.il", tmp_path / "b5.il"
    u16.write_bytes(b"\xff\xfe" + text.encode("utf-16-le"))
    big5.write_bytes(text.encode("big5"))
    assert ladder.main([str(u16)]) == 1
    assert capsys.readouterr().err == (f"{u16}:1:1: the file is UTF-16 (it starts with FF FE, UTF-16's byte order "
                                       f"mark; an editor's \"Unicode\"), not UTF-8: save it as UTF-8\n")
    assert ladder.main([str(big5)]) == 1
    assert capsys.readouterr().err == f"{big5}:1:6: not UTF-8 text (byte 5): save the file as UTF-8\n"


def test_every_rung_comment_of_the_bundled_ladder_is_whole_in_the_csv():
    """The CSV carries a rung's `; Rn` line only, not the comment lines after it: R9's
    statement ran on to a second line and arrived in GX Works2 cut mid-sentence,
    "... no frame is arriving (D8403 counts". Each statement must read as a whole: its
    brackets closed (the detail goes on a plain comment line of the .il)."""
    statements = [i.statement for i in parse_il(IL.read_text(encoding="utf-8"), str(IL)) if i.statement]
    assert len(statements) >= 25
    cut = [s for s in statements if s.count("(") != s.count(")")]
    assert not cut, cut


def pause_resume_parts(pause_at: str = "4s", resume_at: str = "10s"):
    return (press("X3", pause_at), press("X4", resume_at),
            table("expect", sent="run-point 1", after="2s", within="1s"),
            table("expect", sent="pause", after=pause_at, within="350ms"),
            table("expect", sent="run-point 1", after=resume_at, within="350ms"),
            table("expect", never="Y3"))


def test_ladder_pauses_the_running_point_and_resumes_it(tmp_path, program):
    """X3 while point 1 runs: control 01/80 at the next pace (300 ms from the last frame's
    start), between the point's status reads, which go on; Y6 lit while paused, the point
    not counted reached (D222 stays 1) though it would have ended at 8.3 s unpaused; X4
    sends point 1 again at the next pace, Y6 goes out, the robot finishes the point with
    the paused time added and the cycle goes on to point 2. Before, the ladder had no pause:
    X3 and X4 did nothing and point 1 was reached at 8.3 s."""
    result, problems = run_ladder(
        tmp_path, program, "ladder: pause and resume", *pause_resume_parts(),
        table("expect", always="Y6 AND Y1 AND Y2 AND D222 = 1", after="4400ms", within="5500ms"),
        table("expect", that="NOT Y6", after="10s", within="400ms"),
        table("expect", always="D222 = 1 AND Y2", after="10s", within="3800ms"),
        table("expect", reached_point=1, after="10s", within="7s"),
        table("expect", sent="run-point 2", after="13800ms", within="1s"), duration="20s")
    assert result.passed, "\n".join(problems)
    tx = [f for f in result.trace if f.direction == "tx"]
    pause = encode(ControlRequest(1, 1, 0x80))
    paused = [f for f in tx if 4_000_000 < f.t_start_us < 10_000_000]
    assert [f.data for f in paused].count(pause) == 1
    assert {f.data for f in paused} == {pause, encode(StatusRequest(1, 0))}, "the status reads go on while paused"
    assert all(b.t_start_us - a.t_start_us >= 300_000 for a, b in zip(tx, tx[1:]))


def test_ladder_stop_overtakes_a_paused_point(tmp_path, program):
    """X1 while point 1 is paused: the stop goes out at the next pace (after the status
    read on its way), Y6 goes out with the stop's echo, no fault, the cycle ends and the
    point is never sent again."""
    result, problems = run_ladder(
        tmp_path, program, "ladder: pause then stop",
        press("X3", "4s"), press("X1", "7s"),
        table("expect", sent="pause", after="4s", within="350ms"),
        table("expect", that="Y6", after="4s", within="1s"),
        table("expect", sent="stop", after="7s", within="700ms"),
        table("expect", always="NOT Y6 AND NOT Y1 AND NOT Y2", after="8s"),
        table("expect", never="Y3"), duration="14s")
    assert result.passed, "\n".join(problems)
    runs = [f for f in result.trace if f.direction == "tx" and f.data[1] == 6 and f.data[3] not in (0x80, 0xA0)]
    assert len(runs) == 1 and runs[0].t_start_us < 3_000_000, [(f.t_start_us, f.data.hex(" ")) for f in runs]


def test_ladder_resume_without_a_pause_and_a_pause_after_the_stop_send_nothing(tmp_path, program):
    """X4 with nothing paused, X3 and X4 after the stop: no frame (no pause, no point sent
    again that no step machine follows)."""
    result, problems = run_ladder(
        tmp_path, program, "ladder: buttons with nothing to pause",
        press("X4", "4s"), press("X1", "6s"), press("X3", "8s"), press("X4", "9s"),
        table("expect", never="Y6 OR Y3"), duration="12s")
    assert result.passed, "\n".join(problems)
    control = [f for f in result.trace if f.direction == "tx" and f.data[1] == 6]
    assert [f.data[3] for f in control] == [0xA0, 1, 0xA0], [(f.t_start_us, f.data.hex(" ")) for f in control]


def test_ladder_does_not_take_a_paused_task_reported_idle_as_the_point_reached(tmp_path, program):
    """A pause that reaches the robot after the point has ended (pressed in its last status
    read's pace) pauses nothing: the robot reports the task idle. The ladder cannot tell that
    idle from a paused task reported idle, so while Y6 is lit the idle is not the point
    reached (D222 stays, no next point); the resume sends the point again (the emulated robot
    runs it anew: 6 s), and the cycle goes on once that run has ended."""
    result, problems = run_ladder(
        tmp_path, program, "ladder: pause as the point ends", *pause_resume_parts("8s", "11s"),
        table("expect", always="Y6 AND D223 = 0 AND D222 = 1", after="9s", within="2s"),
        table("expect", always="NOT Y6 AND D222 = 1", after="11400ms", within="5500ms"),
        table("expect", sent="run-point 2", after="17s", within="1500ms"), duration="20s")
    assert result.passed, "\n".join(problems)


def test_ladder_a_silent_robot_while_paused_ends_in_the_fault_as_before(tmp_path, program):
    """The robot falls silent while point 1 is paused: three unanswered status reads end in
    the fault (Y3, D225 = 16#0101) as without the pause; Y6 stays lit (the robot was left
    paused) until the acknowledge's stop is answered, and a new start runs point 1 again,
    unpaused (no pause asked before the fault is left over)."""
    result, problems = run_ladder(
        tmp_path, program, "ladder: silent while paused",
        press("X3", "4s"), table("faults", kind="no_reply", at_s=6.0, duration_s=3.0),
        press("X2", "10s"), press("X0", "12s"),
        table("expect", sent="pause", after="4s", within="350ms"),
        table("expect", that="Y3 AND Y6 AND D225 = 16#0101", after="6s", within="3s"),
        table("expect", sent="stop", after="10s", within="1s"),
        table("expect", always="NOT Y6 AND NOT Y3", after="11s"),
        table("expect", sent="run-point 1", after="12s", within="1s"),
        table("expect", that="Y2", after="12500ms", within="1s"), duration="16s", signal="Y3")
    assert result.passed, "\n".join(problems)
    pauses = [f for f in result.trace if f.direction == "tx" and f.data == encode(ControlRequest(1, 1, 0x80))]
    assert len(pauses) == 1


def test_ladder_a_pause_pressed_with_the_start_waits_for_the_point_s_status_read(tmp_path, program):
    """X3 just after X0, while point 1's control command is on its way: the pause is not sent
    straight after that command (UITAMR-CYCLE: a control command's task status is read first,
    M111) but in place of the next status read, and pauses point 1."""
    result, problems = run_ladder(
        tmp_path, program, "ladder: pause with the start", press("X3", "2020ms"),
        table("expect", sent="pause", after="2s", within="1s"),
        table("expect", always="Y6 AND D222 = 1", after="3s", within="8s"), duration="12s")
    assert result.passed, "\n".join(problems)
    control = [f for f in result.trace if f.direction == "tx" and f.data[1] == 6]
    assert [f.data[3] for f in control] == [0xA0, 1, 0x80]
