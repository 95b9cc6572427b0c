"""Whatever the checker lets through, the simulator never dies of RecursionError or
MemoryError: instances that contain themselves and absurd label sizes are load errors at
the label (QA 2 and 3).  The checker is switched off here so that the simulator's own
guard is what is tested."""
from __future__ import annotations

import pytest

import verifier.sim.project
from sim_helpers import load_st
from verifier.sim import LoadError, SimulationError
from verifier.sim.storage import INSTANCE_LIMIT, LABEL_LIMIT


@pytest.fixture(autouse=True)
def no_checker(monkeypatch):
    monkeypatch.setattr(verifier.sim.project, "_run_checker", lambda files, target, platform=None: [])


def refused(src: str) -> str:
    with pytest.raises(LoadError) as err:
        load_st(src)
    return str(err.value)


MAIN = "PROGRAM M\nVAR f : {t}; END_VAR\nf();\nEND_PROGRAM\n"


def test_fb_holding_an_instance_of_itself():
    src = "FUNCTION_BLOCK FB_Nest\nVAR\n    inner : FB_Nest;\nEND_VAR\ninner();\nEND_FUNCTION_BLOCK\n"
    message = refused(src + MAIN.format(t="FB_Nest"))
    assert "t.st:3:5: error: function block FB_Nest contains itself (FB_Nest.inner -> FB_Nest)" in message


def test_two_fbs_holding_each_other_through_an_array():
    src = ("FUNCTION_BLOCK FB_Ping\nVAR\n    aPongs : ARRAY[0..1] OF FB_Pong;\nEND_VAR\nEND_FUNCTION_BLOCK\n"
           "FUNCTION_BLOCK FB_Pong\nVAR\n    ping : FB_Ping;\nEND_VAR\nEND_FUNCTION_BLOCK\n")
    message = refused(src + MAIN.format(t="FB_Ping"))
    assert "t.st:3:5: error: function block FB_Ping contains itself (FB_Ping.aPongs -> FB_Pong.ping -> FB_Ping)" \
        in message


def test_structure_containing_itself():
    src = ("TYPE stLoop :\nSTRUCT\n    wValue : WORD;\n    aNext : ARRAY[0..1] OF stLoop;\nEND_STRUCT;\nEND_TYPE\n"
           "PROGRAM M\nVAR s : stLoop; END_VAR\ns.wValue := 1;\nEND_PROGRAM\n")
    assert "t.st:4:5: error: structure stLoop contains itself (stLoop.aNext -> stLoop)" in refused(src)


def test_absurd_array_is_refused_at_its_label():
    message = refused("PROGRAM M\nVAR\n    a : ARRAY[0..2000000000] OF INT;\nEND_VAR\na[0] := 1;\nEND_PROGRAM\n")
    assert f"t.st:3:5: error: label 'a' of PROGRAM M needs 2,000,000,001 values; " \
           f"the simulator holds at most {LABEL_LIMIT:,} per label" in message


def test_sizes_add_up_through_instances_globals_and_function_locals():
    block = "FUNCTION_BLOCK B\nVAR a : ARRAY[0..999999] OF INT; END_VAR\na[0] := 1;\nEND_FUNCTION_BLOCK\n"
    message = refused(block + "PROGRAM M\nVAR b1, b2, b3, b4, b5 : B; END_VAR\nb1();\nEND_PROGRAM\n")
    assert f"PROGRAM M needs more than {INSTANCE_LIMIT:,} values of labels (at 'b5')" in message
    message = refused("VAR_GLOBAL\n    g : ARRAY[0..2000000] OF BOOL;\nEND_VAR\n"
                      "PROGRAM M\nVAR_EXTERNAL g : ARRAY[0..2000000] OF BOOL; END_VAR\ng[0] := TRUE;\nEND_PROGRAM\n")
    assert "t.st:2:5: error: label 'g' of the global labels needs 2,000,001 values" in message
    message = refused("FUNCTION F : INT\nVAR_INPUT n : INT; END_VAR\nVAR\n    a : ARRAY[0..2000000] OF INT;\n"
                      "END_VAR\nF := n;\nEND_FUNCTION\n")
    assert "t.st:4:5: error: label 'a' of FUNCTION F needs 2,000,001 values" in message


def test_in_out_and_external_labels_are_references_not_copies():
    src = ("VAR_GLOBAL\n    g : ARRAY[0..999999] OF INT;\nEND_VAR\n"
           "FUNCTION_BLOCK B\nVAR_IN_OUT io : ARRAY[0..999999] OF INT; END_VAR\n"
           "VAR_EXTERNAL g : ARRAY[0..999999] OF INT; END_VAR\nio[0] := g[0];\nEND_FUNCTION_BLOCK\n"
           "PROGRAM M\nVAR_EXTERNAL g : ARRAY[0..999999] OF INT; END_VAR\nVAR fbA, fbB, fbC, fbD, fbE : B; END_VAR\n"
           "fbA(io := g);\nEND_PROGRAM\n")
    load_st(src).run_programs(["M"], scans=1)


def test_endless_function_recursion_stops_with_a_located_error():
    src = ("FUNCTION Fact : INT\nVAR_INPUT n : INT; END_VAR\n"
           "IF n <= 1 THEN Fact := 1; ELSE Fact := Fact(n - 1); END_IF;\nEND_FUNCTION\n"
           "PROGRAM M\nVAR x : INT; END_VAR\nx := Fact(30000);\nEND_PROGRAM\n")
    project = load_st(src)
    with pytest.raises(SimulationError) as err:
        project.run_programs(["M"], scans=1)
    assert "t.st:3:" in str(err.value) and "recursion" in str(err.value)


def test_long_flat_expressions_run_and_deep_ones_are_refused_at_the_statement():
    terms = 3000
    src = (f"PROGRAM M\nVAR i : INT := 300; x : INT; b : BOOL; END_VAR\nx := {'+'.join(['i'] * terms)};\n"
           f"b := {' AND '.join(['(i > 0)'] * terms)};\nEND_PROGRAM\n")
    project = load_st(src)
    project.run_programs(["M"], scans=1)
    assert project.program("M").x == (300 * terms + 32768) % 65536 - 32768   # wraps as INT
    assert project.program("M").b is True
    deep = "PROGRAM M\nVAR i, x : INT; END_VAR\nx := 1;\nx := " + "i + (" * 400 + "i" + ")" * 400 + ";\nEND_PROGRAM\n"
    assert "t.st:4:1: error: expression nested too deeply to simulate" in refused(deep)
