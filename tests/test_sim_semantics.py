"""ST semantics in the simulator, one construct and type at a time, against values
worked out by hand from the MELSEC data formats."""
from __future__ import annotations

import math
import struct

import pytest

from sim_helpers import load_st, run_fb, run_program
from verifier.sim import LoadError, SimulationError


#: GX Works2 has no initial values for non-constant labels (the checker refuses them,
#: docs/st-dialect.md §6); tests that start labels at a value use GX Works3 and its CPU,
#: the FX5U (GX Works3 does not program an FX3U). The value semantics under test (wrap,
#: bit strings, conversions, strings) are the same on every CPU profile.
INITIAL_VALUES = {"target": "gxworks3"}


def f32(x: float) -> float:
    return struct.unpack("<f", struct.pack("<f", x))[0]


# ----------------------------------------------------------------------------- integers
@pytest.mark.parametrize("decls, body, label, expected", [
    ("i : INT := 32767;", "i := i + 1;", "i", -32768),
    ("i : INT := -32768;", "i := i - 1;", "i", 32767),
    ("i : INT := 300;", "i := i * 300;", "i", (300 * 300 + 32768) % 65536 - 32768),
    ("i : INT := -32768;", "i := -i;", "i", -32768),
    ("d : DINT := 2147483647;", "d := d + 1;", "d", -2147483648),
    ("i : INT;", "i := 16#FFFF;", "i", -1),            # the ST-converter trap: the CPU sees -1
    ("w : WORD;", "w := NOT w;", "w", 0xFFFF),
    ("i : INT := -7;", "i := i / 2;", "i", -3),          # truncation toward zero
    ("i : INT := 7;", "i := i / -2;", "i", -3),
    ("i : INT := -7;", "i := i MOD 2;", "i", -1),        # the sign of the dividend
    ("i : INT := 7;", "i := i MOD -2;", "i", 1),
    ("i : INT := -32768;", "i := i / -1;", "i", -32768),
    ("d : DINT; i : INT := 30000;", "d := INT_TO_DINT(i) + INT_TO_DINT(i);", "d", 60000),
])
def test_integer_arithmetic_wraps_like_the_cpu(decls, body, label, expected):
    _, fb = run_fb(body, decls, **INITIAL_VALUES)
    assert getattr(fb, label) == expected


@pytest.mark.parametrize("decls, body, label, expected", [
    ("u : UINT;", "u := u - 1;", "u", 65535),
    ("u : UINT := 65535;", "u := u + 2;", "u", 1),
    ("u : UDINT;", "u := u - 1;", "u", 0xFFFFFFFF),
])
def test_unsigned_arithmetic_on_gxworks3(decls, body, label, expected):
    _, fb = run_fb(body, decls, target="gxworks3")
    assert getattr(fb, label) == expected


@pytest.mark.parametrize("expr, expected", [
    ("SHL(w, 4)", 0x2340), ("SHR(w, 4)", 0x0123), ("ROL(w, 4)", 0x2341), ("ROR(w, 4)", 0x4123),
    ("w AND 16#00FF", 0x34), ("w OR 16#F000", 0xF234), ("w XOR 16#FFFF", 0xEDCB),
    ("NOT w", 0xEDCB), ("SHL(w, 16)", 0), ("ROL(w, 20)", 0x2341),
])
def test_bit_string_functions_on_word(expr, expected):
    _, fb = run_fb(f"r := {expr};", "w : WORD := 16#1234; r : WORD;", **INITIAL_VALUES)
    assert fb.r == expected


def test_rotation_of_dword_uses_32_bits():
    _, fb = run_fb("r := ROL(d, 8);", "d : DWORD := 16#12345678; r : DWORD;", **INITIAL_VALUES)
    assert fb.r == 0x34567812


@pytest.mark.parametrize("expr, rtype, expected", [
    ("INT_TO_WORD(-1)", "WORD", 0xFFFF), ("WORD_TO_INT(16#FFFF)", "INT", -1),
    ("DINT_TO_INT(70000)", "INT", 70000 - 65536), ("INT_TO_DINT(-5)", "DINT", -5),
    ("INT_TO_BCD(1234)", "WORD", 0x1234), ("BCD_TO_INT(16#0987)", "INT", 987),
    ("BOOL_TO_INT(TRUE)", "INT", 1), ("TIME_TO_DINT(T#1m2s)", "DINT", 62000),
    ("MAX(3, 9, 4)", "INT", 9), ("MIN(3, 9, 4)", "INT", 3), ("LIMIT(0, 15, 10)", "INT", 10),
    ("SEL(TRUE, 1, 2)", "INT", 2), ("MUX(2, 10, 20, 30)", "INT", 30), ("ABS(-4)", "INT", 4),
    ("ADD(1, 2, 3)", "INT", 6), ("MOD(-9, 4)", "INT", -1), ("DINT_TO_REAL(3)", "REAL", 3.0),
])
def test_standard_functions(expr, rtype, expected):
    _, fb = run_fb(f"r := {expr};", f"r : {rtype};")
    assert fb.r == expected


@pytest.mark.parametrize("cpu, expr, expected", [
    # FX3: INT (FNC 129) "rounded down to the nearest integer value" (FX programming
    # manual §5.11.10) -- the fraction is dropped, so 12.999999 (1.3 / 0.1 in REAL) is 12
    ("fx3u", "REAL_TO_INT(2.5)", 2), ("fx3u", "REAL_TO_INT(-2.5)", -2),
    ("fx3u", "REAL_TO_INT(a / r)", 12), ("fx3g", "REAL_TO_INT(2.9)", 2),
    ("fx3u", "REAL_TO_DINT(-70000.7)", -70000),
    # FX5 / Q: "the first digit after the decimal point ... is rounded off"
    ("fx5u", "REAL_TO_INT(2.5)", 3), ("fx5u", "REAL_TO_INT(-2.5)", -3),
    ("q", "REAL_TO_INT(2.4)", 2), ("q", "REAL_TO_INT(a / r)", 13),
    ("q", "REAL_TO_DINT(-123456.7)", -123457),
])
def test_real_to_integer_follows_the_cpu(cpu, expr, expected):
    rtype = "DINT" if "DINT" in expr else "INT"
    target = {"fx5u": "gxworks3", "q": "gxworks2:q"}.get(cpu, "gxworks2")
    _, fb = run_fb(f"r := 0.1; a := 1.3; x := {expr};", f"x : {rtype}; r, a : REAL;", cpu=cpu,
                   target=target)
    assert fb.x == expected


def test_int_to_bool_and_comparisons():
    _, fb = run_fb("bA := INT_TO_BOOL(i); bB := i > 2; bC := GT(5, i);", "i : INT := 3; bA, bB, bC : BOOL;",
                   **INITIAL_VALUES)
    assert (fb.bA, fb.bB, fb.bC) == (True, True, True)


# ----------------------------------------------------------------------------- REAL and TIME
def test_real_is_rounded_to_single_precision():
    _, fb = run_fb("r := r + 0.2; l := l + 0.2;", "r : REAL := 0.1; l : LREAL := 0.1;",
                   target="gxworks3")
    assert fb.r == f32(f32(0.1) + f32(0.2))
    assert fb.r != 0.1 + 0.2
    assert fb.l == 0.1 + 0.2


@pytest.mark.parametrize("cpu, target", [("fx3u", "gxworks2"), ("q", "gxworks2:q"), ("fx5u", "gxworks3")])
def test_a_constant_meeting_a_real_is_a_real(cpu, target):
    """A REAL constant is single precision on the CPU, as a REAL label holding it is:
    `1.3 / r` computed 1.3 in double precision (13.0 for r = 0.1, where the label gives
    12.999999), and `r = 0.1` was FALSE right after `r := 0.1`. LREAL keeps double."""
    _, fb = run_fb("r := 0.1; c := 1.3; a := 1.3 / r; b := c / r; e := r = 0.1; f := 0.1 = r; "
                   "g := r * 2.0 = 0.2; i := REAL_TO_INT(1.3 / r); "
                   "j := REAL_TO_INT(c / r); k := r < 0.1; "
                   + ("l := 0.1; m := l = 0.1; n := l * 1.3;" if cpu != "fx3u" else ""),
                   "r, c, a, b : REAL; e, f, g, k : BOOL; i, j : INT;"
                   + (" l, n : LREAL; m : BOOL;" if cpu != "fx3u" else ""), cpu=cpu, target=target)
    assert fb.a == fb.b == f32(f32(1.3) / f32(0.1))
    assert (fb.e, fb.f, fb.g, fb.k) == (True, True, True, False)
    assert fb.i == fb.j == (12 if cpu == "fx3u" else 13)
    if cpu != "fx3u":
        assert (fb.l, fb.m, fb.n) == (0.1, True, 0.1 * 1.3)


def test_real_division_and_sqrt():
    _, fb = run_fb("r := 1.0 / 3.0; s := SQRT(2.0);", "r, s : REAL;")
    assert fb.r == f32(1 / 3)
    assert fb.s == f32(2 ** 0.5)


def test_time_values_are_ms():
    _, fb = run_fb("t := T#1s500ms; d := TIME_TO_DINT(t); u := DINT_TO_TIME(d * 2);", "t, u : TIME; d : DINT;")
    assert (fb.t, fb.d, fb.u) == (1500, 1500, 3000)


def test_string_conversions():
    _, fb = run_fb("s := INT_TO_STR(-42); i := STR_TO_INT('123'); r := STR_TO_REAL('1.5');",
                   "s : STRING; i : INT; r : REAL;")
    assert (fb.s, fb.i, fb.r) == ("-42", 123, 1.5)


def test_strings():
    _, fb = run_fb("s := CONCAT(a, 'cd'); n := LEN(s); l := LEFT(s, 3); m := MID(s, 2, 2);",
                   "a : STRING := 'ab'; s, l, m : STRING; n : INT;", **INITIAL_VALUES)
    assert (fb.s, fb.n, fb.l, fb.m) == ("abcd", 4, "abc", "bc")


# ----------------------------------------------------------------------------- bits, devices
def test_bit_of_word_label_reads_and_writes():
    _, fb = run_fb("w.3 := TRUE; w.0 := FALSE; b := w.15;", "w : WORD := 16#8001; b : BOOL;",
                   **INITIAL_VALUES)
    assert fb.w == 0x8008
    assert fb.b is True


def test_bit_of_int_label_keeps_the_sign():
    _, fb = run_fb("i.15 := TRUE;", "i : INT;")
    assert fb.i == -32768


def test_devices_bit_of_word_and_digit_specification():
    project, fb = run_fb("D0.F := TRUE; K4M0 := 16#1234; D1 := K4M0; D2 := K1M4; M100 := D0.F;", "x : INT;")
    dev = project.devices
    assert dev["D0"] == -32768
    assert [dev[f"M{i}"] for i in range(4)] == [False, False, True, False]  # 4 = 0100b
    assert dev["D1"] == 0x1234
    assert dev["D2"] == 3
    assert dev["M100"] is True
    assert dev["K4M0"] == 0x1234


def test_index_registers_and_buffer_memory_on_q():
    src = ("PROGRAM P\nVAR w : WORD; END_VAR\n"
           "W1F := D0Z1;\nD10Z1 := 5;\nU0\\G164 := 8;\nw := INT_TO_WORD(U0\\G165);\nEND_PROGRAM\n")
    project = load_st(src, cpu="q")
    project.devices["Z1"] = 2
    project.devices["D2"] = 77
    project.run_programs(["P"], scans=1)
    assert project.devices["W1F"] == 77 and project.devices["D12"] == 5
    assert project.c24_buffer(0)[164] == 8
    project.devices["Z1"] = 20000
    with pytest.raises(SimulationError) as err:
        project.run_programs(["P"], scans=1)
    assert err.value.location == "t.st:3:8" and "outside D0Z1" in str(err.value)


def test_fx_inputs_are_octal_and_q_inputs_hexadecimal():
    fx = load_st("PROGRAM P\nVAR b : BOOL; END_VAR\nb := X10;\nEND_PROGRAM\n")
    fx.devices["X10"] = True
    fx.run_programs(["P"], scans=1)
    assert fx.program("P").b is True
    assert fx.devices.address("X10").index == 8
    q = load_st("PROGRAM P\nVAR b : BOOL; END_VAR\nb := X1F;\nEND_PROGRAM\n", cpu="q")
    assert q.devices.address("X1F").index == 31


def test_devices_are_shared_by_all_programs():
    project = load_st("PROGRAM A\nD10 := D10 + 1;\nEND_PROGRAM\n"
                      "PROGRAM B\nVAR seen : INT; END_VAR\nseen := D10;\nEND_PROGRAM\n")
    project.run_programs(["A", "B"], scans=3)
    assert project.program("B").seen == 3
    assert project.devices["D10"] == 3


def test_first_scan_and_always_on_flags_fx3():
    project = load_st("PROGRAM P\nVAR first, on, seen : INT; END_VAR\n"
                      "IF M8002 THEN first := first + 1; END_IF;\n"
                      "IF M8000 THEN on := on + 1; END_IF;\nEND_PROGRAM\n")
    project.run_programs(["P"], scans=5)
    assert (project.program("P").first, project.program("P").on) == (1, 5)


def test_first_scan_flags_fx5():
    project = load_st("PROGRAM P\nVAR first, on : INT; END_VAR\n"
                      "IF SM402 THEN first := first + 1; END_IF;\n"
                      "IF SM400 THEN on := on + 1; END_IF;\nEND_PROGRAM\n", target="gxworks3")
    project.run_programs(["P"], scans=4)
    assert (project.program("P").first, project.program("P").on) == (1, 4)


# ----------------------------------------------------------------------------- arrays
def test_array_bounds_and_lower_bound():
    _, fb = run_fb("FOR i := 1 TO 3 DO a[i] := i * 10; END_FOR; s := a[1] + a[3];",
                   "a : ARRAY[1..3] OF INT; i, s : INT;")
    assert fb.s == 40
    assert list(fb.a) == [10, 20, 30]
    assert fb.a[1] == 10


def test_out_of_bounds_index_is_reported_at_its_st_location():
    with pytest.raises(SimulationError) as err:
        run_fb("i := 4;\na[i] := 1;", "a : ARRAY[0..3] OF INT; i : INT;")
    assert err.value.location == "t.st:6:3"
    assert "outside a[0..3]" in str(err.value)
    assert "silently" in str(err.value)
    assert str(err.value).endswith("\n    a[i] := 1;\n      ^")  # the ST line, marked


def test_out_of_bounds_read_in_an_expression():
    with pytest.raises(SimulationError) as err:
        run_fb("i := -1;\nx := a[i] + 1;", "a : ARRAY[0..3] OF INT; i, x : INT;")
    assert err.value.location == "t.st:6:8"


def test_two_dimensional_arrays():
    _, fb = run_fb("FOR i := 0 TO 1 DO FOR j := 0 TO 2 DO m[i, j] := i * 10 + j; END_FOR; END_FOR;"
                   " x := m[1, 2];", "m : ARRAY[0..1, 0..2] OF INT; i, j, x : INT;")
    assert fb.x == 12
    assert fb.m[1, 0] == 10


def test_array_initialiser_with_repeat():
    _, fb = run_fb("", "a : ARRAY[0..5] OF INT := [1, 2(7), 3];", **INITIAL_VALUES)
    assert list(fb.a) == [1, 7, 7, 3, 0, 0]


# ----------------------------------------------------------------------------- operation errors
def test_division_by_zero_sets_m8067_and_keeps_the_destination():
    project, fb = run_fb("x := 5;\nx := x / z;", "x, z : INT;")
    assert fb.x == 5
    assert project.devices["M8067"] is True
    assert project.devices["D8067"] == 6706
    (diag,) = project.diagnostics
    assert diag.location == "t.st:6:6"
    assert "division by zero" in diag.message


def test_division_by_zero_stops_a_q_cpu():
    with pytest.raises(SimulationError) as err:
        run_fb("x := 1 + 1 / z;", "x, z : INT;", cpu="q")
    assert "CPU stops" in str(err.value)
    assert err.value.location.startswith("t.st:5:")


def test_division_by_zero_on_fx5_sets_sm0():
    # FX5 Programming Manual (Instructions) 6.2 "/": error code 3400 "0 is specified for
    # (s2) value" (3405H is the out-of-range class, below)
    project, _ = run_fb("x := 3 MOD z;", "x, z : INT;", target="gxworks3")
    assert project.devices["SM0"] is True
    assert project.devices["SD0"] == 0x3400
    project, _ = run_fb("x := 3 / z;", "x, z : INT;", target="gxworks3")
    assert project.devices["SD0"] == 0x3400


def test_other_operation_errors_on_fx5_keep_the_out_of_range_code():
    project, _ = run_fb("i := 20000; w := INT_TO_BCD(i);", "i : INT; w : WORD;",
                        target="gxworks3")
    assert project.devices["SM0"] is True
    assert project.devices["SD0"] == 0x3405


# ----------------------------------------------------------------------------- control flow
def test_case_with_ranges_and_else():
    src = ("FUNCTION F : INT\nVAR_INPUT x : INT; END_VAR\n"
           "CASE x OF 1, 2: F := 10; 3..5: F := 20; ELSE F := -1; END_CASE;\nEND_FUNCTION\n")
    project = load_st(src)
    assert [project.call("F", v) for v in (1, 2, 4, 6)] == [10, 10, 20, -1]


def test_loops_exit_while_repeat():
    _, fb = run_fb("FOR i := 0 TO 100 DO IF i = 7 THEN EXIT; END_IF; END_FOR;\n"
                   "WHILE n < 5 DO n := n + 1; END_WHILE;\n"
                   "REPEAT k := k + 2; UNTIL k >= 9 END_REPEAT;\n"
                   "FOR j := 10 TO 0 BY -5 DO s := s + j; END_FOR;",
                   "i, n, k, j, s : INT;")
    assert (fb.i, fb.n, fb.k, fb.s, fb.j) == (7, 5, 10, 15, -5)


def test_endless_loop_is_stopped_as_a_watchdog_error():
    with pytest.raises(SimulationError) as err:
        run_fb("WHILE TRUE DO\n  n := n + 1;\nEND_WHILE;", "n : INT;")
    assert "watchdog" in str(err.value)
    assert err.value.location == "t.st:5:1"


@pytest.mark.parametrize("loop", ["FOR i := 0 TO 2000000000 DO\n  n := n + 1;\nEND_FOR;",
                                  "FOR i := 2000000000 TO 0 BY -1 DO\n  n := n + 1;\nEND_FOR;"])
def test_a_for_loop_with_constant_bounds_past_the_watchdog_is_stopped_as_one(loop):
    # constant bounds ran as a Python range without the guard: two billion iterations in
    # one scan, uitamr verify of such a program ran for hours instead of stopping
    with pytest.raises(SimulationError) as err:
        run_fb(loop, "i : DINT; n : DINT;")
    assert "watchdog" in str(err.value)
    assert err.value.location == "t.st:5:1"


def test_a_for_loop_of_a_million_iterations_runs_in_its_scan():
    _, fb = run_fb("FOR i := 1 TO 1000000 DO\n  n := n + 1;\nEND_FOR;", "i : DINT; n : DINT;")
    assert (fb.i, fb.n) == (1000001, 1000000)


def test_return_leaves_the_pou():
    _, fb = run_fb("n := 1;\nRETURN;\nn := 2;", "n : INT;")
    assert fb.n == 1


# ----------------------------------------------------------------------------- POUs
def test_function_with_in_out_and_outputs():
    src = ("FUNCTION F_DIVMOD : INT\nVAR_INPUT a, b : INT; END_VAR\nVAR_OUTPUT r : INT; END_VAR\n"
           "VAR_IN_OUT acc : INT; END_VAR\nF_DIVMOD := a / b; r := a MOD b; acc := acc + 1;\nEND_FUNCTION\n"
           "PROGRAM P\nVAR q, r, acc : INT; END_VAR\nq := F_DIVMOD(a := 17, b := 5, acc := acc, r => r);\nEND_PROGRAM\n")
    project = load_st(src)
    project.run_programs(["P"], scans=2)
    p = project.program("P")
    assert (p.q, p.r, p.acc) == (3, 2, 2)
    value, outputs = project.call_full("F_DIVMOD", 17, 5, 0)
    assert (value, outputs["r"], outputs["acc"]) == (3, 2, 1)


def test_positional_arguments_follow_the_declaration_order_in_out_first():
    """A VAR_IN_OUT declared before the VAR_INPUT takes the first positional argument, in
    the checker (types) as in the simulator (values)."""
    src = ("FUNCTION Fill : INT\nVAR_IN_OUT io_wBuf : ARRAY[0..3] OF INT; END_VAR\n"
           "VAR_INPUT i_wValue : INT; END_VAR\nio_wBuf[0] := i_wValue; Fill := i_wValue;\nEND_FUNCTION\n"
           "PROGRAM P\nVAR a : ARRAY[0..3] OF INT; w : INT; END_VAR\nw := Fill(a, 7);\nEND_PROGRAM\n")
    project = load_st(src)
    project.run_programs(["P"], scans=1)
    assert list(project.program("P").a) == [7, 0, 0, 0] and project.program("P").w == 7


def test_function_array_input_is_copied():
    src = ("FUNCTION F : INT\nVAR_INPUT a : ARRAY[0..2] OF INT; END_VAR\na[0] := 99; F := a[0];\nEND_FUNCTION\n"
           "PROGRAM P\nVAR a : ARRAY[0..2] OF INT; r : INT; END_VAR\nr := F(a);\nEND_PROGRAM\n")
    project = load_st(src)
    project.run_programs(["P"], scans=1)
    assert project.program("P").r == 99
    assert list(project.program("P").a) == [0, 0, 0]


def test_nested_fb_instances_and_structures():
    src = ("TYPE ST_POS : STRUCT x : INT; y : INT; END_STRUCT; END_TYPE\n"
           "FUNCTION_BLOCK FB_IN\nVAR_INPUT i : INT; END_VAR\nVAR_OUTPUT o : INT; END_VAR\no := i * 2;\nEND_FUNCTION_BLOCK\n"
           "FUNCTION_BLOCK FB_OUT\nVAR inner : FB_IN; p, q : ST_POS; r : INT; END_VAR\n"
           "p.x := 3; inner(i := p.x, o => r); q := p; q.y := inner.o + 1;\nEND_FUNCTION_BLOCK\n")
    project = load_st(src)
    fb = project.instance("FB_OUT").scan()
    assert (fb.r, fb.inner.o, fb.q.x, fb.q.y, fb.p.y) == (6, 6, 3, 7, 0)


def test_global_labels_and_device_assignment():
    src = ("VAR_GLOBAL\n gCount : INT;\n gStart AT X0 : BOOL;\n gOut AT Y1 : BOOL;\n gWord AT D50 : WORD;\nEND_VAR\n"
           "PROGRAM P\nVAR_EXTERNAL gCount : INT; gStart : BOOL; gOut : BOOL; gWord : WORD; END_VAR\n"
           "IF gStart THEN gCount := gCount + 1; END_IF; gOut := gStart; gWord := 16#FFFF;\nEND_PROGRAM\n")
    project = load_st(src)
    project.devices["X0"] = True
    project.run_programs(["P"], scans=2)
    assert project.globals.gCount == 2
    assert project.devices["Y1"] is True
    assert project.devices["D50"] == -1
    assert project.globals.gWord == 0xFFFF


def test_pulse_instruction_runs_once_per_rising_edge():
    project, fb = run_fb("MOVP(b, D0 + 1, D0);", "b : BOOL;")
    fb.b = True
    fb.scan(3)
    fb.b = False
    fb.scan()
    fb.b = True
    fb.scan(2)
    assert project.devices["D0"] == 2


# ----------------------------------------------------------------------------- runtime
def test_virtual_clock_with_jitter_is_deterministic_per_seed():
    def times(seed):
        project = load_st("PROGRAM P\nVAR t : INT; END_VAR\nt := t + 1;\nEND_PROGRAM\n",
                          scan_ms=10, jitter_ms=2, seed=seed)
        seen = []
        project.run_programs(["P"], scans=20, on_scan=lambda p: seen.append(p.now_us))
        return seen

    a, b, c = times(1), times(1), times(2)
    assert a == b and a != c
    steps = [y - x for x, y in zip(a, a[1:])]
    assert all(8000 <= s <= 12000 for s in steps) and len(set(steps)) > 1


def test_run_for_virtual_time_and_per_scan_hook():
    project = load_st("PROGRAM P\nVAR n : DINT; END_VAR\nn := n + 1;\nEND_PROGRAM\n", scan_ms=10)
    project.run_programs(["P"], ms=1000)
    assert project.program("P").n == 100
    assert project.now_us == 1_000_000


def test_load_errors_name_file_line_and_column(tmp_path):
    bad = tmp_path / "bad.st"
    bad.write_text("PROGRAM P\nVAR x : INT; END_VAR\nx := ;\nEND_PROGRAM\n")
    with pytest.raises(LoadError) as err:
        import verifier
        verifier.load(str(bad))
    assert f"{bad}:3:" in str(err.value)


def test_unknown_label_is_a_load_error():
    with pytest.raises(LoadError) as err:
        load_st("PROGRAM P\nnope := 1;\nEND_PROGRAM\n")
    assert "t.st:2:" in str(err.value)


def test_python_side_values_are_normalised():
    _, fb = run_fb("", "i : INT; w : WORD; b : BOOL; a : ARRAY[0..1] OF WORD;")
    fb.i = 40000
    fb.w = -1
    fb.a = [0x1FFFF]
    assert (fb.i, fb.w, list(fb.a)) == (40000 - 65536, 0xFFFF, [0xFFFF, 0])
    with pytest.raises(ValueError):
        fb.b = 5
    with pytest.raises(AttributeError):
        fb.missing = 1


def test_every_standard_function_the_checker_knows_has_an_implementation():
    from verifier.sim import stdfuncs
    from verifier.st import library

    class Cx:
        def loc(self, span):
            return 0

        def binary_code(self, op, lc, lt, rc, rt_, span):
            return f"({lc} {op} {rc})", lt

        def unary_code(self, op, code, t, span):
            return code, t

    missing = []
    for name, sig in library.STANDARD_FUNCTIONS.items():
        n = max(1, len([p for p in sig.params if p.name.upper() not in ("EN",)]))
        if stdfuncs.generate(name, [("1", "INT")] * n, Cx(), None) is None:
            missing.append(name)
    assert missing == []


def test_counter_division_in_a_for_loop():
    """`i / k` and `i MOD k` on a FOR counter that stays >= 0 compile to // and %:
    the same results as the CPU's truncating division."""
    src = ("PROGRAM P\nVAR i, j : INT; q, m : ARRAY[0..20] OF INT; n : ARRAY[0..20] OF INT; END_VAR\n"
           "FOR i := 0 TO 20 DO q[i] := i / 3; m[i] := i MOD 4; END_FOR;\n"
           "FOR j := -10 TO 10 DO n[j + 10] := j / 3; END_FOR;\nEND_PROGRAM\n")
    p = run_program(src)
    assert list(p.q) == [i // 3 for i in range(21)] and list(p.m) == [i % 4 for i in range(21)]
    assert list(p.n) == [int(j / 3) for j in range(-10, 11)]  # negative counters: truncation


def test_counter_arithmetic_in_a_for_loop():
    """Index and value arithmetic on FOR counters with constants (named ones too) compiles
    to plain Python arithmetic when no step can wrap, go negative or divide by <= 0: the
    results are those of the CPU's truncating, wrapping arithmetic in every case, checked
    against Python's own arithmetic here (also for the cases that keep the helpers)."""
    src = ("PROGRAM P\nVAR CONSTANT PAIR : INT := 2; BASE : INT := 8; END_VAR\n"
           "VAR i : INT; a : ARRAY[0..40] OF INT; q, m, n, w : ARRAY[0..20] OF INT; END_VAR\n"
           "FOR i := 0 TO 15 DO a[BASE + PAIR * i + 1] := i MOD PAIR + 10 * (i / PAIR); END_FOR;\n"
           "FOR i := 0 TO 20 DO q[i] := (i - 7) / PAIR; m[i] := (i - 7) MOD 3; n[i] := i * 2000;\n"
           "  w[20 - i] := 30000 + i * 200; END_FOR;\nEND_PROGRAM\n")
    p = run_program(src)
    expected_a = [0] * 41
    for i in range(16):
        expected_a[8 + 2 * i + 1] = i % 2 + 10 * (i // 2)
    assert list(p.a) == expected_a
    assert list(p.q) == [int((i - 7) / 2) for i in range(21)]  # truncation, not floor
    assert list(p.m) == [int(math.fmod(i - 7, 3)) for i in range(21)]  # sign of the dividend
    assert list(p.n) == [(i * 2000 + 32768) % 65536 - 32768 for i in range(21)]  # INT wraps
    assert list(p.w) == [(30000 + (20 - i) * 200 + 32768) % 65536 - 32768 for i in range(21)]


def test_counter_arithmetic_index_out_of_range_is_still_an_error():
    src = ("PROGRAM P\nVAR i : INT; a : ARRAY[0..9] OF INT; END_VAR\n"
           "FOR i := 0 TO 9 DO a[i + 1] := i; END_FOR;\nEND_PROGRAM\n")
    with pytest.raises(SimulationError) as err:
        run_program(src)
    assert "outside a[0..9]" in str(err.value) and err.value.location == "t.st:3:22"


def test_and_or_on_bools_give_every_combination_and_still_evaluate_what_can_fail():
    """AND/OR on BOOLs skip a right side that only reads labels (short-circuit): the same
    truth table as the CPU's; a right side that can fail (an index out of range) or do
    something (a FUNCTION call) is still evaluated when the left side decides alone."""
    src = ("FUNCTION F : BOOL\nVAR_INPUT x : INT; END_VAR\n"
           "D0 := D0 + x; F := x > 0;\nEND_FUNCTION\n"
           "PROGRAM P\nVAR a, b : ARRAY[0..3] OF BOOL; r : ARRAY[0..15] OF BOOL;\n"
           "i, j, n : INT; q : BOOL; w : ARRAY[0..1] OF BOOL; END_VAR\n"
           "FOR i := 0 TO 3 DO FOR j := 0 TO 3 DO\n"
           "  r[4 * i + j] := (a[i] AND b[j]) OR (NOT a[i] AND NOT b[j]) OR (a[i] AND NOT b[j] AND i = j);\n"
           "END_FOR; END_FOR;\n"
           "q := FALSE AND F(1); q := TRUE OR F(2); q := q AND F(4);\n"
           "IF FALSE AND w[i] THEN n := 100; END_IF;\nEND_PROGRAM\n")
    project = load_st(src)
    p = project.program("P")
    for k in range(4):
        p.a[k], p.b[k] = k in (1, 3), k in (2, 3)
    with pytest.raises(SimulationError) as err:  # i = 4 after the loop: w[4] is out of range
        project.run_programs(["P"], scans=1)
    assert "outside w[0..1]" in str(err.value)
    a, b = [k in (1, 3) for k in range(4)], [k in (2, 3) for k in range(4)]
    assert list(p.r) == [(a[i] and b[j]) or (not a[i] and not b[j]) or (a[i] and not b[j] and i == j)
                         for i in range(4) for j in range(4)]
    assert project.devices["D0"] == 7 and p.n == 0  # every call ran (1 + 2 + 4), no IF
    assert p.q is True


def test_cannot_fail_accepts_only_plain_reads():
    from verifier.sim.codegen import cannot_fail
    assert cannot_fail("((not (_o1.bOk)) & ((_A_M[8002]) | (((self.wState) == (2)))))")
    assert cannot_fail("(((a) and (b))) or (((self.wState) == (2)))")
    for code in ("_oob(_t4, 5)", "(a[_t] if 0 <= (_t := x) <= 3 else _oob(_t, 1))", "l_F(x)",
                 "(x // 2) == 1", "a[i]", "(_t := 1)", "'text' == s", "x if y else z", "(a) or (l_F(x))", "True (x)"):
        assert not cannot_fail(code), code


def test_lreal_is_refused_when_loading_for_an_fx3():
    """LREAL exists under GX Works2 on the Universal model QCPU only (docs/st-dialect.md §3):
    loading it for the default FX3U was accepted and simulated as a double."""
    with pytest.raises(LoadError) as err:
        run_fb("l := 1.5;", "l : LREAL;")
    assert "t.st:3:5: error: LREAL (FLOAT [Double Precision]) does not exist on the fx3u" in str(err.value)
    _, fb = run_fb("l := 1.5;", "l : LREAL;", cpu="q", target="gxworks2:q")
    assert fb.l == 1.5
