"""Clock relays (docs/instructions.md §2): FX3 M8011-M8014 and Q/FX5 SM409-SM415 toggle
with their manual periods in virtual time, OFF for the first half of each period."""
from __future__ import annotations

import pytest

from sim_helpers import load_st

WATCH = "PROGRAM P\nVAR n : INT; END_VAR\nn := n + 1;\nEND_PROGRAM\n"


def samples(project, relay: str, scans: int) -> list[bool]:
    seen = []
    for _ in range(scans):
        project.run_programs(["P"], scans=1)
        seen.append(project.devices[relay])
    return seen


def half_periods(seen: list[bool]) -> list[int]:
    """Lengths (in scans) of the runs of equal values, the first and last run left out."""
    runs, count = [], 1
    for a, b in zip(seen, seen[1:]):
        if a == b:
            count += 1
        else:
            runs.append(count)
            count = 1
    return runs[1:]


@pytest.mark.parametrize("target, cpu, relay, period_ms, scan_ms", [
    ("gxworks2", "fx3u", "M8011", 10, 1),
    ("gxworks2", "fx3u", "M8012", 100, 10),
    ("gxworks2", "fx3u", "M8013", 1000, 10),
    ("gxworks2", "fx3u", "M8014", 60000, 1000),
    ("gxworks2:q", "q", "SM409", 10, 1),
    ("gxworks2:q", "q", "SM410", 100, 10),
    ("gxworks2:q", "q", "SM411", 200, 10),
    ("gxworks2:q", "q", "SM412", 1000, 10),
    ("gxworks2:q", "q", "SM413", 2000, 100),
    ("gxworks3", "fx5u", "SM412", 1000, 10),
])
def test_fixed_clock_relays(target, cpu, relay, period_ms, scan_ms):
    project = load_st(WATCH, target=target, cpu=cpu, scan_ms=scan_ms)
    seen = samples(project, relay, 5 * period_ms // scan_ms)
    assert seen[0] is False                                  # OFF from power-on for half a period
    assert set(half_periods(seen)) == {period_ms // 2 // scan_ms}


def test_2n_clocks_follow_sd414_and_sd415():
    project = load_st(WATCH, target="gxworks2:q", cpu="q", scan_ms=10)
    assert project.devices["SD414"] == 30 and project.devices["SD415"] == 30  # power-on values
    seen = samples(project, "SM415", 60)
    assert set(half_periods(seen)) == {3}                       # 2 x 30 ms
    project.devices["SD415"] = 50
    project.run_programs(["P"], ms=100)
    assert set(half_periods(samples(project, "SM415", 60))) == {5}   # 2 x 50 ms
    project.devices["SD414"] = 1
    assert set(half_periods(samples(project, "SM414", 500))) == {100}  # 2 x 1 s at 10 ms scans
    project.restart()
    assert project.devices["SD414"] == 30                       # written again at power-on
