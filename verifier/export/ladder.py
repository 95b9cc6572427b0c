"""Instruction-list (.il) ladder programs -> the CSV that GX Works2 reads with
[Project] > [Open Other Data] > [Read from CSV File] (see docs/plc-library.md, "Ladder for
FX3U"; the column layout is UNCONFIRMED, taken from what GX Developer / GX Works2 write
with "Write to CSV File").

The .il format is one instruction per line, operands separated by spaces; lines starting
with ';' are comments, a comment line starting with '; R' names the next rung and becomes
its line statement.

    python -m verifier.export.ladder plc/ladder/UITAMR_LadderFx3.il -o plc/ladder/UITAMR_LadderFx3.csv

`-o FILE` writes the CSV only when the conversion succeeds, whole (a temporary file
renamed over FILE): `... X.il > X.csv` left an empty X.csv on a mistake in the .il, as
the shell empties the file before the command runs. Without -o the CSV goes to stdout.

`--encoding` (utf-8 default, utf-16 = UTF-16 LE with BOM, cp950, cp932, shift_jis): which
one GX Works2 reads is UNCONFIRMED (docs/plc-library.md, "Which encoding"); a rung comment
the chosen one cannot hold is named at its .il line and column.
"""
from __future__ import annotations

import re
import sys
from dataclasses import dataclass
from typing import Callable
from pathlib import Path
from verifier.place import Place
from verifier.textfile import UnreadableText, read_utf8, shown_name, text_lines

HEADER = ("Step Number", "Line Statement", "Instruction", "I/O(Device)", "Blank", "PI Statement", "Note")
PLC_TYPE = "FX3U/FX3UC"

#: instruction -> (program steps on FX3U, operands it takes). Steps: FX3 programming manual,
#: instruction list tables; they only fill the Step column, which GX Works2 recomputes
#: (UNCONFIRMED). Operands: OUT of a timer or counter takes the device and its preset.
INSTRUCTIONS = {"LD": (1, 1), "LDI": (1, 1), "AND": (1, 1), "ANI": (1, 1), "OR": (1, 1), "ORI": (1, 1),
                "ANB": (1, 0), "ORB": (1, 0), "MPS": (1, 0), "MRD": (1, 0), "MPP": (1, 0),
                "LDP": (2, 1), "LDF": (2, 1), "OUT": (1, 1), "SET": (1, 1), "RST": (1, 1), "END": (1, 0),
                "MOV": (5, 2), "ADD": (7, 3), "SUB": (7, 3), "MUL": (7, 3), "DIV": (7, 3), "WAND": (7, 3),
                "INC": (3, 1), "CRC": (7, 3), "RS2": (11, 5)}
COMPARE_STEPS = 5
COMPARES = ("=", "<>", ">", "<", ">=", "<=")


def _is_compare(op: str) -> bool:
    """LD=, AND<>, OR>= ...: a comparison contact (two operands, COMPARE_STEPS steps)."""
    return any(op.startswith(k) and op[len(k):] in COMPARES for k in ("LD", "AND", "OR"))


class IlError(ValueError):
    """A line of an .il file that is not an instruction; names file and line."""


@dataclass(frozen=True)
class Instruction:
    line: int
    op: str
    operands: tuple[str, ...]
    statement: str = ""        # the rung comment that precedes it, on a rung's first instruction
    statement_at: tuple[int, int] = (0, 0)   # the .il line and column where that comment's text starts
    operand_cols: tuple[int, ...] = ()       # the .il column of each operand, on `line`


def parse_il(text: str, name: str = "<il>", notes: list[str] | None = None) -> list[Instruction]:
    """The instructions of an .il; an IlError at the first mistake. `notes` (when given)
    gets a line for each comment directly over an instruction that the CSV will not hold
    (`; 啟動按鈕` with no R and number: no line statement, the comment would vanish)."""
    program: list[Instruction] = []
    pending, pending_at = "", (0, 0)
    loose: tuple[int, int] | None = None  # where the comment on the line before starts, if not an R one
    for number, raw in enumerate(text_lines(text), 1):
        line = raw.strip()
        if not line:
            loose = None
            continue
        if line.startswith(";"):
            comment = line[1:].strip()
            if comment[:1] == "R" and comment[1:2].isdigit():
                pending, pending_at = comment, (number, raw.index(comment) + 1)
                loose = None
            else:
                loose = (number, raw.index(comment) + 1) if comment else None
            continue
        if loose is not None and not pending and notes is not None:
            notes.append(f"{Place(name, *loose)}: note: this comment is not carried into the CSV: only a comment "
                         "that starts with R and a number (; R5 ...) becomes the line statement of the "
                         "instruction after it")
        loose = None
        op, *operands = line.split()
        col = raw.index(op) + 1
        upper = op.upper()
        if _is_compare(upper):
            wanted = 2
        elif upper in INSTRUCTIONS:
            wanted = INSTRUCTIONS[upper][1]
            if upper == "OUT" and operands and operands[0].upper().startswith(("T", "C")):
                wanted = 2
        else:
            known = ", ".join(sorted(INSTRUCTIONS)) + ", LD=/AND=/OR= and the other comparisons"
            raise IlError(f"{Place(name, number, col)}: '{op}' is not an instruction this converter "
                          f"knows (it counts the steps of {known})")
        if len(operands) != wanted:
            # `OUT Y0 ; lamp` counted the comment's words as operands, without a word of why
            why = (" (a comment goes on a line of its own, starting with ';')"
                   if any(o.startswith(";") for o in operands) else "")
            raise IlError(f"{Place(name, number, col)}: {upper} takes {wanted} operand(s), "
                          f"got {len(operands)}: '{line}'{why}")
        if program and program[-1].op == "END":
            raise IlError(f"{Place(name, number, col)}: {upper} after END (line {program[-1].line}): END must be "
                          "the last instruction, the CPU runs nothing after it")
        # devices upper case, as GX Works2 writes them in its CSV (`ld x0` gave the operand "x0")
        cols, at = [], raw.index(op) + len(op)
        for o in operands:
            at = raw.index(o, at)
            cols.append(at + 1)
            at += len(o)
        for k, (o, c) in enumerate(zip(operands, cols)):
            why = _operand_problem(upper, k, o.upper())
            if why:
                raise IlError(f"{Place(name, number, c)}: {why}")
        program.append(Instruction(number, upper, tuple(o.upper() for o in operands), pending, pending_at,
                                   tuple(cols)))
        pending, pending_at = "", (0, 0)
    if not program:
        raise IlError(f"{shown_name(name)}: no instruction in it: an .il holds one instruction a line, "
                      "the last one END")
    if program[-1].op != "END":
        last = program[-1]
        raise IlError(f"{Place(name, last.line, 1)}: the program must end with END: add END after this "
                      f"line ({' '.join((last.op, *last.operands))})")
    return program


#: contacts and coils: their first operand is a bit (a word device there is refused by GX Works2)
_BIT_OPERAND = {"LD", "LDI", "AND", "ANI", "OR", "ORI", "LDP", "LDF", "OUT", "SET"}
#: instruction -> the position of the operand it stores its result in (MOV S D, CRC S D n,
#: RS2 S m D n n1: FX3 programming manual operand orders, as the bundled ladder uses them)
_RESULT_OPERAND = {"MOV": 1, "ADD": 2, "SUB": 2, "MUL": 2, "DIV": 2, "WAND": 2, "INC": 0, "CRC": 1, "RS2": 2}
_CONSTANT = re.compile(r"K-?[0-9]+|H[0-9A-F]+")
_PLAIN_DEVICE = re.compile(r"([A-Z]+)([0-9]+)")
#: FX3U timer and counter numbers. ASSUMPTION (as remembered from the FX3 programming
#: manual's device list, no page read): T0..T511, C0..C255 (C200..C255 32-bit).
_TIMERS_COUNTERS = {"T": 511, "C": 255}


def _operand_problem(op: str, k: int, operand: str) -> str | None:
    """Why the k-th operand of `op` cannot stand in an FX3U program, or None: a device the
    FX3U does not have (X8: octal; D9000; SM400), judged as `uitamr check --platform fx3u`
    judges ST's devices; a word device or constant where a contact or coil takes a bit; a
    constant where the instruction stores its result. Operands of other forms (K4M0, D0Z1,
    D0.F) are left to GX Works2."""
    from verifier.sim.cpu import PROFILES
    from verifier.sim.devices import device_problem

    constant = _CONSTANT.fullmatch(operand) is not None
    device = None if constant else _PLAIN_DEVICE.fullmatch(operand)
    if device is not None:
        letters, number = device.group(1), int(device.group(2))
        if letters in _TIMERS_COUNTERS:
            if number > _TIMERS_COUNTERS[letters]:
                return (f"device {operand} does not exist on the FX3U: {letters} runs "
                        f"{letters}0..{letters}{_TIMERS_COUNTERS[letters]}")
        elif letters not in ("V", "P", "I", "N"):  # index V0-V7, pointers, nesting: not judged
            why = device_problem(operand, PROFILES["fx3u"])
            if why:
                return why
    if k == 0 and op in _BIT_OPERAND and (constant or (device is not None and device.group(1) in ("D", "R", "Z", "V"))):
        kind = "a constant" if constant else "a word device"
        if op == "OUT":
            return f"OUT takes a bit device (Y, M, S) or a timer or counter with its preset; {operand} is {kind}"
        if op == "SET":
            return f"SET takes a bit device (Y, M, S); {operand} is {kind}"
        return (f"{op} takes a bit device (X, Y, M, S, T, C); {operand} is {kind}: compare a word with "
                f"{op}= {operand} K...")
    if constant and _RESULT_OPERAND.get(op) == k:
        return f"{op} stores its result in {operand}, a constant: give a word device (D, R) there"
    return None


def steps(ins: Instruction) -> int:
    if _is_compare(ins.op):
        return COMPARE_STEPS
    if ins.op == "OUT" and ins.operands[0].upper().startswith(("T", "C")):
        return 3
    if ins.op in ("SET", "RST") and ins.operands[0].upper().startswith(("T", "C", "D")):
        return 2 if ins.operands[0].upper().startswith(("T", "C")) else 3
    if ins.op in ("SET", "RST", "OUT") and ins.operands and ins.operands[0].upper()[:2] == "M8":
        return 2
    return INSTRUCTIONS[ins.op][0] if ins.op in INSTRUCTIONS else 1


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


#: --encoding -> (Python codec, bytes put first). ASSUMPTION (docs/plc-library.md, "Which
#: encoding"): no Mitsubishi page found says which one "Read from CSV File" takes; utf-8 stays
#: the default, utf-16 is the form a third-party generator says GX Works2 writes, cp950 / cp932 /
#: shift_jis the code pages of a Traditional Chinese / Japanese Windows.
ENCODINGS = {"utf-8": ("utf-8", b""), "utf-16": ("utf-16-le", b"\xff\xfe"), "cp950": ("cp950", b""),
             "cp932": ("cp932", b""), "shift_jis": ("shift_jis", b"")}


def encode_csv(program: list[Instruction], program_name: str, encoding: str = "utf-8",
               name: str = "<il>") -> bytes:
    """to_csv() as the bytes of `encoding` (a key of ENCODINGS). A rung comment or operand
    with a character the encoding has no code for is an IlError at its .il line and column
    (the .il file name for the program name, which is the file's stem)."""
    codec, bom = ENCODINGS[encoding]

    def refuse(text: str, where: Callable[[int], object], what: str) -> None:
        try:
            text.encode(codec)
        except UnicodeEncodeError as e:
            char = text[e.start]
            raise IlError(f"{where(e.start)}: {what} has '{char}' (U+{ord(char):04X}), which {encoding} cannot "
                          f"encode: write it in another --encoding (utf-16 holds every character) or "
                          f"replace it") from None

    refuse(program_name, lambda i: shown_name(name), "the file name (the CSV's program name)")
    for ins in program:
        if ins.statement:
            refuse(ins.statement, lambda i: Place(name, ins.statement_at[0], ins.statement_at[1] + i), "the comment")
        for operand, col in zip(ins.operands, ins.operand_cols or (1,) * len(ins.operands)):
            refuse(operand, lambda i: Place(name, ins.line, col + i), "the operand")
    return bom + to_csv(program, program_name).encode(codec)


USAGE = "python -m verifier.export.ladder FILE.il [-o FILE.csv] [--encoding ENC]"

ST_OPENINGS = ("PROGRAM", "FUNCTION_BLOCK", "FUNCTION")


def structured_text(path: Path, text: str) -> str | None:
    """Why `path` is structured text rather than an instruction list (a .st file, or text that
    opens with a comment `(*`, PROGRAM or FUNCTION_BLOCK), or None: given one, the converter
    said "'(*' is not an instruction", as if the ST had a typo in it."""
    words = text.lstrip().split(None, 1)
    first = words[0].upper() if words else ""
    if path.suffix.lower() != ".st" and not first.startswith("(*") and first not in ST_OPENINGS:
        return None
    return ("is structured text (ST), not an instruction list: this converter reads .il files "
            "(one instruction a line, ending with END); ST is read by `uitamr check` (to check it) "
            "and `uitamr export` (to import it into GX Works)")


def main(argv: list[str]) -> int:
    import argparse

    parser = argparse.ArgumentParser(prog="python -m verifier.export.ladder", usage=USAGE,
                                     description="The GX Works2 CSV of an instruction list (.il).")
    parser.add_argument("il", metavar="FILE.il")
    parser.add_argument("-o", "--out", metavar="FILE.csv",
                        help="write the CSV to this file, only when the .il converts (default: stdout)")
    parser.add_argument("--encoding", choices=list(ENCODINGS), default="utf-8", type=str.lower,
                        help="the CSV's encoding (default utf-8; utf-16 = UTF-16 LE with BOM; cp950 Traditional "
                             "Chinese, cp932/shift_jis Japanese Windows). Which one GX Works2 expects is "
                             "UNCONFIRMED: see docs/plc-library.md")
    args = parser.parse_args(argv)  # a usage mistake: argparse's message, exit 2
    path = Path(args.il)
    if args.out is not None and Path(args.out).resolve() == path.resolve():
        csv_name = shown_name(str(path.with_suffix(".csv")))
        print(f"{shown_name(args.out)}: is the .il itself: name the .csv to write (-o {csv_name})", file=sys.stderr)
        return 2
    try:
        text = read_utf8(path)
    except UnreadableText as e:
        # a file that cannot be read at all is unusable input (2), as for `uitamr check`;
        # bytes that are not UTF-8 are a mistake at a line of it, as any other (1)
        where = shown_name(str(path)) if e.place is None else Place(str(path), e.place.line, e.place.col)
        print(f"{where}: {e.after_place()}", file=sys.stderr)
        return 1 if e.place is not None else 2
    if (why := structured_text(path, text)) is not None:
        print(f"{shown_name(str(path))}: {why}", file=sys.stderr)
        return 2
    notes: list[str] = []
    try:
        csv = encode_csv(parse_il(text, str(path), notes), path.stem, args.encoding, str(path))
    except IlError as e:
        print(e, file=sys.stderr)
        return 1
    for note in notes:
        print(note, file=sys.stderr)
    if args.out is None:
        sys.stdout.flush()
        sys.stdout.buffer.write(csv)
        sys.stdout.buffer.flush()
        return 0
    try:
        _write_whole(Path(args.out), csv)
    except OSError as e:
        print(f"{shown_name(args.out)}: cannot write: {e.strerror or e}", file=sys.stderr)
        return 2
    return 0


def _write_whole(out: Path, data: bytes) -> None:
    """`data` into `out` at once: written beside it under a temporary name, then renamed over
    it, so that `out` is the old file or the new one, never a part (the temporary file is
    removed when writing fails). A symbolic link is written through to its target, and a
    pipe or a device is written to, as the shell's `> X.csv` did; the mode is set by path
    once the file is closed (Windows' os.chmod takes no file descriptor before 3.13)."""
    import os
    import tempfile

    if out.is_symlink():
        out = Path(os.path.realpath(out))
    if out.exists() and not out.is_file():  # a pipe, a device (/dev/stdout): not replaced by a file
        with open(out, "wb") as f:
            f.write(data)
        return
    fd, temporary = tempfile.mkstemp(dir=out.parent, prefix=f".{out.name}.", suffix=".tmp")
    try:
        with open(fd, "wb") as f:
            f.write(data)
        try:  # the file's own mode, else a new file's (mkstemp's 0600 would hide it from others)
            mode = out.stat().st_mode & 0o7777
        except OSError:
            umask = os.umask(0)
            os.umask(umask)
            mode = 0o666 & ~umask
        os.chmod(temporary, mode)
        os.replace(temporary, out)
    except BaseException:
        Path(temporary).unlink(missing_ok=True)
        raise


if __name__ == "__main__":  # pragma: no cover
    raise SystemExit(main(sys.argv[1:]))
