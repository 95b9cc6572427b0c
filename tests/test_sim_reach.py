"""`load(..., programs=[...])` compiles only the POUs those programs need
(verifier/sim/reach.py), which is what `uitamr verify` asks for; everything is still
parsed and checked, and a run gives exactly what it gives with every POU compiled."""
from __future__ import annotations

from dataclasses import asdict
from pathlib import Path

import pytest

import verifier
from verifier.sim import project as project_module
from verifier.sim.errors import LoadError
from verifier.verify.result import KEEP_ALL
from verifier.verify.runner import run_scenario
from verifier.verify.scenario import load_scenario

ROOT = Path(__file__).resolve().parent.parent

LIBRARY = """
TYPE ST_Slot :
STRUCT
    nValue : INT;
END_STRUCT
END_TYPE

VAR_GLOBAL
    g_fbShared : FB_Global;
END_VAR

FUNCTION FN_Twice : INT
VAR_INPUT
    i_nValue : INT;
END_VAR
FN_Twice := i_nValue * 2;
END_FUNCTION

FUNCTION FN_Step : INT
VAR_INPUT
    i_nValue : INT;
END_VAR
FN_Step := FN_Twice(i_nValue) + 1;
END_FUNCTION

FUNCTION FN_Unused : INT
VAR_INPUT
    i_nValue : INT;
END_VAR
FN_Unused := i_nValue;
END_FUNCTION

FUNCTION_BLOCK FB_Inner
VAR_OUTPUT
    o_nOut : INT;
END_VAR
o_nOut := FN_Step(o_nOut);
END_FUNCTION_BLOCK

FUNCTION_BLOCK FB_Outer
VAR
    fbInner : ARRAY[0..1] OF FB_Inner;
    stSlot : ST_Slot;
END_VAR
VAR_OUTPUT
    o_nSum : INT;
END_VAR
fbInner[0]();
fbInner[1]();
o_nSum := fbInner[0].o_nOut + fbInner[1].o_nOut;
END_FUNCTION_BLOCK

FUNCTION_BLOCK FB_Global
VAR_OUTPUT
    o_nTicks : INT;
END_VAR
o_nTicks := o_nTicks + 1;
END_FUNCTION_BLOCK

FUNCTION_BLOCK FB_Unused
VAR_OUTPUT
    o_nOut : INT;
END_VAR
o_nOut := FN_Unused(3);
END_FUNCTION_BLOCK

PROGRAM Main
VAR
    fbOuter : FB_Outer;
    nSum : INT;
END_VAR
VAR_EXTERNAL
    g_fbShared : FB_Global;
END_VAR
fbOuter();
g_fbShared();
nSum := fbOuter.o_nSum + g_fbShared.o_nTicks;
END_PROGRAM

PROGRAM Other
VAR
    fbUnused : FB_Unused;
END_VAR
fbUnused();
END_PROGRAM
"""


def _load(**options):
    return verifier.load(sources={"lib.st": LIBRARY}, cpu="fx3u", **options)


def test_only_what_the_program_needs_is_compiled():
    project = _load(programs=["main"])  # names are case-blind, as in GX Works
    assert sorted(project.pou_names()) == ["FB_Global", "FB_Inner", "FB_Outer", "FN_Step", "FN_Twice", "Main"]
    assert "FB_UNUSED" not in project.module.source and "FN_UNUSED" not in project.module.source
    assert sorted(_load().pou_names()) == sorted(project.pou_names() + ["FB_Unused", "FN_Unused", "Other"])


def test_the_program_runs_as_with_everything_compiled():
    only, whole = _load(programs=["Main"]), _load()
    for project in (only, whole):
        project.run_programs(["Main"], scans=7)
    assert only.program("Main").nSum == whole.program("Main").nSum == 2 * 127 + 7


def test_a_pou_left_out_is_named_as_left_out():
    with pytest.raises(KeyError, match="'FB_Unused' is not compiled: the project was loaded with programs="):
        _load(programs=["Main"]).instance("FB_Unused")


@pytest.mark.parametrize("programs", [["Main", "Nowhere"], ["FB_Outer"], []])
def test_names_that_are_not_all_programs_compile_everything(programs):
    """So that the caller's own "no such PROGRAM" (the runner's) can list every program."""
    assert "Other" in _load(programs=programs).pou_names()


def test_a_single_name_must_come_in_a_list():
    with pytest.raises(TypeError, match=r"programs is a list of PROGRAM names, e.g. \['Main'\]"):
        _load(programs="Main")


def test_what_only_an_unused_pou_cannot_simulate_does_not_stop_the_program():
    """The check still runs on every file; only code generation is left out."""
    source = LIBRARY.replace("o_nOut := FN_Unused(3);", "o_nOut := FN_Unused(3);\nIF K4M0Z0 > 0 THEN o_nOut := 0; END_IF;")
    with pytest.raises(LoadError, match="index modification of a bit/digit access is not simulated"):
        verifier.load(sources={"lib.st": source}, cpu="fx3u")
    assert "Main" in verifier.load(sources={"lib.st": source}, cpu="fx3u", programs=["Main"]).pou_names()


def test_a_check_error_in_an_unused_pou_is_still_reported():
    source = LIBRARY.replace("o_nOut := FN_Unused(3);", "o_nOut := nUndeclared;")
    with pytest.raises(LoadError, match="nUndeclared"):
        verifier.load(sources={"lib.st": source}, cpu="fx3u", programs=["Main"])


@pytest.mark.parametrize("name", ["fx3u-panel-all-commands", "fx3u-adprw-no-reply", "fx5u-tcp-split", "q-bad-crc"])
def test_bundled_scenarios_give_the_same_results(name, monkeypatch):
    scenario = load_scenario(ROOT / "plc" / "scenarios" / f"{name}.toml")
    asked = []
    compile_files = project_module.compile_files
    monkeypatch.setattr(project_module, "compile_files",
                        lambda *args, programs: asked.append(programs) or compile_files(*args, programs=programs))
    only = run_scenario(scenario, keep=KEEP_ALL)
    monkeypatch.setattr(project_module, "_only_programs", lambda files, programs: None)
    whole = run_scenario(scenario, keep=KEEP_ALL)
    assert asked == [frozenset({scenario.program.upper()}), None]
    first, second = asdict(only), asdict(whole)
    for data in (first, second):
        data.pop("wall_s")
    assert first == second
    assert only.tx_count > 0


def test_a_path_through_a_pou_left_out_is_named_as_left_out():
    """`get` names the program as not compiled, as `program` does, not as a POU that does not exist."""
    project = _load(programs=["Main"])
    with pytest.raises(KeyError, match="'Other' is not compiled: the project was loaded with programs="):
        project.get("Other.fbUnused.o_nOut")
    assert project.get("Main.nSum") == 0 and _load().get("Other.fbUnused.o_nOut") == 0
