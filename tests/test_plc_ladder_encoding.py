"""The ladder converter's --encoding: GX Works2's "Read from CSV File" encoding is not
settled by any source found (docs/plc-library.md, "Which encoding"), so the CSV of an .il
with Traditional Chinese or Japanese rung comments can be written as UTF-8 (default),
UTF-16 LE with BOM, cp950 (Big5), cp932 or shift_jis, and a comment that the chosen one
cannot hold is named at its .il line and column instead of a traceback or '?'."""
from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

from verifier.export import ladder
from verifier.export.ladder import IlError, encode_csv, parse_il, to_csv

ROOT = Path(__file__).resolve().parents[1]
IL_TEXT = "; R1 啟動：機械手臂回原點\nLD X0\nOUT Y0\n; R2 停止\nLDI X1\nOUT Y1\nEND\n"


def _run(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "verifier.export.ladder", *args], cwd=ROOT,
                          capture_output=True, env={"PYTHONPATH": str(ROOT), "PATH": ""})


def test_utf16_is_little_endian_with_bom_tab_separated_and_the_chinese_comment_round_trips(tmp_path):
    il = tmp_path / "arm.il"
    il.write_text(IL_TEXT, encoding="utf-8")
    out = tmp_path / "arm.csv"
    run = _run(str(il), "-o", str(out), "--encoding", "utf-16")
    assert run.returncode == 0, run.stderr
    data = out.read_bytes()
    assert data[:2] == b"\xff\xfe" and data[2:4] == b'"\x00'  # BOM, then '"' as UTF-16 LE
    text = data[2:].decode("utf-16-le")
    assert "\ufeff" not in text  # one BOM, not two
    rows = text.split("\r\n")
    assert rows[2].split("\t")[:2] == ['"Step Number"', '"Line Statement"']
    assert rows[3].split("\t") == ['"0"', '"R1 啟動：機械手臂回原點"', '"LD"', '"X0"', '""', '""', '""']
    assert text == to_csv(parse_il(IL_TEXT, "arm.il"), "arm")


@pytest.mark.parametrize("encoding, codec", [("utf-8", "utf-8"), ("cp950", "cp950")])
def test_the_comment_is_written_in_the_chosen_code_page(tmp_path, encoding, codec):
    il = tmp_path / "arm.il"
    il.write_text(IL_TEXT, encoding="utf-8")
    run = _run(str(il), "--encoding", encoding)  # stdout gets the same bytes as -o
    assert run.returncode == 0, run.stderr
    assert run.stdout == to_csv(parse_il(IL_TEXT, "arm.il"), "arm").encode(codec)
    assert "啟動：機械手臂回原點".encode("cp950") in run.stdout or encoding == "utf-8"


def test_japanese_in_shift_jis_and_cp932():
    program = parse_il("; R1 原点復帰 ～\nLD X0\nOUT Y0\nEND\n", "jp.il")
    assert encode_csv(program, "jp", "cp932", "jp.il").decode("cp932").count("原点復帰 ～") == 1
    # '～' (U+FF5E) is in Windows' cp932 but not in strict Shift-JIS: named, not '?'
    with pytest.raises(IlError, match=r"^jp.il:1:11: the comment has '～' \(U\+FF5E\), which shift_jis cannot "
                                      r"encode: write it in another --encoding"):
        encode_csv(program, "jp", "shift_jis", "jp.il")


def test_a_character_the_code_page_lacks_is_named_at_its_line_and_column(tmp_path):
    """Simplified Chinese '们' is not in Big5 (cp950): was no option; now exit 1, the .il's
    line and column of that character, and the CSV left as it was."""
    il = tmp_path / "arm.il"
    il.write_text("LD X0\n  ;  R1 啟動 们械手\nOUT Y0\nEND\n", encoding="utf-8")
    out = tmp_path / "arm.csv"
    out.write_bytes(b"kept")
    run = _run(str(il), "-o", str(out), "--encoding", "cp950")
    err = run.stderr.decode()
    assert run.returncode == 1 and "Traceback" not in err, err
    assert err == f"{il}:2:12: the comment has '们' (U+4EEC), which cp950 cannot encode: write it in another " \
                  "--encoding (utf-16 holds every character) or replace it\n"
    assert out.read_bytes() == b"kept"


def test_an_operand_and_the_file_name_are_named_too():
    with pytest.raises(IlError, match=r"^x.il:2:8: the operand has 'É'"):
        encode_csv(parse_il("LD X0\nMOV   KÉ D0\nEND\n", "x.il"), "x", "cp950", "x.il")
    with pytest.raises(IlError, match=r"^dir/们.il: the file name \(the CSV's program name\) has '们'"):
        encode_csv(parse_il("LD X0\nEND\n", "dir/们.il"), "们", "cp950", "dir/们.il")


def test_an_unknown_encoding_is_a_usage_error(capsys):
    with pytest.raises(SystemExit) as stop:
        ladder.main([str(ROOT / "plc/ladder/UITAMR_LadderFx3.il"), "--encoding", "big-5"])
    assert stop.value.code == 2
    assert "invalid choice: 'big-5' (choose from 'utf-8', 'utf-16', 'cp950', 'cp932', 'shift_jis')" in \
        capsys.readouterr().err


def test_an_encoding_in_capitals_is_the_same_encoding(tmp_path):
    """`--encoding UTF-16` (as Windows' own dialogs write it) or `CP950` was 'invalid choice';
    `uitamr export --platform FX3U` takes any case too."""
    il = tmp_path / "start.il"
    il.write_text(IL_TEXT, encoding="utf-8")
    for given, codec in (("UTF-16", "utf-16"), ("CP950", "cp950"), ("Utf-8", "utf-8")):
        lower = _run(str(il), "--encoding", codec)
        upper = _run(str(il), "--encoding", given)
        assert (upper.returncode, upper.stdout) == (0, lower.stdout), upper.stderr
