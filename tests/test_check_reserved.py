"""Labels named like a MELSEC instruction of the CPU checked are refused, as GX Works
refuses them (docs/st-dialect.md section 4), also for the instructions the simulator does
not model (DBIN, SORT, STOP ...); the names are data, one module a CPU family
(verifier/st/melsec)."""
from __future__ import annotations

from pathlib import Path

import pytest
from click.testing import CliRunner

from verifier import load
from verifier.cli import main
from verifier.sim.errors import LoadError
from verifier.st import melsec

CPU_TEXT = {"fx3": "FX3U/FX3G CPU (GX Works2", "fx5": "FX5U CPU (GX Works3", "q": "Q CPU (GX Works2"}
PLATFORM_FAMILY = {"fx3u": "fx3", "fx3g": "fx3", "fx5u": "fx5", "q": "q"}
#: per platform: instruction names of its family the simulator does not model (the check
#: let them through before), each in another spelling case
REFUSED = {
    "fx3u": ["DBIN", "Sort", "meanp", "DHSCS", "DECMPP", "RD3A"],
    "fx3g": ["DBIN", "ivck", "SCL2P"],
    "q": ["DBIN", "DSORT", "Stop", "page", "QDRSET", "DSUMP"],
    "fx5u": ["DBIN", "SortTbl", "EDMOV", "RETSTL", "DINT2FLTP", "INT2FLT", "AltD"],
}
#: names of no instruction of any family, nor otherwise reserved
ACCEPTED = ["wDbinValue", "SortIndex", "iMean", "bStopReq", "nPage", "Sorted", "DBINX"]


def run(*args):
    return CliRunner().invoke(main, ["check", *map(str, args)])


def labels(tmp_path: Path, names: list[str]) -> Path:
    """A program declaring `names` (INT labels, one a line from line 3, column 3), each used."""
    decls = "".join(f"  {n} : INT;\n" for n in names)
    body = "".join(f"{n} := 1;\n" for n in names)
    path = tmp_path / "p.st"
    path.write_text(f"PROGRAM P\nVAR\n{decls}END_VAR\n{body}END_PROGRAM\n", encoding="utf-8")
    return path


def error_places(output: str) -> list[str]:
    """The `file:line:col` of each error line in a check's output."""
    return [line.split(": error: ")[0] for line in output.splitlines() if ": error: " in line]


@pytest.mark.parametrize("platform", sorted(REFUSED))
def test_an_instruction_name_of_the_platform_is_refused_at_its_place(tmp_path, platform):
    names = REFUSED[platform]
    path = labels(tmp_path, names)
    done = run("--platform", platform, path)
    assert done.exit_code == 1, done.output
    found = [line for line in done.output.splitlines() if ": error: " in line]
    family = PLATFORM_FAMILY[platform]
    assert found == [
        f"{path}:{3 + i}:3: error: label name '{n}' is the name of a MELSEC instruction of the "
        f"{CPU_TEXT[family]} refuses every instruction name of the CPU as a label, "
        "docs/st-dialect.md section 4); rename it" for i, n in enumerate(names)]
    assert done.output.splitlines()[-1].endswith(f": {len(names)} error(s), 0 warning(s)")


@pytest.mark.parametrize("platform", sorted(REFUSED))
def test_names_that_are_no_instruction_pass(tmp_path, platform):
    done = run("--platform", platform, labels(tmp_path, ACCEPTED))
    assert done.exit_code == 0, done.output
    assert done.output.splitlines()[-1].endswith(": 0 error(s), 0 warning(s)")


def test_an_instruction_of_another_cpu_family_is_a_name_on_this_one(tmp_path):
    # STOP is a Q instruction, RD3A an FX3 one, RETSTL an FX5 one: GX Works2 refuses each
    # only in a project of its CPU series
    path = labels(tmp_path, ["STOP", "RD3A", "RETSTL"])
    assert error_places(run("--platform", "fx3u", path).output) == [f"{path}:4:3"]
    assert error_places(run("--platform", "q", path).output) == [f"{path}:3:3"]
    assert error_places(run("--platform", "fx5u", path).output) == [f"{path}:5:3"]


def test_without_platform_the_names_every_cpu_of_the_editor_has_are_refused(tmp_path):
    # without --platform nothing is asked of the CPU: GX Works2 refuses DBIN in an FX3 and
    # in a Q project alike, STOP only in a Q one, RD3A only in an FX3 one
    path = labels(tmp_path, ["STOP", "RD3A", "RETSTL", "DBIN", "iX"])
    gx2 = run("--target", "gxworks2", path).output
    assert [line for line in gx2.splitlines() if ": error: " in line] == [
        f"{path}:6:3: error: label name 'DBIN' is the name of a MELSEC instruction of the FX3U/FX3G CPU "
        "(GX Works2 refuses every instruction name of the CPU as a label, docs/st-dialect.md section 4); rename it"]
    gx3 = run("--target", "gxworks3", path).output
    assert error_places(gx3) == [f"{path}:5:3", f"{path}:6:3"]
    assert "label name 'RETSTL' is the name of a MELSEC instruction of the FX5U CPU" in gx3
    # IX (index modification of a whole ladder) is a Q instruction only
    assert f"{path}:7:3: error: label name 'iX'" in run("--platform", "q", path).output


@pytest.mark.parametrize("what, decl", [
    ("member", "TYPE ST_A : STRUCT\n  DSORT : INT;\nEND_STRUCT;\nEND_TYPE\n"),
    ("POU", "FUNCTION_BLOCK DSORT\nVAR_INPUT\n  i : INT;\nEND_VAR\nEND_FUNCTION_BLOCK\n"),
])
def test_structure_members_and_pous_are_named_by_the_same_rule(tmp_path, what, decl):
    path = tmp_path / "t.st"
    path.write_text(decl, encoding="utf-8")
    out = run("--platform", "q", path).output
    assert f"error: {what} name 'DSORT' is the name of a MELSEC instruction of the Q CPU" in out, out


def test_verifier_load_refuses_the_instruction_names_of_its_cpu():
    text = "PROGRAM P\nVAR\n  Stop : BOOL;\nEND_VAR\nStop := TRUE;\nEND_PROGRAM\n"
    load(sources={"m.st": text}, cpu="fx3u")  # STOP is no FX3 instruction
    with pytest.raises(LoadError) as e:
        load(sources={"m.st": text}, cpu="q")
    assert "m.st:3:3: error: label name 'Stop' is the name of a MELSEC instruction of the Q CPU" in str(e.value)


def test_export_with_a_platform_refuses_them_too(tmp_path):
    path = labels(tmp_path, ["DSORT"])
    done = CliRunner().invoke(main, ["export", "--platform", "q", "--out", str(tmp_path / "out"), str(path)])
    assert done.exit_code != 0
    assert f"{path}:3:3: error: label name 'DSORT' is the name of a MELSEC instruction of the Q CPU" in done.output


def test_pulse_and_32_bit_forms_are_expanded_from_the_manual_columns():
    assert melsec.expand("MOV dp\nSFTR p\nHSCS d\nSRET\n# a comment\n", "t") == {
        "MOV", "MOVP", "DMOV", "DMOVP", "SFTR", "SFTRP", "HSCS", "DHSCS", "SRET"}
    for bad in ("MOV x", "MOV pp", "mov", "LD=", "MOV d p"):
        with pytest.raises(ValueError, match="line 1"):
            melsec.expand(bad, "t")


def test_every_name_is_an_identifier_and_every_family_is_a_cpu_profiles():
    from verifier.sim.cpu import PROFILES, TARGET_CPUS

    assert dict(melsec.PLATFORM_FAMILY) == {name: p.family for name, p in PROFILES.items()}
    # each editor's families are those of the CPUs it programs (verifier.sim.cpu.TARGET_CPUS)
    assert {t: set(fs) for t, fs in melsec.TARGET_FAMILIES.items()} == {
        t: {PROFILES[c].family for c in cpus} for t, cpus in TARGET_CPUS.items()}
    assert set(melsec.NAMES) == set(melsec.FAMILIES) == {p.family for p in PROFILES.values()}
    for family, names in melsec.NAMES.items():
        assert len(names) > 400, family  # each manual lists several hundred
        assert all(n.isidentifier() and n == n.upper() for n in names), family
    with pytest.raises(ValueError, match="unknown platform 'fx2n'"):
        melsec.families_for("gxworks2", "fx2n")


def test_the_simulators_instructions_are_in_their_familys_list():
    # each instruction the simulator runs on a family is one GX Works refuses there (the
    # ST spellings of the ladder's dotted ones, SP_SOCOPEN, are verifier.st.library's)
    from verifier.sim.instructions import SPECS

    for name, spec in SPECS.items():
        for family in spec.families:
            if family in melsec.NAMES and "_" not in name:
                assert name in melsec.NAMES[family], (name, family)


def test_the_counts_in_the_dialect_doc_are_the_datas():
    import re

    from st_helpers import ROOT

    text = (ROOT / "docs" / "st-dialect.md").read_text(encoding="utf-8")
    rows = dict(re.findall(r"^\| (FX3|FX5|Q) \(`.*\| (\d+) \|$", text, re.M))
    assert {family.lower(): int(n) for family, n in rows.items()} == {f: len(n) for f, n in melsec.NAMES.items()}
