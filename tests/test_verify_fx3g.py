"""`uitamr verify` on the FX3G: `--platform fx3g` and `platform = "fx3g"` run the FX3
library and examples on the FX3G CPU profile (GX Works2, port fx3:1, the FX3's serial
channels), as `uitamr check --platform fx3g` and `uitamr export --platform fx3g` already
took it; a device only the FX3U has is an error at its file:line:col there. The FX3G is
named, never told from the sources: what loads on it loads on the FX3U too."""
from __future__ import annotations

import ast
import json
import re
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest
from click.testing import CliRunner

from verifier.cli import main
from verifier.commands.verify import bundled_scenarios, command
from verifier.verify.scenario import ScenarioError, load_scenario, parse_scenario

REPO = Path(__file__).resolve().parents[1]
PLC = REPO / "plc"
HEALTHY = PLC / "scenarios" / "fx3u-healthy.toml"
FX3_DIRS = [PLC / "core", PLC / "fx3", PLC / "examples" / "common"]
EXAMPLE = PLC / "examples" / "fx3" / "UITAMR_ExampleFx3.st"


def invoke(*args) -> object:
    return CliRunner().invoke(command, [str(a) for a in args], catch_exceptions=False)


def report(path: Path) -> dict:
    return json.loads(path.read_text(encoding="utf-8"))


def test_verify_offers_every_cpu_check_offers_fx3g_among_them():
    from verifier.sim.cpu import PROFILES
    from verifier.verify.scenario import PLATFORMS

    assert set(PLATFORMS) == set(PROFILES)
    shown = invoke("--help")
    assert shown.exit_code == 0 and "[fx3g|fx3u|fx5u|q]" in shown.output
    refused = invoke("--platform", "fx3x")
    assert refused.exit_code == 2
    assert "'fx3x' is not one of 'fx3g', 'fx3u', 'fx5u', 'q'" in refused.output


def test_the_fx3u_healthy_scenario_gives_the_same_run_on_the_fx3g(tmp_path):
    """The bundled FX3 example uses no device the FX3G lacks: the same frames, expectations
    and verdict, the platform named fx3g in the report."""
    runs = {}
    for platform in ("fx3u", "fx3g"):
        path = tmp_path / f"{platform}.json"
        done = invoke("--scenario", HEALTHY, "--platform", platform, "--json", path,
                      "--junit", tmp_path / f"{platform}.xml", "--html", tmp_path / f"{platform}.html")
        assert done.exit_code == 0, done.output
        assert f"PASS {load_scenario(HEALTHY).name}" in done.output and f"UITAMR_ExampleFx3 on {platform}," in done.output
        (runs[platform],) = report(path)["scenarios"]
    (case,) = ET.parse(tmp_path / "fx3g.xml").getroot().iter("testcase")
    assert case.get("classname").endswith(".fx3g")
    assert "<code>UITAMR_ExampleFx3</code> on fx3g (fx3:1)" in (tmp_path / "fx3g.html").read_text(encoding="utf-8")
    fx3g = runs["fx3g"]
    assert (fx3g["verdict"], fx3g["platform"], fx3g["channel"]) == ("pass", "fx3g", "fx3:1")
    assert all(e["passed"] for e in fx3g["expectations"]) and len(fx3g["expectations"]) == 5
    assert {k: v for k, v in fx3g.items() if k != "platform"} == {k: v for k, v in runs["fx3u"].items()
                                                                  if k != "platform"}


def test_a_scenario_file_may_name_the_fx3g_with_the_fx3_channels():
    scenario = parse_scenario('platform = "FX3G"\n')
    assert (scenario.platform, scenario.target, scenario.serial_channel) == ("fx3g", "gxworks2", "fx3:1")
    for channel in ("fx3:2", "adp:1"):
        assert parse_scenario(f'platform = "fx3g"\nchannel = "{channel}"\n').serial_channel == channel
    with pytest.raises(ScenarioError) as error:
        parse_scenario('platform = "fx3g"\nchannel = "fx5:1"\n')
    assert str(error.value) == ("scenario:2:11: channel: channel fx5:1 does not exist on the fx3g CPU; "
                                "the fx3g CPU has fx3:1, fx3:2, adp:1")
    with pytest.raises(ScenarioError) as error:
        parse_scenario('platform = "fx3gx"\n')
    assert error.value.message == "unknown platform 'fx3gx'; expected one of fx3u, fx3g, fx5u, q"
    with pytest.raises(ScenarioError) as error:  # no Ethernet port the library drives
        parse_scenario('platform = "fx3g"\n[converter]\n')
    assert error.value.key == "converter" and "this scenario's platform is 'fx3g'" in error.value.message


def test_a_scenario_file_with_platform_fx3g_runs_on_the_fx3g(tmp_path):
    text = HEALTHY.read_text(encoding="utf-8").replace('platform = "fx3u"', 'platform = "fx3g"')
    sources = [str(PLC / part) for part in ("core/*.st", "fx3/*.st", "examples/common/*.st", "examples/fx3/*.st")]
    text = re.sub(r"^sources = .*$", lambda _: f"sources = {json.dumps(sources)}", text, count=1, flags=re.M)
    scenario = tmp_path / "fx3g-healthy.toml"
    scenario.write_text(text, encoding="utf-8")
    assert load_scenario(scenario).platform == "fx3g"
    path = tmp_path / "r.json"
    done = invoke("--scenario", scenario, "--json", path)
    assert done.exit_code == 0, done.output
    (run,) = report(path)["scenarios"]
    assert (run["verdict"], run["platform"], run["channel"]) == ("pass", "fx3g", "fx3:1")
    checked = CliRunner().invoke(main, ["check", str(scenario)])
    assert checked.exit_code == 0, checked.output


def _example_with_fx3u_devices(tmp_path: Path) -> tuple[Path, int, int]:
    """The FX3 example with Y200 and R24000: devices the FX3U has and the FX3G lacks
    (X/Y0..177 octal, R0..23999 on the FX3G); (path, line of Y200, line of R24000)."""
    text = EXAMPLE.read_text(encoding="utf-8")
    text = text.replace("Y5 := fbEngine.o_bBatteryLow;", "Y200 := fbEngine.o_bBatteryLow;")
    text = text.replace("D105 := fbEngine.o_wRobotErr;", "R24000 := fbEngine.o_wRobotErr;")
    path = tmp_path / "UITAMR_ExampleFx3.st"
    path.write_text(text, encoding="utf-8")
    lines = text.split("\n")
    return path, lines.index("Y200 := fbEngine.o_bBatteryLow;") + 1, lines.index("R24000 := fbEngine.o_wRobotErr;") + 1


def test_a_device_only_the_fx3u_has_is_an_error_at_its_place_on_the_fx3g(tmp_path):
    path, y_line, r_line = _example_with_fx3u_devices(tmp_path)
    sources = [*FX3_DIRS, path]
    on_fx3u = invoke(*sources, "--platform", "fx3u", "--duration", "3s")
    assert on_fx3u.exit_code == 0, on_fx3u.output
    on_fx3g = invoke(*sources, "--platform", "fx3g", "--duration", "3s")
    assert on_fx3g.exit_code == 2 and "Traceback" not in on_fx3g.output
    assert f"{path}:{y_line}:1: error: device Y200 does not exist on the fx3g: Y runs Y0..Y177" in on_fx3g.output
    # the program does not fit the CPU named: not "give --platform fx3u", as if the platform were wrong
    assert ("--platform fx3g: the sources load on the fx3u but not on the fx3g, which has fewer devices "
            "(docs/instructions.md §2; `uitamr check --platform fx3g` lists every one it lacks): for an FX3G "
            "use devices it has; for an FX3U give --platform fx3u") in " ".join(on_fx3g.output.split())
    checked = CliRunner().invoke(main, ["check", "--platform", "fx3g", *map(str, sources)])
    assert checked.exit_code == 1
    assert [line.split(": error: ")[0] for line in checked.output.splitlines() if ": error: " in line] == [
        f"{path}:{y_line}:1", f"{path}:{r_line}:1"]
    # the same from a scenario file's platform key, placed at its line
    scenario = tmp_path / "mine.toml"
    scenario.write_text(f'sources = {json.dumps([str(p) for p in sources])}\nplatform = "fx3g"\nduration = "3s"\n',
                        encoding="utf-8")
    from_file = invoke("--scenario", scenario)
    assert from_file.exit_code == 2
    assert f"{scenario}:2:12: platform: the sources load on the fx3u but not on the fx3g" in from_file.output
    # the file's key is what names the CPU: changing it is said, beside the option
    assert (f"for an FX3U set platform = \"fx3u\" in {scenario} (or give --platform fx3u)"
            in " ".join(from_file.output.split()))
    # a device the scenario sets: refused before the first scan, at its key
    healthy = tmp_path / "initial.toml"
    healthy.write_text(f'sources = {json.dumps([str(p) for p in (*FX3_DIRS, EXAMPLE)])}\nplatform = "fx3g"\n'
                       'duration = "3s"\n\n[initial]\nX200 = true\n', encoding="utf-8")
    refused = invoke("--scenario", healthy)
    assert refused.exit_code == 2
    assert f"{healthy}:6:8: initial.X200: device X200 does not exist on the fx3g: X runs X0..X177" in refused.output


def _bundled_names(platform: str) -> list[str]:
    return [s.name for s in map(load_scenario, bundled_scenarios()) if s.platform == platform]


def test_platform_fx3g_without_sources_runs_its_own_and_the_fx3u_bundled_scenarios_on_the_fx3g(tmp_path):
    """Its own fx3g-* scenarios and the FX3U's, all on the FX3G; only the FX3U's carry the
    note that they were written for another CPU. Before the FX3G had scenarios of its own,
    --platform fx3g picked the FX3U's only, and would have left the fx3g-* files out."""
    path = tmp_path / "fx3g.json"
    invoke("--platform", "fx3g", "--duration", "1s", "--json", path)  # 1 s: the verdict is not the point
    runs = report(path)["scenarios"]
    own, fx3u = _bundled_names("fx3g"), _bundled_names("fx3u")
    assert own and fx3u
    assert sorted(r["name"] for r in runs) == sorted(own + fx3u)
    assert {r["platform"] for r in runs} == {"fx3g"}
    note = "written for the fx3u, run on the fx3g CPU profile (--platform fx3g)"
    assert sorted(r["name"] for r in runs if note in r["notes"]) == sorted(fx3u)
    # the FX3U's own run picks none of the FX3G's
    fx3u_path = tmp_path / "fx3u.json"
    invoke("--platform", "fx3u", "--duration", "1s", "--json", fx3u_path)
    assert sorted(r["name"] for r in report(fx3u_path)["scenarios"]) == sorted(fx3u)


def test_matrix_on_the_fx3g_runs_the_fx3u_fault_sets_and_its_own(tmp_path):
    sources = [*FX3_DIRS, EXAMPLE]
    found = {}
    for platform in ("fx3u", "fx3g"):
        path = tmp_path / f"{platform}.json"
        done = invoke(*sources, "--matrix", "--platform", platform, "--duration", "1s", "--json", path)
        assert done.exit_code in (0, 1), done.output
        found[platform] = report(path)["scenarios"]
    # a fault set that became the same run as another's (the same faults, cut to 1 s) runs
    # once, its note naming the others
    stands_for = re.compile(r"^also stands for (.*) \(the same run\)$")
    covered = {platform: [r["name"] for r in runs] + [ast.literal_eval(m.group(1)) for r in runs for n in r["notes"]
                                                      if (m := stands_for.match(n))]
               for platform, runs in found.items()}
    assert covered["fx3u"] and not set(covered["fx3u"]) & set(_bundled_names("fx3g"))
    assert sorted(covered["fx3g"]) == sorted(covered["fx3u"] + _bundled_names("fx3g"))
    assert {r["platform"] for r in found["fx3g"]} == {"fx3g"}


FX3G_SCENARIOS = sorted((PLC / "scenarios").glob("fx3g-*.toml"))


def test_the_fx3g_has_bundled_scenarios_of_its_own_on_its_rs2_and_modbus_channels():
    """An FX3G integrator's bundled proof and the files to start from: a healthy run and
    faults, on the FX3G's RS2 channel 1 (FX3G-485-BD) and on the MODBUS master (adp:1)."""
    scenarios = {path.stem: load_scenario(path) for path in FX3G_SCENARIOS}
    assert {"fx3g-healthy", "fx3g-no-reply", "fx3g-bad-crc-persistent"} <= set(scenarios)
    assert {s.platform for s in scenarios.values()} == {"fx3g"}
    assert {s.serial_channel for s in scenarios.values()} == {"fx3:1", "adp:1"}
    assert all(s.faults for name, s in scenarios.items() if name != "fx3g-healthy")
    checked = CliRunner().invoke(main, ["check", "--platform", "fx3g", *map(str, FX3G_SCENARIOS)])
    assert checked.exit_code == 0, checked.output


#: a change to a copy of plc/ (file, text, replacement) -> the scenario and the expectations
#: of it that must fail: the fx3g-* expectations pin what the library does on the FX3G
BROKEN = {
    "three attempts become two": ("core/UITAMR_Engine.st", "MAX_ATTEMPTS : INT := 3;", "MAX_ATTEMPTS : INT := 2;",
                                  "fx3g-no-reply", ["not reported before the third attempt has failed"]),
    "three attempts become four": ("core/UITAMR_Engine.st", "MAX_ATTEMPTS : INT := 3;", "MAX_ATTEMPTS : INT := 4;",
                                   "fx3g-adprw-no-reply",
                                   ["three attempts, then the error: two retries, three failed transactions",
                                    "the fault stays latched on the FX3G's outputs (Y3, D101) until the acknowledge"]),
    "no reply reported as 16#0103": ("core/UITAMR_Engine.st", "ERR_TIMEOUT : WORD := 16#0101;",
                                     "ERR_TIMEOUT : WORD := 16#0103;", "fx3g-no-reply",
                                     ["the failure is reported as no reply (16#0101) on the engine and the cycle",
                                      "the fault stays latched on the FX3G's outputs (Y3, D101) until the acknowledge"]),
    "a bad CRC reported as 16#0103": ("core/UITAMR_ParseReply.st", "ERR_CRC : WORD := 16#0102;",
                                      "ERR_CRC : WORD := 16#0103;", "fx3g-bad-crc-persistent",
                                      ["every reply corrupted: three attempts, then 16#0102 with detail 0 on the "
                                       "engine (Y4, D102) and the cycle (Y3, D101)",
                                       "the fault stays latched in the cycle (Y3, D101) until the acknowledge"]),
    "channel 2 set up too": ("fx3/UITAMR_PortFx3.st", "        D8400 := wFormat;\n",
                             "        D8400 := wFormat;\n        D8420 := wFormat;\n", "fx3g-healthy",
                             ["channel 2 is never set up: the robot is on the board's channel 1"]),
    "the adapter's time-out 500 ms": ("fx3/UITAMR_PortAdpFx3.st", "RESPONSE_TIMEOUT_MS : INT := 400;",
                                      "RESPONSE_TIMEOUT_MS : INT := 500;", "fx3g-adprw-no-reply",
                                      ["ch1 MODBUS master settings in the first scan: 400 ms slave response "
                                       "time-out (D8409), no ADPRW retries (D8412)",
                                       "the failure is reported as ADPRW no reply (16#0108) on the engine and the cycle",
                                       "the fault stays latched on the FX3G's outputs (Y3, D101) until the acknowledge"]),
}


@pytest.mark.parametrize("change", sorted(BROKEN))
def test_an_fx3g_scenario_fails_against_a_broken_copy_of_the_library(change, tmp_path):
    import shutil

    path, old, new, name, failing = BROKEN[change]
    shutil.copytree(PLC, tmp_path / "plc")
    broken = tmp_path / "plc" / path
    text = broken.read_text(encoding="utf-8")
    assert text.count(old) == 1, change
    broken.write_text(text.replace(old, new), encoding="utf-8")
    out = tmp_path / "r.json"
    done = invoke("--scenario", tmp_path / "plc" / "scenarios" / f"{name}.toml", "--json", out)
    assert done.exit_code == 1, done.output
    (run,) = report(out)["scenarios"]
    assert [e["expectation"] for e in run["expectations"] if not e["passed"]] == failing


def test_the_fx3g_is_never_told_from_the_sources(tmp_path):
    """Its devices are a part of the FX3U's, its instructions the FX3's: what loads on an
    FX3G loads on an FX3U, so only a name makes a run an FX3G's."""
    from verifier.commands.verify import _CHANNEL_PLATFORMS
    from verifier.sim.cpu import FX3G, FX3U

    assert FX3G.family == FX3U.family
    for name, area in FX3G.areas.items():
        assert FX3U.areas[name].size >= area.size and FX3U.areas[name].radix == area.radix, name
    assert _CHANNEL_PLATFORMS["fx3"] == "fx3u"
    plain = tmp_path / "Plain.st"
    plain.write_text("PROGRAM Plain\nVAR\n    w : INT;\nEND_VAR\nw := w + 1;\nEND_PROGRAM\n", encoding="utf-8")
    done = invoke(plain, "--matrix")
    assert done.exit_code == 2
    assert "they load on fx3u, fx5u, q alike" in done.output and "say --platform fx3u|fx3g|fx5u|q" in done.output
    path = tmp_path / "r.json"
    assert invoke(*FX3_DIRS, EXAMPLE, "--duration", "2s", "--json", path).exit_code == 0
    assert report(path)["scenarios"][0]["platform"] == "fx3u"
