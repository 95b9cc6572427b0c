"""A FOR loop whose whole body copies one array element into another (`dst[i + a] :=
src[i + b]`: the 16-word copies of the port FBs) runs as one slice assignment
(verifier.sim.codegen, `_copy_loop_as_slice`): the same elements and the same final counter
as the element-by-element loop, which still runs when both names hold the same array."""
from __future__ import annotations

import json
from pathlib import Path

import pytest

from sim_helpers import comparable, load_st
from verifier.sim import codegen, compiler
from verifier.verify.report_json import to_dict
from verifier.verify.runner import run_scenario
from verifier.verify.scenario import load_scenario

ROOT = Path(__file__).resolve().parent.parent

COPY = """
FUNCTION_BLOCK FB_COPY
VAR_IN_OUT
    io_aDst : ARRAY[0..9] OF INT;
    io_aSrc : ARRAY[0..9] OF INT;
END_VAR
VAR
    wIndex : INT;
END_VAR
FOR wIndex := 0 TO 5 DO
    io_aDst[wIndex + 2] := io_aSrc[wIndex];
END_FOR;
END_FUNCTION_BLOCK

PROGRAM P
VAR
    fbApart, fbSame : FB_COPY;
    aSrc, aDst, aOne : ARRAY[0..9] OF INT;
    aLow : ARRAY[1..8] OF INT;
    aHigh : ARRAY[0..7] OF INT;
    i, k : INT;
END_VAR
FOR i := 0 TO 9 DO
    aSrc[i] := i + 1;
    aOne[i] := 10 * (i + 1);
END_FOR;
fbApart(io_aDst := aDst, io_aSrc := aSrc);
fbSame(io_aDst := aOne, io_aSrc := aOne);
FOR k := 1 TO 8 DO
    aHigh[k - 1] := aLow[k];
END_FOR;
END_PROGRAM
"""


def _copy(source: str):
    project = load_st(source)
    program = project.program("P")
    program.aLow[3] = 33
    program.aLow[8] = 88
    project.run_programs(["P"], scans=1)
    return project, program


def test_a_copy_loop_is_one_slice_and_copies_the_same_elements():
    project, p = _copy(COPY)
    source = project.module.source
    assert "[2:8] = " in source and "[0:8] = " in source  # the two copies between two arrays
    assert list(p.aDst) == [0, 0, 1, 2, 3, 4, 5, 6, 0, 0]
    assert p.fbApart.wIndex == 6 and p.k == 9  # the counter as the loop leaves it
    assert list(p.aHigh) == [0, 0, 33, 0, 0, 0, 0, 88]


def test_a_copy_within_one_array_goes_element_by_element():
    """fbSame copies aOne onto itself two places up: element by element, each copied value
    is copied again further on (a slice would copy the old values)."""
    _, p = _copy(COPY)
    assert list(p.aOne) == [10, 20, 10, 20, 10, 20, 10, 20, 90, 100]
    assert p.fbSame.wIndex == 6


def _without_slices(monkeypatch) -> None:
    monkeypatch.setattr(codegen.BodyCompiler, "_copy_loop_as_slice", lambda *args: None)
    compiler._GENERATED.clear()  # compile again, not from the cache


@pytest.mark.parametrize("name", ["fx3u-healthy", "q-tcp-split", "fx5u-tcp-healthy", "q-healthy",
                                  "fx5u-adprw-healthy"])
def test_bundled_scenarios_give_the_same_report_with_and_without_slices(name, monkeypatch):
    scenario = load_scenario(ROOT / "plc" / "scenarios" / f"{name}.toml")
    compiler._GENERATED.clear()
    fast = run_scenario(scenario)
    _without_slices(monkeypatch)
    loops = run_scenario(scenario)
    compiler._GENERATED.clear()
    assert comparable(fast) == comparable(loops)
    fast.wall_s = loops.wall_s = 0.0
    assert json.dumps(to_dict([fast]), sort_keys=True) == json.dumps(to_dict([loops]), sort_keys=True)


def test_the_port_fbs_copies_are_slices():
    """The FX3U example's 16-word copies (engine to port, port to reply) run as slices."""
    import verifier

    scenario = load_scenario(ROOT / "plc" / "scenarios" / "fx3u-healthy.toml")
    project = verifier.load(*[str(p) for p in scenario.sources], cpu=scenario.platform,
                            programs=[scenario.program])
    source = project.module.source
    assert "self.io_uPort[8:24] = self.uTx[0:16]" in source
    assert "self.uRx[0:16] = self.io_uPort[24:40]" in source
