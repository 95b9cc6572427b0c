"""The watched labels and expectation inputs are read through accessors resolved once and
recorded only when one changed (issue 12); the result must be the one of the plain path
that reads every label by its name on every scan - for every bundled scenario."""
from __future__ import annotations

from pathlib import Path

import pytest

from sim_helpers import comparable
from verifier.verify.runner import run_scenario
from verifier.verify.scenario import load_scenario

SCENARIOS = sorted((Path(__file__).resolve().parent.parent / "plc" / "scenarios").glob("*.toml"))


@pytest.mark.parametrize("path", SCENARIOS, ids=lambda p: p.stem)
def test_fast_sampling_gives_the_plain_result(path):
    scenario = load_scenario(path)
    fast = run_scenario(scenario)
    plain = run_scenario(scenario, plain=True)
    assert comparable(fast) == comparable(plain)


def test_read_together_merges_slots_and_cells_and_calls_the_rest():
    """Plain labels and device words become attribute loads and list indexing in one
    generated function; anything else (a computed label, a bit of a word) is called; the
    tuple follows the values as they change, in the readers' order."""
    from verifier.sim.values import _slot_reader, read_together

    class Labels:
        __slots__ = ("o_wCount", "bDone")

    labels = Labels()
    labels.o_wCount, labels.bDone = 1, False
    cells = [0, 10, 20]

    def word():
        return cells[2]
    word.item = (cells, 2)
    computed = [7]
    readers = [_slot_reader(labels, "o_wCount"), word, lambda: computed[0], _slot_reader(labels, "bDone")]
    read_all = read_together(readers)
    assert read_all() == (1, 20, 7, False)
    labels.o_wCount, cells[2], computed[0], labels.bDone = 2, 21, 8, True
    assert read_all() == (2, 21, 8, True)
    assert read_together([])() == ()


def test_read_together_calls_a_reader_whose_slot_is_a_python_keyword():
    """A slot named like a Python keyword cannot be an attribute load in generated code."""
    from verifier.sim.values import _slot_reader, read_together

    class Odd:
        pass

    odd = Odd()
    setattr(odd, "pass", 5)
    assert read_together([_slot_reader(odd, "pass")])() == (5,)


def test_the_trace_shares_the_bytes_of_equal_frames_and_stops_at_the_end():
    """A long run repeats the same status poll and reply thousands of times: each distinct
    frame is held once. Frames that start at or after the end of the run are not in it."""
    from verifier.verify.result import TraceRecord
    from verifier.verify.runner import _trace_records

    poll, reply = b"\x01\x01\x03\x00\x00\x08\x3c\x4c", b"\x01\x01\x01\x00\x51\x88"
    frames = [TraceRecord(t, t + 8333, "tx", bytes(bytearray(poll)), "a.st:1:1") for t in (0, 100, 200)]
    frames += [TraceRecord(300, 306, "rx", bytes(bytearray(reply)))]
    records = _trace_records(list(frames), 300)
    assert records == frames[:3]
    assert len({id(r.data) for r in records}) == 1
    scenario = load_scenario(SCENARIOS[[p.stem for p in SCENARIOS].index("fx3u-healthy")])
    trace = run_scenario(scenario).trace
    assert len({id(r.data) for r in trace}) == len({r.data for r in trace}) < len(trace)
    assert trace and all(r.t_start_us < scenario.duration_us for r in trace)
