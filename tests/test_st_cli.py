"""`uitamr check`: output format, exit codes, JSON, targets, several files at once."""
from __future__ import annotations

import json
import sys
from pathlib import Path

import pytest
from click.testing import CliRunner

from st_helpers import CORPUS
from verifier.cli import main
import procs

ROOT = Path(__file__).resolve().parent.parent
GOOD = CORPUS / "valid" / "statements.st"
BAD = CORPUS / "invalid" / "int_from_word.st"
SYNTAX = CORPUS / "invalid" / "missing_semicolon.st"
WARN = CORPUS / "invalid" / "unused_warning.st"


def run(*args: str):
    return CliRunner().invoke(main, ["check", *map(str, args)])


def test_clean_file_exits_0():
    result = run(GOOD)
    assert result.exit_code == 0, result.output
    assert "0 error(s), 0 warning(s)" in result.output


def test_warnings_alone_exit_0():
    result = run(WARN)
    assert result.exit_code == 0
    assert f"{WARN}:4:5: warning: label 'iUnused' is declared but never used" in result.output


def test_error_prints_location_source_line_and_caret():
    result = run(BAD)
    assert result.exit_code == 1
    lines = result.output.splitlines()
    i = lines.index(f"{BAD}:5:7: error: assignment: WORD cannot be stored in INT without conversion; use WORD_TO_INT(...)")
    assert lines[i + 1] == "    iX := wY;"
    assert lines[i + 2] == "          ^^"


def test_one_bad_file_does_not_stop_the_others():
    result = run(SYNTAX, BAD, GOOD)
    assert result.exit_code == 1
    assert f"{SYNTAX}:6:1: error: expected ';' at 5:13 to end the statement before 'iX'" in result.output
    assert f"{BAD}:5:7: error" in result.output
    assert f"{BAD}:6:7: error" in result.output
    assert "3 file(s) checked" in result.output


def test_directory_argument_checks_every_st_file_below_it():
    result = run("--target", "gxworks3", CORPUS / "valid")
    assert result.exit_code == 0, result.output  # multi_file_a/b resolve each other


def test_a_folder_is_read_as_verify_reads_it(tmp_path):
    """A folder named like a file (`old.st/`) below the folder given was taken for a source
    (exit 2, 'is a folder'), and `MAIN.ST` was not seen on a case-sensitive disk, where
    `uitamr verify` read both folders right. check and export now read a folder as verify does."""
    src = tmp_path / "src"
    (src / "old.st").mkdir(parents=True)
    (src / "old.st" / "Inner.st").write_text(GOOD.read_text(encoding="utf-8").replace("PROGRAM ", "PROGRAM Inner_", 1),
                                             encoding="utf-8")
    (src / "MAIN.ST").write_text(GOOD.read_text(encoding="utf-8"), encoding="utf-8")
    result = run(src)
    assert result.exit_code == 0, result.output
    assert "2 file(s) checked" in result.output
    from verifier.verify.sources import expand
    from verifier.commands.check import expand_sources
    assert expand_sources((str(src),)) == expand(str(src), tmp_path)


def test_a_folder_of_scenarios_says_what_it_holds_and_what_to_run(tmp_path, monkeypatch):
    """`uitamr check plc/scenarios` said only "no .st files found in the given directories";
    it names the folder, what it holds, and the commands for its scenarios - which run as
    told. A folder without .st among others is said too, not passed over in silence."""
    monkeypatch.chdir(tmp_path)
    (tmp_path / "scenarios").mkdir()
    (tmp_path / "scenarios" / "a.toml").write_text('name = "a"\n', encoding="utf-8")
    (tmp_path / "scenarios" / "README.md").write_text("notes\n", encoding="utf-8")
    (tmp_path / "empty").mkdir()
    result = run("scenarios")
    assert result.exit_code == 2
    assert result.stderr == (
        'uitamr check: scenarios: no .st file in it or below it: it holds 1 .toml and 1 .md file(s); its 1 .toml '
        'file(s) are scenarios: run them with `uitamr verify --scenario "scenarios"` (on the sources they name, or '
        'on .st files given as arguments), or check them by name with `uitamr check "scenarios/*.toml"`\n')
    told = run("scenarios/*.toml")  # the command it gives
    assert told.exit_code == 0 and "1 file(s) checked: 0 error(s)" in told.output, told.output
    result = run("empty")
    assert result.exit_code == 2 and result.stderr == "uitamr check: empty: no .st file in it: the folder is empty\n"
    result = run(GOOD, "scenarios")
    assert result.exit_code == 0 and "1 file(s) checked" in result.output
    assert result.stderr.startswith("uitamr check: warning: scenarios: no .st file in it or below it: ")


def test_the_toolkits_other_files_named_to_check_say_what_they_are():
    """`uitamr check plc/ladder/UITAMR_LadderFx3.il` read the instruction list as ST and
    said "1:1: error: unexpected ';'" (and exit 1, as if the ladder were a broken program);
    the generated CSV the same. Each now says what the file is and what reads it (exit 2)."""
    ladder = ROOT / "plc" / "ladder"
    result = run(ladder / "UITAMR_LadderFx3.il")
    assert result.exit_code == 2, result.output
    assert result.stderr == (f"uitamr check: {ladder / 'UITAMR_LadderFx3.il'}: an instruction list (the ladder "
                             "program), not ST: `python -m verifier.export.ladder FILE.il` reads it and names its "
                             "mistakes (docs/plc-library.md)\n")
    result = run(ladder / "UITAMR_LadderFx3.csv", GOOD)
    assert result.exit_code == 2 and "a GX Works import file (generated), not ST source" in result.stderr
    assert run(GOOD).exit_code == 0


def test_a_capture_named_to_check_is_told_by_its_content(tmp_path):
    """`uitamr check capture.txt` (a capture of `uitamr monitor`, named like any text file)
    was read as ST: "1:1: error: '#' must follow a radix", exit 1. Its content tells it: it
    says what the file is and what reads it (exit 2); a .txt holding ST is still checked."""
    capture = ROOT / "tests" / "captures" / "bad-master.txt"
    result = run(capture)
    assert result.exit_code == 2, result.output
    assert result.stderr == (f"uitamr check: {capture}: a capture of `uitamr monitor --capture` (times and bytes "
                             f"on the line), not ST: `uitamr replay {capture}` judges its frames "
                             "(docs/commissioning.md)\n")
    exported = tmp_path / "MAIN.txt"  # ST as an editor may export it
    exported.write_text(GOOD.read_text(encoding="utf-8"), encoding="utf-8")
    assert run(exported).exit_code == 0
    comments = tmp_path / "notes.txt"  # nothing that tells a capture: read as ST, its mistake placed
    comments.write_text("# to do\n", encoding="utf-8")
    result = run(comments)
    assert result.exit_code == 1 and f"{comments}:1:1: error:" in result.output, result.output


@pytest.mark.parametrize("name, renamed", [("healthy.toml.txt", "healthy.toml"), ("healthy.txt", "healthy.toml")])
def test_a_scenario_saved_under_another_name_is_told_by_its_content(tmp_path, name, renamed):
    """A scenario Windows saved as `healthy.toml.txt` was read as ST: "1:1: error:
    unexpected 'name'; expected 'FUNCTION', ...", exit 1. Its TOML with a scenario's keys
    tells it: it says what the file is, the name check reads it by, and that verify runs
    it as it is (exit 2); TOML without a scenario's key is still read as ST."""
    scenario = tmp_path / name
    scenario.write_text((ROOT / "plc" / "scenarios" / "fx3u-healthy.toml").read_text(encoding="utf-8"),
                        encoding="utf-8")
    result = run(scenario)
    assert result.exit_code == 2, result.output
    assert result.stderr == (f"uitamr check: {scenario}: a scenario (TOML), not ST: name it {renamed} (`uitamr "
                             f"check` reads scenarios by that name); `uitamr verify --scenario {scenario}` runs it "
                             "as it is\n")
    other = tmp_path / "settings.txt"
    other.write_text("x = 1\n", encoding="utf-8")
    result = run(other)
    assert result.exit_code == 1 and f"{other}:1:1: error: unexpected 'x'" in result.output


def test_a_pattern_is_expanded_as_verify_expands_it(tmp_path, monkeypatch):
    """ci.md's commands (`uitamr check --platform fx3u plc/ verify/*.toml`, the VS Code task)
    rely on the shell to expand `*.toml`; cmd and PowerShell do not, and check took the
    pattern for a file name ("verify/*.toml: no such file") where `uitamr verify 'plc/*.st'`
    expands it itself. check and export now read a pattern as verify does."""
    (tmp_path / "plc").mkdir()
    (tmp_path / "verify").mkdir()
    (tmp_path / "plc" / "MAIN.st").write_text(GOOD.read_text(encoding="utf-8"), encoding="utf-8")
    (tmp_path / "verify" / "healthy.toml").write_text('[[expect]]\nsent = "stop"\nwithin = "1s"\n', encoding="utf-8")
    (tmp_path / "verify" / "broken.toml").write_text("name = 3\n", encoding="utf-8")
    monkeypatch.chdir(tmp_path)
    result = run("plc/*.st", "verify/*.toml")
    assert result.exit_code == 1, result.output
    assert "verify/broken.toml:1:8: error: name: expected a string, got 3" in result.output
    assert result.output.splitlines()[-1].startswith("3 file(s) checked")
    none = run("plc/*.st", "verify/*.tmol")
    assert none.exit_code == 2 and "uitamr check: verify/*.tmol: matches no file" in none.output, none.output
    exported = CliRunner().invoke(main, ["export", "--target", "gxworks2", "--out", "gx2", "plc/*.st"])
    assert exported.exit_code == 0, exported.output
    assert (tmp_path / "gx2" / "IMPORT_ORDER.txt").exists()
    missing = CliRunner().invoke(main, ["export", "--target", "gxworks2", "--out", "gx2", "src/*.st"])
    assert missing.exit_code == 2 and "src/*.st" in missing.output, missing.output


def test_json_format():
    result = run("--format", "json", BAD, WARN)
    assert result.exit_code == 1
    report = json.loads(result.output)
    assert report["errors"] == 2 and report["warnings"] == 1
    first = report["diagnostics"][0]
    assert (first["file"], first["line"], first["col"], first["severity"]) == (str(BAD), 5, 7, "error")


def test_target_option_changes_the_dialect():
    gx3 = CORPUS / "valid" / "gx3_only.st"
    assert run("--target", "gxworks2", gx3).exit_code == 1
    assert run("--target", "gxworks3", gx3).exit_code == 0


def test_usage_errors_exit_2():
    assert run(CORPUS / "no_such_file.st").exit_code == 2
    assert run("--target", "gxworks9", GOOD).exit_code == 2
    assert run("--format", "xml", GOOD).exit_code == 2
    assert run().exit_code == 2


def test_missing_file_is_named(tmp_path):
    result = run(GOOD, tmp_path / "gone.st")
    assert result.exit_code == 2
    assert "gone.st: no such file" in result.output


def test_undecodable_and_binary_files_are_diagnosed_not_crashed(tmp_path):
    junk = tmp_path / "junk.st"
    junk.write_bytes(bytes(range(256)) * 4)
    result = run(junk)
    assert result.exit_code == 1
    assert "Traceback" not in result.output
    assert str(junk) + ":" in result.output


def test_shift_jis_file_is_read(tmp_path):
    path = tmp_path / "sjis.st"
    path.write_bytes("PROGRAM P\nVAR iX : INT; END_VAR\n(* 起動 *)\niX := 1;\nEND_PROGRAM\n".encode("cp932"))
    assert run(path).exit_code == 0


def test_installed_command_runs():
    proc = procs.run([sys.executable, "-m", "verifier.cli", "check", str(BAD)],
                     capture_output=True, text=True, timeout=120)
    assert proc.returncode == 1
    assert f"{BAD}:5:7: error" in proc.stdout


def test_device_file_gets_a_precise_message():
    result = run("/dev/null")
    assert result.exit_code == 2
    assert "/dev/null: is not a regular file (a character device); give a .st file" in result.output
    assert "no such file" not in result.output


def test_pipe_is_not_read(tmp_path):
    import os

    fifo = tmp_path / "pipe.st"
    os.mkfifo(fifo)
    result = run(fifo)  # reading would block forever: it must be refused before that
    assert result.exit_code == 2
    assert f"{fifo}: is not a regular file (a pipe)" in result.output


def test_empty_file_and_comment_only_file_warn_no_pou(tmp_path):
    empty = tmp_path / "empty.st"
    empty.write_bytes(b"")
    comment = tmp_path / "comment.st"
    comment.write_text("(* nothing here yet *)\n", encoding="utf-8")
    result = run(empty, comment)
    assert result.exit_code == 0, result.output
    assert f"{empty}:1:1: warning: no POU in file" in result.output
    assert f"{comment}:1:1: warning: no POU in file" in result.output
    assert "0 error(s), 2 warning(s)" in result.output


def test_globals_only_file_is_not_a_missing_pou(tmp_path):
    path = tmp_path / "globals.st"
    path.write_text("VAR_GLOBAL g_bRun : BOOL; END_VAR\n", encoding="utf-8")
    result = run(path)
    assert result.exit_code == 0 and "no POU" not in result.output


def test_undecodable_bytes_are_named_with_line_and_column(tmp_path):
    path = tmp_path / "bad.st"
    path.write_bytes(b"PROGRAM P\nVAR x : INT; END_VAR\nx := 1; (* \x80\x81 *)\nEND_PROGRAM\n")
    result = run(path)
    assert result.exit_code == 1
    assert f"{path}:3:12: error: byte 0x80 at offset 42 is neither UTF-8 nor Shift-JIS text" in result.output


def test_a_file_named_twice_is_checked_once(tmp_path):
    """`check a a/Main.st` used to report Main as defined twice, in the same file."""
    folder = tmp_path / "a"
    folder.mkdir()
    (folder / "Main.st").write_text("PROGRAM Main\nVAR x : INT; END_VAR\nx := 1;\nEND_PROGRAM\n", encoding="utf-8")
    result = run(folder, folder / "Main.st")
    assert result.exit_code == 0, result.output
    assert "1 file(s) checked" in result.output
