"""`uitamr export`: ST bodies and label tables for GX Works, checked by rebuilding each
POU from what was exported and comparing it with the original parse."""
from __future__ import annotations

import re
from pathlib import Path

import pytest
from click.testing import CliRunner

from verifier import st
from verifier.commands.export import bundled_sources, command
from verifier.export.types import TABLES

ROOT = Path(__file__).resolve().parents[1]


def run(*args):
    return CliRunner().invoke(command, list(args), catch_exceptions=False)


def rebuild(name: str, kind: str, out: Path, target: str, result: str = "") -> str:
    """ST text of a POU put together again from `<name>.labels.tsv` and `<name>.st`."""
    reverse = {v: k for k, v in TABLES[target].items()}
    lines = (out / f"{name}.labels.tsv").read_text().splitlines()
    header, rows = lines[0].split("\t"), [dict(zip(lines[0].split("\t"), r.split("\t"))) for r in lines[1:]]
    assert header[:1] in (["Class"], ["Label Name"])
    blocks: dict[str, list[str]] = {}
    for r in rows:
        dtype = r["Data Type"]
        array = re.fullmatch(r"(.*)\((-?\d+\.\.-?\d+(?:,-?\d+\.\.-?\d+)*)\)", dtype)
        if array:
            base, dims = array.groups()
            decl_type = f"ARRAY[{dims}] OF {reverse.get(base, base)}"
        else:
            decl_type = reverse.get(dtype, dtype)
        init = r.get("Constant") or r.get("Initial Value") or ""
        blocks.setdefault(r["Class"], []).append(f"    {r['Label Name']} : {decl_type}{' := ' + init if init else ''};")
    text = f"{kind} {name}{' : ' + reverse.get(result, result) if result else ''}\n"
    for cls, decls in blocks.items():
        keyword = "VAR CONSTANT" if cls == "VAR_CONSTANT" else cls
        text += f"{keyword}\n" + "\n".join(decls) + "\nEND_VAR\n"
    return text + (out / f"{name}.st").read_text()


@pytest.mark.parametrize("target", ["gxworks2", "gxworks3"])
def test_bundled_library_round_trips_through_the_export(tmp_path, target):
    result = run("--target", target, "--out", str(tmp_path))
    assert result.exit_code == 0, result.output
    order = [line.split("\t") for line in (tmp_path / "IMPORT_ORDER.txt").read_text().splitlines()]
    sources = bundled_sources(target)
    originals = {p.name: p for path in sources for p in st.parse(path.read_text(), str(path), target).pous}
    assert {row[0] for row in order} == set(originals)
    assert ["UITAMR_CRC16", "FUNCTION", TABLES[target]["WORD"]] in order
    for name, kind, *result in order:
        rebuilt = st.parse(rebuild(name, kind, tmp_path, target, *result), f"{name}.rebuilt", target)
        assert rebuilt.ok, [str(d) for d in rebuilt.diagnostics]
        original = originals[name]
        assert rebuilt.pous[0].body == original.body, name
        assert [(v.name, v.type, v.section, v.constant) for v in rebuilt.pous[0].variables] == \
               [(v.name, v.type, v.section, v.constant) for v in original.variables], name


def test_import_order_puts_every_pou_after_what_it_uses(tmp_path):
    run("--target", "gxworks2", "--out", str(tmp_path))
    order = [line.split("\t")[0] for line in (tmp_path / "IMPORT_ORDER.txt").read_text().splitlines()]
    assert order.index("UITAMR_CRC16") < order.index("UITAMR_BuildControl") < order.index("UITAMR_Engine")
    assert order.index("UITAMR_Command") < order.index("UITAMR_Stop") < order.index("UITAMR_PointCycle")
    assert order.index("UITAMR_PortLink") < order.index("UITAMR_PortFx3") < order.index("UITAMR_ExampleFx3")


def test_label_table_uses_the_editors_words(tmp_path):
    run("--target", "gxworks2", "--out", str(tmp_path / "2"))
    run("--target", "gxworks3", "--out", str(tmp_path / "3"))
    gw2 = (tmp_path / "2" / "UITAMR_Engine.labels.tsv").read_text()
    gw3 = (tmp_path / "3" / "UITAMR_Engine.labels.tsv").read_text()
    assert gw2.splitlines()[0] == "Class\tLabel Name\tData Type\tConstant\tComment"
    assert "VAR_INPUT\ti_bEN\tBit\t\trun the engine" in gw2
    assert "VAR_IN_OUT\tio_uPort\tWord[Unsigned]/Bit String[16-bit](0..39)\t\tport interface" in gw2
    assert "VAR_CONSTANT\tPACE_TIME\tTime\tT#300ms\t" in gw2
    assert "VAR\ttmrPace\tTON\t\tstart-to-start pacing" in gw2
    assert "i_wAddress\tWord [Signed]\tVAR_INPUT\t\t\trobot address, 0 = 1" in gw3
    body = (tmp_path / "2" / "UITAMR_Engine.st").read_text()
    assert body.startswith("(* ====") and "VAR_INPUT" not in body and "END_VAR" not in body


def test_a_comment_over_two_lines_after_a_declaration_is_kept(tmp_path):
    """A trailing comment closed on the next line was dropped from the label table, the
    bundled engine's IDLE_POLLS_TO_END among them. Joined into one line, as the editors'
    label comments are."""
    src = tmp_path / "src" / "FB_Two.st"
    src.parent.mkdir()
    src.write_text("FUNCTION_BLOCK FB_Two\nVAR\n    wX : INT;  (* counts the\n                  retries *)\n"
                   "    wY : INT;  (* one line *) wZ : INT;\nEND_VAR\nwX := wY + wZ;\nEND_FUNCTION_BLOCK\n")
    assert run("--target", "gxworks2", "--out", str(tmp_path / "o"), str(src)).exit_code == 0
    table = (tmp_path / "o" / "FB_Two.labels.tsv").read_text()
    assert "VAR\twX\tWord[Signed]\t\tcounts the retries\n" in table
    assert "VAR\twY\tWord[Signed]\t\tone line\n" in table
    run("--target", "gxworks3", "--out", str(tmp_path / "3"))
    assert ("IDLE_POLLS_TO_END\tWord [Signed]\tVAR_CONSTANT\t\t1\t'idle' answers in a row that end a task; "
            "2 if the robot is slow to report a started task\n") in (tmp_path / "3" / "UITAMR_Engine.labels.tsv").read_text()


def test_sources_with_errors_are_reported_with_their_place(tmp_path):
    bad = tmp_path / "FB_Bad.st"
    bad.write_text("FUNCTION_BLOCK FB_Bad\nVAR\n    wX : INT;\nEND_VAR\nwX := ;\n")
    result = CliRunner().invoke(command, ["--target", "gxworks2", "--out", str(tmp_path / "o"), str(bad)])
    assert result.exit_code == 1
    assert f"{bad}:5:" in result.output and "nothing written" in result.output
    assert not (tmp_path / "o").exists()


def test_an_export_into_the_sources_own_folder_never_writes_over_the_source(tmp_path):
    """`--out` = the folder of a source whose name is its POU's: the body alone would
    replace the file (declarations and comments lost). Refused, nothing written."""
    src = tmp_path / "FB_Count.st"
    text = "(* counts *)\nFUNCTION_BLOCK FB_Count\nVAR\n    wX : INT;\nEND_VAR\nwX := wX + 1;\nEND_FUNCTION_BLOCK\n"
    src.write_text(text)
    result = CliRunner().invoke(command, ["--target", "gxworks2", "--out", str(tmp_path), str(src)])
    assert result.exit_code == 1
    assert f"{src}:2:1: error: exporting into {tmp_path} would write FB_Count.st over this source file" in result.output
    assert src.read_text() == text
    assert sorted(p.name for p in tmp_path.iterdir()) == ["FB_Count.st"]
    other = tmp_path / "Counting.st"  # a file named otherwise: its folder is fine
    src.rename(other)
    assert run("--target", "gxworks2", "--out", str(tmp_path), str(other)).exit_code == 0
    assert other.read_text() == text and (tmp_path / "FB_Count.st").exists()


@pytest.mark.parametrize("name", ["GlobalLabels", "GLOBALLABELS"])
def test_a_pou_named_like_the_global_label_table_is_refused(tmp_path, name):
    """A PROGRAM GlobalLabels had its label table written over by the global label table
    (or the other way round): its labels were lost without a word, exit 0. On Windows,
    where GX Works runs, GLOBALLABELS.labels.tsv is the same file."""
    src = tmp_path / "src"
    src.mkdir()
    (src / "Prog.st").write_text(f"PROGRAM {name}\nVAR\n    wX : INT;\nEND_VAR\nwX := gY;\nEND_PROGRAM\n")
    (src / "Globals.st").write_text("VAR_GLOBAL\n    gY : INT;\nEND_VAR\n")
    result = CliRunner().invoke(command, ["--target", "gxworks3", "--out", str(tmp_path / "o"), str(src)])
    assert result.exit_code == 1
    assert (f"{src / 'Prog.st'}:1:1: error: a POU named {name} would have its label table written to "
            "GlobalLabels.labels.tsv") in result.output
    assert not (tmp_path / "o").exists()


def test_exporting_a_folder_into_a_folder_inside_it_runs_twice(tmp_path):
    """`--out src/gx2 src`: the second run read the first run's bodies (no declarations)
    as sources and failed with 'a statement outside a POU' at src/gx2/Main.st."""
    src = tmp_path / "src"
    src.mkdir()
    (src / "Main.st").write_text("PROGRAM Main\nVAR\n    wX : INT;\nEND_VAR\nwX := wX + 1;\nEND_PROGRAM\n")
    args = ["--target", "gxworks2", "--out", str(src / "gx2"), str(src)]
    first = CliRunner().invoke(command, args)
    assert first.exit_code == 0, first.output
    second = CliRunner().invoke(command, args)
    assert second.exit_code == 0, second.output
    assert f"1 file(s) in the --out folder {src / 'gx2'} left out of the sources (an earlier export)" in second.output
    assert (src / "gx2" / "Main.st").read_text() == "wX := wX + 1;\n"
    # the output folder named as the source: its bodies are said to be an export's, not ST
    # sources (was exit 1, 'a statement outside a POU' at src/gx2/Main.st:1:1)
    third = CliRunner().invoke(command, ["--target", "gxworks2", "--out", str(tmp_path / "o"), str(src / "gx2")])
    assert third.exit_code == 2 and "outside a POU" not in third.output
    assert third.output == (f"uitamr export: {src / 'gx2' / 'Main.st'}: a body written by `uitamr export` (its "
                            "declarations are in Main.labels.tsv), not ST source: check the .st files it was "
                            "exported from, with the same --platform\n")


def test_a_pattern_is_read_as_the_folders_and_files_it_matches(tmp_path, monkeypatch):
    """export expands a pattern itself (cmd and PowerShell do not). A pattern matching the
    folder that holds --out ran once and then failed on the first run's bodies ('outside a
    POU'), where the same folder named, or expanded by bash, runs again; a pattern matching
    only a folder without .st files was read as a file of that name ('cannot read: no such
    file', '1 unreadable file(s)', exit 1) instead of refused as matching no source (exit 2)."""
    monkeypatch.chdir(tmp_path)
    (tmp_path / "src").mkdir()
    (tmp_path / "empty").mkdir()
    (tmp_path / "src" / "Main.st").write_text("PROGRAM Main\nVAR\n    wX : INT;\nEND_VAR\nwX := wX + 1;\nEND_PROGRAM\n")
    args = ["--target", "gxworks2", "--out", "src/gx2", "sr[c]"]
    first = run(*args)
    assert first.exit_code == 0, first.output
    second = run(*args)
    assert second.exit_code == 0, second.output
    assert "1 file(s) in the --out folder src/gx2 left out of the sources (an earlier export)" in second.output
    empty = run("--target", "gxworks2", "--out", "o", "emp*")
    assert empty.exit_code == 2 and "emp*" in empty.output and "unreadable" not in empty.output, empty.output
    # worded as check and verify word it
    assert "'emp*' matches no file" in empty.output and "no such file" not in empty.output, empty.output
    both = run("--target", "gxworks2", "--out", "o", "nope*.st", "gone.st")
    assert both.exit_code == 2
    assert "'nope*.st' matches no file; no such file or folder: gone.st" in both.output, both.output


def test_missing_source_is_a_usage_error(tmp_path):
    result = CliRunner().invoke(command, ["--target", "gxworks3", "--out", str(tmp_path), "nope.st"])
    assert result.exit_code == 2 and "nope.st" in result.output


def test_a_scenario_or_a_folder_without_st_is_named_as_such(tmp_path, monkeypatch):
    """`uitamr export ... s.toml` read the scenario as ST ("1:1: error: unexpected 'name'"),
    and a folder of scenarios gave "no .st files to export" without naming it; beside a
    folder that has .st files, it was passed over in silence."""
    monkeypatch.chdir(tmp_path)
    (tmp_path / "scenarios").mkdir()
    (tmp_path / "scenarios" / "s.toml").write_text('name = "s"\n', encoding="utf-8")
    (tmp_path / "src").mkdir()
    (tmp_path / "src" / "Main.st").write_text("PROGRAM Main\nVAR x : INT; END_VAR\nx := 1;\nEND_PROGRAM\n")
    result = run("--target", "gxworks2", "--out", "out", "scenarios/s.toml")
    assert result.exit_code == 2 and not (tmp_path / "out").exists()
    assert result.stderr == ("uitamr export: scenarios/s.toml: a scenario (.toml), not ST source: export writes the "
                             "POUs of .st files; run scenarios with uitamr verify --scenario\n")
    result = run("--target", "gxworks2", "--out", "out", "scenarios")
    assert result.exit_code == 2 and not (tmp_path / "out").exists()
    assert result.stderr.startswith("uitamr export: scenarios: no .st file in it or below it: it holds 1 .toml "
                                    "file(s); its 1 .toml file(s) are scenarios: run them with `uitamr verify "
                                    '--scenario "scenarios"`')
    result = run("--target", "gxworks2", "--out", "out", "src", "scenarios")
    assert result.exit_code == 0 and (tmp_path / "out" / "Main.st").is_file()
    assert result.stderr.startswith("uitamr export: warning: scenarios: no .st file in it or below it")


def test_the_toolkits_other_files_named_to_export_say_what_they_are(tmp_path):
    """`uitamr export` of the ladder's .il, a capture or a scenario saved as .txt read each
    as ST ("1:1: error: unexpected ';'", "'#' must follow a radix", "unexpected 'name'",
    exit 1); each now says what it is and what reads it, as `uitamr check` does (exit 2)."""
    scenario = tmp_path / "healthy.toml.txt"
    scenario.write_text((ROOT / "plc" / "scenarios" / "fx3u-healthy.toml").read_text(encoding="utf-8"),
                        encoding="utf-8")
    capture = ROOT / "tests" / "captures" / "bad-master.txt"
    for source, what in [(ROOT / "plc" / "ladder" / "UITAMR_LadderFx3.il", "an instruction list (the ladder program)"),
                         (capture, f"a capture of `uitamr monitor --capture` (times and bytes on the line), not ST: "
                                   f"`uitamr replay {capture}` judges its frames"),
                         (scenario, "a scenario (TOML), not ST: name it healthy.toml")]:
        result = run("--target", "gxworks2", "--out", str(tmp_path / "out"), str(source), str(ROOT / "plc" / "core"))
        assert result.exit_code == 2 and "Traceback" not in result.output
        assert result.stderr.startswith(f"uitamr export: {source}: {what}"), result.stderr
        assert not (tmp_path / "out").exists()


def test_global_labels_get_their_own_table(tmp_path):
    src = tmp_path / "Main.st"
    src.write_text(
        "VAR_GLOBAL\n    bStart AT X0 : BOOL; (* start button *)\n    wCount : INT;\nEND_VAR\n"
        "VAR_GLOBAL CONSTANT\n    MAX_COUNT : INT := 10;\nEND_VAR\n"
        "PROGRAM Main\nVAR\n    wX : INT;\nEND_VAR\nIF bStart THEN\n    wX := MAX_COUNT;\nEND_IF;\n")
    result = CliRunner().invoke(command, ["--target", "gxworks2", "--out", str(tmp_path / "o"), str(src)])
    assert result.exit_code == 0, result.output
    table = (tmp_path / "o" / "GlobalLabels.labels.tsv").read_text().splitlines()
    assert table[0] == "Class\tLabel Name\tData Type\tConstant\tDevice\tComment"
    assert "VAR_GLOBAL\tbStart\tBit\t\tX0\tstart button" in table
    assert "VAR_GLOBAL_CONSTANT\tMAX_COUNT\tWord[Signed]\t10\t\t" in table
    gw3 = CliRunner().invoke(command, ["--target", "gxworks3", "--out", str(tmp_path / "g3"), str(src)])
    assert gw3.exit_code == 0
    assert "bStart\tBit\tVAR_GLOBAL\tX0\t\t\tstart button" in (tmp_path / "g3" / "GlobalLabels.labels.tsv").read_text()
    assert "1 POU(s) exported" in result.output


# ---------------------------------------------------------------------------- nothing silently lost
INITIALS = """FUNCTION_BLOCK FB_Init
VAR_INPUT
    i_wIn : INT := 3;
END_VAR
VAR_OUTPUT
    o_wOut : INT := 4;
END_VAR
VAR
    wCount : INT := 5;
    bRun : BOOL := TRUE;
    tDelay : TIME := T#2s;
END_VAR
VAR CONSTANT
    MAX_COUNT : INT := 7;
END_VAR
o_wOut := i_wIn + wCount + MAX_COUNT;
END_FUNCTION_BLOCK
"""
GLOBALS = "VAR_GLOBAL\n    gwStart : INT := 9;\nEND_VAR\n"
STRUCT = "TYPE S_Pos :\nSTRUCT\n    wX : INT := 11;\n    wY : INT;\nEND_STRUCT\nEND_TYPE\n"


def _sources(tmp_path):
    paths = []
    for name, text in (("FB_Init.st", INITIALS), ("Globals.st", GLOBALS), ("S_Pos.st", STRUCT)):
        path = tmp_path / name
        path.write_text(text)
        paths.append(path)
    return paths


def _initials(paths):
    """(file, line, label, value) of every non-constant initial value in the sources."""
    found = []
    for path in paths:
        for number, line in enumerate(path.read_text().splitlines(), 1):
            m = re.match(r"\s+(\w+) : \w+ := (\S+);", line)
            if m and m.group(1) != "MAX_COUNT":
                found.append((path, number, m.group(1), m.group(2)))
    return found


@pytest.mark.parametrize("target", ["gxworks2", "gxworks3"])
def test_no_initial_value_is_dropped_silently(tmp_path, target):
    """QA finding 7: every initial value is in a written table, or named (file:line) in the
    output - as a refusal or as a note - never just gone."""
    paths = _sources(tmp_path)
    out = tmp_path / "out"
    result = CliRunner().invoke(command, ["--target", target, "--out", str(out), *map(str, paths)])
    tables = "".join(p.read_text() for p in out.glob("*.tsv")) if out.exists() else ""
    for path, line, label, value in _initials(paths):
        row = [r for r in tables.splitlines() if r.split("\t")[0] == label or label in r.split("\t")[:2]]
        carried = any(value in r.split("\t") for r in row)
        named = f"{path}:{line}:" in result.output
        assert carried or named, (label, value, result.output)
    if target == "gxworks3":
        assert result.exit_code == 0, result.output
        assert not (out / "DROPPED_INITIAL_VALUES.txt").exists()


def test_dropped_initial_values_are_listed_with_their_place(tmp_path):
    from verifier.export import dropped_initial_values
    paths = _sources(tmp_path)
    files = [st.parse(p.read_text(), str(p), "gxworks2") for p in paths]
    dropped = dropped_initial_values(files, "gxworks2")
    assert [(d.owner, d.label, d.value) for d in dropped] == [
        ("FB_Init", "i_wIn", "3"), ("FB_Init", "o_wOut", "4"), ("FB_Init", "wCount", "5"),
        ("FB_Init", "bRun", "TRUE"), ("FB_Init", "tDelay", "T#2s"), ("global", "gwStart", "9"),
        ("S_Pos", "wX", "11")]
    assert str(dropped[2]).startswith(f"{paths[0]}:9:21: note: VAR 'FB_Init.wCount' := 5 not exported")
    files3 = [st.parse(p.read_text(), str(p), "gxworks3") for p in paths]
    assert dropped_initial_values(files3, "gxworks3") == []


def test_gxworks3_carries_initial_values_in_every_table(tmp_path):
    out = tmp_path / "out"
    run("--target", "gxworks3", "--out", str(out), *map(str, _sources(tmp_path)))
    assert "wCount\tWord [Signed]\tVAR\t5\t" in (out / "FB_Init.labels.tsv").read_text()
    assert "gwStart\tWord [Signed]\tVAR_GLOBAL\t\t9\t" in (out / "GlobalLabels.labels.tsv").read_text()
    assert (out / "S_Pos.struct.tsv").read_text().splitlines() == [
        "Label Name\tData Type\tInitial Value\tComment", "wX\tWord [Signed]\t11\t", "wY\tWord [Signed]\t\t"]
    assert (out / "IMPORT_ORDER.txt").read_text().splitlines()[0] == "S_Pos\tSTRUCT"
    # the import pages say what to do with that line: they said it only of FUNCTION,
    # FUNCTION_BLOCK and PROGRAM lines
    for page in ("import-gxworks2.md", "import-gxworks3.md"):
        steps = (ROOT / "docs" / page).read_text(encoding="utf-8").split("IMPORT_ORDER.txt order", 1)[1]
        assert "0. A `STRUCT` line" in steps.split("\n## ", 1)[0], page


def test_the_help_names_every_kind_of_file_the_export_writes(tmp_path):
    """--out's help named the label tables and IMPORT_ORDER.txt but not <Type>.struct.tsv,
    which import-gxworks2.md and import-gxworks3.md describe and the export writes."""
    out = tmp_path / "out"
    run("--target", "gxworks3", "--out", str(out), *map(str, _sources(tmp_path)))
    helps = " ".join(run("--help").output.split())
    for written in sorted(out.iterdir()):
        kind = re.sub(r"^(?!GlobalLabels|IMPORT_ORDER)[A-Za-z_]+\.(st|labels\.tsv|struct\.tsv)$",
                      lambda m: "<Type>." + m.group(1) if m.group(1) == "struct.tsv" else "<POU>." + m.group(1),
                      written.name)
        assert kind in helps, written.name


@pytest.mark.parametrize("text", ["", "(* only a comment *)\n", "\n\n"])
def test_a_file_without_a_pou_is_a_usage_error_naming_it(tmp_path, text):
    """QA finding 20: it used to print '0 POU(s) exported' and exit 0."""
    empty = tmp_path / "Empty.st"
    empty.write_text(text)
    out = tmp_path / "out"
    result = CliRunner().invoke(command, ["--target", "gxworks2", "--out", str(out), str(empty)])
    assert result.exit_code == 2, result.output
    assert f"{empty}:1:1: error: no POU" in result.output
    assert not out.exists() or not any(out.iterdir())


# ---- --program: only what a program needs ---------------------------------------------------


def _bundled_programs():
    """(sources, program, target) of every bundled scenario, each set once."""
    import tomllib

    seen = {}
    for path in sorted((ROOT / "plc" / "scenarios").glob("*.toml")):
        data = tomllib.loads(path.read_text(encoding="utf-8"))
        sources = tuple(sorted(str(p) for pattern in data["sources"] for p in path.parent.glob(pattern)))
        platform = data.get("platform", "fx3u")
        seen[(sources, data["program"])] = (platform, "gxworks3" if platform == "fx5u" else "gxworks2")
    return [(sources, program, *rest) for (sources, program), rest in seen.items()]


@pytest.mark.parametrize("sources, program, platform, target", _bundled_programs(),
                         ids=lambda v: v if isinstance(v, str) else "")
def test_export_of_a_program_writes_what_the_simulator_runs_of_it(tmp_path, sources, program, platform, target):
    """--program exports the POUs `uitamr verify` compiles for that program (both ask
    verifier.sim.reach.needed): the export writes what the compiled module holds, on every
    bundled program."""
    import verifier

    result = run("--target", target, "--out", str(tmp_path), "--program", program, *sources)
    assert result.exit_code == 0, result.output
    exported = {line.split("\t")[0].upper() for line in (tmp_path / "IMPORT_ORDER.txt").read_text().splitlines()}
    project = verifier.load(*sources, target=target, cpu=platform, programs=[program])
    compiled = set(re.findall(r"^(?:class|def) (?:FB|FN|PRG)_(\w+)", project.module.source, re.M))
    assert exported == compiled
    every = {p.name.upper() for s in sources for p in st.parse(Path(s).read_text(), s, target).pous}
    assert exported < every  # a real choice: the folders hold POUs this program does not use
    written = {p.name for p in tmp_path.iterdir()}
    assert written == {f"{name}{ext}" for name in (line.split("\t")[0] for line in
                       (tmp_path / "IMPORT_ORDER.txt").read_text().splitlines()) for ext in (".st", ".labels.tsv")} \
        | {"IMPORT_ORDER.txt"} | ({"GlobalLabels.labels.tsv"} if "GlobalLabels.labels.tsv" in written else set())


NEEDS = """
TYPE Pair :
STRUCT
    wValue : WORD;
END_STRUCT
END_TYPE

TYPE Outer :
STRUCT
    stPair : Pair;
END_STRUCT
END_TYPE

TYPE Unused :
STRUCT
    wA : WORD;
END_STRUCT
END_TYPE

FUNCTION Twice : INT
VAR_INPUT
    iX : INT;
END_VAR
Twice := iX * 2;
END_FUNCTION

FUNCTION Never : INT
VAR_INPUT
    iX : INT;
END_VAR
Never := iX;
END_FUNCTION

FUNCTION_BLOCK Inner
VAR_OUTPUT
    o_wOut : INT;
END_VAR
o_wOut := Twice(iX := 3);
END_FUNCTION_BLOCK

FUNCTION_BLOCK Spare
VAR
    wN : INT;
END_VAR
wN := Never(iX := 1);
END_FUNCTION_BLOCK

PROGRAM Main
VAR
    aInner : ARRAY[0..1] OF Inner;
    aOuter : ARRAY[0..1] OF Outer;
END_VAR
aInner[0]();
aOuter[1].stPair.wValue := 1;
END_PROGRAM

PROGRAM Other
VAR
    fbSpare : Spare;
END_VAR
fbSpare();
END_PROGRAM
"""


def test_export_of_a_program_follows_arrays_structures_and_functions(tmp_path):
    source = tmp_path / "lib.st"
    source.write_text(NEEDS)
    out = tmp_path / "out"
    result = run("--target", "gxworks3", "--out", str(out), "--program", "main", str(source))
    assert result.exit_code == 0, result.output
    order = [line.split("\t")[0] for line in (out / "IMPORT_ORDER.txt").read_text().splitlines()]
    assert order == ["Pair", "Outer", "Twice", "Inner", "Main"]  # a structure after the ones its members use
    assert sorted(p.name for p in out.iterdir()) == sorted(
        ["IMPORT_ORDER.txt", "Outer.struct.tsv", "Pair.struct.tsv", "Twice.st", "Twice.labels.tsv", "Inner.st",
         "Inner.labels.tsv", "Main.st", "Main.labels.tsv"])
    both = run("--target", "gxworks3", "--out", str(tmp_path / "both"), "--program", "Main", "--program", "Other",
               str(source))
    assert both.exit_code == 0, both.output
    assert both.output.startswith("6 POU(s) exported")  # Twice, Inner, Main; Never, Spare, Other


def test_export_of_an_unknown_program_names_the_programs_and_writes_nothing(tmp_path):
    source = tmp_path / "lib.st"
    source.write_text(NEEDS)
    out = tmp_path / "out"
    result = CliRunner().invoke(command, ["--target", "gxworks3", "--out", str(out), "--program", "Mian", str(source)])
    assert result.exit_code == 2
    assert "no POU Mian in the sources (their PROGRAMs: Main, Other)" in result.output
    assert not out.exists()


@pytest.mark.parametrize("args, program, hint", [
    (["--target", "gxworks2"], "UITAMR_ExampleFx5", "UITAMR_ExampleFx5 is bundled for fx5u: export it with --platform fx5u"),
    (["--platform", "q"], "UITAMR_ExampleFx3",
     "UITAMR_ExampleFx3 is bundled for fx3u, fx3g: export it with --platform fx3u (or fx3g)"),
    (["--target", "gxworks3"], "UITAMR_ExampleQ", "UITAMR_ExampleQ is bundled for q: export it with --platform q")])
def test_a_bundled_program_of_another_platform_is_named_with_the_platform_that_exports_it(tmp_path, args, program,
                                                                                          hint):
    """import-gxworks3.md's `--program UITAMR_ExampleFx5` with gxworks2.md's `--target
    gxworks2` (or the FX3 example under `--platform q`): the error listed the PROGRAMs of
    that export only, not that the example is bundled for another CPU and how to export it."""
    result = run(*args, "--out", str(tmp_path / "out"), "--program", program)
    assert result.exit_code == 2
    assert result.stderr.startswith(f"uitamr export: nothing written: --program: no POU {program} in the sources")
    assert result.stderr.rstrip().endswith(f"; {hint}"), result.stderr
    assert "is bundled" not in run(*args, "--out", str(tmp_path / "out"), "--program", "Nope").stderr
    assert not (tmp_path / "out").exists()


def test_export_of_a_program_still_checks_every_file(tmp_path):
    (tmp_path / "lib.st").write_text(NEEDS)
    (tmp_path / "broken.st").write_text("FUNCTION_BLOCK Broken\nVAR\n    x : INT;\nEND_VAR\nx := TRUE;\nEND_FUNCTION_BLOCK\n")
    result = run("--target", "gxworks3", "--out", str(tmp_path / "out"), "--program", "Main", str(tmp_path))
    assert result.exit_code == 1
    assert "broken.st:5:6: error" in result.output


@pytest.mark.parametrize("page, target, example", [("import-gxworks2.md", "gxworks2", "UITAMR_ExampleFx3"),
                                                   ("import-gxworks3.md", "gxworks3", "UITAMR_ExampleFx5")])
def test_the_import_pages_list_what_export_writes_for_the_example(tmp_path, page, target, example):
    text = " ".join((ROOT / "docs" / page).read_text(encoding="utf-8").split())
    listed = re.search(rf"example \(`{example}`\) these are (.*?) and the example", text).group(1)
    result = run("--target", target, "--out", str(tmp_path), "--program", example)
    assert result.exit_code == 0, result.output
    written = [line.split("\t")[0] for line in (tmp_path / "IMPORT_ORDER.txt").read_text().splitlines()]
    assert re.findall(r"`(\w+)`", listed) + [example] == written
    # "The ADPRW variant (`UITAMR_ExampleAdpFx3`) takes `A` and `B` in place of `C`, `D` and
    # `E`; ... `UITAMR_ExampleTcpQ` takes `F` and `G` in its place": the other examples
    variants = re.findall(r"`(UITAMR_\w+)`\)? takes ((?:`\w+`(?:, | and )?)+) in (?:place of ((?:`\w+`(?:, | and )?)+)"
                          r"|its place)", text)
    assert len(variants) == {"gxworks2": 3, "gxworks3": 2}[target], variants
    replaced: list[str] = []
    for variant, taken, dropped in variants:
        replaced = re.findall(r"`(\w+)`", dropped) or replaced
        out = tmp_path / variant
        assert run("--target", target, "--out", str(out), "--program", variant).exit_code == 0
        pous = {line.split("\t")[0] for line in (out / "IMPORT_ORDER.txt").read_text().splitlines()}
        assert pous == (set(written) - {example} - set(replaced)) | set(re.findall(r"`(\w+)`", taken)) | {variant}, variant


# ---- --platform: what is written, checked against the CPU as `uitamr check --platform` does ----


def export(*args):
    from verifier.cli import main

    return CliRunner().invoke(main, ["export", *map(str, args)])


def checked(platform: str, *paths) -> list[str]:
    """What `uitamr check --platform` says that export --platform says too: every error and
    the CPU's warnings (not the check's others, an unused label), as file:line:col lines."""
    import json

    from verifier.cli import main

    done = CliRunner().invoke(main, ["check", "--platform", platform, "--format", "json", *map(str, paths)])
    return [f"{d['file']}:{d['line']}:{d['col']}: {d['severity']}: {d['message']}"
            for d in json.loads(done.stdout)["diagnostics"]
            if d["severity"] == "error" or d["rule"] == "UITAMR-ST-CPU"]


def diagnostic_lines(output: str) -> list[str]:
    return [line for line in output.splitlines() if re.match(r"\S.*:\d+:\d+: (error|warning): ", line)]


def folder(path: Path) -> dict[str, bytes]:
    return {p.name: p.read_bytes() for p in sorted(path.iterdir())}


PORT = """FUNCTION_BLOCK Port
VAR_OUTPUT
    o_bBusy : BOOL;
END_VAR
o_bBusy := {busy};
END_FUNCTION_BLOCK
"""

MAIN = """PROGRAM Main
VAR
    fbPort : Port;
    wCount : INT;
END_VAR
fbPort();
wCount := wCount + 1;
Y0 := fbPort.o_bBusy;
END_PROGRAM
"""

SPARE = """PROGRAM Spare
VAR
    bFirst : BOOL;
END_VAR
bFirst := {first};
END_PROGRAM
"""


def _project(tmp_path: Path, busy: str = "M10", first: str = "M11") -> Path:
    src = tmp_path / "src"
    src.mkdir(exist_ok=True)
    (src / "Port.st").write_text(PORT.format(busy=busy), encoding="utf-8")
    (src / "Main.st").write_text(MAIN, encoding="utf-8")
    (src / "Spare.st").write_text(SPARE.format(first=first), encoding="utf-8")
    return src


def test_export_refuses_a_device_the_cpu_does_not_have_and_writes_nothing(tmp_path):
    src = _project(tmp_path, busy="SM8561")  # the FX5U's RS2 send request, written for an FX3U
    out = tmp_path / "out"
    done = export("--platform", "fx3u", "--out", out, src)
    assert done.exit_code == 1, done.output
    assert done.exception is None or isinstance(done.exception, SystemExit)
    assert diagnostic_lines(done.stderr) == [
        f"{src / 'Port.st'}:5:12: error: device SM8561: the fx3u has no SM devices; its special relays are "
        "M8000..M8511"]
    assert done.stderr.splitlines()[-1] == "uitamr export: nothing written, 1 error(s)"
    assert done.stdout == "" and not out.exists()
    assert checked("fx3u", src) == diagnostic_lines(done.stderr)  # as `uitamr check --platform` says it
    # an earlier export in --out is left as it was: no partial output
    (tmp_path / "ok").mkdir()
    assert export("--target", "gxworks2", "--out", out, _project(tmp_path / "ok")).exit_code == 0
    before = folder(out)
    assert export("--platform", "fx3u", "--out", out, src).exit_code == 1
    assert folder(out) == before
    # without --platform nothing is asked of the CPU: the export is written as before
    assert export("--target", "gxworks2", "--out", tmp_path / "plain", src).exit_code == 0


@pytest.mark.parametrize("platform, call, message", [
    ("q", "CRC(TRUE, w[0], 4, x);", "CRC does not exist on the q (it is a fx3/fx5 instruction)"),
    ("q", "RS2(D200, 8, D220, 8, 1);", "RS2 does not exist on the q (it is a fx3/fx5 instruction)"),
    ("fx3u", "G_OUTPUT(TRUE, 16#0, w, w, bb);", "G_OUTPUT does not exist on the fx3u (it is a q instruction)"),
])
def test_export_refuses_an_instruction_the_cpu_does_not_have(tmp_path, platform, call, message):
    # RS2 with a Q's C24 in mind (5 arguments): one error, not also the FX's operand errors
    path = tmp_path / "P.st"
    path.write_text(f"PROGRAM P\nVAR\n  x : INT; w : ARRAY[0..3] OF WORD; bb : ARRAY[0..1] OF BOOL;\nEND_VAR\n"
                    f"{call}\nEND_PROGRAM\n", encoding="utf-8")
    out = tmp_path / "out"
    done = export("--platform", platform, "--out", out, path)
    assert done.exit_code == 1, done.output
    assert diagnostic_lines(done.stderr) == [f"{path}:5:1: error: {message}"]
    assert checked(platform, path) == diagnostic_lines(done.stderr)
    assert not out.exists()


def test_export_prints_the_cpus_warnings_and_goes_on(tmp_path):
    # an FX3 habit on a Q: M8002 exists there as an ordinary relay the CPU never sets
    src = _project(tmp_path, busy="M8002")
    done = export("--platform", "q", "--out", tmp_path / "q", src)
    assert done.exit_code == 0, done.output
    assert diagnostic_lines(done.stderr) == [
        f"{src / 'Port.st'}:5:12: warning: M8002 is an ordinary internal relay on the q (the CPU never sets it); "
        "the FX3's special relay M8002 (ON in the first scan) is SM402 on the q"]
    assert checked("q", src) == diagnostic_lines(done.stderr)
    assert done.stdout.startswith("3 POU(s) exported for gxworks2 into ")
    plain = export("--target", "gxworks2", "--out", tmp_path / "plain", src)
    assert plain.exit_code == 0 and plain.stderr == ""
    assert folder(tmp_path / "q") == folder(tmp_path / "plain")


@pytest.mark.parametrize("platform, target", [("fx3u", "gxworks2"), ("fx3g", "gxworks2"), ("q", "gxworks2"),
                                              ("fx5u", "gxworks3")])
def test_a_clean_export_with_platform_is_the_export_without_it(tmp_path, platform, target):
    """The check adds nothing to what is written; the bundled library of the platform (no
    SOURCES) is the editor's bundled library without the other CPU families' folders."""
    family = {"fx3u": "fx3", "fx3g": "fx3", "q": "q", "fx5u": "fx5"}[platform]
    folders = ["core", family, "examples/common", f"examples/{family}"]
    with_platform = export("--platform", platform.upper(), "--out", tmp_path / "p")  # any case, as check
    assert with_platform.exit_code == 0, with_platform.output
    assert with_platform.stderr == ""
    without = export("--target", target, "--out", tmp_path / "t", *(ROOT / "plc" / f for f in folders))
    assert without.exit_code == 0, without.output
    assert folder(tmp_path / "p") == folder(tmp_path / "t")
    explicit = export("--platform", platform, "--target", target, "--out", tmp_path / "e", "--program", "Main",
                      _project(tmp_path))
    assert explicit.exit_code == 0, explicit.output
    assert export("--target", target, "--out", tmp_path / "e2", "--program", "Main",
                  _project(tmp_path)).exit_code == 0
    assert folder(tmp_path / "e") == folder(tmp_path / "e2")


def test_export_with_program_checks_only_the_pous_it_writes(tmp_path):
    # Spare is not written for --program Main: its FX5U device does not refuse an FX3U export
    src = _project(tmp_path, first="SM400", busy="M8002")
    out = tmp_path / "main"
    done = export("--platform", "fx3u", "--out", out, "--program", "Main", src)
    assert done.exit_code == 0, done.output
    assert (out / "IMPORT_ORDER.txt").read_text().split() == ["Port", "FUNCTION_BLOCK", "Main", "PROGRAM"]
    whole = export("--platform", "fx3u", "--out", tmp_path / "all", src)
    assert whole.exit_code == 1
    assert diagnostic_lines(whole.stderr) == [
        f"{src / 'Spare.st'}:5:11: error: device SM400: the fx3u has no SM devices; its special relays are "
        "M8000..M8511: use M8000 (always ON)"]
    spare = export("--platform", "fx3u", "--out", tmp_path / "spare", "--program", "Spare", src)
    assert spare.exit_code == 1 and diagnostic_lines(spare.stderr) == diagnostic_lines(whole.stderr)
    assert not (tmp_path / "all").exists() and not (tmp_path / "spare").exists()
    # the warnings too: M8002 in Port is the Q's concern only when Port is written
    on_q = export("--platform", "q", "--out", tmp_path / "q", "--program", "Spare", src)
    assert on_q.exit_code == 0 and on_q.stderr == "", on_q.output
    assert "M8002" in export("--platform", "q", "--out", tmp_path / "q2", "--program", "Main", src).stderr
    # every source is still checked by the ST check, as without --platform
    (src / "Broken.st").write_text("FUNCTION_BLOCK Broken\nVAR\n    x : INT;\nEND_VAR\nx := TRUE;\n"
                                   "END_FUNCTION_BLOCK\n", encoding="utf-8")
    broken = export("--platform", "fx3u", "--out", tmp_path / "b", "--program", "Main", src)
    assert broken.exit_code == 1 and "Broken.st:5:6: error" in broken.stderr


@pytest.mark.parametrize("platform, target", [("fx3u", "gxworks3"), ("q", "gxworks3"), ("fx5u", "gxworks2")])
def test_export_refuses_a_platform_its_target_does_not_program(tmp_path, platform, target):
    done = export("--platform", platform, "--target", target, "--out", tmp_path / "out", _project(tmp_path))
    assert done.exit_code == 2
    assert "Traceback" not in done.output
    (line,) = done.output.splitlines()
    assert line.startswith(f"uitamr export: --platform {platform} and --target {target} disagree: ")
    assert "drop --target" in line
    assert not (tmp_path / "out").exists()


def test_export_needs_a_target_or_a_platform(tmp_path):
    """The export of a folder with neither --target nor --platform: the error said only
    "Missing option '--target'. Choose from: gxworks2, gxworks3", not that a CPU will do."""
    done = export("--out", tmp_path / "out", ROOT / "plc" / "core")
    assert done.exit_code == 2 and "Traceback" not in done.output
    assert done.output.splitlines()[-1] == (
        "Error: Missing option '--target' or '--platform': name the editor (--target gxworks2 for FX3U/FX3G "
        "and Q, gxworks3 for FX5U) or the CPU, which implies it (--platform fx3g, fx3u, fx5u, q)")
    assert not (tmp_path / "out").exists()


def test_sources_of_the_other_editors_cpu_are_exported_with_a_warning_naming_the_right_target(tmp_path):
    """An FX5U program (RS2 with SM8561) exported with --target gxworks2: no GX Works2 CPU
    loads it, so the export says to use --target gxworks3; the right target says nothing."""
    plc = Path(__file__).resolve().parents[1] / "plc"
    sources = [str(plc / "core"), str(plc / "fx5" / "UITAMR_PortFx5.st"), str(plc / "examples" / "common"),
               str(plc / "examples" / "fx5" / "UITAMR_ExampleFx5.st")]
    wrong = CliRunner().invoke(command, ["--target", "gxworks2", "--out", str(tmp_path / "a"), *sources])
    assert wrong.exit_code == 0
    assert ("uitamr export: warning: the sources load on fx5u only, which GX Works3 programs, not GX Works2: "
            "export them with --target gxworks3") in wrong.output
    right = CliRunner().invoke(command, ["--target", "gxworks3", "--out", str(tmp_path / "b"), *sources])
    assert right.exit_code == 0 and "warning" not in right.output
    fx3 = [str(plc / "core"), str(plc / "fx3" / "UITAMR_PortFx3.st"), str(plc / "examples" / "common"),
           str(plc / "examples" / "fx3" / "UITAMR_ExampleFx3.st")]
    back = CliRunner().invoke(command, ["--target", "gxworks3", "--out", str(tmp_path / "c"), *fx3])
    assert "export them with --target gxworks2" in back.output



def test_fx5_sources_exported_for_gxworks2_do_what_import_gxworks3_says(tmp_path):
    """import-gxworks3.md said FX5U-only sources "(RS2 with SM8561, SP_SOCOPEN)" exported
    with --target gxworks2 are written with a warning; the TCP port's SP_SOCOPEN (and the
    FX5's ADPRW) are errors there and nothing is written. The page now tells the two apart;
    each port it names does what it says."""
    text = " ".join((ROOT / "docs" / "import-gxworks3.md").read_text(encoding="utf-8").split())
    said = re.search(r"are either written with a warning that says to use `--target gxworks3` \((.*?)\), or refused "
                     r"when they call an instruction GX Works2 does not have \((.*?)\): an error at each call that "
                     r"names `--target gxworks3`, and nothing is written \(exit 1\)", text)
    assert said, "import-gxworks3.md no longer says what --target gxworks2 does with FX5U sources"
    warned, refused = (re.findall(r"`(UITAMR_\w+)`", part) for part in said.groups())
    assert warned == ["UITAMR_PortFx5"] and refused == ["UITAMR_PortTcpFx5", "UITAMR_PortAdpFx5"]
    for port in warned + refused:
        out = tmp_path / port
        result = CliRunner().invoke(command, ["--target", "gxworks2", "--out", str(out), str(ROOT / "plc" / "core"),
                                              str(ROOT / "plc" / "fx5" / f"{port}.st")])
        if port in warned:
            assert result.exit_code == 0 and (out / f"{port}.st").exists(), result.output
            assert "warning: the sources load on fx5u only" in result.output and "--target gxworks3" in result.output
        else:
            assert result.exit_code == 1 and not out.exists(), result.output
            assert "error:" in result.output and "(or --target gxworks3)" in result.output, result.output
            assert "uitamr export: nothing written" in result.output


@pytest.mark.parametrize("page, target", [("import-gxworks2.md", "gxworks2"), ("import-gxworks3.md", "gxworks3")])
def test_the_import_steps_say_what_to_do_with_every_file_the_export_writes(tmp_path, page, target):
    """The import pages' §3 (the steps in GX Works) said what to do with each POU's files and
    each structure's table, but nothing of GlobalLabels.labels.tsv, which the export writes
    for a program with VAR_GLOBAL (and §1 announces) and which is no line of
    IMPORT_ORDER.txt: an integrator with global labels had no step for them. Each kind of
    file written for such a program is now named in §3."""
    source = tmp_path / "Main.st"
    source.write_text("TYPE Rec :\nSTRUCT\n    wA : INT;\nEND_STRUCT;\nEND_TYPE\nVAR_GLOBAL\n    gRec : Rec;\nEND_VAR\n"
                      "PROGRAM Main\nVAR\n    wB : INT;\nEND_VAR\nwB := gRec.wA;\nEND_PROGRAM\n", encoding="utf-8")
    out = tmp_path / "out"
    result = run("--target", target, "--out", str(out), str(source))
    assert result.exit_code == 0, result.output
    kinds = {re.sub(r"^(Main|Rec)(?=\.)", "NAME", p.name) for p in out.iterdir()}
    assert kinds == {"IMPORT_ORDER.txt", "GlobalLabels.labels.tsv", "NAME.struct.tsv", "NAME.labels.tsv", "NAME.st"}
    text = (ROOT / "docs" / page).read_text(encoding="utf-8")
    steps = text.split("## 3. ", 1)[1].split("\n## ", 1)[0]
    for kind in kinds:
        named = kind.replace("NAME", "")
        assert re.search(rf"`[^`]*{re.escape(named)}`", steps), (page, kind)


def test_checking_an_export_folder_says_to_check_its_sources(tmp_path):
    """`uitamr check --platform fx3u gx2/` on what export wrote printed, per body, 'a statement
    ('o_bENO') outside a POU' (28 errors, exit 1): the bodies have no declarations. Now each
    is named an export's body (exit 2), as check names the toolkit's other files."""
    from verifier.cli import main

    out = tmp_path / "gx 2 ü"  # a folder name with a space and a non-ASCII letter
    assert run("--platform", "fx3u", "--out", str(out)).exit_code == 0
    result = CliRunner().invoke(main, ["check", "--platform", "fx3u", str(out)])
    assert result.exit_code == 2, result.output
    assert "outside a POU" not in result.output
    assert (f"uitamr check: {out / 'UITAMR_CRC16.st'}: a body written by `uitamr export` (its declarations are in "
            "UITAMR_CRC16.labels.tsv), not ST source: check the .st files it was exported from, with the same "
            "--platform") in result.output.splitlines()
    # the same file alone, without IMPORT_ORDER.txt beside it, is read as ST again
    (out / "IMPORT_ORDER.txt").unlink()
    assert "outside a POU" in CliRunner().invoke(main, ["check", str(out / "UITAMR_CRC16.st")]).output


def test_an_export_into_the_folder_of_an_earlier_one_leaves_none_of_its_files(tmp_path):
    """Exporting again into the same --out (fewer POUs, the other editor) left the earlier
    files beside the new ones, unlisted: a GlobalLabels.labels.tsv the import guides say to
    paste when it is there, GX Works2 tables among GX Works3 ones. Now they are removed and
    named; a file no export wrote stays."""
    src = tmp_path / "src"
    src.mkdir()
    (src / "Cell.st").write_text("VAR_GLOBAL\n    gwMode : INT;\nEND_VAR\nPROGRAM Cell\ngwMode := 1;\nEND_PROGRAM\n"
                                 "FUNCTION_BLOCK FB_Old\nVAR\n    wX : INT;\nEND_VAR\nwX := 1;\nEND_FUNCTION_BLOCK\n")
    (src / "Main.st").write_text("PROGRAM Main\nVAR\n    wX : INT;\nEND_VAR\nwX := wX + 1;\nEND_PROGRAM\n")
    out = tmp_path / "gx"
    assert run("--target", "gxworks2", "--out", str(out), str(src)).exit_code == 0
    assert (out / "GlobalLabels.labels.tsv").is_file() and (out / "FB_Old.st").is_file()
    (out / "my notes.txt").write_text("mine\n")
    result = CliRunner().invoke(command, ["--target", "gxworks3", "--out", str(out), str(src / "Main.st")])
    assert result.exit_code == 0, result.output
    assert sorted(p.name for p in out.iterdir()) == ["IMPORT_ORDER.txt", "Main.labels.tsv", "Main.st", "my notes.txt"]
    assert (f"uitamr export: note: removed 5 file(s) of an earlier export into {out} that this one does not hold: "
            "FB_Old.st, FB_Old.labels.tsv, Cell.st, Cell.labels.tsv and 1 more") in result.output.splitlines()
    # again: nothing of an earlier export left to remove, nothing said
    again = CliRunner().invoke(command, ["--target", "gxworks3", "--out", str(out), str(src / "Main.st")])
    assert again.exit_code == 0 and "removed" not in again.output


@pytest.mark.parametrize("blank", ["", " "])
def test_a_blank_out_folder_is_refused(tmp_path, monkeypatch, blank):
    """`--out "$OUT"` with OUT unset wrote the whole library into the current folder."""
    monkeypatch.chdir(tmp_path)
    result = CliRunner().invoke(command, ["--platform", "q", "--out", blank])
    assert result.exit_code == 2
    assert result.output.splitlines()[-1] == ("Error: Invalid value for '--out': the folder is empty: give the folder "
                                              "to write into, e.g. --out gx2")
    assert list(tmp_path.iterdir()) == []


# ------------------------------------------------------- GX Works3 local label classes
# MELSEC iQ-F FX5 Programming Manual (Program Design) §4.2 "Class" (p. 33,
# https://www.easymanua.ls/mitsubishi-electric/melsec-iq-f-series/manual/744685?p=35): the
# local label classes a GX Works3 POU can hold. There is no VAR_EXTERNAL: a POU uses a
# global label by its name.
GX3_LOCAL_CLASSES = {"VAR", "VAR_CONSTANT", "VAR_RETAIN", "VAR_INPUT", "VAR_OUTPUT", "VAR_OUTPUT_RETAIN",
                     "VAR_IN_OUT", "VAR_PUBLIC", "VAR_PUBLIC_RETAIN"}


def _program_with_a_global(folder: Path) -> None:
    """Globals.st (gbStart AT X10) and Main.st, which declares it VAR_EXTERNAL and reads it."""
    (folder / "Globals.st").write_text("VAR_GLOBAL\n    gbStart AT X10 : BOOL; (* start *)\nEND_VAR\n")
    (folder / "Main.st").write_text(
        "PROGRAM Main\nVAR_EXTERNAL\n    gbStart : BOOL;\nEND_VAR\nVAR\n    bRun : BOOL;\nEND_VAR\n"
        "bRun := gbStart;\nEND_PROGRAM\n")


def test_gxworks3_label_tables_hold_only_the_classes_gx_works3_has(tmp_path):
    """An integrator's program that declares the global labels it uses in VAR_EXTERNAL (as
    `uitamr check` accepts and IEC 61131-3 writes it) was exported with VAR_EXTERNAL rows in
    its label table: GX Works3 has no such local label class, so the paste was refused. The
    globals are in GlobalLabels.labels.tsv, and the POU uses them by name."""
    _program_with_a_global(tmp_path)
    out = tmp_path / "gx3"
    result = run("--target", "gxworks3", "--out", str(out), str(tmp_path / "Globals.st"), str(tmp_path / "Main.st"))
    assert result.exit_code == 0, result.output
    rows = [line.split("\t") for line in (out / "Main.labels.tsv").read_text().splitlines()[1:]]
    assert [(r[0], r[2]) for r in rows] == [("bRun", "VAR")]
    assert "gbStart\tBit\tVAR_GLOBAL\tX10" in (out / "GlobalLabels.labels.tsv").read_text()
    assert "gbStart := " not in (out / "Main.st").read_text() and "bRun := gbStart;" in (out / "Main.st").read_text()


# MELSEC-Q/L/F Structured Programming Manual (Fundamentals), Table 4.3.3-1 "Label classes"
# (the GX Works2 classes; VAR_GLOBAL / VAR_GLOBAL_CONSTANT are the global label editor's): no
# VAR_EXTERNAL either.
GX2_LOCAL_CLASSES = {"VAR", "VAR_CONSTANT", "VAR_RETAIN", "VAR_INPUT", "VAR_OUTPUT", "VAR_IN_OUT"}


def test_gxworks2_label_tables_hold_only_the_classes_gx_works2_has(tmp_path):
    """The GX Works3 fix above left GX Works2's tables with their VAR_EXTERNAL rows, a class
    the GX Works2 manual does not list either: the same program exported for GX Works2
    has them no more; the global is in GlobalLabels.labels.tsv."""
    _program_with_a_global(tmp_path)
    out = tmp_path / "gx2"
    result = run("--target", "gxworks2", "--out", str(out), str(tmp_path / "Globals.st"), str(tmp_path / "Main.st"))
    assert result.exit_code == 0, result.output
    rows = [line.split("\t") for line in (out / "Main.labels.tsv").read_text().splitlines()[1:]]
    assert [(r[0], r[1]) for r in rows] == [("VAR", "bRun")], rows
    assert "gbStart" in (out / "GlobalLabels.labels.tsv").read_text()
    assert run("--target", "gxworks2", "--out", str(tmp_path / "lib")).exit_code == 0
    for table in (tmp_path / "lib").glob("*.labels.tsv"):
        classes = {line.split("\t")[0] for line in table.read_text().splitlines()[1:]}
        assert classes <= GX2_LOCAL_CLASSES, (table.name, classes - GX2_LOCAL_CLASSES)


def test_the_bundled_gxworks3_export_uses_only_gx_works3_label_classes(tmp_path):
    assert run("--target", "gxworks3", "--out", str(tmp_path)).exit_code == 0
    for table in tmp_path.glob("*.labels.tsv"):
        classes = {line.split("\t")[2] for line in table.read_text().splitlines()[1:]}
        assert classes <= GX3_LOCAL_CLASSES, (table.name, classes - GX3_LOCAL_CLASSES)
