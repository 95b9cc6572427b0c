"""A run judged as it goes (verifier.verify.stream: what `uitamr verify` does when no
report lists every frame) finds exactly what the same run judged as a whole finds: the
same violations in the same order, the same expectation results, notes, events and
frame counts - on every bundled scenario and on random ones with faults, converters,
inputs and every kind of expectation. The exchanges it lets go of along the way are let
go of early and often here (COMPACT_AT patched small, the frames taken every virtual
second), so that path is exercised too."""
from __future__ import annotations

import shutil
from dataclasses import asdict
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from test_idle_skip import robot_scenarios
from test_verify_pipeline import FX3_EXAMPLE, VARIANTS, library_copy
from verifier.verify import runner as runner_module
from verifier.verify import stream as stream_module
from verifier.verify.result import KEEP_ALL, Keep
from verifier.verify.runner import run_scenario
from verifier.verify.scenario import load_scenario, parse_scenario

ROOT = Path(__file__).resolve().parent.parent
SCENARIOS = sorted((ROOT / "plc" / "scenarios").glob("*.toml"))
STREAMED = Keep(frames=False, details=True)


def _findings(result) -> dict:
    data = asdict(result)
    for key in ("trace", "frame_counts", "wall_s"):
        data.pop(key)
    data["counts"] = (result.tx_count, result.rx_count)
    return data


def _same(scenario, monkeypatch, compact_at: int, every_us: int = 0) -> tuple:
    monkeypatch.setattr(stream_module, "COMPACT_AT", compact_at)
    monkeypatch.setattr(runner_module, "STREAM_EVERY_US", every_us)  # 0: every virtual second
    whole = run_scenario(scenario, keep=KEEP_ALL)
    streamed = run_scenario(scenario, keep=STREAMED)
    assert streamed.trace == []
    assert _findings(streamed) == _findings(whole)
    return whole, streamed


@pytest.mark.parametrize("path", SCENARIOS, ids=lambda p: p.stem)
def test_bundled_scenarios_streamed_find_the_same(path, monkeypatch):
    whole, _ = _same(load_scenario(path), monkeypatch, compact_at=2)
    assert whole.tx_count > 0


def test_a_long_run_lets_go_of_what_it_judged(monkeypatch):
    """10 minutes of fx3u-healthy, the frames taken as the command takes them: what the
    stream still holds at the end is bounded, not the run's two thousand exchanges."""
    made = []
    original = stream_module.Stream.finish

    def spy(self, *args, **kwargs):
        made.append(len(self.pairing.traffic.exchanges))
        return original(self, *args, **kwargs)

    monkeypatch.setattr(stream_module.Stream, "finish", spy)
    text = (ROOT / "plc" / "scenarios" / "fx3u-healthy.toml").read_text(encoding="utf-8")
    text = text.replace('duration = "60s"', 'duration = "600s"')
    assert 'duration = "600s"' in text
    scenario = parse_scenario(text, ROOT / "plc" / "scenarios" / "long.toml")
    whole, _ = _same(scenario, monkeypatch, compact_at=stream_module.COMPACT_AT, every_us=runner_module.STREAM_EVERY_US)
    assert whole.tx_count > 1900
    # at most one step of COMPACT_AT not yet let go of, and the last ten seconds' few
    assert made and made[-1] < stream_module.COMPACT_AT + 100


EXPECTATIONS = st.lists(st.sampled_from([
    '[[expect]]\nsent = "stop"',
    '[[expect]]\nsent = "run-point 2"\nafter = "3s"\nwithin = "20s"',
    '[[expect]]\nreached_point = 1',
    '[[expect]]\nreached_point = 2\nwithin = "25s"',
    '[[expect]]\nthat = "fbEngine.o_wTxCount > 5"\nwithin = "4s"',
    '[[expect]]\nalways = "fbEngine.o_wRetryCount < 3"',
    '[[expect]]\nnever = "fbEngine.o_wCommErrCount > 0"\nafter = "2s"',
    '[response_handling]\nsignal = "fbEngine.o_bErr"\nwithin = "1s"',
]), max_size=4, unique=True)


@settings(max_examples=25, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(text=robot_scenarios(), extra=EXPECTATIONS, compact_at=st.sampled_from([1, 2, 5]),
       every_s=st.sampled_from([0, 1, 3]))
def test_random_scenarios_streamed_find_the_same(text, extra, compact_at, every_s, monkeypatch):
    head, sep, tail = text.partition("[robot]")
    response = [e for e in extra if e.startswith("[response_handling]")]
    text = head + "\n".join(response) + "\n" + sep + tail + "\n".join(e for e in extra if e not in response) + "\n"
    scenario = parse_scenario(text, ROOT / "plc" / "scenarios" / "random.toml")
    _same(scenario, monkeypatch, compact_at, every_s * 1_000_000)


@pytest.mark.parametrize("variant", sorted(VARIANTS))
def test_broken_libraries_streamed_break_the_same_rules(tmp_path, monkeypatch, variant):
    """Programs that break each rule (tests/test_verify_pipeline.py's broken copies of the
    library), run for 40 s: the violations judged as the run goes are the whole run's."""
    edits, options, _ = VARIANTS[variant]
    copy = library_copy(tmp_path, edits)
    text = FX3_EXAMPLE.format(duration="40s", robot=options.get("robot", ""), faults=options.get("faults", ""),
                              point_within="10s")
    whole, _ = _same(parse_scenario(text, copy / "scenario.toml"), monkeypatch, compact_at=2)
    assert whole.violation_count > 0


def test_a_run_the_program_stops_midway_streamed_ends_the_same(tmp_path, monkeypatch):
    """The Q example with an index that runs out of its array after 12 s of traffic: the
    Q CPU stops (an operation error), and the run judged as it goes ends where the whole
    run ends, with the same findings and expectations (one cut short by the stop)."""
    copy = tmp_path / "plc"
    shutil.copytree(ROOT / "plc", copy, ignore=shutil.ignore_patterns("ladder"))
    example = copy / "examples" / "q" / "UITAMR_ExampleQ.st"
    text = example.read_text(encoding="utf-8")
    text = text.replace("    bEngineOn : BOOL;", "    bEngineOn : BOOL;\n    iScan : INT;\n    wCrash : ARRAY[0..3] OF WORD;", 1)
    text = text.replace("bEngineOn := NOT SM402;", "bEngineOn := NOT SM402;\niScan := iScan + 1;\n"
                        "IF iScan > 1200 THEN\n    wCrash[iScan - 1197] := 1;\nEND_IF;", 1)
    example.write_text(text, encoding="utf-8")
    scenario_text = (copy / "scenarios" / "q-healthy.toml").read_text(encoding="utf-8")
    scenario = parse_scenario(scenario_text, copy / "scenarios" / "q-crash.toml")
    whole, streamed = _same(scenario, monkeypatch, compact_at=2)
    assert whole.aborted and "UITAMR_ExampleQ.st" in whole.aborted
    assert 10_000_000 < whole.ended_us < scenario.duration_us and whole.tx_count > 30
    assert whole.failed_expectations


def test_events_no_report_lists_are_let_go_of(monkeypatch):
    """A converter that splits every reply makes an event per reply: a run that keeps no
    details reads the drops among them and lets the rest go, so ten minutes hold a few,
    not thousands (each hand-over used to sort and scan them all again)."""
    from verifier.link import converter as converter_module

    made = []

    class Recorded(converter_module.Converter):
        def __init__(self, *args, **kwargs):
            super().__init__(*args, **kwargs)
            made.append(self)

    monkeypatch.setattr(runner_module, "Converter", Recorded)
    text = (ROOT / "plc" / "scenarios" / "fx5u-tcp-split.toml").read_text(encoding="utf-8")
    text = text.replace('duration = "60s"', 'duration = "600s"')
    assert 'duration = "600s"' in text
    scenario = parse_scenario(text, ROOT / "plc" / "scenarios" / "long-split.toml")
    lean = run_scenario(scenario, keep=Keep(frames=False, details=False))
    assert made[-1].event_count > 1000 and len(made[-1].events) < 100
    whole = run_scenario(scenario)
    assert (lean.violations, lean.expectations, lean.notes) == (whole.violations, whole.expectations, whole.notes)
    assert (lean.tx_count, lean.rx_count) == (whole.tx_count, whole.rx_count) and whole.tx_count > 1900
