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


ADDRESS_EXAMPLES = {  # platform: (folder of its port FBs, example, its start button)
    "fx3u": ("fx3", "fx3/UITAMR_ExampleFx3", "X0"),
    "fx5u": ("fx5", "fx5/UITAMR_ExampleFx5", "X0"),
    "q": ("q", "q/UITAMR_ExampleQ", "X20"),
}


@pytest.mark.parametrize("platform", sorted(ADDRESS_EXAMPLES))
def test_an_example_with_its_address_out_of_range_sends_nothing_and_reports_0315_once(tmp_path, platform):
    """The platform example with ROBOT_ADDRESS 300, run by `uitamr verify`: the engine (the
    same on every platform) reports 16#0315 with the address as detail from the start and
    holds it, the line stays silent, and the cycle started on its button ends with 16#0315
    (it used to end with 16#0107 while the engine retried the stop, refused, every 2 s)."""
    plc = Path(__file__).resolve().parents[1] / "plc"
    ports, example, button = ADDRESS_EXAMPLES[platform]
    source = (plc / "examples" / f"{example}.st").read_text(encoding="utf-8")
    assert "ROBOT_ADDRESS : INT := 1;" in source
    name = example.split("/")[1]
    (tmp_path / f"{name}.st").write_text(source.replace("ROBOT_ADDRESS : INT := 1;", "ROBOT_ADDRESS : INT := 300;"),
                                         encoding="utf-8")
    sources = [f"{plc.as_posix()}/core/*.st", f"{plc.as_posix()}/{ports}/*.st",
               f"{plc.as_posix()}/examples/common/*.st", f"{name}.st"]
    (tmp_path / "s.toml").write_text(f"""
sources = {sources!r}
program = "{name}"
platform = "{platform}"
duration = "8s"

[[inputs]]
at = "2s"
set = {{ {button} = true }}
pulse = "500ms"

[[expect]]
always = "fbEngine.o_bErr AND fbEngine.o_uErrId = 16#0315 AND fbEngine.o_uErrDetail = 300"
after = "0.1s"

[[expect]]
never = "fbEngine.o_wTxCount <> 0 OR fbEngine.o_bInitDone OR fbEngine.o_bBusy"

[[expect]]
that = "fbCycle.o_bErr AND fbCycle.o_uErrId = 16#0315"
after = "2s"
within = "0.5s"
""".replace("'", '"'), encoding="utf-8")
    result = run_scenario(load_scenario(tmp_path / "s.toml"))
    assert result.aborted is None, result.aborted
    assert result.tx_count == 0
    assert not result.failed_expectations, [str(e.message if hasattr(e, "message") else e)
                                            for e in result.failed_expectations]
