"""Every POU of the library passes `uitamr check` for the editor of its platform, with
no warning: GX Works label rules, types, instruction signatures."""
from __future__ import annotations

from pathlib import Path

import pytest
from click.testing import CliRunner

from verifier import st
from verifier.commands.check import command as check_command

PLC = Path(__file__).resolve().parents[1] / "plc"
SETS = {
    "fx3u": ("gxworks2", ["core", "fx3", "examples/common", "examples/fx3"]),
    "q": ("gxworks2", ["core", "q", "examples/common", "examples/q"]),
    "fx5u": ("gxworks3", ["core", "fx5", "examples/common", "examples/fx5"]),
}


def files(parts):
    out = []
    for part in parts:
        path = PLC / part
        out += sorted(path.glob("*.st")) if path.is_dir() else [path]
    return out


@pytest.mark.parametrize("platform", sorted(SETS))
def test_platform_set_checks_clean(platform):
    target, parts = SETS[platform]
    sources = [st.parse(p.read_text(), str(p), target) for p in files(parts)]
    findings = [d for s in sources for d in s.diagnostics] + st.check(sources, target)
    assert not findings, "\n".join(str(d) for d in findings)


def test_check_command_accepts_the_library():
    result = CliRunner().invoke(check_command, ["--target", "gxworks2", *map(str, files(SETS["fx3u"][1]))])
    assert result.exit_code == 0, result.output
    assert "0 error(s), 0 warning(s)" in result.output


@pytest.mark.parametrize("platform", sorted(SETS))
def test_platform_set_has_only_devices_and_instructions_of_its_cpu(platform):
    # every .st file (test_every_st_file_belongs_to_a_checked_set), not only those a bundled
    # scenario names: uitamr check --platform, which implies the editor
    result = CliRunner().invoke(check_command, ["--platform", platform, *map(str, files(SETS[platform][1]))])
    assert result.exit_code == 0, result.output
    assert f"checked for {SETS[platform][0]} on the {platform} CPU: 0 error(s), 0 warning(s)" in result.output


def test_every_st_file_belongs_to_a_checked_set():
    checked = {p for _, parts in SETS.values() for p in files(parts)}
    assert set(PLC.rglob("*.st")) <= checked


def _statements(node):
    """Every node below `node` (through the syntax fields, as the simulator's walkers go)."""
    from verifier.st import ast

    stack = [node]
    while stack:
        item = stack.pop()
        if isinstance(item, list):
            stack.extend(item)
        elif isinstance(item, ast.Node):
            yield item
            stack.extend(ast.syntax_fields(item))


def test_the_library_keeps_to_the_statements_its_docs_name():
    """docs/plc-library.md: IF/ELSIF/ELSE and FOR only - no CASE, WHILE, REPEAT, EXIT or
    RETURN, which the library's dialect leaves out for both GX Works versions."""
    from verifier.st import ast

    left_out = (ast.Case, ast.While, ast.Repeat, ast.Exit, ast.Return)
    found = []
    for path in sorted(PLC.rglob("*.st")):
        for pou in st.parse(path.read_text(encoding="utf-8"), str(path)).pous:
            found += [f"{path.relative_to(PLC)}: {pou.name}: {type(n).__name__}"
                      for n in _statements(pou.body) if isinstance(n, left_out)]
    assert not found, found


def test_a_program_without_the_library_files_is_told_which_files_to_add(tmp_path):
    # an integrator's own program, checked or exported without the library's files: the
    # error names the library file that declares the FB or FUNCTION, not "declare it"
    main = tmp_path / "Station.st"
    main.write_text(
        "PROGRAM Station\n"
        "VAR\n"
        "    fbEngine : UITAMR_Engine;\n"
        "    uBytes : ARRAY[0..15] OF WORD;\n"
        "    uCrc : WORD;\n"
        "    fbOwn : FB_NotInTheLibrary;\n"
        "END_VAR\n"
        "uCrc := UITAMR_CRC16(uBytes, 6);\n"
        "END_PROGRAM\n", encoding="utf-8")
    result = CliRunner().invoke(check_command, ["--target", "gxworks2", str(main)])
    assert result.exit_code == 1, result.output
    lines = [line for line in result.output.splitlines() if ": error: " in line]
    engine = PLC / "core" / "UITAMR_Engine.st"
    crc = PLC / "core" / "UITAMR_CRC16.st"
    assert lines[0] == (f"{main}:3:16: error: unknown type 'UITAMR_Engine'; the UITAMR library "
                        f"declares it: add {engine} (or its folder) to the sources")
    assert lines[1] == (f"{main}:6:13: error: unknown type 'FB_NotInTheLibrary'; declare the "
                        "structure or function block, or use a GX Works type")
    assert lines[2] == (f"{main}:8:9: error: unknown function or instruction 'UITAMR_CRC16'; the "
                        f"UITAMR library declares it: add {crc} (or its folder) to the sources")


def test_the_file_to_add_is_named_where_the_integrator_vendored_the_library(tmp_path, monkeypatch):
    # docs/import-gxworks2.md "Your own program": the toolkit as vendor/uitamr (a submodule,
    # here a symlink), some of its files given, one left out. The file to add is named by
    # the path the integrator reaches it by, not where the symlink leads.
    (tmp_path / "vendor").mkdir()
    (tmp_path / "vendor" / "uitamr").symlink_to(PLC.parent, target_is_directory=True)
    (tmp_path / "src").mkdir()
    (tmp_path / "src" / "Main.st").write_text(
        "PROGRAM Main\nVAR\n    fbPort : UITAMR_PortFx3;\n    uPort : ARRAY[0..39] OF WORD;\nEND_VAR\n"
        "fbPort(i_bEN := TRUE, i_wChannel := 1, io_uPort := uPort);\nEND_PROGRAM\n", encoding="utf-8")
    monkeypatch.chdir(tmp_path)
    result = CliRunner().invoke(check_command, ["--platform", "fx3u", "vendor/uitamr/plc/core", "src"])
    assert result.exit_code == 1, result.output
    lines = [line for line in result.output.splitlines() if ": error: " in line]
    assert lines == ["src/Main.st:3:14: error: unknown type 'UITAMR_PortFx3'; the UITAMR library declares it: "
                     "add vendor/uitamr/plc/fx3/UITAMR_PortFx3.st (or its folder) to the sources"]


def test_the_file_to_add_is_named_in_a_vendored_copy_of_the_library(tmp_path, monkeypatch):
    # import-gxworks2.md's own-program commands, the toolkit a git submodule: a copy, no
    # link to the installed toolkit. The file to add was named by the installed toolkit's
    # absolute path, not the vendor/uitamr/plc/q/UITAMR_PortQC24.st the integrator has.
    import shutil

    vendored = tmp_path / "vendor" / "uitamr" / "plc"
    for folder in ("core", "q"):
        shutil.copytree(PLC / folder, vendored / folder)
    (tmp_path / "src").mkdir()
    (tmp_path / "src" / "Main.st").write_text(
        "PROGRAM Main\nVAR\n    fbPort : UITAMR_PortQC24;\nEND_VAR\nfbPort();\nEND_PROGRAM\n", encoding="utf-8")
    monkeypatch.chdir(tmp_path)
    hint = "error: unknown type 'UITAMR_PortQC24'; the UITAMR library declares it: add {} (or its folder) to the sources"
    result = CliRunner().invoke(check_command, ["--platform", "q", "vendor/uitamr/plc/core", "src"])
    assert result.exit_code == 1, result.output
    assert [line for line in result.output.splitlines() if ": error: " in line] == [
        "src/Main.st:3:14: " + hint.format("vendor/uitamr/plc/q/UITAMR_PortQC24.st")]
    monkeypatch.chdir(vendored)  # from inside the copy: the path from there
    result = CliRunner().invoke(check_command, ["--platform", "q", "core", "../../../src"])
    assert "../../../src/Main.st:3:14: " + hint.format("q/UITAMR_PortQC24.st") in result.output
    # the copy given by its absolute path: its own file, not the installed toolkit's
    result = CliRunner().invoke(check_command, ["--platform", "q", str(vendored / "core"), str(tmp_path / "src")])
    assert f"{tmp_path / 'src' / 'Main.st'}:3:14: " + hint.format(vendored / "q" / "UITAMR_PortQC24.st") in result.output
    shutil.rmtree(vendored / "q")  # a copy without the file: the installed toolkit's, which exists
    result = CliRunner().invoke(check_command, ["--platform", "q", "core", "../../../src"])
    assert hint.format(PLC / "q" / "UITAMR_PortQC24.st") in result.output


def test_a_call_with_the_old_run_input_i_benable_is_told_its_new_name(tmp_path):
    """docs/plc-library.md: the engine's and the ports' run input i_bEnable is now i_bEN,
    and 'uitamr check names every call that still uses i_bEnable'. It named the call but
    said only "UITAMR_Engine has no parameter 'i_bEnable'": not what to write instead."""
    main = tmp_path / "Main.st"
    main.write_text("PROGRAM Main\nVAR\n    fbPort : UITAMR_PortFx3;\n    fbEngine : UITAMR_Engine;\n"
                    "    uMbx : ARRAY[0..15] OF WORD;\n    uPort : ARRAY[0..39] OF WORD;\nEND_VAR\n"
                    "fbPort(i_bEnable := TRUE, i_wChannel := 1, io_uPort := uPort);\n"
                    "fbEngine(i_bEnable := NOT M8002, i_wAddress := 1, i_bMonitor := TRUE, io_uMbx := uMbx, "
                    "io_uPort := uPort);\nEND_PROGRAM\n")
    result = CliRunner().invoke(check_command, ["--platform", "fx3u", str(PLC / "core"),
                                                str(PLC / "fx3" / "UITAMR_PortFx3.st"), str(main)])
    assert result.exit_code == 1
    for line, fb in ((8, "UITAMR_PortFx3"), (9, "UITAMR_Engine")):
        assert f"{main}:{line}:" in result.output
        assert (f"{fb} has no parameter 'i_bEnable'; its run input "
                "is i_bEN (renamed from i_bEnable, docs/plc-library.md): write 'i_bEN := ...'") in result.output


def test_a_misspelt_fb_parameter_gets_the_name_probably_meant(tmp_path):
    main = tmp_path / "Main.st"
    main.write_text("PROGRAM Main\nVAR\n    fbRun : UITAMR_RunPoint;\n    uMbx : ARRAY[0..15] OF WORD;\n"
                    "END_VAR\nfbRun(i_bEN := TRUE, i_bExecute := TRUE, i_wPiont := 4, io_uMbx := uMbx);\n"
                    "END_PROGRAM\n")
    result = CliRunner().invoke(check_command, ["--target", "gxworks2", str(PLC / "core"), str(main)])
    assert result.exit_code == 1
    assert "UITAMR_RunPoint has no parameter 'i_wPiont'; did you mean 'i_wPoint'?" in result.output
