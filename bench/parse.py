"""Speed of the ST front end (parse + check, as `uitamr check` runs them), side by side
with blark (parse only) on the same IEC text, in the same run.

    python bench/parse.py [--lines 10000] [--blark-lines N] [--repeat 3]

The corpus is generated from tests/corpus/valid and plc/: every file both parsers read
(blark is a TwinCAT grammar, so MELSEC devices, `&`, K/H constants... are left out by
construction), with a missing END_ keyword added (blark needs it) and POU names
numbered so copies stay distinct, repeated until it has at least --lines lines. Both
parsers get the same chunks (one POU each), after both have built their grammar.
Ours is timed as `uitamr check` works: the chunks written as files to a temporary folder
and read by the function the command runs (`verifier.commands.check.check_findings`:
every file read and parsed — `verifier.st.parse`, the fast path, lark where it bails —,
then all of them checked together, the garbage collector held off as the command holds
it); best of --repeat runs. Also shown, not in the goal's ratio: parse alone, the lark
reference parser alone (`parse_reference`), and the whole `uitamr check` process on the
same folder (wall time, best of --repeat: interpreter start, imports and output included,
what a user waits for; with its own ratio to blark). Prints lines/s of each and the
ratio. blark comes from the `bench` extra (`pip install -e '.[bench]'`).
"""
from __future__ import annotations

import argparse
import os
import re
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from verifier.commands.check import check_findings  # noqa: E402
from verifier.st.parser import get_parser, parse, parse_reference  # noqa: E402

_POU_START = re.compile(r"^\s*(FUNCTION_BLOCK|FUNCTION|PROGRAM)\s+(\w+)", re.IGNORECASE | re.MULTILINE)


def _candidate_sources() -> list[str]:
    paths = sorted((ROOT / "tests" / "corpus" / "valid").glob("*.st")) + sorted((ROOT / "plc").rglob("*.st"))
    texts = []
    for path in paths:
        text = path.read_text(encoding="utf-8")
        source = parse(text, str(path), "gxworks3")
        if not source.ok or len(source.pous) != 1 or source.types or source.globals:
            continue
        kind = source.pous[0].kind
        if not re.search(rf"END_{kind}\s*$", text.strip(), re.IGNORECASE):
            text = text.rstrip() + f"\nEND_{kind}\n"
        texts.append(text)
    return texts


def _blark_accepts(text: str, blark_parser) -> bool:
    from blark.parse import parse_source_code

    return parse_source_code(text, parser=blark_parser).exception is None


def _rename(text: str, names: list[str], n: int) -> str:
    """Copy n of a chunk: every POU name of the corpus (declared here or in a chunk this
    one calls) numbered, so copies stay distinct and still refer to each other."""
    for name in names:
        text = re.sub(rf"\b{re.escape(name)}\b", f"{name}_{n}", text)
    return text


def build_corpus(min_lines: int, blark_parser) -> list[str]:
    """Chunks (one POU each) of IEC text both parsers accept, >= min_lines in total."""
    base = [t for t in _candidate_sources() if _blark_accepts(t, blark_parser)]
    if not base:
        raise SystemExit("no corpus file is accepted by both parsers")
    names = [m.group(2) for t in base for m in _POU_START.finditer(t)]
    chunks: list[str] = []
    lines = 0
    n = 0
    while lines < min_lines:
        for text in base:
            chunk = _rename(text, names, n)
            chunks.append(chunk)
            lines += chunk.count("\n") + 1
        n += 1
    return chunks


def count_lines(chunks: list[str]) -> int:
    return sum(c.count("\n") + 1 for c in chunks)


def write_corpus(chunks: list[str], folder: Path) -> list[Path]:
    """The chunks as .st files in `folder`, in order."""
    paths = []
    for i, chunk in enumerate(chunks):
        path = folder / f"bench{i:04}.st"
        path.write_text(chunk, encoding="utf-8")
        paths.append(path)
    return paths


def time_check(paths: list[Path], repeat: int) -> tuple[float, int]:
    """Best of `repeat` runs of what `uitamr check --target gxworks3` runs on the files
    (`check_findings`: read, parse, check together). Returns the time and the number of
    check findings (the corpus's files use POUs of files it leaves out, so the check has
    things to say, as `uitamr check` would); fails on any syntax finding."""
    best = float("inf")
    findings: list = []
    for _ in range(repeat):
        start = time.perf_counter()
        _files, findings = check_findings(paths, "gxworks3")
        best = min(best, time.perf_counter() - start)
    syntax = [f for f in findings if f.rule == "UITAMR-ST-SYNTAX"]
    if syntax:
        raise SystemExit(f"our parser rejected a chunk: {syntax[0].diagnostic}")
    return best, len(findings)


def time_command(folder: Path, repeat: int) -> float:
    """Best of `repeat` wall times of the whole `uitamr check --target gxworks3 FOLDER`
    process (interpreter start, imports, grammar load, output included): what a user
    waits for."""
    program = "import sys; from verifier.entry import main; sys.argv[0] = 'uitamr'; main()"
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    best = float("inf")
    for _ in range(repeat):
        start = time.perf_counter()
        run = subprocess.run([sys.executable, "-c", program, "check", "--target", "gxworks3", str(folder)],
                             stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, env=env)
        best = min(best, time.perf_counter() - start)
        if run.returncode not in (0, 1):  # 1: the corpus's findings; 2: the command failed
            raise SystemExit(f"uitamr check failed (exit {run.returncode}): {run.stderr.decode(errors='replace')}")
    return best


def time_parse(chunks: list[str], repeat: int, reader=parse) -> float:
    """Best of `repeat` runs: parse every chunk with `reader` (failing on any syntax
    diagnostic), from text in memory, no check."""
    best = float("inf")
    for _ in range(repeat):
        start = time.perf_counter()
        for i, chunk in enumerate(chunks):
            source = reader(chunk, f"bench{i}.st", "gxworks3")
            if not source.ok:
                raise SystemExit(f"our parser rejected chunk {i}: {source.diagnostics[0]}")
        best = min(best, time.perf_counter() - start)
    return best


def time_blark(chunks: list[str], blark_parser) -> float:
    from blark.parse import parse_source_code

    start = time.perf_counter()
    for i, chunk in enumerate(chunks):
        result = parse_source_code(chunk, parser=blark_parser)
        if result.exception is not None:
            raise SystemExit(f"blark rejected chunk {i}: {result.exception}")
    return time.perf_counter() - start


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--lines", type=int, default=10_000, help="corpus size in lines (default 10000)")
    ap.add_argument("--blark-lines", type=int, default=0,
                    help="time blark on only the first N lines' worth of chunks (0 = all; blark is slow)")
    ap.add_argument("--repeat", type=int, default=3, help="best of N runs for our parser")
    args = ap.parse_args(argv)
    try:
        from blark.parse import get_parser as blark_get_parser
    except ImportError:
        print("blark is not installed: pip install -e '.[bench]'", file=sys.stderr)
        return 2

    get_parser()                      # build (or load the cached) LALR tables first
    blark_parser = blark_get_parser()  # and blark's Earley grammar
    chunks = build_corpus(args.lines, blark_parser)
    total = count_lines(chunks)

    with tempfile.TemporaryDirectory(prefix="uitamr-bench-parse-") as folder:
        paths = write_corpus(chunks, Path(folder))
        ours, findings = time_check(paths, args.repeat)
        whole = time_command(Path(folder), args.repeat)
    ours_rate = total / ours
    parse_only = time_parse(chunks, args.repeat)
    reference = time_parse(chunks, args.repeat, reader=parse_reference)

    blark_chunks = chunks
    if args.blark_lines:
        blark_chunks, acc = [], 0
        for c in chunks:
            if acc >= args.blark_lines:
                break
            blark_chunks.append(c)
            acc += c.count("\n") + 1
    blark_total = count_lines(blark_chunks)
    theirs = time_blark(blark_chunks, blark_parser)
    blark_rate = blark_total / theirs

    print(f"corpus: {total} lines in {len(chunks)} POUs (IEC text both parsers accept)")
    print(f"uitamr parse + check           : {total:>7} lines in {ours:8.3f} s = {ours_rate:>10.0f} lines/s"
          f" ({findings} check findings)")
    print(f"  (parse alone                 : {total:>7} lines in {parse_only:8.3f} s = {total / parse_only:>10.0f} lines/s)")
    print(f"  (lark reference parser alone : {total:>7} lines in {reference:8.3f} s = {total / reference:>10.0f} lines/s)")
    print(f"blark parse (lark Earley)      : {blark_total:>7} lines in {theirs:8.3f} s = {blark_rate:>10.0f} lines/s")
    print(f"ratio: {ours_rate / blark_rate:.1f}x blark's lines/s, parse + check against parse (goal: >= 500x)")
    print(f"whole `uitamr check` process   : {total:>7} lines in {whole:8.3f} s = {total / whole:>10.0f} lines/s"
          f" ({total / whole / blark_rate:.1f}x blark's lines/s; interpreter start, imports and output included)")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
