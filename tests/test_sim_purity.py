"""FUNCTIONs whose result depends on their inputs alone are remembered per argument
values (verifier/sim/purity.py); every other FUNCTION runs on every call, so side effects
(operation errors) and what it reads (devices, globals) stay exactly as the CPU has them."""
from __future__ import annotations

from sim_helpers import load_st
from verifier.sim.purity import pure_functions

SOURCES = """
VAR_GLOBAL gOffset : INT; END_VAR
FUNCTION XorSum : WORD
VAR_INPUT a : ARRAY[0..3] OF WORD; n : INT; END_VAR
VAR i : INT; END_VAR
XorSum := 0;
FOR i := 0 TO n - 1 DO XorSum := XorSum XOR SHL(a[i], 1); END_FOR;
END_FUNCTION
FUNCTION Twice : WORD
VAR_INPUT a : ARRAY[0..3] OF WORD; END_VAR
Twice := XorSum(a, 4) XOR XorSum(a, 3);
END_FUNCTION
FUNCTION Half : INT
VAR_INPUT x : INT; END_VAR
Half := x / 2;
END_FUNCTION
FUNCTION FromDevice : INT
VAR_INPUT x : INT; END_VAR
FromDevice := x + D100;
END_FUNCTION
FUNCTION FromGlobal : INT
VAR_INPUT x : INT; END_VAR
VAR_EXTERNAL gOffset : INT; END_VAR
FromGlobal := x + gOffset;
END_FUNCTION
FUNCTION ViaImpure : INT
VAR_INPUT x : INT; END_VAR
ViaImpure := Half(x);
END_FUNCTION
PROGRAM P
VAR a : ARRAY[0..3] OF WORD; w : WORD; r : INT; z : INT; END_VAR
w := XorSum(a, 4) XOR Twice(a);
r := Half(r) + FromDevice(1) + FromGlobal(1) + ViaImpure(2);
r := Half(z) + 0;
END_PROGRAM
"""


def test_only_input_only_functions_are_remembered():
    project = load_st(SOURCES)
    functions = {k: v for k, v in project.module.pous.items() if v.kind == "FUNCTION"}
    assert pure_functions(functions) == {"XORSUM", "TWICE"}
    namespace = project.module.namespace
    assert hasattr(namespace["FN_XORSUM"], "__wrapped__") and not hasattr(namespace["FN_HALF"], "__wrapped__")


def test_remembered_results_follow_the_array_contents_and_the_rest_runs_every_call():
    project = load_st(SOURCES)
    assert project.call("XorSum", [1, 2, 3, 4], 4) == 8
    assert project.call("XorSum", [1, 2, 3, 5], 4) == 10      # another array: computed again
    assert project.call("XorSum", [1, 2, 3, 4], 4) == 8
    assert project.call("XorSum", [1, 2, 3, 4], 3) == 0        # another count
    assert project.call("Twice", [1, 1, 1, 1]) == 2
    project.devices["D100"] = 5
    assert project.call("FromDevice", 1) == 6
    project.devices["D100"] = 7
    assert project.call("FromDevice", 1) == 8             # reads the device each time
    project.globals.gOffset = 3
    assert project.call("FromGlobal", 1) == 4
    project.call("Half", 0)
    project.call("Half", 1)
    project.run_programs(["P"], scans=1)
    assert project.devices["M8067"] is False               # no division by zero yet
    # a FUNCTION that divides is never remembered: a division by zero flags every time
    src = "FUNCTION Hundredth : INT\nVAR_INPUT x : INT; END_VAR\nHundredth := 100 / x;\nEND_FUNCTION\n"
    inv = load_st(src)
    for _ in range(2):
        inv.devices["M8067"] = False
        inv.call("Hundredth", 0)
        assert inv.devices["M8067"] is True
    assert len([d for d in inv.diagnostics if "division by zero" in d.message]) == 2
