"""The rung table of docs/plc-library.md ("Ladder for FX3U") against the instruction list it
explains (plc/ladder/UITAMR_LadderFx3.il): the same rungs in the same order, and in each
row only devices, steps, constants and timer times that rung has - so an edit of one that
leaves the other behind fails here, not in front of an integrator reading the table."""
from __future__ import annotations

import re
from pathlib import Path

import pytest

from test_plc_ladder import next_device, timer_ms
from verifier.export.ladder import parse_il

ROOT = Path(__file__).resolve().parents[1]
IL = ROOT / "plc" / "ladder" / "UITAMR_LadderFx3.il"
GUIDE = ROOT / "docs" / "plc-library.md"
DEVICE = re.compile(r"\b([XYMDT]\d+)\b")
STEP = "D220"  # the step register, as the Devices paragraph names it


def _section() -> str:
    text = GUIDE.read_text(encoding="utf-8")
    return text[text.index("## Ladder for FX3U"):text.index("\n## ", text.index("## Ladder for FX3U") + 1)]


def _rows() -> dict[str, str]:
    return dict(re.findall(r"^\| (R\d+) \| (.*) \|$", _section(), re.M))


def _rungs() -> dict[str, list]:
    """The .il's instructions by rung: a rung starts at its "; Rn ..." comment."""
    rungs: dict[str, list] = {}
    name = None
    for ins in parse_il(IL.read_text(encoding="utf-8"), str(IL)):
        if ins.statement:
            name = ins.statement.split()[0]
            rungs[name] = []
        if name is not None:
            rungs[name].append(ins)
    return rungs


def _devices(text: str) -> set[str]:
    """The devices `text` names, ranges (D200–D203) one by one."""
    found = set(DEVICE.findall(text))
    for first, last in re.findall(r"\bD(\d+)[–-]D(\d+)\b", text):
        found |= {f"D{n}" for n in range(int(first), int(last) + 1)}
    return found


def _written(rung: list) -> set[str]:
    """Every device a rung reads or writes: its operands, and the device after the
    destination of DIV (the remainder, as the ladder's ST translation in test_plc_ladder.py
    writes it) and of MUL (the high word of the 32-bit product, which the FX3U writes and
    the translation leaves out: no rung reads it)."""
    devices = {op for ins in rung for op in ins.operands}
    devices |= {next_device(ins.operands[2]) for ins in rung if ins.op in ("DIV", "MUL")}
    return devices


def _value(operand: str) -> int | None:
    if re.fullmatch(r"K-?\d+", operand):
        return int(operand[1:])
    if re.fullmatch(r"H[0-9A-F]+", operand):
        return int(operand[1:], 16)
    return None


def test_the_table_has_the_rungs_of_the_il_in_order():
    assert list(_rows()) == list(_rungs())


@pytest.mark.parametrize("rung", list(_rows()))
def test_a_row_names_only_devices_of_its_rung(rung):
    """A device in the row is one the rung's instructions use (R17's remainder D224 is DIV's
    D223 + 1); context from other rungs is named by its rung (R4, R12), not its devices."""
    assert _devices(_rows()[rung]) <= _written(_rungs()[rung])


@pytest.mark.parametrize("rung", list(_rows()))
def test_a_row_names_the_steps_its_rung_acts_in_and_goes_to(rung):
    """"Step N" (a capital S) is the step the rung acts in (LD= D220 KN); every step it
    moves to (MOV KN D220) is named in the row, and the row names no other."""
    text, instructions = _rows()[rung], _rungs()[rung]
    acts_in = {_value(i.operands[1]) for i in instructions if i.op == "LD=" and i.operands[0] == STEP}
    goes_to = {_value(i.operands[0]) for i in instructions if i.op == "MOV" and i.operands[1] == STEP}
    assert {int(n) for n in re.findall(r"\bStep (\d+)", text)} == acts_in
    assert {int(n) for n in re.findall(r"\b[Ss]tep (\d+)", text)} == acts_in | goes_to


@pytest.mark.parametrize("rung", list(_rows()))
def test_the_values_a_row_gives_are_the_rungs(rung):
    """`D8400 = H1C81`, `D225 = 16#0101`, `D8409 = 5`: the rung moves that value there;
    a constant written as the .il writes it (HA001, H1600) is one of the rung's operands."""
    text, instructions = _rows()[rung], _rungs()[rung]
    moves = {(i.operands[1], _value(i.operands[0])) for i in instructions if i.op == "MOV"}
    operands = {op for i in instructions for op in i.operands}
    for device, given in re.findall(r"\b(D\d+) = (H[0-9A-F]+|16#[0-9A-F]+|\d+)\b(?![#\w]| *[+×*/])", text):
        value = int(given[3:], 16) if given.startswith("16#") else _value(given) if given[0] == "H" else int(given)
        assert (device, value) in moves, f"{rung}: {device} = {given}"
    for constant in re.findall(r"\bH[0-9A-F]{4}\b", text):
        assert constant in operands, f"{rung}: {constant}"


def test_the_timer_times_are_the_il_presets():
    """"T200 pacing 300 ms" and the like, in the Devices paragraph and the rows, against the
    preset of the timer's OUT, in the FX3U's units as test_plc_ladder.py translates them
    (T200-T245 count 10 ms)."""
    presets = {i.operands[0]: timer_ms(*i.operands) for rung in _rungs().values() for i in rung
               if i.op == "OUT" and i.operands[0].startswith("T")}
    named = re.findall(r"\b(T\d+)\b[^.;|\d]{0,25}?\b(\d+) ms\b", " ".join(_section().split()))
    assert {timer for timer, _ in named} == set(presets)
    for timer, ms in named:
        assert presets[timer] == int(ms), f"{timer}: {ms} ms in the guide, {presets[timer]} ms in the .il"


def test_every_device_of_the_il_is_explained():
    """Each device the .il uses is in the Devices paragraph or in a row (the CPU's own M8002,
    D8400 ... where a rung uses them), and the paragraph lists the devices the .il's own
    heading lists, no more and no fewer."""
    section = _section()
    paragraph = section[section.index("Devices:"):section.index("| rung |")]
    listed = _devices(paragraph)
    named = listed | _devices(" ".join(_rows().values()))
    unexplained = {rung: sorted(_devices(" ".join(op for i in instructions for op in i.operands)) - named)
                   for rung, instructions in _rungs().items()}
    assert {rung: devices for rung, devices in unexplained.items() if devices} == {}
    lines = IL.read_text(encoding="utf-8").splitlines()
    heading = "\n".join(lines[:next(n for n, line in enumerate(lines) if line.startswith("; R1 "))])
    assert listed == _devices(heading[heading.index("Devices:"):])


def test_an_instruction_the_guide_quotes_is_in_its_rung():
    """"change R1's `MOV H1C81 D8400`": the quoted instruction is one of that rung's."""
    quoted = re.findall(r"\b(R\d+)'s `([^`]+)`", _section())
    assert quoted
    for rung, text in quoted:
        op, *operands = text.split()
        assert any(i.op == op and list(i.operands) == operands for i in _rungs()[rung]), f"{rung}: {text}"


def test_the_devices_paragraph_lists_every_register_the_ladder_writes():
    """An integrator keeps their own data clear of the ladder's devices by the Devices
    paragraph (and the .il's heading), so it must name every data register the rungs write:
    the reply's CRC and byte count (D214, D215) and the product of R6's MUL, which in 16-bit
    operation fills two registers (D230 and D231, the high word: FX Series Programming
    Manual §5.3.3, cited in the paragraph). Before, D214, D215, D230 and D231 were in no
    list, and D231 nowhere on the page."""
    section = _section()
    paragraph = " ".join(section[section.index("Devices:"):section.index("| rung |")].split())
    listed = _devices(paragraph)
    writes = {"MOV": -1, "ADD": -1, "MUL": -1, "DIV": -1, "WAND": -1, "CRC": 1, "INC": 0}
    written = set()
    for instructions in _rungs().values():
        for ins in instructions:
            if ins.op in writes:
                written.add(ins.operands[writes[ins.op]])
                if ins.op in ("MUL", "DIV"):  # 32-bit product / the remainder in D+1
                    written.add(next_device(ins.operands[-1]))
    own = {d for d in written if re.fullmatch(r"D\d+", d) and int(d[1:]) < 8000}
    assert own and sorted(own - listed) == []
    assert "MUL" in paragraph and "§5.3.3" in paragraph
