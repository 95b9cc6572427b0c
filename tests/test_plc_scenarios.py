"""Every bundled scenario (plc/scenarios/*.toml) run against the library and examples:
no rule broken, every expectation met. This is `uitamr verify` with no arguments, one
test per scenario so a failure names its scenario."""
from __future__ import annotations

from pathlib import Path

import pytest

from verifier.verify.runner import run_scenario
from verifier.verify.scenario import load_scenario

SCENARIOS = sorted((Path(__file__).resolve().parents[1] / "plc" / "scenarios").glob("*.toml"))


def test_there_are_bundled_scenarios_for_every_platform():
    names = [p.name for p in SCENARIOS]
    for prefix in ("fx3u-", "fx5u-", "q-", "fx5u-adprw-", "fx3u-adprw-"):
        assert any(n.startswith(prefix) for n in names), prefix


@pytest.mark.parametrize("path", SCENARIOS, ids=[p.stem for p in SCENARIOS])
def test_bundled_scenario_passes(path):
    result = run_scenario(load_scenario(path))
    problems = [f"{v.rule} at {v.t_us / 1e6:.3f} s: {v.message}" for v in result.all_violations()[:5]]
    problems += [str(e.message if hasattr(e, "message") else e) for e in result.failed_expectations]
    assert result.aborted is None, result.aborted
    assert result.passed, "\n".join(problems)


@pytest.mark.parametrize("scan_us", [1_000, 60_000])
@pytest.mark.parametrize("name", ["fx3u-healthy", "fx3u-no-reply", "q-healthy"])
def test_examples_hold_the_rules_at_any_scan_time(name, scan_us):
    """Pacing, time-outs and retries are timed by TON, not by scan counting: a 1 ms and a
    60 ms scan give the same compliant traffic."""
    from dataclasses import replace
    scenario = load_scenario(SCENARIOS[0].parent / f"{name}.toml")
    result = run_scenario(replace(scenario, scan_us=scan_us))
    assert result.passed, [v.message for v in result.all_violations()[:5]] + [str(e) for e in result.failed_expectations]
