"""One way to number lines everywhere (`verifier.textfile.text_lines`): at line feeds, as
lark, tomllib and the byte-position helper count. Form feeds, NEL (U+0085) and the
Unicode line/paragraph separators can stand inside comments and strings; Python's
`str.splitlines` breaks at them, which printed the wrong source line under a message and
put a scenario key on the wrong line. A lone carriage return (classic Mac OS files) ends
an ST line, as in every editor."""
from __future__ import annotations

import re
import sys
from pathlib import Path

import pytest
from click.testing import CliRunner
from hypothesis import given, strategies as st_

import verifier
from verifier.cli import main
from verifier.sim.errors import SimulationError
from verifier.textfile import text_lines
import procs

ROOT = Path(__file__).resolve().parents[1]
# characters str.splitlines breaks at that are not line feeds
SPLITLINES_ONLY = ["\x0b", "\x0c", "\x1c", "\x1d", "\x1e", "\x85", "\u2028", "\u2029"]


@given(st_.text(alphabet=st_.sampled_from(["a", " ", "\n", "\r", *SPLITLINES_ONLY])))
def test_lines_are_counted_at_line_feeds_only(text):
    lines = text_lines(text)
    assert len(lines) == text.count("\n") + (0 if text == "" or text.endswith("\n") else 1)
    parts = text.split("\n")
    for line, part in zip(lines, parts):
        assert line == (part[:-1] if part.endswith("\r") else part)


@given(st_.text(alphabet=st_.characters(blacklist_characters=SPLITLINES_ONLY + ["\r"])))
def test_the_same_lines_as_splitlines_where_only_line_feeds_break(text):
    assert text_lines(text) == text.splitlines()


def check(path: Path):
    return CliRunner().invoke(main, ["check", str(path)])


PROGRAM = ["PROGRAM P", "(* note{sep}still the comment *)", "VAR x : INT; END_VAR", "x := y;", "END_PROGRAM", ""]


@pytest.mark.parametrize("sep", ["\x0c", "\x85", "\u2028", "\u2029"], ids=["FF", "NEL", "LS", "PS"])
def test_check_prints_the_line_the_message_is_about(tmp_path, sep):
    path = tmp_path / "p.st"
    path.write_text("\n".join(PROGRAM).replace("{sep}", sep), encoding="utf-8")
    out = check(path).output.splitlines()
    assert out[0] == f"{path}:4:6: error: undefined label 'y'; declare it in a VAR block"
    assert out[1:3] == ["    x := y;", "         ^"]


@pytest.mark.parametrize("end", ["\r", "\r\n", "\n"], ids=["CR", "CRLF", "LF"])
def test_a_file_with_any_line_end_is_read_line_by_line(tmp_path, end):
    path = tmp_path / "p.st"
    path.write_bytes(end.join(PROGRAM).replace("{sep}", " ").encode())
    out = check(path).output.splitlines()
    assert out[0] == f"{path}:4:6: error: undefined label 'y'; declare it in a VAR block"
    assert out[1:3] == ["    x := y;", "         ^"]


def test_a_run_time_error_shows_its_st_line_in_a_classic_mac_file(tmp_path):
    text = "\r".join(["PROGRAM P", "VAR a : ARRAY[0..3] OF INT; i : INT; END_VAR", "i := i + 1;",
                      "a[i * 2] := 1;", "END_PROGRAM", ""])
    path = tmp_path / "p.st"
    path.write_bytes(text.encode())
    project = verifier.load(path, stop_on_operation_error=True)
    with pytest.raises(SimulationError) as caught:
        project.run_programs(["P"], scans=3)
    assert f"{path}:4:" in str(caught.value)
    assert "    a[i * 2] := 1;" in str(caught.value)


def test_a_scenario_key_is_placed_on_its_line_past_a_line_separator(tmp_path):
    (tmp_path / "p.st").write_text("PROGRAM P\nEND_PROGRAM\n")
    scenario = tmp_path / "s.toml"
    scenario.write_text('name = "x"\n# a note \u2028 on one line\nsources = ["p.st"]\nprogram = "P"\n'
                        'platform = "fx3u"\nduration = "abc"\n', encoding="utf-8")
    out = check(scenario).output.splitlines()
    assert out[0].startswith(f"{scenario}:6:12: error: duration:")
    assert out[1] == '    duration = "abc"'


def test_a_trace_whose_scenario_name_holds_a_line_separator_replays(tmp_path):
    """`--trace` writes names as they are (JSON lets U+2028 stand raw); replay reads them."""
    source = (ROOT / "plc/scenarios/fx3u-healthy.toml").read_text(encoding="utf-8")
    source = source.replace('"../', f'"{(ROOT / "plc").as_posix()}/')
    source = re.sub(r'^name = "[^"]*"', lambda m: 'name = "line\u2028separated"', source, flags=re.M)
    source = re.sub(r'^duration = "[^"]*"', 'duration = "3s"', source, flags=re.M)
    scenario = tmp_path / "s.toml"
    scenario.write_text(source, encoding="utf-8")
    trace = tmp_path / "t.jsonl"
    uitamr = [sys.executable, "-m", "verifier.cli"]
    done = procs.run([*uitamr, "verify", "--scenario", scenario, "--trace", trace],
                     capture_output=True, text=True, timeout=120)
    assert trace.exists(), done.stdout + done.stderr
    assert "\u2028" in trace.read_text(encoding="utf-8")
    done = procs.run([*uitamr, "replay", trace], capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stdout + done.stderr
    assert "not a JSON trace record" not in done.stdout + done.stderr


def test_export_of_a_classic_mac_file_keeps_its_lines(tmp_path):
    from verifier.commands.export import command

    lines = ["FUNCTION_BLOCK FB_A", "(* header *)", "VAR_INPUT i_bX : BOOL; END_VAR",
             "VAR_OUTPUT o_bY : BOOL; END_VAR", "o_bY := i_bX;", "(* last *)", "END_FUNCTION_BLOCK", ""]
    for end, name in (("\n", "lf"), ("\r", "cr")):
        folder = tmp_path / name
        folder.mkdir()
        (folder / "FB_A.st").write_bytes(end.join(lines).encode())
        result = CliRunner().invoke(command, ["--target", "gxworks2", str(folder / "FB_A.st"), "--out", str(tmp_path / f"out-{name}")],
                                    catch_exceptions=False)
        assert result.exit_code == 0, result.output
    for exported in ("FB_A.st", "FB_A.labels.tsv"):
        assert (tmp_path / "out-cr" / exported).read_text() == (tmp_path / "out-lf" / exported).read_text()
    assert "o_bY := i_bX;" in (tmp_path / "out-cr" / "FB_A.st").read_text()


@pytest.mark.parametrize("end", ["\r", "\r\n", "\n"], ids=["CR", "CRLF", "LF"])
def test_a_capture_with_any_line_end_is_replayed_line_by_line(tmp_path, end):
    """`str.splitlines` read a classic Mac OS capture (lone CRs) line by line; numbering at
    line feeds alone made its first line, a comment, swallow the file: replay said NO
    TRAFFIC. A plain capture and a JSONL trace are read alike with any line end."""
    plain = tmp_path / "plain.txt"
    plain.write_bytes(end.join(["# bench capture", "0.000000 tx 01 06 01 A0 00 00 88 14",
                                "0.015000 rx 01 06 01 A0 00 00 88 14", ""]).encode())
    trace = tmp_path / "trace.jsonl"
    records = ['{"scenario": "s", "t": 0.0, "t_end": 0.001146, "dir": "tx", "hex": "01 06 01 A0 00 00 88 14"}',
               '{"scenario": "s", "t": 0.015, "t_end": 0.016146, "dir": "rx", "hex": "01 06 01 A0 00 00 88 14"}']
    trace.write_bytes((end.join(records) + end).encode())
    for capture in (plain, trace):
        result = CliRunner().invoke(main, ["replay", str(capture)])
        assert "1 request in" in result.output, result.output
        assert result.exit_code == 0, result.output


def test_a_toml_file_with_lone_cr_line_ends_is_told_to_be_saved_with_lf_or_crlf(tmp_path):
    """TOML allows LF and CRLF only; tomllib's own message ("Expected newline...") did not
    say why a file from a classic Mac editor is refused."""
    scenario = tmp_path / "s.toml"
    scenario.write_bytes(b'name = "x"\rsources = ["p.st"]\r')
    out = check(scenario).output
    assert "line ends are lone carriage returns (classic Mac OS), which TOML does not allow: " \
           "save it with LF or CRLF line ends" in out
    faults = tmp_path / "f.toml"
    faults.write_bytes(b"[robot]\rturnaround_ms = 5\r")
    done = procs.run([sys.executable, "-m", "verifier.cli", "emulate", "--tcp", "0", "--faults", faults],
                     capture_output=True, text=True, timeout=60)
    assert done.returncode == 2 and "save it with LF or CRLF line ends" in done.stderr
