"""`run_scenario` keeps what existed before the run out of the garbage collector's full
passes while it scans (gc.freeze), and gives it back at the end (gc.unfreeze): the result
is the same either way, and a caller that froze objects itself keeps them frozen."""
from __future__ import annotations

import gc
from dataclasses import replace
from pathlib import Path

from sim_helpers import comparable
from verifier.verify.runner import run_scenario
from verifier.verify.scenario import load_scenario

SCENARIO = Path(__file__).resolve().parent.parent / "plc" / "scenarios" / "fx3u-healthy.toml"


def _run_seeing_frozen(**kwargs):
    """The result, and the frozen-object counts seen on each progress step of the run."""
    seen: list[int] = []
    result = run_scenario(replace(load_scenario(SCENARIO), duration_us=3_000_000),
                          progress=lambda now, end: seen.append(gc.get_freeze_count()), **kwargs)
    return result, seen


def test_the_objects_made_before_a_run_are_frozen_while_it_runs_and_only_then():
    assert gc.get_freeze_count() == 0
    result, seen = _run_seeing_frozen()
    assert len(seen) == 3 and min(seen) > 1000  # the compiled program, the scenario, ...
    assert gc.get_freeze_count() == 0
    plain, _ = _run_seeing_frozen(plain=True)
    assert comparable(result) == comparable(plain)


def test_a_callers_frozen_objects_stay_frozen(monkeypatch):
    """The run neither freezes more nor thaws the caller's objects. (It compared the frozen
    count with the one before the run: a frozen object the run frees - an entry an earlier
    test left in a cache the run evicts - lowered it, and the full suite failed on it once.)"""
    calls = []
    monkeypatch.setattr(gc, "freeze", lambda real=gc.freeze: (calls.append("freeze"), real())[1])
    monkeypatch.setattr(gc, "unfreeze", lambda real=gc.unfreeze: (calls.append("unfreeze"), real())[1])
    gc.freeze()
    try:
        frozen = gc.get_freeze_count()
        calls.clear()
        _, seen = _run_seeing_frozen()
        assert calls == []  # left as the caller had them
        assert len(seen) == 3 and all(0 < count <= frozen for count in seen)
        assert 0 < gc.get_freeze_count() <= frozen
    finally:
        gc.unfreeze()


def test_a_run_with_the_collector_off_leaves_it_off_and_freezes_nothing():
    gc.disable()
    try:
        _, seen = _run_seeing_frozen()
        assert seen == [0] * 3 and not gc.isenabled()
    finally:
        gc.enable()
