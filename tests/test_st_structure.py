"""Whole-project rules: recursion and storage sizes are refused by the checker with a
location, so the simulator never meets them (no RecursionError or MemoryError)."""
from __future__ import annotations

import pytest

import verifier.sim
from verifier import st

SELF_FB = """FUNCTION_BLOCK FB_Self
VAR inner : FB_Self; bRun : BOOL; END_VAR
inner(); bRun := NOT bRun;
END_FUNCTION_BLOCK
"""
RECURSIVE_FUNCTION = """FUNCTION Fact : INT
VAR_INPUT n : INT; END_VAR
IF n <= 1 THEN Fact := 1; ELSE Fact := n * Fact(n - 1); END_IF;
END_FUNCTION
PROGRAM Main
VAR r : INT; END_VAR
r := Fact(5);
END_PROGRAM
"""
HUGE_ARRAY = """PROGRAM Main
VAR a : ARRAY[0..2000000000] OF INT; END_VAR
a[0] := 1;
END_PROGRAM
"""


def errors(text: str, target: str = "gxworks2") -> list[str]:
    source = st.parse(text, "t.st", target)
    return [str(d) for d in source.diagnostics + st.check([source], target) if d.is_error]


def test_fb_holding_itself_is_an_error_at_the_label():
    assert errors(SELF_FB) == ["t.st:2:5: error: function block FB_Self holds an instance of itself "
                               "(FB_Self.inner -> FB_Self); GX Works does not allow recursion: a type "
                               "cannot contain itself, directly or through others"]


def test_recursive_function_is_an_error_at_the_call():
    (message,) = errors(RECURSIVE_FUNCTION)
    assert message.startswith("t.st:3:44: error: Fact calls itself (Fact -> Fact)")


def test_no_cycle_no_error():
    text = """FUNCTION_BLOCK FB_Leaf
VAR_OUTPUT q : BOOL; END_VAR
q := TRUE;
END_FUNCTION_BLOCK
FUNCTION_BLOCK FB_Tree
VAR a, b : FB_Leaf; END_VAR
a(); b();
END_FUNCTION_BLOCK
"""
    assert errors(text) == []


def test_long_acyclic_chain_of_fbs_is_sized_without_deep_recursion():
    n = 3000
    parts = [f"FUNCTION_BLOCK FB_{i}\nVAR x : FB_{i + 1}; w : WORD; END_VAR\nx(); w := 1;\nEND_FUNCTION_BLOCK\n"
             for i in range(n)]
    parts.append(f"FUNCTION_BLOCK FB_{n}\nVAR w : WORD; END_VAR\nw := 1;\nEND_FUNCTION_BLOCK\n")
    assert errors("".join(parts)) == []


def test_long_chain_of_fbs_is_checked_without_deep_recursion():
    n = 3000  # deeper than Python's recursion limit: the graph walk must be iterative
    parts = [f"FUNCTION_BLOCK FB_{i}\nVAR x : FB_{i + 1}; END_VAR\nx();\nEND_FUNCTION_BLOCK\n" for i in range(n)]
    parts.append(f"FUNCTION_BLOCK FB_{n}\nVAR x : FB_0; END_VAR\nx();\nEND_FUNCTION_BLOCK\n")
    found = errors("".join(parts))
    assert len(found) == 1 and "FB_0 holds an instance of itself" in found[0]


@pytest.mark.parametrize("text, where", [
    (SELF_FB, "t.st:2:5: error: function block FB_Self holds an instance of itself"),
    (RECURSIVE_FUNCTION, "t.st:3:44: error: Fact calls itself"),
    (HUGE_ARRAY, "t.st:2:15: error: array bound 2000000000 is outside the index range -32768..32767"),
])
def test_simulator_refuses_with_the_location_never_crashes(text, where):
    with pytest.raises(verifier.sim.LoadError) as err:
        verifier.sim.load(sources={"t.st": text})
    assert where in str(err.value)


def test_flat_600_term_sum_is_reported_at_its_statement():
    text = "PROGRAM Main\nVAR i, y : INT; END_VAR\ny := 1;\ny := " + "+".join(["i"] * 600) + ";\nEND_PROGRAM\n"
    source = st.parse(text, "t.st")
    found = st.check([source])
    assert [(d.line, d.col, d.severity) for d in found] == [(4, 1, "error")]
    assert "nested too deeply" in found[0].message


def test_too_deep_initial_value_is_reported_at_its_label():
    text = "PROGRAM Main\nVAR CONSTANT y : INT := " + "+".join(["1"] * 700) + "; END_VAR\nEND_PROGRAM\n"
    source = st.parse(text, "t.st")
    found = [d for d in st.check([source]) if d.is_error]
    assert [(d.line, d.col) for d in found] == [(2, 14)]
    assert "initial value nested too deeply" in found[0].message


def test_real_constants_outside_the_real_types_are_errors_at_the_constant():
    """1.0E999 is an infinity in Python and 1.0E39 one once stored in a REAL: the
    simulator stopped with NameError('inf') instead of the checker saying what is wrong."""
    text = ("PROGRAM Main\nVAR r : REAL; l : LREAL; b : BOOL; END_VAR\n"
            "r := 1.0E39;\nb := 1.0E999 > 0.0;\nl := 1.0E39;\nr := 3.0E38;\nEND_PROGRAM\n")
    assert errors(text) == [
        "t.st:3:6: error: assignment: 1.0E39 is outside the REAL range (about ±3.4E38); a REAL label cannot hold it",
        "t.st:4:6: error: 1.0E999 is outside the range of every real type (LREAL reaches about ±1.8E308)",
    ]


def test_an_if_or_case_with_more_branches_than_the_simulator_runs_is_an_error():
    """About 3,000 branches make Python's compiler give up; check said nothing and the
    simulator's error had no place. At the limit, both still load and run."""
    def program(n_elsif: int, n_case: int) -> str:
        elsifs = "".join(f"ELSIF i = {k} THEN\n    y := {k};\n" for k in range(1, n_elsif + 1))
        cases = "".join(f"{k}: y := {k};\n" for k in range(n_case))
        return ("PROGRAM Main\nVAR i, y : INT; END_VAR\nIF i = 0 THEN\n    y := 0;\n" + elsifs + "END_IF;\n"
                "CASE i OF\n" + cases + "END_CASE;\nEND_PROGRAM\n")

    found = errors(program(1000, 1001))
    assert [f.split(": error: ")[1].split(":")[0] for f in found] == [
        "IF with 1000 ELSIF branches", "CASE with 1001 branches"]
    assert found[0].startswith("t.st:3:1:")
    project = verifier.sim.load(sources={"t.st": program(999, 1000)})
    main = project.program("Main")
    main.i = 998
    project.run_programs(["Main"], scans=1)
    assert main.y == 998
