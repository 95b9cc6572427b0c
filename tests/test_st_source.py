"""The one ST file reader (`verifier.st.read_source`): UTF-8 with or without BOM, else
Shift-JIS, else an error naming the byte — the same answer for check, export and load."""
from __future__ import annotations

import re

import pytest
from hypothesis import example, given, strategies as st_

import verifier.sim
from verifier import st
from verifier.st.source import decode_source

PROGRAM = "PROGRAM P\nVAR iX : INT; END_VAR\n(* 起動 *)\niX := 1;\nEND_PROGRAM\n"


@pytest.mark.parametrize("data", [
    PROGRAM.encode("utf-8"), b"\xef\xbb\xbf" + PROGRAM.encode("utf-8"), PROGRAM.encode("cp932"),
], ids=["utf-8", "utf-8-bom", "shift-jis"])
def test_encodings_read_to_the_same_text(tmp_path, data):
    path = tmp_path / "p.st"
    path.write_bytes(data)
    assert st.read_source(path) == (PROGRAM, [])


def test_neither_encoding_is_an_error_not_a_guess(tmp_path):
    path = tmp_path / "junk.st"
    path.write_bytes(b"PROGRAM P\n\xff\xfe\xfd\n")
    text, problems = st.read_source(path)
    assert text == ""
    (problem,) = problems
    assert (problem.file, problem.line, problem.col, problem.severity) == (str(path), 2, 1, "error")
    assert "byte 0xFF at offset 10 is neither UTF-8 nor Shift-JIS" in problem.message


@pytest.mark.parametrize("encoding, order", [("utf-16", None), ("utf-16-le", "little"), ("utf-16-be", "big")])
def test_a_utf16_file_is_named_as_utf16(tmp_path, encoding, order):
    """Windows editors save "Unicode" as UTF-16 with a byte order mark: said so, with what
    to do, instead of "byte 0xFF at offset 0 is neither UTF-8 nor Shift-JIS"."""
    bom = {"little": b"\xff\xfe", "big": b"\xfe\xff"}
    data = PROGRAM.encode(encoding) if order is None else bom[order] + PROGRAM.encode(encoding)
    order = order or ("little" if data.startswith(b"\xff\xfe") else "big")
    path = tmp_path / "p.st"
    path.write_bytes(data)
    text, (problem,) = st.read_source(path)
    assert text == "" and (problem.line, problem.col) == (1, 1)
    assert f"the file is UTF-16 ({order}-endian" in problem.message and "save it as UTF-8" in problem.message


@pytest.mark.parametrize("make, message", [
    (lambda tmp: tmp / "missing.st", "cannot read: no such file"),
    (lambda tmp: tmp, "is a folder"),
    (lambda tmp: "/dev/null", "is not a regular file (a character device)"),
])
def test_what_is_not_a_file_is_said_precisely(tmp_path, make, message):
    text, (problem,) = st.read_source(make(tmp_path))
    assert text == "" and message in problem.message


@given(st_.binary(max_size=200))
def test_any_bytes_give_text_or_one_error(data):
    text, problems = decode_source(data, "x.st")
    assert (text == "") or not problems
    assert len(problems) <= 1
    if not problems:
        assert data.decode("utf-8-sig", errors="ignore") == text or data.decode("cp932") == text


def test_load_uses_the_same_reader(tmp_path):
    path = tmp_path / "junk.st"
    path.write_bytes(b"PROGRAM P\n\xff\xfe\xfd\n")
    with pytest.raises(verifier.sim.LoadError) as err:
        verifier.load(str(path))
    assert f"{path}:2:1: error: byte 0xFF" in str(err.value)


def test_multibyte_label_names_are_refused_with_the_reason():
    source = st.parse("PROGRAM P\nVAR 速度 : INT; END_VAR\nEND_PROGRAM\n", "m.st")
    (problem,) = source.diagnostics
    assert (problem.line, problem.col) == (2, 5)
    assert "names are ASCII" in problem.message


def test_export_reads_with_the_same_reader(tmp_path):
    from click.testing import CliRunner

    from verifier.cli import main

    sjis = tmp_path / "P.st"
    sjis.write_bytes(PROGRAM.encode("cp932"))
    out = tmp_path / "out"
    done = CliRunner().invoke(main, ["export", "--target", "gxworks2", "--out", str(out), str(sjis)])
    assert done.exit_code == 0, done.output
    assert "iX := 1;" in (out / "P.st").read_text(encoding="utf-8")
    assert (out / "P.labels.tsv").read_text(encoding="utf-8").splitlines()[1].split("\t")[1] == "iX"
    junk = tmp_path / "junk.st"
    junk.write_bytes(b"PROGRAM P\n\xff\xfe\xfd\n")
    refused = CliRunner().invoke(main, ["export", "--target", "gxworks2", "--out", str(out), str(junk)])
    assert refused.exit_code == 1
    assert f"{junk}:2:1: error: byte 0xFF" in refused.output


def test_after_a_byte_order_mark_the_byte_named_is_the_one_that_is_not_utf8(tmp_path):
    # the offset was counted from after the mark: "byte 0x28 at offset 13" and column 1,
    # the '(' three bytes before the 0x82 that is not UTF-8
    path = tmp_path / "bom.st"
    path.write_bytes(b"\xef\xbb\xbfPROGRAM P\n(* \x82\xa0 \xff *)\nEND_PROGRAM\n")
    text, (problem,) = st.read_source(path)
    assert (problem.line, problem.col) == (2, 4)
    assert "byte 0x82 at offset 16 is neither UTF-8 nor Shift-JIS" in problem.message


@given(st_.sampled_from([b"", b"\xef\xbb\xbf"]), st_.binary(max_size=200))
@example(b"", b"\xff\xfe\x00")  # UTF-16's byte order mark: the bytes named are the first two
def test_the_byte_an_error_names_is_at_the_offset_it_names(bom, body):
    data = bom + body
    _, problems = decode_source(data, "x.st")
    for problem in problems:
        utf16 = re.match(r"the file is UTF-16 \((little|big)-endian: it starts with the bytes ([0-9A-F]{2}) ([0-9A-F]{2}),",
                         problem.message)
        if utf16:
            assert data[:2] == bytes(int(b, 16) for b in utf16.group(2, 3))
            assert data[:2] == {"little": b"\xff\xfe", "big": b"\xfe\xff"}[utf16.group(1)]
            assert (problem.line, problem.col) == (1, 1)
            continue
        named, offset = re.match(r"byte 0x([0-9A-F]{2}) at offset (\d+)", problem.message).groups()
        assert data[int(offset)] == int(named, 16)
        data[len(bom):int(offset)].decode("utf-8")  # what comes before it is UTF-8 text
        with pytest.raises(UnicodeDecodeError):
            data[int(offset):].decode("utf-8")
