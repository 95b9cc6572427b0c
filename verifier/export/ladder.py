"""Instruction-list (.il) ladder programs -> the CSV that GX Works2 reads with
[Project] > [Open Other Data] > [Read from CSV File] (see docs/plc-library.md, "Ladder for
FX3U"; the column layout is UNCONFIRMED, taken from what GX Developer / GX Works2 write
with "Write to CSV File").

The .il format is one instruction per line, operands separated by spaces; lines starting
with ';' are comments, a comment line starting with '; R' names the next rung and becomes
its line statement.

    python -m verifier.export.ladder plc/ladder/UITAMR_LadderFx3.il > plc/ladder/UITAMR_LadderFx3.csv
"""
from __future__ import annotations

import sys
from dataclasses import dataclass
from pathlib import Path
from verifier.textfile import UnreadableText, read_utf8, text_lines

HEADER = ("Step Number", "Line Statement", "Instruction", "I/O(Device)", "Blank", "PI Statement", "Note")
PLC_TYPE = "FX3U/FX3UC"

#: program steps per instruction on FX3U (FX3 programming manual, instruction list tables);
#: the numbers only fill the Step column, which GX Works2 recomputes (UNCONFIRMED)
STEPS = {"LD": 1, "LDI": 1, "AND": 1, "ANI": 1, "OR": 1, "ORI": 1, "ANB": 1, "ORB": 1,
         "MPS": 1, "MRD": 1, "MPP": 1, "LDP": 2, "LDF": 2, "OUT": 1, "SET": 1, "RST": 1,
         "END": 1, "MOV": 5, "ADD": 7, "SUB": 7, "MUL": 7, "DIV": 7, "WAND": 7, "INC": 3,
         "CRC": 7, "RS2": 11}
COMPARE_STEPS = 5
#: operands each instruction takes (OUT of a timer or counter: the device and its preset)
OPERANDS = {"LD": 1, "LDI": 1, "AND": 1, "ANI": 1, "OR": 1, "ORI": 1, "ANB": 0, "ORB": 0,
            "MPS": 0, "MRD": 0, "MPP": 0, "LDP": 1, "LDF": 1, "OUT": 1, "SET": 1, "RST": 1,
            "END": 0, "MOV": 2, "ADD": 3, "SUB": 3, "MUL": 3, "DIV": 3, "WAND": 3, "INC": 1,
            "CRC": 3, "RS2": 5}
COMPARES = ("=", "<>", ">", "<", ">=", "<=")


class IlError(ValueError):
    """A line of an .il file that is not an instruction; names file and line."""


@dataclass(frozen=True)
class Instruction:
    line: int
    op: str
    operands: tuple[str, ...]
    statement: str = ""        # the rung comment that precedes it, on a rung's first instruction


def parse_il(text: str, name: str = "<il>") -> list[Instruction]:
    program: list[Instruction] = []
    pending = ""
    for number, raw in enumerate(text_lines(text), 1):
        line = raw.strip()
        if not line:
            continue
        if line.startswith(";"):
            comment = line[1:].strip()
            if comment[:1] == "R" and comment[1:2].isdigit():
                pending = comment
            continue
        op, *operands = line.split()
        col = raw.index(op) + 1
        upper = op.upper()
        compare = next((upper[len(k):] for k in ("LD", "AND", "OR") if upper[len(k):] in COMPARES
                        and upper.startswith(k)), None)
        if compare is not None:
            wanted = 2
        elif upper in OPERANDS:
            wanted = OPERANDS[upper]
            if upper == "OUT" and operands and operands[0].upper().startswith(("T", "C")):
                wanted = 2
        else:
            known = ", ".join(sorted(OPERANDS)) + ", LD=/AND=/OR= and the other comparisons"
            raise IlError(f"{name}:{number}:{col}: '{op}' is not an instruction this converter "
                          f"knows (it counts the steps of {known})")
        if len(operands) != wanted:
            raise IlError(f"{name}:{number}:{col}: {upper} takes {wanted} operand(s), "
                          f"got {len(operands)}: '{line}'")
        program.append(Instruction(number, upper, tuple(operands), pending))
        pending = ""
    if not program or program[-1].op != "END":
        raise IlError(f"{name}: the program must end with END")
    return program


def steps(ins: Instruction) -> int:
    if ins.op.startswith(("LD", "AND", "OR")) and any(c in ins.op for c in "=<>"):
        return COMPARE_STEPS
    if ins.op == "OUT" and ins.operands[0].upper().startswith(("T", "C")):
        return 3
    if ins.op in ("SET", "RST") and ins.operands[0].upper().startswith(("T", "C", "D")):
        return 2 if ins.operands[0].upper().startswith(("T", "C")) else 3
    if ins.op in ("SET", "RST", "OUT") and ins.operands and ins.operands[0].upper()[:2] == "M8":
        return 2
    return STEPS.get(ins.op, 1)


def _row(*cells: str) -> str:
    return "\t".join(f'"{c}"' for c in cells)


def to_csv(program: list[Instruction], program_name: str) -> str:
    rows = [_row(program_name), _row("PLC Information:", PLC_TYPE), _row(*HEADER)]
    step = 0
    for ins in program:
        first, *rest = ins.operands or ("",)
        rows.append(_row(str(step), ins.statement, ins.op, first, "", "", ""))
        rows += [_row("", "", "", operand, "", "", "") for operand in rest]
        step += steps(ins)
    return "\r\n".join(rows) + "\r\n"


def main(argv: list[str]) -> int:
    if len(argv) != 1:
        print("usage: python -m verifier.export.ladder FILE.il > FILE.csv", file=sys.stderr)
        return 2
    path = Path(argv[0])
    try:
        text = read_utf8(path)
    except UnreadableText as e:
        print(f"{path}: {e}", file=sys.stderr)
        return 1
    try:
        sys.stdout.write(to_csv(parse_il(text, str(path)), path.stem))
    except IlError as e:
        print(e, file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":  # pragma: no cover
    raise SystemExit(main(sys.argv[1:]))
