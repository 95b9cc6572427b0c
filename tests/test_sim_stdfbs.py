"""Standard function blocks in virtual time: timers evaluated when the FB is called (PT in
ms), edge detectors, counters, bistables."""
from __future__ import annotations

import pytest

from sim_helpers import load_st
from verifier.sim import LoadError

TIMERS = """
FUNCTION_BLOCK FB_T
VAR_INPUT bInput : BOOL; END_VAR
VAR
    fbOn : TON; fbOff : TOF; fbPulse : TP;
END_VAR
fbOn(IN := bInput, PT := T#100ms);
fbOff(IN := bInput, PT := T#100ms);
fbPulse(IN := bInput, PT := T#100ms);
END_FUNCTION_BLOCK
"""


def trace(fb, inputs_by_scan):
    out = []
    for b in inputs_by_scan:
        fb.bInput = b
        fb.scan()
        out.append((fb.fbOn.Q, fb.fbOff.Q, fb.fbPulse.Q))
    return out


def test_ton_rises_pt_after_in_and_et_counts_in_ms():
    fb = load_st(TIMERS, scan_ms=10).instance("FB_T")
    fb.bInput = True
    fb.scan(10)   # t = 0 .. 90 ms
    assert fb.fbOn.Q is False and fb.fbOn.ET == 90
    fb.scan()     # t = 100 ms
    assert fb.fbOn.Q is True and fb.fbOn.ET == 100
    fb.bInput = False
    fb.scan()
    assert fb.fbOn.Q is False and fb.fbOn.ET == 0


def test_tof_holds_q_for_pt_after_in_falls():
    fb = load_st(TIMERS, scan_ms=10).instance("FB_T")
    fb.bInput = True
    fb.scan(2)
    fb.bInput = False
    fb.scan()     # falls at t = 20 ms
    assert fb.fbOff.Q is True
    fb.scan(9)    # t = 110 ms: 90 ms after the fall
    assert fb.fbOff.Q is True and fb.fbOff.ET == 90
    fb.scan()     # t = 120 ms
    assert fb.fbOff.Q is False


def test_tp_pulse_has_fixed_length_and_is_not_retriggered():
    fb = load_st(TIMERS, scan_ms=10).instance("FB_T")
    states = trace(fb, [True] * 3 + [False] * 3 + [True] * 8)
    pulse = [s[2] for s in states]
    # rising edge at 0 ms: Q for 0..90 ms (10 scans) regardless of IN in between
    assert pulse[:10] == [True] * 10
    assert pulse[10] is False


def test_timer_is_evaluated_only_when_called():
    src = """
FUNCTION_BLOCK FB_T
VAR_INPUT bCall : BOOL; END_VAR
VAR t : TON; END_VAR
IF bCall THEN t(IN := TRUE, PT := T#50ms); END_IF;
END_FUNCTION_BLOCK
"""
    fb = load_st(src, scan_ms=10).instance("FB_T")
    fb.bCall = True
    fb.scan()                # started at 0 ms
    fb.bCall = False
    fb.scan(20)              # not called: ET frozen
    assert fb.t.ET == 0 and fb.t.Q is False
    fb.bCall = True
    fb.scan()                # called at 210 ms: 210 ms since the start
    assert fb.t.Q is True and fb.t.ET == 50


def test_edges_counters_bistables():
    src = """
FUNCTION_BLOCK FB_C
VAR_INPUT bClk, bReset : BOOL; END_VAR
VAR
    rt : R_TRIG; ft : F_TRIG; cu : CTU; cd : CTD; cud : CTUD; fbSr : SR; fbRs : RS;
    nRise, nFall : INT;
END_VAR
rt(CLK := bClk); ft(CLK := bClk);
IF rt.Q THEN nRise := nRise + 1; END_IF;
IF ft.Q THEN nFall := nFall + 1; END_IF;
cu(CU := bClk, R := bReset, PV := 3);
cd(CD := bClk, LD := bReset, PV := 2);
cud(CU := bClk, CD := FALSE, R := bReset, LD := FALSE, PV := 2);
fbSr(S1 := bClk, R := bReset); fbRs(S := bClk, R1 := bReset);
END_FUNCTION_BLOCK
"""
    fb = load_st(src).instance("FB_C")
    fb.bReset = True
    fb.scan()
    fb.bReset = False
    for clk in [False, True, True, False, True, False, True, False]:
        fb.bClk = clk
        fb.scan()
    assert (fb.nRise, fb.nFall) == (3, 3)
    assert (fb.cu.CV, fb.cu.Q) == (3, True)
    assert (fb.cd.CV, fb.cd.Q) == (-1, True)
    assert (fb.cud.CV, fb.cud.QU) == (3, True)
    assert fb.fbSr.Q1 is True and fb.fbRs.Q1 is True
    fb.bClk, fb.bReset = True, True
    fb.scan()
    assert fb.fbSr.Q1 is True      # set dominant
    assert fb.fbRs.Q1 is False     # reset dominant
    assert fb.cu.CV == 0


def test_timer_resolution_option_counts_in_ticks():
    fb = load_st(TIMERS, scan_ms=10, timer_resolution_ms=100).instance("FB_T")
    fb.bInput = True
    fb.scan(9)          # 0 .. 80 ms: no 100 ms tick yet
    assert fb.fbOn.ET == 0
    fb.scan(2)          # 100 ms
    assert fb.fbOn.ET == 100 and fb.fbOn.Q is True


def test_bad_scan_options_are_load_errors():
    import pytest

    from verifier.sim import LoadError

    with pytest.raises(LoadError, match="jitter"):
        load_st(TIMERS, scan_ms=10, jitter_ms=10)
    with pytest.raises(LoadError, match="timer resolution"):
        load_st(TIMERS, timer_resolution_ms=0)


@pytest.mark.parametrize("resolution", [7, 1000, 10.0, True, "10"])
def test_a_timer_resolution_no_cpu_timer_has_is_refused_naming_the_ones_it_has(resolution):
    with pytest.raises(LoadError) as err:
        load_st(TIMERS, timer_resolution_ms=resolution)
    assert (f"verifier.load(timer_resolution_ms={resolution!r}): error: the timer resolution (timer_resolution_ms) must be 1, 10 or 100 ms, "
            f"the resolutions the CPU's timers count in; got {resolution!r}") in str(err.value)
