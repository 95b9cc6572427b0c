"""`uitamr verify` as users and CI call it: exit codes 0/1/2, clear messages without
tracebacks, the report files, parallel scenarios, and the README's main command."""
from __future__ import annotations

import json
import re
import os
import subprocess
import sys
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest
from click.testing import CliRunner

from file_helpers import write_files
from verifier.commands.verify import bundled_scenarios, command
import procs

REPO = Path(__file__).resolve().parents[1]
PLC = REPO / "plc"
FX3_SOURCES = [
    *sorted((PLC / "core").glob("*.st")), *sorted((PLC / "fx3").glob("*.st")),
    *sorted((PLC / "examples" / "common").glob("*.st")), PLC / "examples" / "fx3" / "UITAMR_ExampleFx3.st",
]


def invoke(*args: str):
    return CliRunner().invoke(command, [str(a) for a in args], catch_exceptions=False)


def test_sources_without_a_scenario_run_a_healthy_robot(tmp_path):
    report = tmp_path / "r.json"
    result = invoke(*FX3_SOURCES, "--program", "UITAMR_ExampleFx3", "--duration", "4s", "--json", report)
    assert result.exit_code == 0, result.output
    data = json.loads(report.read_text())
    assert data["verdict"] == "pass"
    (scenario,) = data["scenarios"]
    assert scenario["name"] == "healthy robot" and scenario["duration"] == 4.0
    assert scenario["frames"]["tx"] >= 10  # the engine polls while idle


def test_a_copied_bundled_scenario_runs_on_the_files_given_though_its_sources_are_not_beside_it(tmp_path):
    """docs/scenarios.md: `uitamr verify FILES...` replaces the scenario's `sources`. A copy of
    a bundled scenario (it names `../core/*.st`) ended with exit 2, "sources[0]: '../core/*.st'
    matches no file", before the FILES given were used."""
    copy = tmp_path / "fx3u-healthy.toml"
    copy.write_text((PLC / "scenarios" / "fx3u-healthy.toml").read_text(encoding="utf-8"), encoding="utf-8")
    assert '"../core/*.st"' in copy.read_text(encoding="utf-8")
    report = tmp_path / "r.json"
    result = invoke("--scenario", copy, *FX3_SOURCES, "--json", report)
    assert result.exit_code == 0, result.output
    assert json.loads(report.read_text())["verdict"] == "pass"
    # without FILES the copy's sources are looked for, and named at their line
    result = invoke("--scenario", copy)
    assert result.exit_code == 2
    assert "sources[0]: '../core/*.st' matches no file" in result.output


def test_every_report_is_written(tmp_path):
    paths = {kind: tmp_path / f"out.{kind}" for kind in ("json", "junit", "trace", "html")}
    result = invoke(*FX3_SOURCES, "--program", "UITAMR_ExampleFx3", "--duration", "3s", "--scan", "5ms",
                    "--json", paths["json"], "--junit", paths["junit"], "--trace", paths["trace"],
                    "--html", paths["html"])
    assert result.exit_code == 0, result.output
    assert json.loads(paths["json"].read_text())["scenarios"][0]["scan"] == 0.005
    assert ET.parse(paths["junit"]).getroot().get("failures") == "0"
    first = json.loads(paths["trace"].read_text().splitlines()[0])
    assert first["dir"] == "tx" and first["hex"] == "01 06 01 A0 00 00 88 14" and first["meaning"] == "stop (01/A0)"
    assert "<svg" in paths["html"].read_text()
    for path in paths.values():
        assert f"wrote {path}" in result.output


def test_violations_exit_1(tmp_path):
    engine = (PLC / "core" / "UITAMR_Engine.st").read_text(encoding="utf-8")
    broken = tmp_path / "UITAMR_Engine.st"
    broken.write_text(engine.replace("PACE_TIME : TIME := T#300ms;", "PACE_TIME : TIME := T#150ms;"), encoding="utf-8")
    sources = [broken if p.name == "UITAMR_Engine.st" else p for p in FX3_SOURCES]
    junit = tmp_path / "j.xml"
    result = invoke(*sources, "--program", "UITAMR_ExampleFx3", "--duration", "3s", "--junit", junit)
    assert result.exit_code == 1
    assert "UITAMR-PACING" in result.output and "FAIL" in result.output
    failure = ET.parse(junit).getroot().find("./testsuite/testcase/failure")
    assert failure.get("type") == "UITAMR-PACING"


def _run_cli(*args) -> subprocess.CompletedProcess:
    return procs.run([sys.executable, "-m", "verifier.cli", "verify", *map(str, args)],
                     capture_output=True, text=True, timeout=600, cwd=REPO)


def test_bad_scenario_exits_2_with_file_line_and_key(tmp_path):
    scenario = tmp_path / "s.toml"
    scenario.write_text('program = "UITAMR_ExampleFx3"\n[[expect]]\nthat = "o_bOK"\nwithin = "5"\n')
    done = _run_cli("--scenario", scenario)
    assert done.returncode == 2
    assert f"{scenario}:4:10: expect[0].within" in done.stderr
    assert "Traceback" not in done.stderr + done.stdout


def test_st_errors_exit_2_with_file_line_and_column(tmp_path):
    bad = tmp_path / "Bad.st"
    bad.write_text("PROGRAM Bad\nVAR\n    x : INT;\nEND_VAR\nx := x + ;\nEND_PROGRAM\n")
    done = _run_cli(bad, "--duration", "1s")
    assert done.returncode == 2
    assert f"{bad}:5:" in done.stderr
    assert "Traceback" not in done.stderr + done.stdout


def test_unknown_program_and_labels_exit_2(tmp_path):
    done = _run_cli(*FX3_SOURCES, "--program", "NoSuchProgram", "--duration", "1s")
    assert done.returncode == 2 and "no PROGRAM 'NoSuchProgram'" in done.stderr
    assert "UITAMR_ExampleFx3" in done.stderr  # says which programs there are
    scenario = tmp_path / "s.toml"
    scenario.write_text('program = "UITAMR_ExampleFx3"\nduration = "1s"\n[[expect]]\nthat = "fbEngine.o_bNope"\n')
    done = _run_cli(*FX3_SOURCES, "--scenario", scenario)
    assert done.returncode == 2 and "no label 'fbEngine.o_bNope'" in done.stderr
    assert "Traceback" not in done.stderr
    scenario.write_text('program = "UITAMR_ExampleFx3"\nduration = "1s"\nwatch = ["uMbx"]\n')
    done = _run_cli(*FX3_SOURCES, "--scenario", scenario)
    assert done.returncode == 2 and "'uMbx' in UITAMR_ExampleFx3 is not a single value" in done.stderr


def test_unusable_options_exit_2(tmp_path):
    assert _run_cli("--duration", "soon").returncode == 2
    done = _run_cli(*FX3_SOURCES, "--html", tmp_path / "missing" / "r.html")
    assert done.returncode == 2 and "does not exist" in done.stderr
    done = _run_cli(tmp_path / "none.st")
    assert done.returncode == 2 and "Traceback" not in done.stderr


def test_a_scenario_given_as_source_is_pointed_to_scenario_option():
    scenario = PLC / "scenarios" / "fx3u-healthy.toml"
    done = _run_cli(scenario)
    assert done.returncode == 2
    assert f"{scenario} is a scenario, not ST source: give it as --scenario {scenario}" in done.stderr


def test_a_capture_trace_or_report_given_as_source_says_what_it_is(tmp_path, monkeypatch):
    """`uitamr verify site.txt`, the capture a site session left, was read as ST: "site.txt:1:1:
    error: '#' must follow a radix", and a trace or a JSON report "unexpected character '{'",
    where `uitamr check` and `uitamr export` say what the file is and what reads it."""
    monkeypatch.chdir(tmp_path)
    (tmp_path / "site.txt").write_text("# uitamr monitor capture of /dev/ttyUSB0, 9600 8N1\n"
                                       "0.001042 01 06 01 A0 00 00 88 14\n0.5 end\n", encoding="utf-8")
    (tmp_path / "site.jsonl").write_text('{"t": 0.0, "dir": "tx", "hex": "01 06 01 A0 00 00 88 14"}\n')
    (tmp_path / "site.json").write_text('{"verdict": "pass", "scenarios": []}\n')
    for name, says in (("site.txt", "site.txt: a capture of `uitamr monitor --capture` (times and bytes on the "
                                    "line), not ST: `uitamr replay site.txt` judges its frames"),
                       ("site.jsonl", "site.jsonl: a trace (JSON Lines), not ST: `uitamr replay` reads it"),
                       ("site.json", "site.json: a report, not ST: give the .st sources it reports on")):
        result = invoke(name, *map(str, FX3_SOURCES))
        assert result.exit_code == 2, result.output
        assert says in result.output and "radix" not in result.output and "'{'" not in result.output


def test_st_source_given_as_a_scenario_is_pointed_to_the_arguments():
    """`--scenario Main.st` said 'Main.st:1:9: not valid TOML: Expected '=' after a key',
    which does not say the file went to the wrong option."""
    source = FX3_SOURCES[-1]
    result = invoke("--scenario", source)
    assert result.exit_code == 2
    assert f"{source} is ST source, not a scenario: give it without --scenario" in result.output


def test_the_bundled_scenarios_cover_every_fault_kind():
    from verifier.amr.faults import FAULT_KINDS
    from verifier.verify.scenario import load_scenario

    kinds = {fault.kind for path in bundled_scenarios() for fault in load_scenario(path).faults}
    assert kinds == set(FAULT_KINDS)
    platforms = {load_scenario(path).platform for path in bundled_scenarios()}
    assert platforms == {"fx3u", "fx3g", "fx5u", "q"}


def test_the_readme_command_verifies_the_bundled_examples_in_parallel(tmp_path):
    """`uitamr verify` with no arguments: every bundled scenario, every one compliant."""
    junit = tmp_path / "bundled.xml"
    done = procs.run(["uitamr", "verify", "--jobs", "2", "--junit", str(junit)],
                     capture_output=True, text=True, timeout=900, cwd=tmp_path)
    assert done.returncode == 0, done.stdout + done.stderr
    cases = ET.parse(junit).getroot().findall("./testsuite/testcase")
    assert len(cases) == len(bundled_scenarios()) >= 10
    assert all(case.find("failure") is None and case.find("error") is None for case in cases)
    assert f"PASS: {len(cases)} scenario(s) compliant" in done.stdout


def test_list_rules():
    from verifier.verify.rules import RULES

    result = invoke("--list-rules")
    assert result.exit_code == 0
    for rule in RULES:
        assert rule.id in result.output


FX5_SOURCES = [PLC / "core", PLC / "fx5", PLC / "examples" / "common", PLC / "examples" / "fx5" / "UITAMR_ExampleFx5.st"]


def test_matrix_runs_user_sources_under_the_bundled_robot_and_faults_of_their_platform(tmp_path):
    """The platform is told from the sources (FX5 RS2/SM/SD); only that platform's bundled
    scenarios run; their example-specific inputs/expectations are left out and each result
    says so; scenarios that became the same run (healthy via RS2 and via ADPRW, and the stop
    button during a run and the pause scenarios, whose only difference was the buttons) run
    once, and the one run names the others."""
    from verifier.verify.scenario import load_scenario

    report = tmp_path / "m.json"
    result = invoke(*FX5_SOURCES, "--matrix", "--duration", "6s", "--json", report,
                    "--response-signal", "fbEngine.o_bErr")
    assert result.exit_code == 0, result.output
    data = json.loads(report.read_text())
    fx5 = [s for s in map(load_scenario, bundled_scenarios()) if s.platform == "fx5u" and s.converter is None]
    names = [s["name"] for s in data["scenarios"]]
    merged = {note.split("'")[1] for s in data["scenarios"] for note in s["notes"] if "also stands for" in note}
    assert merged == {"FX5U: power-on stop, then a cycle over points 1-3", "FX5U: the stop button during point 2",
                      "FX5U: point 1 of the cycle paused on the way and resumed",
                      "FX5U: a paused point of the cycle stopped",
                      "FX5U ADPRW: point 1 of the cycle paused on the way and resumed"}
    assert sorted(names + sorted(merged)) == sorted(s.name for s in fx5)
    for scenario in data["scenarios"]:
        assert scenario["platform"] == "fx5u" and scenario["program"] == "UITAMR_ExampleFx5"
        assert [e["expectation"] for e in scenario["expectations"]] == ["sent stop within 5 s"]
        assert any("not applied" in note and "operator input(s)" in note for note in scenario["notes"])
    assert any("also stands for" in note for s in data["scenarios"] for note in s["notes"])
    assert "note: bundled scenario run against your sources" in result.output


def test_matrix_notes_name_a_bundled_scenario_as_its_headline_does(monkeypatch):
    """Under --matrix from the repository, a bundled scenario's headline named it
    plc/scenarios/fx3u-garbage.toml but its notes /abs/.../plc/scenarios/fx3u-garbage.toml:34:1:
    the notes now name the file as the headline does (relative inside the working folder)."""
    monkeypatch.chdir(REPO)
    sources = [str(p.relative_to(REPO)) for p in FX3_SOURCES]
    result = invoke(*sources, "--matrix", "--platform", "fx3g", "--duration", "3s")
    assert result.exit_code == 0, result.output
    headlines = re.findall(r"^(?:PASS|FAIL) .* \((plc/scenarios/[^)]+\.toml)\): ", result.output, re.M)
    placed = re.findall(r"^    note: (\S+\.toml):\d+:\d+: ", result.output, re.M)
    assert headlines and placed, result.output
    assert set(placed) <= set(headlines) and str(REPO) not in result.output


def test_matrix_of_a_tcp_program_runs_the_converter_scenarios_only(tmp_path):
    """The FX5U TCP example (its library folder also holds the serial port FBs) runs under the
    bundled FX5U converter scenarios, not the serial ones (the two pause scenarios, whose
    only difference from the healthy one is the buttons, in its run); a converter refusing
    connections at first moves the power-on stop's window after the refusals."""
    from verifier.verify.scenario import load_scenario

    report = tmp_path / "m.json"
    sources = [PLC / d for d in ("core", "fx5", "examples/common")] + \
        [PLC / "examples" / "fx5" / "UITAMR_ExampleTcpFx5.st"]
    result = invoke(*sources, "--matrix", "--duration", "8s", "--json", report)
    assert result.exit_code == 0, result.output
    data = json.loads(report.read_text())
    tcp = {s.name for s in map(load_scenario, bundled_scenarios()) if s.platform == "fx5u" and s.converter}
    merged = {note.split("'")[1] for s in data["scenarios"] for note in s["notes"] if "also stands for" in note}
    assert merged == {"FX5U over TCP: point 1 of the cycle paused on the way and resumed",
                      "FX5U over TCP: a paused point of the cycle stopped"}
    assert {s["name"] for s in data["scenarios"]} | merged == tcp and len(tcp) == 7
    refused = next(s for s in data["scenarios"] if "refuses" in s["name"])
    assert [e["expectation"] for e in refused["expectations"]] == ["sent stop within 5 s after 3 s"]


def test_a_plain_run_of_a_tcp_program_puts_the_robot_behind_a_healthy_converter(tmp_path):
    """`uitamr verify SOURCES` of a program that opens a TCP connection (the FX5U Ethernet
    example, its library folder holding the serial ports too) runs the healthy robot behind
    the default converter, as --matrix does, instead of on the silent serial port fx5:1."""
    report = tmp_path / "tcp.json"
    sources = [PLC / d for d in ("core", "fx5", "examples/common")] + \
        [PLC / "examples" / "fx5" / "UITAMR_ExampleTcpFx5.st"]
    result = invoke(*sources, "--duration", "3s", "--json", report)
    assert result.exit_code == 0, result.output
    (scenario,) = json.loads(report.read_text())["scenarios"]
    assert (scenario["platform"], scenario["channel"]) == ("fx5u", "tcp")
    assert scenario["frames"]["tx"] >= 5 and scenario["expectations"][0]["passed"]
    assert "converter at the address the program opens" in scenario["description"]
    serial = [PLC / d for d in ("core", "fx5", "examples/common")] + [PLC / "examples" / "fx5" / "UITAMR_ExampleFx5.st"]
    result = invoke(*serial, "--duration", "2s", "--json", report)
    assert result.exit_code == 0, result.output
    assert json.loads(report.read_text())["scenarios"][0]["channel"] == "fx5:1"


def test_matrix_needs_a_platform_it_can_tell(tmp_path):
    plain = tmp_path / "Plain.st"
    plain.write_text("PROGRAM Plain\nVAR\n    w : INT;\nEND_VAR\nw := w + 1;\nEND_PROGRAM\n", encoding="utf-8")
    result = invoke(plain, "--matrix")
    assert result.exit_code == 2
    assert "cannot tell the platform from the sources: they load on fx3u, fx5u, q alike" in result.output
    assert "say --platform" in result.output
    broken = tmp_path / "Broken.st"
    broken.write_text("PROGRAM Broken\nVAR\n    w : INT;\nEND_VAR\nw := w + ;\nEND_PROGRAM\n", encoding="utf-8")
    result = invoke(broken, "--matrix")
    assert result.exit_code == 2 and f"the sources do not load: {broken}:5:" in result.output
    result = invoke(plain, "--duration", "1s", "--response-signal", "o_bErr OR")
    assert result.exit_code == 2 and "--response-signal: " in result.output and "column" in result.output


def test_a_plain_run_tells_the_platform_from_the_sources(tmp_path):
    """No --platform: Q sources (G_OUTPUT) run on the Q, not on the default FX3U."""
    q_sources = [PLC / "core", PLC / "q", PLC / "examples" / "common", PLC / "examples" / "q" / "UITAMR_ExampleQ.st"]
    report = tmp_path / "q.json"
    result = invoke(*q_sources, "--duration", "2s", "--json", report)
    assert result.exit_code == 0, result.output
    (scenario,) = json.loads(report.read_text())["scenarios"]
    assert (scenario["platform"], scenario["channel"], scenario["program"]) == ("q", "q:1", "UITAMR_ExampleQ")


def test_a_scenario_on_the_wrong_platform_says_which_platform_to_set(tmp_path):
    """An FX5U program in a scenario that forgot `platform` (so fx3u): the error names the
    scenario's platform, not only the library file whose SM device the FX3U lacks."""
    fx5 = [PLC / "core", PLC / "fx5", PLC / "examples" / "common", PLC / "examples" / "fx5" / "UITAMR_ExampleFx5.st"]
    text = f'name = "mine"\nsources = {json.dumps([str(p) for p in fx5])}\nduration = "2s"\n'
    unset = tmp_path / "unset.toml"
    unset.write_text(text, encoding="utf-8")
    result = invoke("--scenario", unset)
    assert result.exit_code == 2
    assert "fx5/UITAMR_Port" in result.output  # the load errors stay (named from the working folder)
    assert (f"{unset}:1:1: platform: the sources load on fx5u, not on fx3u (the default): set "
            'platform = "fx5u" in the scenario, or give --platform fx5u') in result.output
    wrong = tmp_path / "wrong.toml"
    wrong.write_text(text + 'platform = "q"\n', encoding="utf-8")
    result = invoke("--scenario", wrong)
    assert result.exit_code == 2
    assert (f"{wrong}:4:12: platform: the sources load on fx5u, not on q: set "
            'platform = "fx5u" in the scenario, or give --platform fx5u') in result.output
    broken = tmp_path / "Broken.st"  # an ST error loads nowhere: no platform to suggest
    broken.write_text("PROGRAM Broken\nVAR\n    w : INT;\nEND_VAR\nw := w + ;\nEND_PROGRAM\n", encoding="utf-8")
    result = invoke("--scenario", unset, broken)
    assert result.exit_code == 2 and "Broken.st:5:" in result.output and "platform:" not in result.output


def test_a_wrong_platform_option_is_not_blamed_on_a_scenario_file(tmp_path):
    """`--platform fx3u` given for FX5U sources: the message names the option the user gave
    and what to give instead - not 'fx3u (the default)' nor 'set platform = ... in the
    scenario' for a run that has no scenario file, or whose file says fx5u."""
    fx5 = [PLC / "core", PLC / "fx5", PLC / "examples" / "common", PLC / "examples" / "fx5" / "UITAMR_ExampleFx5.st"]
    result = invoke(*fx5, "--platform", "fx3u", "--duration", "2s")
    assert result.exit_code == 2
    assert "--platform fx3u: the sources load on fx5u, not on fx3u: give --platform fx5u" in result.output
    assert "(the default)" not in result.output and "in the scenario" not in result.output
    result = invoke("--scenario", PLC / "scenarios" / "fx5u-healthy.toml", "--platform", "q")
    assert result.exit_code == 2
    assert "--platform q: the sources load on fx5u, not on q: give --platform fx5u" in result.output


def test_platform_without_sources_picks_the_bundled_scenarios_of_that_platform(tmp_path):
    from verifier.verify.scenario import load_scenario

    report = tmp_path / "q.json"
    invoke("--platform", "q", "--duration", "1s", "--json", report)  # 1 s: the verdict is not the point
    names = {s["name"] for s in json.loads(report.read_text())["scenarios"]}
    assert names == {load_scenario(p).name for p in bundled_scenarios() if load_scenario(p).platform == "q"}


def test_parallel_batches_group_sources_and_cover_every_scenario():
    """--jobs: scenarios with the same sources share a batch (one worker parses them once),
    no batch takes more than 1/(2 jobs) of the work unless it is a single scenario, every
    scenario is in exactly one batch, longest batch first."""
    from verifier.commands.verify import _batches
    from verifier.verify.scenario import load_scenario

    scenarios = [load_scenario(p) for p in bundled_scenarios()]
    cost = [s.duration_us // s.scan_us for s in scenarios]
    for jobs in (2, 3, 8):
        batches = _batches(scenarios, jobs)
        assert sorted(i for b in batches for i in b) == list(range(len(scenarios)))
        for batch in batches:
            assert len({(scenarios[i].sources, scenarios[i].target) for i in batch}) == 1
            assert len(batch) == 1 or sum(cost[i] for i in batch) <= sum(cost) / (2 * jobs)
        sizes = [sum(cost[i] for i in b) for b in batches]
        assert sizes == sorted(sizes, reverse=True)


def test_a_duration_that_ends_the_run_before_a_fault_says_the_fault_was_not_tested(tmp_path):
    """--duration shorter than a scenario's fault times: the faults never struck, and with
    --matrix (the scenario's own expectations left out) the run passed with a note that
    claimed 'robot, faults, timing and every rule applied'. The run now says which were not."""
    sources = [str(p) for p in FX3_SOURCES]
    scenario = tmp_path / "s.toml"
    scenario.write_text(f'sources = {json.dumps(sources)}\nprogram = "UITAMR_ExampleFx3"\nduration = "10s"\n'
                        '[[faults]]\nkind = "no_reply"\nat_s = 1.0\nduration_s = 0.5\n'
                        '[[faults]]\nkind = "anti_collision"\nat_s = 6.0\n')
    report = tmp_path / "r.json"
    result = invoke("--scenario", scenario, "--duration", "3s", "--json", report)
    assert result.exit_code in (0, 1), result.output
    note = "--duration 3s ends the run before 1 of its scripted fault(s), not tested: anti_collision at 6 s"
    assert note in result.output
    (run,) = json.loads(report.read_text())["scenarios"]
    assert note in run["notes"]
    result = invoke("--scenario", scenario, "--duration", "7s")  # every fault strikes: no such note
    assert "not tested" not in result.output


def test_a_fault_due_at_the_microsecond_the_duration_ends_is_said_not_tested(tmp_path):
    """The robot times a fault by its at_s rounded to the µs (Fault.at_us): at_s = 2.9999995
    is due at 3 s, which --duration 3s never reaches. --duration's note compared the unrounded
    time (2999999.5 µs, before the end: no note) while the missed-fault note left it to
    --duration's: the fault went untested without a word."""
    sources = [str(p) for p in FX3_SOURCES]
    scenario = tmp_path / "s.toml"
    scenario.write_text(f'sources = {json.dumps(sources)}\nprogram = "UITAMR_ExampleFx3"\nduration = "10s"\n'
                        '[[faults]]\nkind = "no_reply"\nat_s = 2.9999995\nduration_s = 0.5\n')
    result = invoke("--scenario", scenario, "--duration", "3s")
    assert result.exit_code in (0, 1), result.output
    assert "--duration 3s ends the run before 1 of its scripted fault(s), not tested: " in result.output


def test_a_duration_that_ends_the_run_before_an_input_says_it_was_not_applied(tmp_path):
    # --duration 15s on a scenario that presses X4 at 20 s: the run went on as if no one
    # pressed it, and only the expectations on its outcome hinted at why
    sources = [str(p) for p in FX3_SOURCES]
    scenario = tmp_path / "s.toml"
    scenario.write_text(f'sources = {json.dumps(sources)}\nprogram = "UITAMR_ExampleFx3"\nduration = "30s"\n'
                        '[[inputs]]\nat = "1s"\nset = {{ X0 = true }}\npulse = "300ms"\n'
                        '[[inputs]]\nat = "20s"\nset = {{ X1 = true }}\n'.replace("{{", "{").replace("}}", "}"))
    result = invoke("--scenario", scenario, "--duration", "15s")
    assert ("note: --duration 15s ends the run before 1 of its operator input(s), not applied: inputs[1] at 20.000 s"
            in result.output), result.output
    assert "not applied" not in invoke("--scenario", scenario, "--duration", "21s").output


def test_jobs_beyond_the_batches_start_no_idle_workers(tmp_path, monkeypatch):
    """The process pool forks all its workers at once: --jobs 5000 for two scenarios
    forked 5000 processes and the run never ended. It gets a worker per batch at most."""
    import concurrent.futures
    from verifier.commands import verify

    asked = []

    class Pool(concurrent.futures.ThreadPoolExecutor):  # records the size, runs in threads
        def __init__(self, max_workers, initializer=None):  # a worker process's set-up: not for threads
            asked.append(max_workers)
            super().__init__(max_workers=min(max_workers, 4))

    monkeypatch.setattr(verify, "ProcessPoolExecutor", Pool)
    sources = [str(p) for p in FX3_SOURCES]
    scenario = tmp_path / "s.toml"
    scenario.write_text(f'sources = {json.dumps(sources)}\nprogram = "UITAMR_ExampleFx3"\nduration = "1s"\n')
    result = invoke("--scenario", scenario, "--scenario", scenario, "--jobs", "5000")
    assert result.exit_code in (0, 1), result.output
    assert asked and asked[0] <= 2


def test_parallel_run_reports_what_a_serial_run_reports(tmp_path):
    """The JSON report of --jobs 2 is the one of --jobs 1, in the same order (wall times aside)."""
    def report(jobs: int):
        out = tmp_path / f"j{jobs}.json"
        result = invoke("--platform", "fx5u", "--duration", "4s", "--jobs", str(jobs), "--json", out)
        assert result.exit_code in (0, 1), result.output
        return re.sub(r'"wall[^"]*": [0-9.e+-]+', '"wall": 0', out.read_text())
    assert report(2) == report(1)


@pytest.mark.parametrize("jobs", ["1", "2"])
def test_every_scan_reports_what_the_default_reports(tmp_path, jobs):
    """--every-scan (every scan run, every label read by name) is the reference the default
    fast path must match: the same JSON report byte for byte, wall times aside."""
    def report(*extra: str):
        out = tmp_path / f"r{len(extra)}.json"
        result = invoke("--platform", "fx3u", "--duration", "8s", "--jobs", jobs, "--json", out, *extra)
        assert result.exit_code in (0, 1), result.output
        return re.sub(r'"wall[^"]*": [0-9.e+-]+', '"wall": 0', out.read_text())
    assert report("--every-scan") == report()


def test_a_report_in_a_folder_that_is_a_file_says_so(tmp_path):
    """`--json src.st/r.json` said 'the folder .../src.st does not exist' of a file that does."""
    from verifier.commands.report_files import ReportError, check_folders

    (tmp_path / "src.st").write_text("")
    with pytest.raises(ReportError, match=r"src.st is a file, not a folder$"):
        check_folders(str(tmp_path / "src.st" / "r.json"))
    with pytest.raises(ReportError, match=r"nope does not exist$"):
        check_folders(str(tmp_path / "nope" / "r.json"))


def test_a_function_block_or_no_program_at_all_is_named_as_such():
    """`--program UITAMR_Engine` (the FB under test) said 'no PROGRAM ... they define:
    none', and sources with no PROGRAM said 'say which PROGRAM to run (--program ...)',
    which no --program could satisfy."""
    core = sorted((PLC / "core").glob("*.st")) + sorted((PLC / "fx3").glob("*.st"))
    result = invoke(*core, "--program", "UITAMR_Engine", "--duration", "1s")
    assert result.exit_code == 2
    assert "UITAMR_Engine is a FUNCTION_BLOCK, not a PROGRAM: name the PROGRAM that calls it" in result.output
    result = invoke(*core, "--duration", "1s")
    assert result.exit_code == 2
    assert "the sources define no PROGRAM, only function blocks and functions" in result.output


def test_sources_with_no_program_are_placed_at_the_scenarios_sources_key(tmp_path, monkeypatch):
    """A scenario whose `sources` hold only function blocks named the file alone; now its
    `sources` key, and the SOURCES on the command line when they replaced them (they are to
    blame, not the file: it said 's.toml:' with no line)."""
    monkeypatch.chdir(tmp_path)
    (tmp_path / "fb.st").write_text("FUNCTION_BLOCK F\nVAR x : INT; END_VAR\nx := 1;\nEND_FUNCTION_BLOCK\n")
    (tmp_path / "s.toml").write_text('name = "x"\nsources = ["fb.st"]\n')
    result = invoke("--scenario", "s.toml")
    assert result.exit_code == 2
    assert "error: s.toml:2:11: sources: the sources define no PROGRAM" in result.output
    result = invoke("--scenario", "s.toml", "fb.st")
    assert result.exit_code == 2
    assert "error: SOURCES (fb.st): the sources define no PROGRAM" in result.output


def test_text_in_square_brackets_is_shown_as_written_not_read_as_markup(tmp_path):
    """The console library reads "[...]" as styling: user text in an error must be escaped,
    or "[/]" crashes and "uMbx[i]" loses its index (found by a robustness sweep)."""
    done = _run_cli(*FX3_SOURCES, "--program", "[/]")
    assert done.returncode == 2 and "Traceback" not in done.stderr
    assert "no PROGRAM '[/]' in the sources" in done.stderr
    scenario = tmp_path / "s.toml"
    scenario.write_text('program = "UITAMR_ExampleFx3"\nduration = "1s"\nwatch = ["uMbx[i]"]\n')
    done = _run_cli(*FX3_SOURCES, "--scenario", scenario)
    assert done.returncode == 2 and "'uMbx[i]'" in done.stderr


def test_two_reports_to_one_file_are_refused_before_the_run(tmp_path):
    report = tmp_path / "r.out"
    done = _run_cli(*FX3_SOURCES, "--json", report, "--html", report)
    assert done.returncode == 2 and "are the same file" in done.stderr and not report.exists()


def test_a_run_that_cannot_start_writes_its_mistakes_as_junit_errors(tmp_path):
    """Exit 2 with --junit left no report (a CI server's test summary showed nothing, or
    the last run's report still lying there): now each mistake is an <error> test case
    whose message is its place, and the run still exits 2 with the errors on stderr."""
    report = tmp_path / "v.xml"
    report.write_text("<testsuites name='the last run'/>", encoding="utf-8")
    first, second = tmp_path / "a.toml", tmp_path / "b.toml"
    first.write_text('program = "UITAMR_ExampleFx3"\nduration = "5q"\n', encoding="utf-8")
    second.write_text('program = "UITAMR_ExampleFx3"\n[[expect]]\nthat = "o_bOK"\nwithin = "5"\n', encoding="utf-8")
    done = _run_cli("--scenario", first, "--scenario", second, "--junit", report)
    assert done.returncode == 2, done.stdout + done.stderr
    assert f"a.toml:2:12: duration: '5q' is not a duration" in done.stderr
    assert f"wrote {report} (these errors as test cases)" in done.stderr
    root = ET.parse(report).getroot()
    assert (root.get("tests"), root.get("failures"), root.get("errors")) == ("2", "0", "2")
    cases = root.findall("./testsuite/testcase")
    assert [case.get("file") for case in cases] == [str(first), str(second)]
    errors = [case.find("error") for case in cases]
    assert all(e.get("type") == "unusable-input" for e in errors)
    assert errors[0].get("message").startswith(f"{first}:2:12: duration: '5q' is not a duration")
    assert errors[1].get("message").startswith(f"{second}:4:10: ")


def test_st_that_does_not_load_is_a_junit_error_at_its_place(tmp_path):
    write_files(tmp_path, {"MAIN.st": "PROGRAM MAIN\nVAR\n    x : INT;\nEND_VAR\nx := ;\nEND_PROGRAM\n"})
    result = invoke(tmp_path / "MAIN.st", "--platform", "fx3u", "--junit", tmp_path / "v.xml")
    assert result.exit_code == 2, result.output
    (case,) = ET.parse(tmp_path / "v.xml").getroot().findall("./testsuite/testcase")
    assert case.get("name") == f"{tmp_path / 'MAIN.st'}:5:6" and case.get("classname") == "uitamr.verify.input"
    assert case.find("error").get("message").startswith(f"{tmp_path / 'MAIN.st'}:5:6: error: expected an expression")


def test_the_junit_of_a_run_that_cannot_start_is_not_written_over_an_input(tmp_path):
    scenario = tmp_path / "s.toml"
    text = 'program = "UITAMR_ExampleFx3"\nduration = "5q"\n'
    scenario.write_text(text, encoding="utf-8")
    done = _run_cli("--scenario", scenario, "--junit", scenario)
    assert done.returncode == 2 and "'5q' is not a duration" in done.stderr
    assert "the JUnit report was not written: " in done.stderr and "one of the run's input files" in done.stderr
    assert scenario.read_text(encoding="utf-8") == text


def test_the_junit_of_a_run_that_cannot_start_is_not_written_over_a_file_of_a_named_folder(tmp_path):
    """--scenario FOLDER and SOURCES given as a folder: their files are inputs too. The JUnit
    report of a scenario's mistake was written over a.toml of the folder (and over an ST
    source of a SOURCES folder), only the names as given being checked."""
    folder, sources = tmp_path / "sc", tmp_path / "src"
    folder.mkdir()
    sources.mkdir()
    kept = {folder / "a.toml": 'program = "MAIN"\n', folder / "b.toml": 'program = "MAIN"\nduration = "5q"\n'}
    write_files(sources, {"MAIN.st": "PROGRAM MAIN\nVAR\n    x : INT;\nEND_VAR\nx := 1;\nEND_PROGRAM\n"})
    kept[sources / "MAIN.st"] = (sources / "MAIN.st").read_text(encoding="utf-8")
    for path, text in kept.items():
        path.write_text(text, encoding="utf-8")
    for report in (folder / "a.toml", sources / "MAIN.st"):
        done = _run_cli(sources, "--scenario", folder, "--junit", report)
        assert done.returncode == 2 and "'5q' is not a duration" in done.stderr, done.stderr
        assert "the JUnit report was not written: " in done.stderr and "one of the run's input files" in done.stderr
        assert {path: path.read_text(encoding="utf-8") for path in kept} == kept


def test_the_junit_of_a_run_that_cannot_start_is_not_written_over_the_st_a_broken_scenario_names(tmp_path):
    """The ST a broken scenario file names is not known when the run cannot start: a
    --junit naming it replaced the program with XML. A file that holds no XML is kept."""
    program = "PROGRAM MAIN\nVAR\n    x : INT;\nEND_VAR\nx := 1;\nEND_PROGRAM\n"
    write_files(tmp_path, {"MAIN.st": program, "s.toml": 'sources = ["MAIN.st"]\nduration = "5q"\n'})
    done = _run_cli("--scenario", tmp_path / "s.toml", "--junit", tmp_path / "MAIN.st")
    assert done.returncode == 2 and "'5q' is not a duration" in done.stderr, done.stderr
    assert "the JUnit report was not written: " in done.stderr and "holds no XML" in done.stderr
    assert (tmp_path / "MAIN.st").read_text(encoding="utf-8") == program


def test_a_named_pipe_as_scenario_is_refused_not_waited_on(tmp_path):
    fifo = tmp_path / "s.toml"
    os.mkfifo(fifo)
    done = _run_cli("--scenario", fifo)
    assert done.returncode == 2 and "not a regular file" in done.stderr


def test_scenario_files_with_a_byte_order_mark_or_bad_bytes(tmp_path):
    from verifier.verify.scenario import ScenarioError, load_scenario

    text = (PLC / "scenarios" / "fx3u-healthy.toml").read_text(encoding="utf-8").replace('"../', f'"{PLC}/')
    with_bom = tmp_path / "bom.toml"
    with_bom.write_bytes(b"\xef\xbb\xbf" + text.encode("utf-8"))
    assert load_scenario(with_bom).program == "UITAMR_ExampleFx3"
    latin1 = tmp_path / "latin1.toml"
    latin1.write_bytes(b'name = "x"\n# caf\xe9\n')
    with pytest.raises(ScenarioError) as caught:
        load_scenario(latin1)
    assert str(caught.value) == f"{latin1}:2:6: not UTF-8 text (byte 16): save the file as UTF-8"


def test_huge_numbers_in_a_scenario_are_refused_at_their_key(tmp_path):
    """1e308 ms used to reach the simulator as an infinity and stop the run there, blamed
    on the ST program."""
    text = (PLC / "scenarios" / "fx3u-healthy.toml").read_text(encoding="utf-8").replace('"../', f'"{PLC}/')
    scenario = tmp_path / "s.toml"
    scenario.write_text(text.replace("point_duration_s = 6.0", "point_duration_s = 1e308"), encoding="utf-8")
    done = _run_cli("--scenario", scenario)
    assert done.returncode == 2 and "Traceback" not in done.stderr
    assert "robot.point_duration_s: 1e+308 is out of range" in done.stderr


def test_a_report_over_one_of_the_run_inputs_is_refused(tmp_path):
    """--json onto the scenario, --html onto an ST source: the input was replaced."""
    text = (PLC / "scenarios" / "fx3u-healthy.toml").read_text(encoding="utf-8").replace('"../', f'"{PLC}/')
    scenario = tmp_path / "s.toml"
    scenario.write_text(text, encoding="utf-8")
    done = _run_cli("--scenario", scenario, "--json", scenario)
    assert done.returncode == 2 and "is one of the run's input files" in done.stderr
    assert scenario.read_text(encoding="utf-8") == text
    source = tmp_path / "Main.st"
    source.write_text("PROGRAM Main\nVAR x : INT; END_VAR\nx := 1;\nEND_PROGRAM\n", encoding="utf-8")
    done = _run_cli(source, "--html", source)
    assert done.returncode == 2 and "is one of the run's input files" in done.stderr


def test_a_pipe_named_as_source_is_called_what_it_is(tmp_path):
    fifo = tmp_path / "p.st"
    os.mkfifo(fifo)
    done = _run_cli(fifo)
    assert done.returncode == 2 and "is not a regular file" in done.stderr and "no such file" not in done.stderr


def test_a_fault_timed_after_the_end_of_the_run_is_an_error(tmp_path):
    text = (PLC / "scenarios" / "fx3u-no-reply.toml").read_text(encoding="utf-8").replace('"../', f'"{PLC}/')
    scenario = tmp_path / "s.toml"
    scenario.write_text(re.sub(r"at_s = [0-9.]+", "at_s = 500", text, count=1), encoding="utf-8")
    done = _run_cli("--scenario", scenario)
    assert done.returncode == 2 and "faults[0].at_s: is at or after the end of the run" in done.stderr


def test_junit_stays_well_formed_with_control_characters_in_a_name(tmp_path):
    import xml.dom.minidom

    text = (PLC / "scenarios" / "fx3u-healthy.toml").read_text(encoding="utf-8").replace('"../', f'"{PLC}/')
    scenario = tmp_path / "s.toml"
    scenario.write_text(re.sub(r'^name = ".*"$', r'name = "bad\\u0001name\\u001b[31m"', text, count=1, flags=re.M),
                        encoding="utf-8")
    report = tmp_path / "r.xml"
    done = _run_cli("--scenario", scenario, "--junit", report)
    assert done.returncode == 0, done.stderr
    case = xml.dom.minidom.parse(str(report)).getElementsByTagName("testcase")[0]
    assert case.getAttribute("name") == "bad\\x01name\\x1b[31m"
    assert "\x1b" not in done.stdout and "bad\\x01name" in done.stdout


def test_the_fx5_second_port_can_carry_the_robot(tmp_path):
    """The FX5 port FB drives channel 2 (FX5-485-BD) as well as the built-in port: a
    program set to it passes with --channel fx5:2, and the same program fails on fx5:1."""
    from test_verify_pipeline import library_copy

    plc = library_copy(tmp_path, {"examples/fx5/UITAMR_ExampleFx5.st": [
        ("SERIAL_CHANNEL : INT := 1;", "SERIAL_CHANNEL : INT := 2;")]})
    scenario = PLC / "scenarios" / "fx5u-healthy.toml"
    text = scenario.read_text(encoding="utf-8").replace('"../', f'"{plc.as_posix()}/')
    copy = tmp_path / "fx5u-ch2.toml"
    copy.write_text(text, encoding="utf-8")
    report = tmp_path / "r.json"
    passed = invoke("--scenario", copy, "--channel", "fx5:2", "--json", report)
    assert passed.exit_code == 0, passed.output
    (result,) = json.loads(report.read_text())["scenarios"]
    assert result["channel"] == "fx5:2" and result["frames"]["tx"] > 10
    failed = invoke("--scenario", copy, "--channel", "fx5:1")
    assert failed.exit_code == 1 and "the program sent nothing on fx5:1 in the whole run" in failed.output
    assert "frame(s) on fx5:2: the robot hangs on fx5:1 in this run: give --channel fx5:2" in failed.output
    # the integrator's mistake may be the program's channel, not the scenario's: both fixes are named
    assert ('or channel = "fx5:2" in the scenario; or, if the robot is wired to fx5:1, make the program drive fx5:1'
            in " ".join(failed.output.split())), failed.output


def test_a_silent_run_says_where_the_program_did_talk(tmp_path):
    """Nothing on the robot's line: the note names the route the program used instead and
    the setting that puts the robot there - the ADPRW port (adp:1), a TCP connection with no
    [converter], a converter at another address, a serial port under a [converter]."""
    fx5 = [PLC / "core", PLC / "fx5", PLC / "examples" / "common"]
    adprw = invoke(*fx5, PLC / "examples" / "fx5" / "UITAMR_ExampleAdpFx5.st", "--duration", "2s")
    assert adprw.exit_code == 1
    assert re.search(r"the program sent nothing on fx5:1 in the whole run; it sent \d+ frame\(s\) on adp:1: the robot "
                     r'hangs on fx5:1 in this run: give --channel adp:1, or channel = "adp:1" in the scenario',
                     " ".join(adprw.output.split())), adprw.output
    assert invoke(*fx5, PLC / "examples" / "fx5" / "UITAMR_ExampleAdpFx5.st", "--duration", "2s",
                  "--channel", "adp:1").exit_code == 0
    healthy = (PLC / "scenarios" / "fx5u-tcp-healthy.toml").read_text(encoding="utf-8")
    healthy = healthy.replace('"../', f'"{PLC.as_posix()}/')
    serial = tmp_path / "tcp-without-converter.toml"
    serial.write_text(healthy.replace("[converter]", "[robot.unused]").split("[robot.unused]")[0]
                      + "[[expect]]\nsent = \"stop\"\n", encoding="utf-8")
    result = invoke("--scenario", serial, "--duration", "3s")
    assert result.exit_code == 1
    assert "it opened TCP connections" in result.output and "add a [converter] table" in result.output
    elsewhere = tmp_path / "converter-elsewhere.toml"
    elsewhere.write_text(healthy.replace('ip = "192.168.3.50"', 'ip = "192.168.3.60"'), encoding="utf-8")
    result = invoke("--scenario", elsewhere, "--duration", "3s")
    assert result.exit_code == 1
    assert ("nothing reached the robot's line through the converter: the PLC opens a connection to "
            "192.168.3.50:4001: nothing answers there (the converter is at 192.168.3.60:4001); set the "
            "scenario's [converter] ip and port to what the program opens") in result.output
    assert ("to what the program opens, or, if the converter is at 192.168.3.60:4001, make the program open that "
            "(its port FB's address and port inputs)") in " ".join(result.output.split())
    rs2 = (PLC / "scenarios" / "fx5u-healthy.toml").read_text(encoding="utf-8").replace('"../', f'"{PLC.as_posix()}/')
    behind = tmp_path / "rs2-behind-a-converter.toml"
    behind.write_text(rs2.replace("[robot]", "[converter]\n\n[robot]"), encoding="utf-8")
    result = invoke("--scenario", behind, "--duration", "3s")
    assert result.exit_code == 1
    assert "the program opened no connection to it)" in result.output
    assert "frame(s) on fx5:1: a serial port, not the TCP route: drop [converter] from the scenario" in result.output


def test_a_reader_that_goes_away_loses_no_report(tmp_path):
    """`uitamr verify --json r.json | head -1`: once the pipe's reader is gone, the rest of
    the console text is dropped, the reports are still written and the exit status is the
    verdict's (before, the console library exited 1 at once and r.json was never written)."""
    report = tmp_path / "r.json"
    proc = procs.spawn([sys.executable, "-m", "verifier.cli", "verify", "--scenario",
                             str(PLC / "scenarios" / "q-bad-crc.toml"), "--duration", "5s", "--json", str(report)],
                       stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    proc.stdout.close()  # no reader: the first line printed meets a broken pipe
    _, stderr = procs.finish(proc, 120)
    assert proc.returncode == 1, stderr.decode()  # q-bad-crc's verdict, not the pipe's
    assert b"Traceback" not in stderr and b"BrokenPipe" not in stderr
    assert json.loads(report.read_text(encoding="utf-8"))["verdict"] == "fail"


def test_a_channel_without_a_platform_picks_the_cpu_it_belongs_to(tmp_path):
    """ST that loads on every CPU and `--channel q:1`: the run is on a Q CPU, not on the
    default FX3U that has no such port; a --platform that contradicts it is still refused."""
    source = tmp_path / "Main.st"
    source.write_text("PROGRAM Main\nVAR\n    n : INT;\nEND_VAR\nn := n + 1;\nEND_PROGRAM\n", encoding="utf-8")
    report = tmp_path / "r.json"
    ran = invoke(source, "--channel", "q:1", "--duration", "2s", "--json", report)
    assert ran.exit_code == 1 and "Main on q," in ran.output  # it sends nothing: the stop is missing
    (scenario,) = json.loads(report.read_text())["scenarios"]
    assert (scenario["platform"], scenario["channel"]) == ("q", "q:1")
    refused = invoke(source, "--channel", "q:1", "--platform", "fx3u", "--duration", "2s")
    assert refused.exit_code == 2 and "channel q:1 does not exist on the fx3u CPU" in refused.output


def _vendored_project(tmp_path: Path) -> Path:
    """An integrator's project with the toolkit as vendor/uitamr, a symlink out of it (as
    a submodule checked out elsewhere), and a scenario whose sources go through it; the
    pacing rule tightened so that the run has violations with their origins."""
    project = tmp_path / "project"
    (project / "vendor").mkdir(parents=True)
    (project / "vendor" / "uitamr").symlink_to(REPO, target_is_directory=True)
    (project / "ci").mkdir()
    (project / "ci" / "healthy.toml").write_text(
        'name = "vendored"\n'
        'sources = ["../vendor/uitamr/plc/core/*.st", "../vendor/uitamr/plc/fx3/*.st", '
        '"../vendor/uitamr/plc/examples/common", "../vendor/uitamr/plc/examples/fx3/UITAMR_ExampleFx3.st"]\n'
        'program = "UITAMR_ExampleFx3"\nduration = "2s"\n\n[rules]\nmin_period = "400ms"\n', encoding="utf-8")
    return project


@pytest.mark.parametrize("how", [[], ["--every-scan"], ["--jobs", "2", "--scenario", "ci/healthy.toml"]])
def test_origins_name_the_toolkit_by_the_path_the_sources_reach_it(tmp_path, monkeypatch, how):
    """The ST location that sent a frame was shown where the symlink leads (/.../plc/fx3/...),
    a path outside the project, beside the scenario file shown relative to it. It is shown
    as the sources reach it, relative to the working folder: vendor/uitamr/plc/fx3/..."""
    monkeypatch.chdir(_vendored_project(tmp_path))
    result = invoke("--scenario", "ci/healthy.toml", "--json", "r.json", "--trace", "t.jsonl", "--html", "r.html",
                    *how)
    assert result.exit_code == 1, result.output
    origin = re.compile(r"vendor/uitamr/plc/fx3/UITAMR_PortFx3\.st:\d+:\d+")
    assert re.search(rf"UITAMR-PACING .* sent by {origin.pattern}\n", result.output), result.output
    for scenario in json.loads(Path("r.json").read_text())["scenarios"]:
        assert scenario["file"] == "ci/healthy.toml"
        assert scenario["violations"] and all(origin.fullmatch(v["origin"]) for v in scenario["violations"])
    sent = [json.loads(line) for line in Path("t.jsonl").read_text().splitlines()]
    assert sent and all(origin.fullmatch(f["origin"]) for f in sent if f.get("dir") == "tx")  # end records: no dir
    page = Path("r.html").read_text(encoding="utf-8")
    assert origin.search(page) and str(REPO / "plc") not in page


def test_sources_given_through_a_symlink_are_shown_as_given(tmp_path, monkeypatch):
    # SOURCES on the command line, a folder of them and a file, absolute and relative
    project = _vendored_project(tmp_path)
    monkeypatch.chdir(project)
    plc = "vendor/uitamr/plc"
    result = invoke(project / plc / "core", f"{plc}/fx3/", f"{plc}/examples/common",
                    f"{plc}/examples/fx3/UITAMR_ExampleFx3.st", "--duration", "1s", "--trace", "t.jsonl")
    assert result.exit_code == 0, result.output
    first = json.loads(Path("t.jsonl").read_text().splitlines()[0])
    assert re.fullmatch(r"vendor/uitamr/plc/fx3/UITAMR_PortFx3\.st:\d+:\d+", first["origin"]), first
    # from the folder above, the same files are that folder's project/vendor/...
    monkeypatch.chdir(tmp_path)
    assert invoke("--scenario", "project/ci/healthy.toml", "--trace", "t.jsonl").exit_code == 1
    first = json.loads(Path("t.jsonl").read_text().splitlines()[0])
    assert first["origin"].startswith("project/vendor/uitamr/plc/fx3/UITAMR_PortFx3.st:"), first
    # and the bundled scenarios, run from the toolkit itself, as before
    monkeypatch.chdir(REPO)
    assert invoke("--scenario", "plc/scenarios/fx3u-healthy.toml", "--duration", "1s", "--trace",
                  tmp_path / "b.jsonl").exit_code in (0, 1)
    first = json.loads((tmp_path / "b.jsonl").read_text().splitlines()[0])
    assert first["origin"].startswith("plc/fx3/UITAMR_PortFx3.st:"), first


def test_a_scenario_without_expectations_expects_the_answered_power_on_stop(tmp_path):
    """Judged by the rules alone, a program that never reaches the robot breaks none: a
    scenario with no [[expect]] expects the power-on stop, as a run without a scenario file
    does - a TCP program whose converter is elsewhere fails, the healthy one passes."""
    healthy = (PLC / "scenarios" / "fx5u-tcp-healthy.toml").read_text(encoding="utf-8")
    healthy = healthy.replace('"../', f'"{PLC.as_posix()}/').split("[[inputs]]")[0]
    assert "[[expect]]" not in healthy
    fine = tmp_path / "rules-only.toml"
    fine.write_text(healthy, encoding="utf-8")
    report = tmp_path / "r.json"
    result = invoke("--scenario", fine, "--duration", "3s", "--json", report)
    assert result.exit_code == 0, result.output
    (scenario,) = json.loads(report.read_text())["scenarios"]
    assert [e["expectation"] for e in scenario["expectations"]] == ["sent stop within 3 s"]
    assert scenario["notes"][0].startswith("no [[expect]] in the scenario: it expects what every program must do")
    elsewhere = tmp_path / "converter-elsewhere.toml"
    elsewhere.write_text(healthy.replace('ip = "192.168.3.50"', 'ip = "192.168.3.60"'), encoding="utf-8")
    result = invoke("--scenario", elsewhere, "--duration", "3s")
    assert result.exit_code == 1, result.output
    assert "expected sent stop within 3 s: stop (01/A0)" in result.output
    refused = tmp_path / "refused.toml"
    refused.write_text(healthy.replace("delay = ", 'refuse_until = "4s"\ndelay = '), encoding="utf-8")
    result = invoke("--scenario", refused, "--duration", "20s", "--json", report)
    assert result.exit_code == 0, result.output
    assert json.loads(report.read_text())["scenarios"][0]["expectations"][0]["expectation"] == \
        "sent stop within 5 s after 4 s"


def test_matrix_runs_a_tcp_program_with_its_own_converter_address(tmp_path):
    """The bundled converter's 192.168.3.50:4001 is the example's CONVERTER_IP/PORT: an FX5U
    program opening its own converter (192.168.10.20:502) passes the TCP scenarios under
    --matrix, and the note says the example's address was not applied."""
    from test_verify_pipeline import library_copy

    plc = library_copy(tmp_path, {"examples/fx5/UITAMR_ExampleTcpFx5.st": [
        ("CONVERTER_IP : DWORD := 16#C0A80332;", "CONVERTER_IP : DWORD := 16#C0A80A14;"),
        ("CONVERTER_PORT : WORD := 4001;", "CONVERTER_PORT : WORD := 502;")]})
    sources = [plc / "core", plc / "fx5" / "UITAMR_PortTcpFx5.st", plc / "examples" / "common",
               plc / "examples" / "fx5" / "UITAMR_ExampleTcpFx5.st"]
    report = tmp_path / "m.json"
    result = invoke(*sources, "--matrix", "--duration", "6s", "--json", report)
    assert result.exit_code == 0, result.output
    data = json.loads(report.read_text())
    assert len(data["scenarios"]) == 5
    for scenario in data["scenarios"]:
        assert scenario["frames"]["tx"] >= 1 and scenario["expectations"][0]["passed"]
        assert any("its converter address (192.168.3.50:4001)" in note for note in scenario["notes"])
    plain = invoke(*sources, "--duration", "3s", "--json", report)
    assert plain.exit_code == 0, plain.output
    own = tmp_path / "own.toml"  # a scenario of one's own still tests the address
    own.write_text("platform = \"fx5u\"\n[converter]\n[[expect]]\nsent = \"stop\"\n", encoding="utf-8")
    result = invoke(*sources, "--scenario", own, "--duration", "5s")
    assert result.exit_code == 1 and "192.168.10.20:502: nothing answers there" in result.output


def test_a_healthy_converter_is_not_reported_as_a_fault(tmp_path):
    """The TCP route's converter (its address, delays, and its own scripted drops) is the
    run's `converter`, not one of the robot's `faults`: the JUnit text of a healthy TCP run
    said 'fault: converter 192.168.3.50:4001, delay 3 ms, packing 5 ms'."""
    paths = {kind: tmp_path / f"r.{kind}" for kind in ("json", "xml", "html")}
    scenario = PLC / "scenarios" / "fx5u-tcp-healthy.toml"
    result = invoke("--scenario", scenario, "--duration", "3s", "--json", paths["json"], "--junit", paths["xml"],
                    "--html", paths["html"])
    assert result.exit_code == 1, result.output  # its point-3 expectation needs the whole run
    report = json.loads(paths["json"].read_text())
    assert report["schema"] == 2  # the converter's move out of "faults" (docs/verifier.md)
    (run,) = report["scenarios"]
    assert run["faults"] == [] and run["converter"] == "converter 192.168.3.50:4001, delay 3 ms, packing 5 ms"
    out = ET.parse(paths["xml"]).getroot().find(".//system-out").text
    assert "fault:" not in out and "\nconverter 192.168.3.50:4001, delay 3 ms, packing 5 ms" in out
    assert "<b>TCP route:</b> converter 192.168.3.50:4001" in paths["html"].read_text()
    assert "<b>Faults:</b>" not in paths["html"].read_text()
    serial = invoke("--scenario", PLC / "scenarios" / "fx5u-no-reply.toml", "--duration", "2s", "--json", paths["json"])
    (run,) = json.loads(paths["json"].read_text())["scenarios"]
    assert run["converter"] is None and run["faults"] == ["no_reply at 4 s for 4 s"], serial.output


def test_the_junit_and_html_run_line_give_the_scan_jitter_the_seed_draws(tmp_path):
    """A CI user reruns a failure from its JUnit or HTML report: both said "scan 10 ms, seed 7"
    of a scenario with scan_jitter = "2ms" - a seed that draws nothing without the jitter -
    and a scenario without a description began its <system-out> with an empty line."""
    scenario = tmp_path / "s.toml"
    scenario.write_text('program = "UITAMR_ExampleFx3"\nduration = "2s"\nscan_jitter = "2ms"\nseed = 7\n',
                        encoding="utf-8")
    xml, page = tmp_path / "r.xml", tmp_path / "r.html"
    result = invoke(*FX3_SOURCES, "--scenario", scenario, "--junit", xml, "--html", page)
    assert result.exit_code == 0, result.output
    out = ET.parse(xml).getroot().find(".//system-out").text
    assert out.splitlines()[0] == ("program UITAMR_ExampleFx3 on fx3u (fx3:1), 2.000 s of virtual time, "
                                   "scan 10 ms ±2 ms, seed 7"), out
    assert "scan 10.0 ms ±2.0 ms · seed 7" in page.read_text(encoding="utf-8")
    scenario.write_text('program = "UITAMR_ExampleFx3"\nduration = "2s"\nseed = 7\n', encoding="utf-8")
    invoke(*FX3_SOURCES, "--scenario", scenario, "--junit", xml)  # no jitter: the line as before
    assert ET.parse(xml).getroot().find(".//system-out").text.startswith(
        "program UITAMR_ExampleFx3 on fx3u (fx3:1), 2.000 s of virtual time, scan 10 ms, seed 7\n")


def test_a_misspelt_label_in_a_scenario_offers_the_label_meant(tmp_path):
    """'fbBat.o_bOK' for the instance fbBatt, 'o_bOkay' for o_bOK: the error says which label
    was probably meant; a name like no label gets no guess."""
    base = (PLC / "scenarios" / "fx5u-healthy.toml").read_text(encoding="utf-8").replace('"../', f'"{PLC.as_posix()}/')
    for wrong, message in (
            ("fbEngin.o_bErr", "the program UITAMR_ExampleFx5 has no label 'fbEngin.o_bErr'; did you mean 'fbEngine'?"),
            ("fbEngine.o_bErrr", "no label 'fbEngine.o_bErrr' in the program UITAMR_ExampleFx5: fbEngine has no "
                                 "member 'o_bErrr'; did you mean 'o_bErr'?"),
            ("zzz", "the program UITAMR_ExampleFx5 has no label 'zzz'"),
            # an abbreviated instance: the label guess asked for 80 % alike (the key guess 60 %) and made none
            ("fbEng.o_bErr", "the program UITAMR_ExampleFx5 has no label 'fbEng.o_bErr'; did you mean 'fbEngine'?"),
            # written in one case: compared case aside, as the 80 % guess did (upper-cased)
            ("FBENGIN.o_bErr", "the program UITAMR_ExampleFx5 has no label 'FBENGIN.o_bErr'; did you mean 'fbEngine'?"),
            # fbCycle's input asked of fbEngine: at 60 % alike the guess would be its constant KIND_STATUS
            ("fbEngine.i_bStart", "no label 'fbEngine.i_bStart' in the program UITAMR_ExampleFx5: fbEngine has no "
                                  "member 'i_bStart'"),
            # a standard FB's member too (its inputs and outputs are its labels)
            ("fbEngine.tmrPace.PTT", "no label 'fbEngine.tmrPace.PTT' in the program UITAMR_ExampleFx5: "
                                     "fbEngine.tmrPace has no member 'PTT'; did you mean 'PT'?")):
        path = tmp_path / "s.toml"
        path.write_text(base.replace('never = "fbEngine.o_bErr OR fbCycle.o_bErr"', f'never = "{wrong}"'),
                        encoding="utf-8")
        result = invoke("--scenario", path, "--duration", "2s")
        assert result.exit_code == 2
        assert result.output.strip().endswith(f"expect[2].never: {message}"), result.output


def test_every_label_mistake_of_a_scenario_is_reported_in_one_run(tmp_path):
    """An integrator's scenario with a misspelt watch, a misspelt input label and a misspelt
    condition label exited 2 naming one of them, and not the first in the file (the
    condition's, at line 29): three CI runs to clean up one file. Now each is an error at its
    own line and column, in the file's order, and a JUnit test case each."""
    base = (PLC / "scenarios" / "fx5u-healthy.toml").read_text(encoding="utf-8").replace('"../', f'"{PLC.as_posix()}/')
    text = (base.replace('watch = ["fbEngine.o_wTxCount"', 'watch = ["fbEngine.o_wTxCnt"')
            .replace("set = { X0 = true }", "set = { bEngineOnn = true }")
            .replace('never = "fbEngine.o_bErr OR fbCycle.o_bErr"', 'never = "fbEngin.o_bErr OR fbCycle.o_bErr"'))
    path, xml = tmp_path / "s.toml", tmp_path / "r.xml"
    path.write_text(text, encoding="utf-8")
    lines = text.splitlines()
    # a watch item at its string (its opening quote), an input at its label, a condition's label at itself
    at = [(n + 1, line.index(word) + 1) for word in ('"fbEngine.o_wTxCnt', "bEngineOnn", "fbEngin.o_bErr")
          for n, line in enumerate(lines) if word in line]
    result = invoke("--scenario", path, "--duration", "2s", "--junit", xml)
    assert result.exit_code == 2
    errors = [line for line in result.output.splitlines() if line.startswith("error:")]
    assert [re.match(r"error: .*s\.toml:(\d+):(\d+): ", e).groups() for e in errors] == \
        [(str(line), str(col)) for line, col in at], result.output
    assert "watch[0]: no label 'fbEngine.o_wTxCnt'" in errors[0]
    assert "inputs[0].set: the program UITAMR_ExampleFx5 has no label 'bEngineOnn'; did you mean 'bEngineOn'?" in errors[1]
    assert "expect[2].never: the program UITAMR_ExampleFx5 has no label 'fbEngin.o_bErr'" in errors[2]
    cases = ET.parse(xml).getroot().findall(".//testcase")
    assert [case.get("line") for case in cases] == [str(line) for line, _ in at]


def test_a_renamed_instance_gets_no_guess_that_lacks_the_member(tmp_path):
    """ci.md: a renamed instance makes the job exit 2 with "no label ...". The FX3U example
    with its engine renamed fbRobot and `--response-signal fbEngine.o_bErr` was told "did
    you mean 'bEngineOn'?": a BOOL, which has no o_bErr. A guess for a part of a path must
    have the rest of the path."""
    main = tmp_path / "MAIN.st"
    main.write_text((PLC / "examples" / "fx3" / "UITAMR_ExampleFx3.st").read_text(encoding="utf-8")
                    .replace("fbEngine", "fbRobot").replace("PROGRAM UITAMR_ExampleFx3", "PROGRAM MAIN"),
                    encoding="utf-8")
    sources = [PLC / "core", PLC / "fx3", PLC / "examples" / "common", main]
    result = invoke(*sources, "--program", "MAIN", "--platform", "fx3u", "--response-signal", "fbEngine.o_bErr")
    assert result.exit_code == 2
    assert result.output.strip().endswith("--response-signal: the program MAIN has no label 'fbEngine.o_bErr'"), \
        result.output
    result = invoke(*sources, "--program", "MAIN", "--platform", "fx3u", "--response-signal", "fbRobott.o_bErr")
    assert result.output.strip().endswith("has no label 'fbRobott.o_bErr'; did you mean 'fbRobot'?"), result.output


def test_the_converter_drop_a_scenario_scripts_is_marked_as_its_fault_on_the_page(tmp_path):
    """verifier.md: the scenario's faults are large orange marks, also on the overview strip.
    The TCP route's scripted drop (converter.dropped) is one - a healthy converter run has none."""
    from verifier.verify.events_shown import event_class

    assert event_class("converter.dropped") == "fault" and event_class("converter.accepted") == "line"
    pages = {}
    for name in ("fx5u-tcp-dropped", "fx5u-tcp-healthy"):
        page = tmp_path / f"{name}.html"
        invoke("--scenario", PLC / "scenarios" / f"{name}.toml", "--duration", "25s", "--html", page)
        pages[name] = page.read_text(encoding="utf-8")
    marks = re.findall(r'class="ovfault" x="([\d.]+)"', pages["fx5u-tcp-dropped"])
    assert len(marks) == 1
    assert re.findall(r'class="ovfault" x="', pages["fx5u-tcp-healthy"]) == []


def test_a_fault_that_met_no_request_is_noted_at_its_line(tmp_path):
    """A scenario's fault whose window saw no request of its kind (here control commands
    while only status reads went out) or whose request number never came tested nothing,
    yet the run passed without a word: now each such fault is a note at its line."""
    scenario, result, notes = _run_with_faults(tmp_path, '[[faults]]\nkind = "bad_crc"\nat_s = 2.0\nduration_s = 1.0\n'
                                                         'requests = "control"\n\n'
                                                         '[[faults]]\nkind = "exception"\non_request = 500\n\n'
                                                         '[[faults]]\nkind = "no_reply"\nat_s = 3.0\n')
    assert (f"{scenario}:4:1: faults[0]: bad_crc at 2 s for 1 s, control requests only: no control request "
            "reached the robot from 2 s for 1 s, so this fault was not tested") in result.output
    assert f"{scenario}:10:1: faults[1]: exception (code 04) on request 500: request 500 never reached" in result.output
    assert "faults[2]" not in result.output                  # the no_reply at 3 s met a status read
    assert sum("was not tested" in note for note in notes) == 2


def _run_with_faults(tmp_path, faults: str):
    """The FX3U example for 5 s under `faults` (TOML from the scenario's line 4 on): the
    scenario file, the command's result and the JSON report's notes."""
    scenario = tmp_path / "s.toml"
    scenario.write_text('program = "UITAMR_ExampleFx3"\nduration = "5s"\n\n' + faults, encoding="utf-8")
    report = tmp_path / "r.json"
    result = invoke(*FX3_SOURCES, "--scenario", scenario, "--json", report)
    assert result.exit_code == 0, result.output
    return scenario, result, json.loads(report.read_text())["scenarios"][0]["notes"]


def test_a_state_fault_that_changed_nothing_is_noted_at_its_line(tmp_path):
    """An integrator's off_tape fault while the robot ran points, not a tape command, and an
    anti_collision with the range set to 0 m: the robot's log said "no effect", the run
    passed (or failed on expectations) and nothing said the fault tested nothing - as
    under --matrix, where the bundled off-tape scenario's fault meets a program that never
    follows a tape. Each is now a note at its line, as a reply fault that met no request."""
    scenario, result, notes = _run_with_faults(tmp_path, '[[faults]]\nkind = "off_tape"\nat_s = 2.0\n\n'
                                                         '[robot]\ncollision_range_stage = 0\n\n'
                                                         '[[faults]]\nkind = "anti_collision"\non_request = 3\n')
    assert (f"{scenario}:4:1: faults[0]: off_tape at 2 s: no magnetic-tape task (seek, follow, rotate) was "
            "running when it struck, and it has no effect otherwise, so this fault was not tested") in result.output
    assert re.search(rf"{re.escape(str(scenario))}:11:1: faults\[1\]: anti_collision on request 3: the "
                     r"anti-collision range was 0 m \(off\) when it struck at [\d.]+ s, so this fault was not "
                     r"tested", result.output), result.output
    assert sum("was not tested" in note for note in notes) == 2
    # the same faults where they bite say nothing: the bundled off-tape scenario's tape task
    result = invoke("--scenario", PLC / "scenarios" / "fx3u-off-tape.toml")
    assert result.exit_code == 0 and "was not tested" not in result.output, result.output


NEVER_REARMED = """PROGRAM MAIN
VAR
    uSend : ARRAY[0..3] OF WORD;
    uRecv : ARRAY[0..3] OF WORD;
    tPoll : TON;
    wReplies : INT;
END_VAR
IF M8002 THEN
    D8400 := 16#1C81;
    D8409 := 5;
    uSend[0] := 16#0601;
    uSend[1] := 16#A001;
    uSend[2] := 16#0000;
    uSend[3] := 16#1488;
END_IF;
tPoll(IN := NOT tPoll.Q, PT := T#400ms);
IF tPoll.Q AND NOT M8402 THEN
    M8402 := TRUE;
END_IF;
IF M8403 THEN
    wReplies := wReplies + 1;
END_IF;
RS2(TRUE, uSend[0], 8, 8, 1, uRecv[0]);
END_PROGRAM
"""


def test_a_reception_never_rearmed_is_named_on_the_console_and_in_junit(tmp_path, monkeypatch):
    # the program sends the stop every 400 ms and never resets M8403: every reply after the
    # first is discarded. Only the JSON report said so, without a place; the console and
    # the JUnit report, what a CI user reads, said nothing
    (tmp_path / "MAIN.st").write_text(NEVER_REARMED, encoding="utf-8")
    monkeypatch.chdir(tmp_path)
    result = invoke("MAIN.st", "--platform", "fx3u", "--duration", "3s", "--junit", "v.xml", "--json", "v.json")
    lines = [line for line in result.output.splitlines() if line.startswith("    simulator ")]
    assert len(lines) == 1, result.output  # one line for every discarded reply
    assert re.fullmatch(
        r"    simulator ×\d+, first at \d\.\d{3} s: RS2 fx3:1: \d received byte\(s\) discarded because M8403 was "
        r"still ON: reset M8403 \(receive complete\) once the received data is read, or RS2 receives nothing "
        r"more \(docs/instructions\.md §7\)  at MAIN\.st:23:1", lines[0]), lines[0]
    out = ET.parse(tmp_path / "v.xml").getroot().find(".//system-out").text
    assert lines[0].strip() in out.splitlines()
    every = json.loads((tmp_path / "v.json").read_text())["scenarios"][0]["simulator_diagnostics"]
    assert int(re.search(r"×(\d+)", lines[0]).group(1)) == len(every) > 1
    # the JSON list names the file as the console does, not by its absolute path
    assert all(entry.startswith("MAIN.st:23:1: t=") for entry in every), every[0]
    # the HTML page: the console's line, not one item per discarded reply
    invoke("MAIN.st", "--platform", "fx3u", "--duration", "3s", "--html", "v.html")
    notes = re.findall(r'<li class="mono simulator-note">(.*?)</li>', (tmp_path / "v.html").read_text())
    assert notes == [lines[0].strip().removeprefix("simulator ")]


def back_to_back(*point_crcs):
    """The stop, then one FC06 point command (register 16#0102, 16#0103, ...) per CRC given, each
    as soon as the CPU has sent the request before it: the requests run together on the line."""
    points = "".join(f"""ELSIF wStep = {step} AND NOT M8402 THEN
    uSend[0] := 16#0601;
    uSend[1] := 16#0{step}01;
    uSend[2] := 16#0000;
    uSend[3] := {crc};
    M8402 := TRUE;
    wStep := {step + 1};
""" for step, crc in enumerate(point_crcs, start=2))
    return """PROGRAM MAIN
VAR
    uSend : ARRAY[0..3] OF WORD;
    uRecv : ARRAY[0..3] OF WORD;
    wStep : INT;
END_VAR
IF M8002 THEN
    D8400 := 16#1C81;
    D8409 := 5;
END_IF;
(* scan 1: the stop; scan 2, as soon as the CPU has sent it: the point command(s) *)
IF wStep = 1 THEN
    uSend[0] := 16#0601;
    uSend[1] := 16#A001;
    uSend[2] := 16#0000;
    uSend[3] := 16#1488;
    M8402 := TRUE;
    wStep := 2;
""" + points + """ELSIF wStep = 0 THEN
    wStep := 1;
END_IF;
M8403 := FALSE;
RS2(TRUE, uSend[0], 8, 8, 1, uRecv[0]);
END_PROGRAM
"""


def failures_of(tmp_path, monkeypatch, program, *args):
    """`uitamr verify` of program as MAIN.st on the fx3u for 1 s, which fails: its JUnit
    failures, message by rule."""
    (tmp_path / "MAIN.st").write_text(program, encoding="utf-8")
    monkeypatch.chdir(tmp_path)
    result = invoke("MAIN.st", "--platform", "fx3u", "--duration", "1s", "--junit", "v.xml", *args)
    assert result.exit_code == 1, result.output
    return {f.get("type"): f.get("message") for f in ET.parse(tmp_path / "v.xml").getroot().iter("failure")}


@pytest.mark.parametrize("crc, crc_finding", [
    ("16#F629", None),  # 01 06 01 02 00 00 29 F6: both requests right, sent too close
    ("16#F6D9", "UITAMR-CRC: 1 violation(s); first at 0.010 s: the second of two requests ran together: "
                "01 06 01 02 00 00 D9 F6 followed 01 06 01 A0 00 00 88 14 after a silence of 1.667 ms, less than "
                "t3.5 = 3.65 ms, so the robot takes them for one frame and discards it; its CRC bytes are D9 F6, "
                "expected 29 F6 (CRC-16/MODBUS of the first 6 bytes, low byte first)"),
])
@pytest.mark.parametrize("path", [[], ["--every-scan"]])  # judged as it goes, and as a whole
def test_two_requests_run_together_are_judged_one_by_one(tmp_path, monkeypatch, crc, crc_finding, path):
    # the line makes one 16-byte frame of two requests 1.7 ms apart: UITAMR-CRC said
    # 'expected 29 ED (CRC-16/MODBUS of the first 14 bytes)' of a frame no one built, and
    # UITAMR-FORMAT only 'too long for an FC06 request: 16 bytes', not why
    failures = failures_of(tmp_path, monkeypatch, back_to_back(crc), *path)
    assert failures.get("UITAMR-CRC") == crc_finding
    assert failures["UITAMR-FORMAT"] == (
        "UITAMR-FORMAT: 1 violation(s); first at 0.010 s: two requests ran together: 01 06 01 02 00 00 "
        + ("D9 F6" if crc_finding else "29 F6") + " followed 01 06 01 A0 00 00 88 14 after a silence of 1.667 ms, "
        "less than t3.5 = 3.65 ms, so the robot takes them for one frame and discards it: leave at least t3.5 of "
        "silence between two requests (and wait for the reply, or its time-out, before the next)")


THREE_TOGETHER = ("three requests ran together: 01 06 01 02 00 00 29 F6 followed 01 06 01 A0 00 00 88 14 after a "
                  "silence of 1.667 ms, 01 06 01 03 00 00 {crc} followed that after 1.667 ms, each less than t3.5 = "
                  "3.65 ms, so the robot takes them for one frame and discards it")


@pytest.mark.parametrize("crc, crc_finding", [
    ("16#3678", None),  # 01 06 01 03 00 00 78 36: all three right, sent too close
    ("16#F6D9", "UITAMR-CRC: 1 violation(s); first at 0.010 s: the third of " + THREE_TOGETHER.format(crc="D9 F6")
                + "; its CRC bytes are D9 F6, expected 78 36 (CRC-16/MODBUS of the first 6 bytes, low byte first)"),
])
@pytest.mark.parametrize("path", [[], ["--every-scan"]])  # judged as it goes, and as a whole
def test_three_requests_run_together_are_split_at_both_pauses(tmp_path, monkeypatch, crc, crc_finding, path):
    # the line recorded the first pause only, and the bytes before it were worked out from
    # the frame's whole silence (both pauses): no split, and UITAMR-CRC said 'expected D3 2C
    # (CRC-16/MODBUS of the first 22 bytes)', UITAMR-FORMAT 'too long for an FC06 request: 24 bytes'
    failures = failures_of(tmp_path, monkeypatch, back_to_back("16#F629", crc), "--json", "v.json", *path)
    assert failures.get("UITAMR-CRC") == crc_finding
    assert failures["UITAMR-FORMAT"] == (
        "UITAMR-FORMAT: 1 violation(s); first at 0.010 s: " + THREE_TOGETHER.format(crc="D9 F6" if crc_finding else "78 36")
        + ": leave at least t3.5 of silence between two requests (and wait for the reply, or its time-out, before "
        "the next)")
    (run,) = json.loads((tmp_path / "v.json").read_text())["scenarios"]
    assert [e["t"] for e in run["line_events"] if e["kind"] == "gap"] == [0.02, 0.03]  # each pause on the line


def test_a_program_the_sources_lack_is_reported_at_the_scenarios_program_line(tmp_path, monkeypatch):
    # 'verify/healthy.toml: no PROGRAM ...' named the file only, though the line is known
    (tmp_path / "MAIN.st").write_text(NEVER_REARMED, encoding="utf-8")
    (tmp_path / "s.toml").write_text('name = "x"\nsources = ["MAIN.st"]\nprogram = "CELL_MAIN"\n', encoding="utf-8")
    monkeypatch.chdir(tmp_path)
    result = invoke("--scenario", "s.toml")
    assert result.exit_code == 2
    assert "error: s.toml:3:11: program: no PROGRAM 'CELL_MAIN' in the sources; they define: MAIN" in result.output
    # --program replaces the file's: then the file's line is not the place
    result = invoke("--scenario", "s.toml", "--program", "OTHER")
    assert result.exit_code == 2
    assert "error: --program: no PROGRAM 'OTHER' in the sources; they define: MAIN" in result.output


def test_a_function_block_as_program_and_a_channel_the_cpu_lacks_are_reported_at_their_lines(tmp_path, monkeypatch):
    # issue 11: every scenario error has file:line:column; these two named the file only
    # ('s.toml: FB_X is a FUNCTION_BLOCK, not a PROGRAM', 's.toml: channel q:1 does not exist
    # on the fx3u CPU'), though the key that says so is in the file
    write_files(tmp_path, {
        "MAIN.st": NEVER_REARMED,
        "FB_X.st": "FUNCTION_BLOCK FB_X\nVAR_INPUT i_b : BOOL; END_VAR\nEND_FUNCTION_BLOCK\n",
        "fb.toml": 'name = "x"\nsources = ["MAIN.st", "FB_X.st"]\nprogram = "FB_X"\n',
        "ch.toml": 'name = "x"\nsources = ["MAIN.st"]\nplatform = "fx3u"\nchannel = "q:1"\n',
    })
    monkeypatch.chdir(tmp_path)
    result = invoke("--scenario", "fb.toml")
    assert result.exit_code == 2
    assert "error: fb.toml:3:11: program: FB_X is a FUNCTION_BLOCK, not a PROGRAM: name the PROGRAM" in result.output
    result = invoke("--scenario", "ch.toml")
    assert result.exit_code == 2
    assert ("error: ch.toml:4:11: channel: channel q:1 does not exist on the fx3u CPU; the fx3u CPU has "
            "fx3:1, fx3:2, adp:1") in result.output
    # given on the command line, the option is the place, not the file's line
    result = invoke("--scenario", "fb.toml", "--program", "FB_X")
    assert result.exit_code == 2 and "error: --program: FB_X is a FUNCTION_BLOCK" in result.output
    (tmp_path / "fx3u.toml").write_text('name = "x"\nsources = ["MAIN.st"]\nplatform = "fx3u"\n', encoding="utf-8")
    result = invoke("--scenario", "fx3u.toml", "--channel", "q:2")
    assert result.exit_code == 2 and "error: --channel: channel q:2 does not exist on the fx3u CPU" in result.output


def test_matrix_with_two_programs_asks_for_program_without_naming_a_bundled_file(tmp_path, monkeypatch):
    # the error named plc/scenarios/fx3u-address-out-of-range.toml and its 'program' key,
    # a file the user did not write and cannot change
    (tmp_path / "MAIN.st").write_text(NEVER_REARMED, encoding="utf-8")
    (tmp_path / "OTHER.st").write_text(NEVER_REARMED.replace("PROGRAM MAIN", "PROGRAM OTHER"), encoding="utf-8")
    monkeypatch.chdir(tmp_path)
    result = invoke("MAIN.st", "OTHER.st", "--platform", "fx3u", "--matrix")
    assert result.exit_code == 2
    assert ("error: --matrix runs one PROGRAM of your sources under the bundled fault sets: say which with "
            "--program; the sources define: MAIN, OTHER") in result.output
    assert "scenarios/" not in result.output


def test_no_response_signal_names_the_error_outputs_the_program_has(tmp_path):
    # 'set [response_handling] signal ... (e.g. "o_bErr")' for a program that has no
    # o_bErr: the user had to find which of its FB outputs to name
    scenario = tmp_path / "s.toml"
    scenario.write_text(
        'name = "bad CRC for 8 s"\nprogram = "UITAMR_ExampleFx3"\nduration = "20s"\n'
        '[[faults]]\nkind = "bad_crc"\nat_s = 5.0\nduration_s = 8.0\n', encoding="utf-8")
    result = invoke(*FX3_SOURCES, "--scenario", scenario)
    assert result.exit_code == 1, result.output
    assert ("and the scenario names no output to show it: set [response_handling] signal in the scenario or "
            "--response-signal (the program has no o_bErr; its FB instances have fbPort.o_bErr, fbEngine.o_bErr, "
            "fbCycle.o_bErr)") in " ".join(result.output.split())


def test_junit_error_of_a_stopped_cpu_says_where_and_why_in_its_message(tmp_path, monkeypatch):
    # <error message="simulation stopped">: a CI server's list showed no place and no reason
    (tmp_path / "Crash.st").write_text(
        "PROGRAM Crash\nVAR\n    a : ARRAY[0..3] OF INT;\n    i : INT;\nEND_VAR\ni := i + 1;\na[i] := 1;\nEND_PROGRAM\n",
        encoding="utf-8")
    monkeypatch.chdir(tmp_path)
    result = invoke("Crash.st", "--platform", "fx3u", "--duration", "1s", "--junit", "v.xml")
    assert result.exit_code == 1
    (error,) = ET.parse(tmp_path / "v.xml").getroot().iter("error")
    assert error.get("type") == "simulation"
    assert re.fullmatch(r"simulation stopped: Crash\.st:7:3: index 4 is outside a\[0\.\.3\].*\(at t=0\.\d+ s\)",
                        error.get("message")), error.get("message")


def test_a_scenario_without_sources_says_the_file_can_list_them(tmp_path, monkeypatch):
    # 'no ST sources: give them as arguments' left out the scenario's own 'sources' key
    (tmp_path / "s.toml").write_text('program = "MAIN"\n', encoding="utf-8")
    monkeypatch.chdir(tmp_path)
    result = invoke("--scenario", "s.toml")
    assert result.exit_code == 2
    assert ('error: s.toml:1:1: sources: no ST sources: list them in the file (sources = ["plc/*.st"] for .st files in '
            "plc/ of the working folder: paths relative to the file's folder) or give them as arguments (uitamr verify "
            "FILE.st ...)") in " ".join(result.output.split())


def test_a_key_the_scenario_leaves_out_is_placed_at_the_start_of_the_file(tmp_path, monkeypatch):
    """An error about a top-level key the scenario does not hold ('sources', 'program', the
    default 'scan') named the file without a line ("s.toml: no ST sources", "s.toml: say which
    PROGRAM"); like a key missing from an [[inputs]] table (placed at its header), it is placed
    at the table it belongs in: the file, 1:1. A scenario without a file names no place."""
    monkeypatch.chdir(tmp_path)
    (tmp_path / "two.st").write_text("PROGRAM MainA\nVAR x : INT; END_VAR\nx := 1;\nEND_PROGRAM\n"
                                     "PROGRAM MainB\nVAR x : INT; END_VAR\nx := 2;\nEND_PROGRAM\n")
    (tmp_path / "none.toml").write_text('name = "x"\nduration = "1s"\n')
    (tmp_path / "two.toml").write_text('name = "x"\nduration = "1s"\nsources = ["two.st"]\n')
    result = invoke("--scenario", "none.toml")
    assert result.exit_code == 2
    assert "error: none.toml:1:1: sources: no ST sources: list them in the file" in result.output
    result = invoke("--scenario", "two.toml")
    assert result.exit_code == 2
    assert ('error: two.toml:1:1: program: say which PROGRAM to run (program = "MainA" in the file, or --program); '
            "the sources define: MainA, MainB") in " ".join(result.output.split())
    result = invoke("two.st", "--scenario", "none.toml")  # the program is still the file's to name
    assert result.exit_code == 2 and "error: none.toml:1:1: program: say which PROGRAM" in result.output
    result = invoke("two.st")  # no file: the option alone
    assert result.exit_code == 2
    assert "error: say which PROGRAM to run with --program; the sources define: MainA, MainB" in result.output
    result = invoke("--scenario", "two.toml", "--program", "MainA", "--duration", "5ms")
    assert result.exit_code == 2
    assert ("error: two.toml:1:1: scan: the scan time (10ms, the default) is longer than the whole run (5ms) "
            "with --duration 5ms") in " ".join(result.output.split())


def test_the_progress_bar_first_shows_how_far_the_work_is():
    """On a terminal the bar's first frame said 0 % though it appeared (after half a second)
    with the run well on - or with the run over: rich drew the task as it was added, before
    its first update. It shows the work done; a run over before the bar would appear shows
    none (it would be drawn, then erased at once)."""
    import io
    import time

    from rich.console import Console

    from verifier.commands.verify import SHOW_PROGRESS_AFTER_S, _LazyProgress

    def frames(*updates: int) -> list[str]:
        out = io.StringIO()
        progress = _LazyProgress(Console(file=out, force_terminal=True, width=100), 1000, True)
        progress.started = time.perf_counter() - SHOW_PROGRESS_AFTER_S - 1  # a long run
        for done in updates:
            progress.update(done, "[1/1] soak")
        progress.stop()
        return re.findall(r"(\d+)% ", out.getvalue())

    shown = frames(400, 1000)
    assert shown and shown[0] == "40" and "0" not in shown, shown
    assert frames(1000) == []


def test_a_response_signal_that_reads_no_label_is_refused():
    # --response-signal TRUE made every failure 'noticed': the rule could not fail
    result = invoke(*FX3_SOURCES, "--program", "UITAMR_ExampleFx3", "--duration", "1s", "--response-signal", "TRUE")
    assert result.exit_code == 2
    assert "--response-signal: 'TRUE' reads no label" in result.output


@pytest.mark.parametrize("report", [None, "--json"])
def test_a_window_cut_off_by_the_duration_option_asks_for_a_longer_one(tmp_path, report):
    """fx3u-healthy expects point 3 within 40 s; --duration 10s ends the run before: the
    advice was "make the scenario's duration longer", though the file's 60 s was long
    enough. Judged as it goes (no report) and as a whole (--json) alike."""
    args = ["--scenario", PLC / "scenarios" / "fx3u-healthy.toml", "--duration", "10s"]
    if report:
        args += [report, tmp_path / "r.json"]
    result = invoke(*args)
    assert result.exit_code == 1, result.output
    assert "before the window closed at 40.000 s: give a longer --duration" in result.output
    assert "make the scenario's duration longer" not in result.output


def test_a_fault_after_the_runs_end_is_not_said_to_have_met_no_request(tmp_path):
    """A reply fault whose window opens after the run ended was noted as "no control
    request reached the robot from 2 s for 1.5 s", as if the program had sent nothing then:
    with --duration 1s the run simply ended first (--duration's own note says so, once), and
    a CPU that stopped at 1 s is said as such."""
    result = invoke("--scenario", PLC / "scenarios" / "fx3u-exception.toml", "--duration", "1s")
    assert "ends the run before 1 of its scripted fault(s), not tested: exception (code 04) at 2 s" in result.output
    assert "no control request reached the robot" not in result.output, result.output
    assert result.output.count("not tested") == 1, result.output

    program = tmp_path / "stop.st"
    program.write_text("PROGRAM MAIN\nVAR\n    tWait : TON;\n    wZero : INT;\n    wOut : INT;\nEND_VAR\n"
                       "tWait(IN := TRUE, PT := T#1s);\nIF tWait.Q THEN\n    wOut := 5 / wZero;\nEND_IF;\n"
                       "END_PROGRAM\n", encoding="utf-8")
    scenario = tmp_path / "s.toml"
    scenario.write_text(f'sources = ["{program.name}"]\nplatform = "q"\nduration = "5s"\n\n'
                        '[[faults]]\nkind = "bad_crc"\nat_s = 2.0\nduration_s = 1.0\n', encoding="utf-8")
    report = tmp_path / "r.json"
    result = invoke("--scenario", scenario, "--json", report)
    (run,) = json.loads(report.read_text())["scenarios"]
    assert run["aborted"], result.output
    (note,) = [note for note in run["notes"] if "faults[0]" in note]
    assert "the simulation stopped at 1.0" in note and "before its window opened at 2 s" in note, note
    assert "reached the robot" not in note


@pytest.mark.parametrize("edit, options, message", [
    (('duration = "60s"', 'duration = "60s"\nscan = "59s"'), ("--duration", "3s"),
     r"fx3u-adprw-exception\.toml:9:8: scan: the scan time \(59s\) is longer than the whole run \(3s\) with --duration 3s"),
    (("", ""), ("--scan", "2min"),
     r"fx3u-adprw-exception\.toml:8:12: duration: the scan time \(2min\) is longer than the whole run \(1min\) with --scan 2min"),
    (('duration = "60s"', 'duration = "60s"\nscan_jitter = "5ms"'), ("--scan", "2ms"),
     r"fx3u-adprw-exception\.toml:9:15: scan_jitter: must be shorter than the scan time \(2ms\) with --scan 2ms"),
])
def test_an_option_that_clashes_with_a_scenario_file_is_named_with_the_files_line(tmp_path, edit, options, message):
    """`--duration 3s` on a scenario with scan = "59s" (the CLI fuzz found it): the message
    was 'NAME: the scan time is longer than the whole run', with no file, line or option."""
    text = (PLC / "scenarios" / "fx3u-adprw-exception.toml").read_text(encoding="utf-8")
    text = text.replace('scan = "10ms"\n', "").replace(*edit).replace('"../', f'"{PLC.as_posix()}/')
    scenario = tmp_path / "fx3u-adprw-exception.toml"
    scenario.write_text(text, encoding="utf-8")
    result = CliRunner().invoke(command, ["--scenario", str(scenario), *options], catch_exceptions=False)
    assert result.exit_code == 2, result.output
    assert re.search(message, result.stderr), result.stderr


def test_scan_and_duration_options_that_clash_are_named_without_a_files_line():
    """`--scan 2min --duration 1min` on a scenario file: both values are the options', yet the
    message pointed at the file's `duration = "60s"` line as if the file were wrong."""
    scenario = PLC / "scenarios" / "fx3u-adprw-exception.toml"
    result = CliRunner().invoke(command, ["--scenario", str(scenario), "--scan", "2min", "--duration", "1min"],
                                catch_exceptions=False)
    assert result.exit_code == 2, result.output
    assert "--scan 2min: the scan time is longer than the whole run (--duration 1min)" in result.stderr, result.stderr
    assert ".toml" not in result.stderr, result.stderr


def test_matrix_on_the_bundled_example_keeps_its_response_signal(tmp_path):
    """--matrix with the FX3U example's own sources and program: the persistent bad-CRC
    scenario failed UITAMR-RESPONSE-HANDLING ("names no output to show it"), because the
    scenario's signal, fbEngine.o_bErr, was dropped as "written for UITAMR_ExampleFx3" -
    the very program run. Another program still gets the default signal."""
    report = tmp_path / "r.json"
    result = invoke(*FX3_SOURCES, "--program", "UITAMR_ExampleFx3", "--matrix", "--json", report)
    assert result.exit_code == 0, result.output
    runs = {s["name"]: s for s in json.loads(report.read_text())["scenarios"]}
    persistent = runs["FX3U: every reply has a bad CRC for 5 s"]
    assert persistent["verdict"] == "pass"
    assert not any("its response signal" in note for note in persistent["notes"])
    # the panel's off-tape fault meets a program that never follows a tape: noted at the
    # fault's line in the bundled file (the matrix dropped every line of the file)
    off_tape = runs["FX3U: the robot leaves the tape while following it"]
    assert any(re.search(r"fx3u-off-tape\.toml:\d+:1: faults\[0\]: off_tape at 4 s: no magnetic-tape task", note)
               for note in off_tape["notes"]), off_tape["notes"]
    panel = tmp_path / "panel.json"  # the panel scenarios are written for UITAMR_PanelFx3
    sources = FX3_SOURCES[:-1] + [PLC / "examples" / "fx3" / "UITAMR_PanelFx3.st"]
    invoke(*sources, "--program", "UITAMR_PanelFx3", "--matrix", "--duration", "6s", "--json", panel)
    notes = [n for s in json.loads(panel.read_text())["scenarios"] for n in s["notes"]]
    assert any("being written for UITAMR_ExampleFx3" in n and "its response signal (fbEngine.o_bErr)" in n
               for n in notes)


def test_the_response_signal_ci_md_names_judges_a_fault_that_strikes_between_commands(tmp_path):
    """docs/ci.md's --matrix job names the program's error output for
    UITAMR-RESPONSE-HANDLING. The example's MAIN, built on the library as the bundled
    examples are, failed the bundled persistent bad-CRC scenario under --matrix with the
    signal ci.md showed (the cycle's o_bErr, 'fbRobot.o_bErr'): the matrix applies no
    operator input, so that fault strikes while no command runs, when only the engine,
    which polls the robot between commands, sees it. ci.md now names the engine's o_bErr
    and says why; the cycle's still fails, as it should. (The scenario is re-aimed as
    --matrix re-aims it, without running the whole matrix.)"""
    from verifier.commands.verify import _with_signal
    from verifier.verify.matrix import for_user_sources
    from verifier.verify.runner import run_scenario
    from verifier.verify.scenario import load_scenario

    guide = (REPO / "docs" / "ci.md").read_text(encoding="utf-8")
    signal = re.search(r'--matrix\n\s+--response-signal "([^"]+)"', guide).group(1)
    main = tmp_path / "MAIN.st"
    main.write_text((PLC / "examples" / "fx3" / "UITAMR_ExampleFx3.st").read_text(encoding="utf-8")
                    .replace("PROGRAM UITAMR_ExampleFx3", "PROGRAM MAIN"), encoding="utf-8")
    persistent = load_scenario(PLC / "scenarios" / "fx3u-bad-crc-persistent.toml")
    mine = for_user_sources(persistent, (*FX3_SOURCES[:-1], main), "MAIN", None)
    assert mine.inputs == ()
    assert run_scenario(_with_signal(mine, signal)).passed
    cycle = run_scenario(_with_signal(mine, "fbCycle.o_bErr"))
    assert [rule for rule, found in cycle.violations.items() if found] == ["UITAMR-RESPONSE-HANDLING"]


def test_every_bad_scenario_file_is_named_in_one_run(tmp_path):
    """Two scenario files with mistakes among three: both named, each at its place, and the
    good one not run (verify stopped at the first mistake and left the second for the next
    run, while `uitamr check` listed both)."""
    first, good, second = (tmp_path / name for name in ("a.toml", "b.toml", "c.toml"))
    first.write_text('program = "UITAMR_ExampleFx3"\nduration = "5 sec"\n')
    good.write_text('program = "UITAMR_ExampleFx3"\nduration = "1s"\n')
    second.write_text('program = "UITAMR_ExampleFx3"\n[[inputs]]\nat = "1s"\nset = { X0 = "on" }\n')
    done = _run_cli("--scenario", first, "--scenario", good, "--scenario", second)
    assert done.returncode == 2, done.stderr
    lines = done.stderr.splitlines()
    assert [line.split(": ")[1] for line in lines if line.startswith("error: ")] == \
        [f"{first}:2:12", f"{second}:4:14"]
    assert "Traceback" not in done.stderr and done.stdout == ""


@pytest.mark.parametrize("jobs", ["1", "2"])
def test_every_scenario_naming_a_missing_label_is_named_in_one_run(tmp_path, jobs):
    """Scenario files that read well but name labels the program does not have: each found
    when its run is set up, and verify stopped at the first one, leaving the next for the
    next run (journey32b, a folder of an integrator's scenarios). Every one is now named in
    one run, each at its place, serially and across --jobs workers; the good one among
    them is not reported."""
    text = (PLC / "scenarios" / "fx3u-healthy.toml").read_text(encoding="utf-8").replace('"../', f'"{PLC}/')
    good = text.replace('duration = "60s"', 'duration = "3s"')
    assert good != text
    files = []
    for name, wrong in (("a", "fbEngin.o_bErr"), ("b", ""), ("c", "fbCycl.o_bErr")):
        path = tmp_path / f"{name}.toml"
        path.write_text(good.replace("fbEngine.o_bErr OR", f"{wrong} OR") if wrong else good, encoding="utf-8")
        files += ["--scenario", path]
    done = _run_cli(*files, "--jobs", jobs)
    assert done.returncode == 2, done.stderr
    errors = [line for line in done.stderr.splitlines() if line.startswith("error: ")]
    assert [line.split(": ")[1] for line in errors] == [f"{tmp_path / 'a.toml'}:36:10", f"{tmp_path / 'c.toml'}:36:10"], \
        done.stderr
    assert "'fbEngin.o_bErr'" in errors[0] and "'fbCycl.o_bErr'" in errors[1]
    assert "Traceback" not in done.stderr and done.stdout == ""


def test_every_scenario_file_without_sources_is_named_in_one_run(tmp_path):
    """Two scenario files that name no ST sources (none given as arguments either): both
    named, each its own error line (verify named only the first and left the second for
    the next run, while a mistake in reading the files names every file)."""
    first, second = tmp_path / "a.toml", tmp_path / "b.toml"
    first.write_text('program = "UITAMR_ExampleFx3"\nduration = "1s"\n')
    second.write_text('duration = "2s"\nprogram = "UITAMR_ExampleFx3"\n')
    done = _run_cli("--scenario", first, "--scenario", second)
    assert done.returncode == 2, done.stderr
    errors = [line for line in done.stderr.splitlines() if line.startswith("error: ")]
    assert [line.split(": ")[1] for line in errors] == [f"{first}:1:1", f"{second}:1:1"]
    assert all("no ST sources" in line for line in errors)
    assert "Traceback" not in done.stderr and done.stdout == ""


def test_a_channel_that_picked_a_cpu_the_sources_do_not_fit_is_blamed(tmp_path):
    """`uitamr verify FX3-SOURCES --channel fx5:1` (no scenario file, no --platform: the
    port picks its CPU) said "the sources load on fx3u, not on fx5u (the default): give
    --platform fx3u", though nothing was a default and --platform fx3u beside --channel
    fx5:1 is refused in turn. The option that picked the CPU is named, with the ports of
    the CPU the sources fit."""
    result = invoke(*FX3_SOURCES, "--program", "UITAMR_ExampleFx3", "--channel", "fx5:1", "--duration", "1s")
    assert result.exit_code == 2, result.output
    assert "(the default)" not in result.output, result.output
    assert ("--channel fx5:1: a port of the fx5u, on which the sources do not load; they load on fx3u: give a "
            "port of the fx3u (fx3:1, fx3:2, adp:1) or leave --channel out") in " ".join(result.output.split())


def test_a_channel_over_the_tcp_route_is_not_applied_silently(tmp_path):
    """`--channel fx5:2` with a TCP scenario (a [converter]) ran as if the option were not
    there, and said nothing: the integrator believed the robot on channel 2 was tested. A
    run of TCP scenarios only refuses it (exit 2), as the file's own `channel` beside
    [converter] is refused; beside a serial scenario, the TCP one's run says in a note."""
    tcp, serial = PLC / "scenarios" / "fx5u-tcp-healthy.toml", PLC / "scenarios" / "fx5u-healthy.toml"
    refused = invoke("--scenario", tcp, "--channel", "fx5:2", "--duration", "1s", "--junit", tmp_path / "v.xml")
    assert refused.exit_code == 2, refused.output
    assert "--channel fx5:2: names a serial port, and every scenario of this run reaches the robot over TCP" in (
        " ".join(refused.output.split()))
    report = tmp_path / "r.json"
    both = invoke("--scenario", tcp, "--scenario", serial, "--channel", "fx5:1", "--duration", "1s", "--json", report)
    assert both.exit_code == 1, both.output  # the examples' 40 s windows: the runs are cut short
    over_tcp, on_serial = json.loads(report.read_text())["scenarios"]
    note = "--channel fx5:1 not applied: this scenario reaches the robot over TCP through its converter, not a serial port"
    assert note in over_tcp["notes"] and note not in on_serial["notes"]
    assert on_serial["channel"] == "fx5:1"


def test_st_errors_of_a_program_without_platform_are_the_ones_of_its_cpu(tmp_path):
    """An FX5U integrator's program with a WORD array index (and an initial value, which GX
    Works3 keeps) run with `uitamr verify SOURCES --program Main` and no --platform: it
    loads on no CPU, and its errors were listed for the FX3U, led by GX Works2's "label
    tables have no initial value column" - a mistake it does not have on the FX5U. Now the
    errors are those of the CPU that finds fewest: the FX5U's."""
    main = tmp_path / "Main.st"
    main.write_text(
        "PROGRAM Main\nVAR\n    fbPort : UITAMR_PortFx5;\n    fbEngine : UITAMR_Engine;\n"
        "    uMbx : ARRAY[0..15] OF WORD;\n    uPort : ARRAY[0..39] OF WORD;\n"
        "    wRoute : ARRAY[0..3] OF INT := [1, 2, 3, 4];\n    wIdx : WORD;\n    wPoint : INT;\nEND_VAR\n"
        "fbPort(i_bEN := TRUE, i_wChannel := 1, io_uPort := uPort);\n"
        "fbEngine(i_bEN := NOT SM402, i_wAddress := 1, i_bMonitor := TRUE, io_uMbx := uMbx, io_uPort := uPort);\n"
        "wPoint := wRoute[wIdx];\nEND_PROGRAM\n", encoding="utf-8")
    result = invoke(PLC / "core", PLC / "fx5" / "UITAMR_PortFx5.st", main, "--program", "Main")
    assert result.exit_code == 2
    assert "array index must be INT or DINT, not WORD" in result.output, result.output
    assert "initial value column" not in result.output, result.output
