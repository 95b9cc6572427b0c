"""Every bundled scenario (plc/scenarios/*.toml) run against the library and examples:
no rule broken, every expectation met. This is `uitamr verify` with no arguments, one
test per scenario so a failure names its scenario."""
from __future__ import annotations

import re
from pathlib import Path

import pytest

from verifier.verify.runner import run_scenario
from verifier.verify.scenario import load_scenario

ROOT = Path(__file__).resolve().parents[1]
SCENARIOS = sorted((ROOT / "plc" / "scenarios").glob("*.toml"))


def test_there_are_bundled_scenarios_for_every_platform():
    names = [p.name for p in SCENARIOS]
    for prefix in ("fx3u-", "fx3g-", "fx5u-", "q-", "fx5u-adprw-", "fx3u-adprw-"):
        assert any(n.startswith(prefix) for n in names), prefix


def squeezed(name):
    """The text of ROOT / name with every run of white space one blank (docs wrap sentences)."""
    return " ".join((ROOT / name).read_text(encoding="utf-8").split())


#: the routes of issue 9, each a bundled scenario that `uitamr verify` runs by default:
#: the two Ethernet ports through a healthy, refusing, dropping, splitting and silent
#: converter, and the FX3U's RS-232 adapter
ROUTE_SCENARIOS = {
    **{f"{platform}-tcp-{case}": (platform, True) for platform in ("fx5u", "q")
       for case in ("healthy", "refused", "dropped", "split", "no-reply")},
    "fx3u-rs232-healthy": ("fx3u", False),
}


@pytest.mark.parametrize("name", sorted(ROUTE_SCENARIOS))
def test_every_route_case_is_a_bundled_scenario_of_the_default_run(name):
    from verifier.commands.verify import bundled_scenarios

    assert ROOT / "plc" / "scenarios" / f"{name}.toml" in bundled_scenarios()
    platform, over_tcp = ROUTE_SCENARIOS[name]
    scenario = load_scenario(ROOT / "plc" / "scenarios" / f"{name}.toml")
    assert scenario.platform == platform and (scenario.converter is not None) == over_tcp


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


@pytest.mark.parametrize("scan_ms", [39, 41, 43, 51])
@pytest.mark.parametrize("name", ["fx3u-late-reply", "fx5u-late-reply"])
def test_a_retry_waits_while_a_late_reply_is_arriving(name, scan_ms):
    """At these scan times the engine's retry (after the reply time-out and the guard) fell
    due while the 800 ms late reply was on the line, and the port sent it into the robot's
    frame (UITAMR-HALF-DUPLEX; the robot could not read the retry either). The RS2 ports
    now listen before talking: while D8403 (SD8561 on the FX5) counts bytes of an
    unfinished reception the send waits, and goes once the reception has ended. The rules
    only: the scenarios' expectations are timed for their own 10 ms scan (request numbers,
    the guard restart they pin, the command the replies from 30 s meet)."""
    from dataclasses import replace
    scenario = load_scenario(SCENARIOS[0].parent / f"{name}.toml")
    result = run_scenario(replace(scenario, scan_us=scan_ms * 1000))
    assert result.aborted is None, result.aborted
    assert [v.message for v in result.all_violations()] == []


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
    plc = ROOT / "plc"
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


def test_the_fx5_adprw_example_under_a_silent_robot_times_out_as_import_gxworks3_sets_it(tmp_path):
    """The FX5's MODBUS master takes its slave response time-out from the module
    parameters, which import-gxworks3.md §4 sets to 400 ms (less than the engine's 500 ms):
    the FX3U ADPRW no-reply scenario run on the FX5U example shows the engine's three
    attempts on the line and 16#0108 (ADPRW 16#0309), as on the FX3U. With the 3 s the
    simulator took before, one frame went out and the engine's own time-outs said 16#0101."""
    import json

    guide = squeezed("docs/import-gxworks3.md")
    assert "**Slave Response Timeout 400 ms** (less than the engine's 500 ms)" in guide
    plc = (ROOT / "plc").as_posix()
    text = (ROOT / "plc" / "scenarios" / "fx3u-adprw-no-reply.toml").read_text(encoding="utf-8")
    text = (text.replace('"../fx3/UITAMR_PortAdpFx3.st"', '"../fx5/UITAMR_PortAdpFx5.st"')
            .replace("UITAMR_ExampleAdpFx3", "UITAMR_ExampleAdpFx5").replace("examples/fx3/", "examples/fx5/")
            .replace('platform = "fx3u"', 'platform = "fx5u"').replace('"../', f'"{plc}/'))
    path = tmp_path / "fx5u-adprw-no-reply.toml"
    path.write_text(text, encoding="utf-8")
    result = run_scenario(load_scenario(path))
    assert result.passed, (result.all_violations(), [e.detail for e in result.expectations])
    silent = [f for f in result.trace if f.direction == "tx" and 4_000_000 <= f.t_start_us < 6_000_000]
    assert len(silent) == 3  # the engine's three attempts, each ended by the 400 ms time-out
    assert json.dumps(result.watched["fbEngine.o_uErrId"]).count("264") >= 1  # 16#0108


def test_the_adprw_reply_window_is_the_slave_response_time_out_as_plc_library_says():
    """docs/plc-library.md: on the ADPRW route a reply 400-500 ms late is lost to ADPRW
    (D8409 = 400 ms) and the command is repeated; the default 500 ms rules see an answered
    command sent twice (UITAMR-CYCLE), reply_timeout = 400 ms a retry. The bundled
    fx3u-adprw-late-reply scenario runs both ways here."""
    from dataclasses import replace
    guide = squeezed("docs/plc-library.md")
    assert "`[rules] reply_timeout = \"400ms\"` when it has late replies" in guide
    scenario = load_scenario(ROOT / "plc" / "scenarios" / "fx3u-adprw-late-reply.toml")
    assert scenario.options.reply_timeout_us == 400_000
    assert run_scenario(scenario).passed
    default = run_scenario(replace(scenario, options=replace(scenario.options, reply_timeout_us=500_000)))
    assert [v.rule for v in default.all_violations()] == ["UITAMR-CYCLE"]


def test_the_rs232_choice_is_read_in_the_first_scan_only_as_wiring_rs232_says(tmp_path):
    """docs/wiring-rs232.md said bUseRs232 could come 'from an input before the engine
    starts'; the port reads it in its first scan only. Set at 1 s, D8400 keeps the RS-485
    format H1C81 for the whole run, and the guide now says so."""
    import json
    guide = squeezed("docs/wiring-rs232.md")
    assert "It reads `i_bRs232` only in that first scan" in guide
    plc = (ROOT / "plc").as_posix()
    text = (ROOT / "plc" / "scenarios" / "fx3u-rs232-healthy.toml").read_text(encoding="utf-8")
    text = text.split("[[expect]]")[0].replace('at = "0s"', 'at = "1s"').replace('"../', f'"{plc}/')
    path = tmp_path / "rs232-late.toml"
    path.write_text(text + '\n[[expect]]\nalways = "D8400 = 16#1C81"\nafter = "20ms"\nwithin = "59s"\n', encoding="utf-8")
    result = run_scenario(load_scenario(path))
    assert result.passed, [str(e) for e in result.failed_expectations]
    assert json.dumps(result.watched["D8400"]).count(str(0x0081)) == 0


def test_the_fx3u_adprw_import_guide_names_the_modbus_setup_the_library_does_not_write():
    """An ADPRW integrator following import-gxworks2.md §5 found parameters for RS2 and the
    QJ71C24N but nothing for the FX3U-485ADP-MB, whose master mode and line format neither
    the port nor the example writes. The guide now names them; the protocol word it gives
    follows the D8401 bit table it cites (b0 MODBUS, b4 0 = master, b8 0 = RTU)."""
    guide = squeezed("docs/import-gxworks2.md")
    assert "**FX3U + FX3U-485ADP-MB (ADPRW, `UITAMR_PortAdpFx3`" in guide
    assert "D8401 = H0001" in guide
    modbus, master, rtu = 1 << 0, 0 << 4, 0 << 8
    assert modbus | master | rtu == 0x0001
    example = (ROOT / "plc" / "examples" / "fx3" / "UITAMR_ExampleAdpFx3.st").read_text(encoding="utf-8")
    port = (ROOT / "plc" / "fx3" / "UITAMR_PortAdpFx3.st").read_text(encoding="utf-8")
    body = lambda text: text.split("END_VAR")[-1]
    # what the guide says the library leaves to the integrator, it indeed leaves
    assert "D8401" not in body(example) + body(port) and "D8400" not in body(example) + body(port)
    assert "D8409 := RESPONSE_TIMEOUT_MS" in port and "D8412 := RETRIES" in port


def test_plc_readme_sends_the_485adp_mb_integrator_to_rs485_wiring_not_rs232():
    """plc/README.md's ADPRW row said 'same' guide as the row above it, which is the RS-232
    route's (import-gxworks2 + wiring-rs232): an FX3U-485ADP-MB integrator was sent to the
    RS-232 cable page."""
    rows = [line for line in (ROOT / "plc" / "README.md").read_text(encoding="utf-8").splitlines()
            if line.startswith("| FX3U + FX3U-485ADP-MB (ADPRW)")]
    assert len(rows) == 1
    guides = rows[0].split("|")[4]
    assert "wiring-rs485.md" in guides and "import-gxworks2.md" in guides and "wiring-rs232" not in guides


@pytest.mark.parametrize("stop_at", ["2.5s", "2.55s"])
def test_the_stop_button_right_after_a_point_command_breaks_no_rule(tmp_path, stop_at):
    """The example sends the stop at once when X1 comes, even right after the run-point
    command and before the status read that would follow it (the engine's priority slot):
    UITAMR-CYCLE reported that as a violation, though holding the stop back would be the
    worse program. The stop goes out first, the cycle ends, nothing else is sent for it."""
    plc = ROOT / "plc"
    text = (plc / "scenarios" / "fx3u-stop-during-run.toml").read_text(encoding="utf-8")
    text = text.replace('"../', f'"{plc.as_posix()}/').replace('at = "11s"', f'at = "{stop_at}"')
    text = text.replace('after = "11s"', f'after = "{stop_at}"').replace("reached_point = 1", "reached_point = 9")
    text = text.replace('[[expect]]\nreached_point = 9\nwithin = "10s"\n', "")
    (tmp_path / "s.toml").write_text(text, encoding="utf-8")
    result = run_scenario(load_scenario(tmp_path / "s.toml"))
    assert result.aborted is None, result.aborted
    control = [f for f in result.trace if f.direction == "tx" and f.data[1] == 6]
    assert [f.data[2:4].hex() for f in control[:3]] == ["01a0", "0101", "01a0"]  # stop, run 1, stop
    assert control[2].t_start_us - control[1].t_start_us < 400_000  # no status read between them
    assert result.passed, [v.message for v in result.all_violations()[:5]] + [str(e) for e in result.failed_expectations]


def test_an_exception_on_the_fx5_adprw_route_is_repeated_as_the_docs_say():
    """The FX5 MODBUS manual's error code for an exception response was not found, so
    UITAMR_PortAdpFx5 reads none and cannot tell an exception from a time-out: the engine
    repeats the point command three times and ends with 16#0108 (port 16#0309), where the
    FX3U port reports 16#0103 after one. The difference used to be undocumented (the FX5
    port's header even said SD8500 held the code 'per the FX5 manual'); instructions.md
    now marks it an ASSUMPTION, plc-library.md says what the integrator sees, and the two
    bundled exception scenarios show both routes."""
    assert "the FX5 MODBUS manual's code for an exception response and the register holding it were not " \
           "found (**ASSUMPTION**" in squeezed("docs/plc-library.md")
    assert "**ASSUMPTION**: SD8500 as the error-code register of CH1 and every FX5 code above are the " \
           "simulator's own." in squeezed("docs/instructions.md")
    assert "per the FX5 manual" not in squeezed("plc/fx5/UITAMR_PortAdpFx5.st")
    assert "plc/scenarios/fx5u-adprw-exception.toml" in squeezed("docs/import-gxworks3.md")
    points = {}
    for platform in ("fx3u", "fx5u"):
        result = run_scenario(load_scenario(ROOT / "plc" / "scenarios" / f"{platform}-adprw-exception.toml"))
        assert result.passed, (result.all_violations(), [e.detail for e in result.expectations])
        points[platform] = [f for f in result.trace if f.direction == "tx" and 2_000_000 <= f.t_start_us < 3_500_000
                            and f.data[:4] == bytes([0x01, 0x06, 0x01, 0x01])]  # run point 1
    assert len(points["fx3u"]) == 1 and len(points["fx5u"]) == 3
    # the fault outlasts the three attempts at a slow scan too (it ended before the third at 120 ms)
    from dataclasses import replace
    slow = replace(load_scenario(ROOT / "plc" / "scenarios" / "fx5u-adprw-exception.toml"), scan_us=120_000)
    assert run_scenario(slow).passed


def _route(scenario):
    """The column of docs/plc-library.md's fault coverage table a bundled scenario belongs in."""
    if scenario.converter is not None:
        return "TCP (FX5U, Q)"
    if scenario.channel == "adp:1":
        return {"fx3u": "FX3U/FX3G ADPRW", "fx3g": "FX3U/FX3G ADPRW", "fx5u": "FX5U ADPRW"}[scenario.platform]
    return {"fx3u": "FX3U/FX3G RS2", "fx3g": "FX3U/FX3G RS2", "fx5u": "FX5U RS2", "q": "Q QJ71C24N"}[scenario.platform]


def test_the_fault_coverage_table_names_every_bundled_scenario_in_its_route():
    """docs/plc-library.md "Fault coverage of the bundled scenarios": every file of
    plc/scenarios/ is in the table once, in the column of its route (a scenario added,
    renamed or removed without the table is found here), and every name there is a file."""
    text = (ROOT / "docs" / "plc-library.md").read_text(encoding="utf-8")
    section = text.split("## Fault coverage of the bundled scenarios", 1)[1].split("\n## ", 1)[0]
    rows = [line.strip().strip("|").split("|") for line in section.splitlines() if line.startswith("| ")]
    header = [cell.strip() for cell in rows[0]]
    assert header[0] == "fault"
    placed = []
    for row in rows[1:]:
        for column, cell in zip(header[1:], row[1:]):
            placed += [(name, column) for name in re.findall(r"`([a-z0-9-]+)`", cell)]
    names = [name for name, _ in placed]
    assert sorted(names) == sorted(p.stem for p in SCENARIOS)
    for name, column in placed:
        assert _route(load_scenario(ROOT / "plc" / "scenarios" / f"{name}.toml")) == column, name


def test_the_fx3u_adprw_port_paragraph_names_every_scenario_that_verifies_it():
    """docs/plc-library.md's FX3U-485ADP-MB paragraph ends with the bundled scenarios that
    verify the port; it named four of the seven after session 26 added the ADPRW route's bad
    CRC (205), wrong address (213) and garbage, the scenarios that show those codes."""
    text = squeezed("docs/plc-library.md")
    paragraph = text.split("Verified under `uitamr verify` by `plc/scenarios/fx3u-adprw-healthy.toml`", 1)[1]
    paragraph = paragraph.split("As for every ADPRW detail above", 1)[0]
    named = set(re.findall(r"`(fx3u-adprw-[a-z-]+)\.toml`", paragraph)) | {"fx3u-adprw-healthy"}
    assert named == {p.stem for p in SCENARIOS if p.stem.startswith("fx3u-adprw-")}


#: the FX5U and Q examples with pause and resume: (scenario of that example, start, stop, pause, resume)
PAUSE_EXAMPLES = {
    "UITAMR_ExampleFx5": ("fx5u-pause-stop", "X0", "X1", "X3", "X4"),
    "UITAMR_ExampleAdpFx5": ("fx5u-adprw-pause-resume", "X0", "X1", "X3", "X4"),
    "UITAMR_ExampleTcpFx5": ("fx5u-tcp-pause-stop", "X0", "X1", "X3", "X4"),
    "UITAMR_ExampleQ": ("q-pause-stop", "X20", "X21", "X23", "X24"),
    "UITAMR_ExampleTcpQ": ("q-tcp-pause-stop", "X20", "X21", "X23", "X24"),
}


@pytest.mark.parametrize("example", sorted(PAUSE_EXAMPLES))
def test_the_resume_button_of_an_fx5u_or_q_example_moves_nothing_when_no_point_runs(example):
    """The FX5U and Q examples' resume is the point of the cycle sent again (UITAMR_Command
    kind 2); sent with nothing paused it would be a new run that no UITAMR_RunPoint follows.
    They ask it only while a point of the cycle runs: pressed before the start and after the
    stop has ended the paused point, it sends nothing; the line carries the power-on stop,
    point 1, the pause and the stop, and no rule is broken."""
    from dataclasses import replace

    from verifier.verify.scenario import InputStep

    name, start, stop, pause, resume = PAUSE_EXAMPLES[example]
    scenario = load_scenario(ROOT / "plc" / "scenarios" / f"{name}.toml")
    assert scenario.program == example
    steps = [(1.0, resume), (2.0, start), (4.0, pause), (7.0, stop), (9.0, resume)]
    scenario = replace(scenario, duration_us=14_000_000, expectations=[],
                       inputs=[InputStep(at_us=int(at * 1e6), values={device: True}, pulse_us=300_000, key=f"inputs[{i}]")
                               for i, (at, device) in enumerate(steps)])
    result = run_scenario(scenario)
    assert result.aborted is None, result.aborted
    assert [v.message for v in result.all_violations()] == []
    controls = [f.data[2:4] for f in result.trace if f.direction == "tx" and f.data[1] == 0x06]
    assert controls == [b"\x01\xa0", b"\x01\x01", b"\x01\x80", b"\x01\xa0"]   # stop, point 1, pause, stop
