"""The watched labels and expectation inputs are read through accessors resolved once and
recorded only when one changed (issue 12); the result must be the one of the plain path
that reads every label by its name on every scan - for every bundled scenario."""
from __future__ import annotations

from dataclasses import asdict
from pathlib import Path

import pytest

from verifier.verify.runner import run_scenario
from verifier.verify.scenario import load_scenario

SCENARIOS = sorted((Path(__file__).resolve().parent.parent / "plc" / "scenarios").glob("*.toml"))


def _comparable(result) -> dict:
    data = asdict(result)
    data.pop("wall_s")
    return data


@pytest.mark.parametrize("path", SCENARIOS, ids=lambda p: p.stem)
def test_fast_sampling_gives_the_plain_result(path):
    scenario = load_scenario(path)
    fast = run_scenario(scenario)
    plain = run_scenario(scenario, plain=True)
    assert _comparable(fast) == _comparable(plain)
