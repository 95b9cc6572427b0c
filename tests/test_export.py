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


def test_sources_with_errors_are_reported_with_their_place(tmp_path):
    bad = tmp_path / "FB_Bad.st"
    bad.write_text("FUNCTION_BLOCK FB_Bad\nVAR\n    wX : INT;\nEND_VAR\nwX := ;\n")
    result = CliRunner().invoke(command, ["--target", "gxworks2", "--out", str(tmp_path / "o"), str(bad)])
    assert result.exit_code == 1
    assert f"{bad}:5:" in result.output and "nothing written" in result.output
    assert not (tmp_path / "o").exists()


def test_missing_source_is_a_usage_error(tmp_path):
    result = CliRunner().invoke(command, ["--target", "gxworks3", "--out", str(tmp_path), "nope.st"])
    assert result.exit_code == 2 and "nope.st" in result.output


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
