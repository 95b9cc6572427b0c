"""`uitamr check --platform`: devices and instructions against a CPU, with the simulator's rules."""
from __future__ import annotations

import json
from pathlib import Path

import pytest
from click.testing import CliRunner

from st_helpers import ROOT
from verifier.cli import main
from verifier.commands.check_formats import RULES

SCENARIOS = sorted((ROOT / "plc" / "scenarios").glob("*.toml"))

BAD = """PROGRAM Bad
VAR
  x : INT;
END_VAR
x := D8403;
SM400 := TRUE;
END_PROGRAM
"""


Q_SERIAL = "a QJ71C24N is driven with G_OUTPUT / G_INPUT and its switch settings (UITAMR_PortQC24, docs/import-gxworks2.md)"
SM400_ON_FX3U = "device SM400: the fx3u has no SM devices; its special relays are M8000..M8511: use M8000 (always ON)"


def run(*args):
    return CliRunner().invoke(main, ["check", *map(str, args)])


def write(tmp_path: Path, text: str, name: str = "p.st") -> Path:
    path = tmp_path / name
    path.write_text(text, encoding="utf-8")
    return path


def program(body: str, decls: str = "x : INT; b : BOOL;") -> str:
    return f"PROGRAM P\nVAR\n  {decls}\nEND_VAR\n{body}\nEND_PROGRAM\n"


def errors(output: str) -> list[str]:
    return [line for line in output.splitlines() if ": error: " in line]


def test_sm400_on_an_fx3u_is_an_error_at_its_place(tmp_path):
    bad = write(tmp_path, BAD)
    assert run(bad).exit_code == 0  # without --platform nothing is asked of the CPU
    done = run("--platform", "fx3u", bad)
    assert done.exit_code == 1
    lines = done.output.splitlines()
    assert lines[0] == (f"{bad}:6:1: error: device SM400: the fx3u has no SM devices; its special "
                        "relays are M8000..M8511: use M8000 (always ON)")
    assert lines[1:3] == ["    SM400 := TRUE;", "    ^^^^^"]
    assert lines[-1] == "1 file(s) checked for gxworks2 on the fx3u CPU: 1 error(s), 0 warning(s)"
    q = run("--platform", "q", bad)  # SM400 and D8403 are Q devices; D8403 an ordinary one
    assert q.exit_code == 0
    assert q.output.splitlines()[0] == (f"{bad}:5:6: warning: D8403 is an ordinary data register on the q "
                                        "(the CPU never sets it); the FX3's D8403 (RS2 ch1 received byte count) "
                                        "has no device on the q: a QJ71C24N is driven with G_OUTPUT / G_INPUT and "
                                        "its switch settings (UITAMR_PortQC24, docs/import-gxworks2.md)")
    assert errors(run("--platform", "fx5u", bad).output) == [  # the FX5U has SM400 but D0..D7999
        f"{bad}:5:6: error: device D8403 does not exist on the fx5u: D runs D0..D7999; "
        "the FX3's D8403 (RS2 ch1 received byte count) is SD8561 on the fx5u (docs/instructions.md §8); as the "
        "FX3U-485ADP-MB's ADPRW ch1 MODBUS error details it has no device known on the fx5u: the register of the "
        "FX5 ADPRW's error code was not found (docs/instructions.md §10)"]


@pytest.mark.parametrize("platform, body, col, message", [
    ("fx3u", "x := D9000;", 6, "device D9000 does not exist on the fx3u: D runs D0..D8511"),
    ("fx3u", "b := X18;", 6, "device X18: X numbers are base 8 on the fx3u"),
    ("fx3g", "b := X200;", 6, "device X200 does not exist on the fx3g: X runs X0..X177"),  # octal
    ("fx3u", "x := D0Z8;", 6, "device D0Z8: index register Z8 does not exist on the fx3u (Z0..Z7)"),
    ("fx5u", "x := D8000;", 6, "device D8000 does not exist on the fx5u: D runs D0..D7999; "
                               "FX3 special registers are SD devices on the fx5u"),
    ("fx5u", "x := D8067;", 6, "device D8067 does not exist on the fx5u: D runs D0..D7999; the FX3's special "
                               "register D8067 (operation error code) is SD0 on the fx5u"),
    ("q", "b := M8402;", 6, "device M8402 does not exist on the q: M runs M0..M8191; the FX3's M8402 (RS2 ch1 "
                            "send request) has no device on the q: a QJ71C24N is driven with G_OUTPUT / G_INPUT "
                            "and its switch settings (UITAMR_PortQC24, docs/import-gxworks2.md)"),
    ("q", "b := M8500;", 6, "device M8500 does not exist on the q: M runs M0..M8191; "
                            "FX3 special relays are SM devices on the q"),
    # the FX3's serial devices, moved to an FX5U: its own RS2 devices, or the module parameters
    ("fx5u", "x := D8400;", 6, "device D8400 does not exist on the fx5u: D runs D0..D7999; the FX3's D8400 "
                               "(RS2 ch1 communication format) has no device on the fx5u: its serial ports take "
                               "the line settings from the module parameters (GX Works3: Module Parameter > 485 "
                               "Serial Port, docs/import-gxworks3.md §4)"),
    ("fx5u", "x := D8429;", 6, "device D8429 does not exist on the fx5u: D runs D0..D7999; the FX3's D8429 "
                               "(RS2 ch2 receive time-out) is SD8631 on the fx5u, in ms (docs/instructions.md §8); "
                               "as the FX3U-485ADP-MB's ADPRW ch2 slave response time-out it is a module parameter "
                               "on the fx5u (GX Works3: Module Parameter > 485 Serial Port, docs/import-gxworks3.md §4)"),
    ("q", "x := W2000;", 6, "device W2000 does not exist on the q: W runs W0..W1FFF"),  # hexadecimal
    ("fx3u", "x := SD0;", 6, "device SD0: the fx3u has no SD devices; its special registers are "
                             "D8000..D8511: use D8067 (operation error code)"),
    ("fx3u", "b := SM402;", 6, "device SM402: the fx3u has no SM devices; its special relays are "
                               "M8000..M8511: use M8002 (ON in the first scan)"),
    ("fx3u", "b := SM8561;", 6, "device SM8561: the fx3u has no SM devices; its special relays are M8000..M8511"),
    ("q", "x := K4M8190;", 6, "K4M8190 runs past the end of M"),
    # buffer memory: before, check passed these and verify stopped with an internal
    # "simulator fault ... IndexError" at the statement
    ("q", "x := U0\\G30000;", 6, "U0\\G30000: buffer memory word 30000 is past G24575 (5FFFH), the end of "
                                   "what the simulator models per module (docs/instructions.md)"),
    ("q", "x := U200\\G1;", 6, "U200\\G1: module U200 would start at I/O 2000, past the q's X/Y1FFF; Un is "
                                "the start I/O number without its last digit (U2 for X/Y020)"),
])
def test_device_out_of_range_or_unknown_to_the_cpu(tmp_path, platform, body, col, message):
    path = write(tmp_path, program(body))
    done = run("--platform", platform, path)
    assert done.exit_code == 1, done.output
    assert errors(done.output) == [f"{path}:5:{col}: error: {message}"]


FX5_MODBUS_PARAMETER = ("a module parameter on the fx5u (GX Works3: Module Parameter > 485 Serial Port, "
                        "docs/import-gxworks3.md §4)")


@pytest.mark.parametrize("body, message", [
    # an FX3U ADPRW program moved to an FX5U: D8409 was only named as RS2's receive time-out,
    # sending the integrator to SD8621 for the MODBUS slave response time-out
    ("D8409 := 400;", "device D8409 does not exist on the fx5u: D runs D0..D7999; the FX3's D8409 (RS2 ch1 "
                      "receive time-out) is SD8621 on the fx5u, in ms (docs/instructions.md §8); as the "
                      "FX3U-485ADP-MB's ADPRW ch1 slave response time-out it is " + FX5_MODBUS_PARAMETER),
    ("D8412 := 0;", "device D8412 does not exist on the fx5u: D runs D0..D7999; the FX3's D8412 (the "
                    "FX3U-485ADP-MB's ADPRW ch1 retries) is " + FX5_MODBUS_PARAMETER),
    ("x := D8422;", "device D8422 does not exist on the fx5u: D runs D0..D7999; the FX3's D8422 (RS2 ch2 bytes "
                    "left to send) is SD8570 on the fx5u (docs/instructions.md §8); as the FX3U-485ADP-MB's ADPRW "
                    "ch2 MODBUS error code it has no device known on the fx5u: the register of the FX5 ADPRW's "
                    "error code was not found (docs/instructions.md §10)"),
])
def test_an_fx3_modbus_register_on_the_fx5u_names_its_modbus_meaning_too(tmp_path, body, message):
    path = write(tmp_path, program(body, "x : INT;"))
    done = run("--platform", "fx5u", path)
    assert done.exit_code == 1, done.output
    assert errors(done.output) == [f"{path}:5:{1 if body.startswith('D') else 6}: error: {message}"]


@pytest.mark.parametrize("platform, body, message", [
    ("q", "b := M8002;", "M8002 is an ordinary internal relay on the q (the CPU never sets it); "
                         "the FX3's special relay M8002 (ON in the first scan) is SM402 on the q"),
    ("q", "b := M8013;", "M8013 is an ordinary internal relay on the q (the CPU never sets it); "
                         "the FX3's special relay M8013 (1000 ms clock) is SM412 on the q"),
    ("fx5u", "b := M8000;", "M8000 is an ordinary internal relay on the fx5u (the CPU never sets it); "
                            "the FX3's special relay M8000 (always ON) is SM400 or SM8000 on the fx5u"),
    ("q", "x := D8400;", "D8400 is an ordinary data register on the q (the CPU never sets it); the FX3's "
                         "D8400 (RS2 ch1 communication format) has no device on the q: " + Q_SERIAL),
    ("q", "x := D8100;", "D8100 is an ordinary data register on the q (the CPU never sets it); "
                         "FX3 special registers are SD devices on the q"),
    ("fx5u", "b := M8402;", "M8402 is an ordinary internal relay on the fx5u (the CPU never sets it); the FX3's "
                            "M8402 (RS2 ch1 send request) is SM8561 on the fx5u (docs/instructions.md §8)"),
    ("fx5u", "b := M8161;", "M8161 is an ordinary internal relay on the fx5u (the CPU never sets it); the FX3's "
                            "M8161 (8-bit mode of CRC) is SM8161 on the fx5u (docs/instructions.md §6); RS2's "
                            "8-bit mode is SD8622 / SD8632 there"),
])
def test_an_fx3_special_number_on_another_cpu_is_a_warning_that_names_its_equivalent(
        tmp_path, platform, body, message):
    # an FX3 habit in a Q or FX5U program: the device exists there, as an ordinary one that
    # nothing sets, so `NOT M8002` is TRUE from the first scan on a Q
    path = write(tmp_path, program(body, "b : BOOL;" if body.startswith("b") else "x : INT;"))
    done = run("--platform", platform, path)
    assert done.exit_code == 0, done.output
    assert done.output.splitlines()[0] == f"{path}:5:6: warning: {message}"
    assert done.output.splitlines()[-1].endswith(": 0 error(s), 1 warning(s)")
    data = json.loads(run("--platform", platform, "--format", "json", path).output)
    assert [(d["severity"], d["rule"]) for d in data["diagnostics"]] == [("warning", "UITAMR-ST-CPU")]


def test_the_fx3_special_numbers_are_the_fx3s_own(tmp_path):
    body = "b := M8002;\nx := D8400;\nb := M8511;"
    assert run("--platform", "fx3u", write(tmp_path, program(body))).output.endswith(
        ": 0 error(s), 0 warning(s)\n")


def test_the_cpus_own_devices_pass(tmp_path):
    body = "x := D8511;\nb := X377;\nx := D0Z7;\nb := M8000;\nx := K4M8496;"
    assert run("--platform", "fx3u", write(tmp_path, program(body))).exit_code == 0


@pytest.mark.parametrize("platform, call, message", [
    ("q", "CRC(TRUE, w[0], 4, x);", "CRC does not exist on the q (it is a fx3/fx5 instruction)"),
    ("q", "ADPRW(TRUE, 1, 3, 0, 1, w[0]);", "ADPRW does not exist on the q (it is a fx3 instruction)"),
    ("fx3u", "G_OUTPUT(TRUE, 16#0, w, w, bb);", "G_OUTPUT does not exist on the fx3u (it is a q instruction)"),
])
def test_an_instruction_the_cpu_does_not_have(tmp_path, platform, call, message):
    path = write(tmp_path, program(call, "x : INT; w : ARRAY[0..3] OF WORD; bb : ARRAY[0..1] OF BOOL;"))
    assert run(path).exit_code == 0  # GX Works2 has the instruction, for some CPU
    done = run("--platform", platform, path)
    assert done.exit_code == 1, done.output
    assert errors(done.output) == [f"{path}:5:1: error: {message}"]


def test_devices_assigned_to_global_labels_are_checked(tmp_path):
    path = write(tmp_path, "VAR_GLOBAL\n  bRun AT SM400 : BOOL;\nEND_VAR\n", "globals.st")
    done = run("--platform", "fx3u", path)
    assert done.exit_code == 1
    assert done.output.startswith(f"{path}:2:11: error: device SM400: the fx3u has no SM devices")


def _bundled_sets() -> list[tuple[str, tuple[Path, ...]]]:
    from verifier.verify.scenario import load_scenario

    sets = {(s.platform, s.sources) for s in map(load_scenario, SCENARIOS)}
    return sorted(sets)


@pytest.mark.parametrize("platform, sources", _bundled_sets(),
                         ids=lambda v: v if isinstance(v, str) else f"{len(v)}-files")
def test_every_bundled_library_set_checks_clean_on_its_platform(platform, sources):
    done = run("--platform", platform, *sources)
    assert done.exit_code == 0, done.output
    assert done.output.endswith(f"on the {platform} CPU: 0 error(s), 0 warning(s)\n")


def test_the_bundled_sets_cover_every_platform_verify_runs():
    # every platform has bundled scenarios of its own (the FX3G's fx3g-*, written for the FX3
    # library: it runs the FX3U's too, scenario.BUNDLED_AS, and the FX3 sets check clean on it below)
    from verifier.verify.scenario import PLATFORMS

    assert {platform for platform, _ in _bundled_sets()} == set(PLATFORMS)


def test_the_fx3_sets_check_clean_on_the_fx3g_that_verify_runs_them_on():
    sets = [sources for platform, sources in _bundled_sets() if platform == "fx3u"]
    assert sets
    for sources in sets:
        done = run("--platform", "fx3g", *sources)
        assert done.exit_code == 0, done.output
        assert done.output.endswith("on the fx3g CPU: 0 error(s), 0 warning(s)\n")


@pytest.mark.parametrize("own, other", [("fx3u", "q"), ("q", "fx3u"), ("q", "fx3g")])
def test_check_reports_what_the_simulator_refuses_to_load(own, other):
    # the loader stops at its first device/instruction error; check finds it, and the rest
    import verifier
    from verifier.sim import LoadError

    sources = next(s for p, s in _bundled_sets() if p == own)
    with pytest.raises(LoadError) as err:
        verifier.load(*sources, target="gxworks2", cpu=other)
    first = err.value.diagnostics[0]
    done = run("--platform", other, *sources)
    assert done.exit_code == 1
    assert str(first) in done.output.splitlines()
    assert int(done.output.splitlines()[-1].split(": ")[1].split()[0]) > 1


def test_every_format_carries_the_cpu_errors_with_their_positions(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    write(tmp_path, BAD, "bad.st")
    data = json.loads(run("--platform", "fx3u", "--format", "json", "bad.st").output)
    assert (data["target"], data["platform"], data["errors"]) == ("gxworks2", "fx3u", 1)
    assert data["diagnostics"] == [{
        "file": "bad.st", "line": 6, "col": 1, "end_line": 6, "end_col": 6, "severity": "error",
        "message": SM400_ON_FX3U,
        "rule": "UITAMR-ST-CPU"}]

    github = run("--platform", "fx3u", "--format", "github", "bad.st")
    assert github.exit_code == 1
    assert github.output.splitlines() == [
        "::error file=bad.st,line=6,col=1,endLine=6,endColumn=6,title=uitamr check UITAMR-ST-CPU::"
        + SM400_ON_FX3U,
        "1 file(s) checked for gxworks2 on the fx3u CPU: 1 error(s), 0 warning(s)"]

    sarif = json.loads(run("--platform", "fx3u", "--format", "sarif", "bad.st").output)
    sarif_run = sarif["runs"][0]
    rules = [r["id"] for r in sarif_run["tool"]["driver"]["rules"]]
    assert set(rules) == set(RULES) | {"UITAMR-ST-CPU"}
    (result,) = sarif_run["results"]
    assert result["ruleId"] == "UITAMR-ST-CPU" and rules[result["ruleIndex"]] == "UITAMR-ST-CPU"
    assert result["level"] == "error"
    assert result["locations"][0]["physicalLocation"] == {
        "artifactLocation": {"uri": "bad.st", "uriBaseId": "%SRCROOT%"},
        "region": {"startLine": 6, "startColumn": 1, "endLine": 6, "endColumn": 6}}


def test_without_platform_the_formats_name_no_platform(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    write(tmp_path, BAD, "bad.st")
    assert "platform" not in json.loads(run("--format", "json", "bad.st").output)
    sarif = json.loads(run("--format", "sarif", "bad.st").output)
    assert {r["id"] for r in sarif["runs"][0]["tool"]["driver"]["rules"]} == set(RULES)


def test_platform_implies_its_editors_dialect():
    fx5 = ROOT / "plc" / "fx5" / "UITAMR_PortTcpFx5.st"  # SP_SOCOPEN: GX Works3 only
    assert run(fx5).exit_code == 1
    done = run("--platform", "fx5u", fx5)
    assert done.output.splitlines()[-1].startswith("1 file(s) checked for gxworks3 on the fx5u CPU:")
    assert run("--platform", "fx5u", "--target", "gxworks3", fx5).output == done.output


@pytest.mark.parametrize("platform, target", [("fx3u", "gxworks3"), ("q", "gxworks3"), ("fx5u", "gxworks2")])
def test_a_contradictory_target_and_platform_is_a_usage_error(tmp_path, platform, target):
    done = run("--platform", platform, "--target", target, write(tmp_path, BAD))
    assert done.exit_code == 2
    assert done.exception is None or isinstance(done.exception, SystemExit)
    assert "Traceback" not in done.output
    (line,) = done.output.splitlines()
    assert line.startswith(f"uitamr check: --platform {platform} and --target {target} disagree: ")
    assert "drop --target" in line


def test_platform_choices_are_the_cpu_profiles(tmp_path):
    from verifier.sim.cpu import PROFILES

    done = run("--platform", "fx2n", write(tmp_path, BAD))
    assert done.exit_code == 2
    assert all(name in done.output for name in PROFILES)


def test_an_instruction_the_cpu_lacks_is_one_error_not_also_its_other_cpus_operands(tmp_path):
    # RS2 written into a Q program with a C24 in mind: the fix is another instruction, so
    # the FX's argument list and operand types are not also held against the call
    body = "RS2(D200, 8, D220, 8, 1);\nx := 0;"
    path = write(tmp_path, program(body, "x : INT;"))
    done = run("--platform", "q", path)
    assert done.exit_code == 1
    assert errors(done.output) == [f"{path}:5:1: error: RS2 does not exist on the q (it is a fx3/fx5 instruction)"]
    on_fx3 = errors(run("--platform", "fx3u", path).output)  # where RS2 exists, they stand
    assert on_fx3[0] == f"{path}:5:1: error: RS2 takes 6 argument(s) (EN, s, m, n, n1, d), 5 given"
    assert len(on_fx3) == 3


@pytest.mark.parametrize("platform, call, message", [
    ("fx5u", "ZP_OPEN(TRUE, 'U0', 1, w[0], b[0]);", "ZP_OPEN does not exist on the fx5u (it is a q instruction)"),
    ("q", "SP_SOCOPEN(TRUE, 'U0', 1, w[0], b[0]);", "SP_SOCOPEN does not exist on the q (it is a fx5 instruction)"),
])
def test_an_instruction_of_the_other_editor_is_one_error_too(tmp_path, platform, call, message):
    # the QJ71E71's ZP_OPEN in an FX5U program is not also 'not available for GX Works3': the
    # CPU's error names the CPU that has it; without --platform the editor's error stands
    path = write(tmp_path, program(call, "w : ARRAY[0..9] OF WORD; b : ARRAY[0..1] OF BOOL;"))
    assert errors(run("--platform", platform, path).output) == [f"{path}:5:1: error: {message}"]
    editor = "GX Works3" if platform == "fx5u" else "GX Works2"
    target = "gxworks3" if platform == "fx5u" else "gxworks2"
    name = call.split("(")[0]
    assert errors(run("--target", target, path).output) == [
        f"{path}:5:1: error: instruction {name} is not available for {editor}; {name} is a {HOME[platform]} "
        "instruction: check " + HOW[platform]]


HOME = {"fx5u": "GX Works2 (Q)", "q": "GX Works3 (FX5U)"}  # the editor the call is from (ZP_OPEN: a Q's)
HOW = {"fx5u": "Q sources with --platform q (or --target gxworks2)",
       "q": "FX5U sources with --platform fx5u (or --target gxworks3)"}


def test_the_fx3_adprw_in_an_fx5u_file_sends_to_the_fx3_platforms_not_to_the_q(tmp_path):
    """The FX3U's six-operand ADPRW copied into an FX5U program: the hint said to check it
    with '--platform fx3u, fx3g or q', and a Q has no ADPRW at all."""
    path = write(tmp_path, program("ADPRW(TRUE, 1, 6, 16#0100, 1, w[0]);", "w : ARRAY[0..1] OF WORD;"))
    assert errors(run("--platform", "fx5u", path).output) == [
        f"{path}:5:1: error: ADPRW takes 7 argument(s) (EN, s, s1, s2, s3, s4d1, d2), 6 given; with 6 arguments it "
        "is the GX Works2 (FX3U/FX3G) ADPRW: check FX3 sources with --platform fx3u or fx3g (or --target gxworks2)"]


def test_the_one_family_gx_works2_instructions_are_the_simulators():
    from verifier.sim.instructions import SPECS
    from verifier.st.check import _GX2_ONE_FAMILY
    from verifier.st.library import INSTRUCTIONS

    gx2_only = {n for n, sig in INSTRUCTIONS.items() if sig.targets == ("gxworks2",)}
    assert set(_GX2_ONE_FAMILY) == gx2_only
    for name, (_, _, platforms) in _GX2_ONE_FAMILY.items():
        families = {"fx3u": "fx3", "fx3g": "fx3", "q": "q"}
        assert {families[p] for p in platforms.split(" or ")} == set(SPECS[name].families), name


def test_check_refuses_the_scenario_devices_verify_refuses_for_its_platform(tmp_path):
    # [initial] and [[inputs]] devices are checked against the scenario's own platform by
    # `uitamr verify` (exit 2 at the key); `uitamr check` said 0 errors for the same file
    scenario = write(tmp_path, 'platform = "fx3u"\n\n[initial]\nD300 = 300\nSM400 = true\n\n'
                               '[[inputs]]\nat = "1s"\nset = { D9000 = 1 }\n', "s.toml")
    done = run(scenario)
    assert done.exit_code == 1, done.output
    assert errors(done.output) == [
        f"{scenario}:5:9: error: initial.SM400: device SM400: the fx3u has no SM devices; its special relays "
        "are M8000..M8511: use M8000 (always ON)",
        f"{scenario}:9:9: error: inputs[0].set: device D9000 does not exist on the fx3u: D runs D0..D8511"]
    assert run(write(tmp_path, 'platform = "q"\n\n[initial]\nSM400 = true\nD9000 = 1\n', "q.toml")).exit_code == 0


def test_a_scenario_without_platform_is_judged_for_the_platform_given(tmp_path):
    """An FX5U project's scenario that names no platform, checked and verified with
    --platform fx5u as ci.md does: its FX5U devices and its [converter] are judged for the
    FX5U both commands run it on, not for the file's default fx3u - check said
    'SD8621: the fx3u has no SD devices' of a file verify ran, and verify refused the
    [converter] it would run on the FX5U."""
    from verifier.commands.verify import command as verify

    plc = ROOT / "plc"
    text = ('[initial]\nSD8621 = 5\n\n[[inputs]]\nat = "1s"\nset = { SM8561 = false }\n\n'
            '[converter]\n\n[[expect]]\nsent = "stop"\n')
    scenario = write(tmp_path, text, "own.toml")
    done = run("--platform", "fx5u", scenario)
    assert done.exit_code == 0, done.output
    assert done.output.splitlines()[-1] == "1 file(s) checked for gxworks3 on the fx5u CPU: 0 error(s), 0 warning(s)"
    alone = run(scenario)  # no --platform: the file's own default, fx3u, as ci.md says
    assert alone.exit_code == 1
    ci_md = " ".join((ROOT / "docs" / "ci.md").read_text(encoding="utf-8").split())
    assert ("with `--platform`, that CPU, the one `uitamr verify --platform` runs every scenario on (also a file "
            "that names its own `platform`); without it, the file's `platform`, and for a file that names none the "
            "fx3u") in ci_md
    scenarios_md = " ".join((ROOT / "docs" / "scenarios.md").read_text(encoding="utf-8").split())
    assert ("set against the CPU `uitamr verify` runs the file on — with `--platform`, that CPU, also for a file "
            "that names its own `platform`") in scenarios_md  # it said: against the file's own platform
    st_dialect_md = " ".join((ROOT / "docs" / "st-dialect.md").read_text(encoding="utf-8").split())
    assert ("checked against the CPU `uitamr verify` runs the file on (with `--platform`, that CPU, also for a file "
            "that names its own `platform`") in st_dialect_md  # it said: against its platform, with or without
    assert errors(alone.output)[0] == (
        f"{scenario}:8:1: error: converter: the TCP route needs a PLC with an Ethernet port the library drives "
        "(fx5u or q); this scenario names no platform, so it is 'fx3u' (the default): add platform = \"fx5u\" "
        "(or \"q\") to the file, or give --platform")
    sources = [plc / "core", plc / "fx5", plc / "examples" / "common", plc / "examples" / "fx5" / "UITAMR_ExampleTcpFx5.st"]
    ran = CliRunner().invoke(verify, [*map(str, sources), "--scenario", str(scenario), "--platform", "fx5u",
                                      "--duration", "3s"])
    assert ran.exit_code == 0, ran.output


def test_a_converter_on_the_platform_option_is_blamed_on_the_option(tmp_path):
    """--platform fx3u given for a scenario that names none and has a [converter]: the
    message said "so it is 'fx3u' (the default) ... or give --platform" to a user who gave
    --platform fx3u. It names the option, and the platforms to give instead."""
    from verifier.commands.verify import command as verify

    scenario = write(tmp_path, '[converter]\n\n[[expect]]\nsent = "stop"\n', "own.toml")
    expected = (f"{scenario}:1:1: error: converter: the TCP route needs a PLC with an Ethernet port the library "
                "drives (fx5u or q); this scenario names no platform and --platform fx3u runs it on the fx3u: give "
                "--platform fx5u (or q), or leave --platform out and add platform = \"fx5u\" (or \"q\") to the file")
    done = run("--platform", "fx3u", scenario)
    assert done.exit_code == 1 and errors(done.output)[0] == expected, done.output
    ran = CliRunner().invoke(verify, [str(ROOT / "plc" / "core"), "--scenario", str(scenario), "--platform", "fx3u"])
    where, message = expected.split(": error: ")
    assert ran.exit_code == 2 and f"error: {where}: {message}" in " ".join(ran.output.split()), ran.output


@pytest.mark.parametrize("spelling", ["FX3U", "Fx3u"])
def test_the_cpu_may_be_written_as_mitsubishi_writes_it(tmp_path, spelling):
    # the scenario's `platform = "FX3U"` is read in any case; so is the option
    done = run("--platform", spelling, write(tmp_path, BAD))
    assert done.exit_code == 1, done.output
    assert done.output.splitlines()[-1] == "1 file(s) checked for gxworks2 on the fx3u CPU: 1 error(s), 0 warning(s)"


def test_verify_takes_the_platform_in_any_case(tmp_path):
    done = CliRunner().invoke(main, ["verify", "--platform", "Q", "--duration", "1s", str(ROOT / "plc" / "core"),
                                     str(ROOT / "plc" / "q"), str(ROOT / "plc" / "examples" / "common"),
                                     str(ROOT / "plc" / "examples" / "q" / "UITAMR_ExampleQ.st")])
    assert "Invalid value for '--platform'" not in done.output
    assert "on q" in done.output, done.output


def test_verify_notes_an_fx3_special_number_in_the_program_it_runs(tmp_path):
    """The classic FX-to-Q port: `NOT M8002` for the first scan, where the Q's is SM402.
    The program runs (M8002 is an ordinary relay there), and `uitamr verify` says what it
    reads, as `check --platform q` warns; only for the POUs the program runs."""
    source = ROOT / "plc" / "examples" / "q" / "UITAMR_ExampleQ.st"
    text = source.read_text(encoding="utf-8")
    assert text.count("bEngineOn := NOT SM402;") == 1
    (tmp_path / "UITAMR_ExampleQ.st").write_text(text.replace("bEngineOn := NOT SM402;", "bEngineOn := NOT M8002;"),
                                                 encoding="utf-8")
    # an FX3 program beside it, not run: not noted
    (tmp_path / "Fx3Beside.st").write_text(program("b := M8002;").replace("PROGRAM P", "PROGRAM Fx3Beside"),
                                           encoding="utf-8")
    scenario = (ROOT / "plc" / "scenarios" / "q-healthy.toml").read_text(encoding="utf-8")
    scenario = scenario.replace('"../', f'"{(ROOT / "plc").as_posix()}/').replace(
        f'"{(ROOT / "plc").as_posix()}/examples/q/*.st"', f'"{tmp_path.as_posix()}/*.st"')
    (tmp_path / "s.toml").write_text(scenario, encoding="utf-8")
    result = CliRunner().invoke(main, ["verify", "--scenario", str(tmp_path / "s.toml"), "--json",
                                       str(tmp_path / "r.json")])
    report = json.loads((tmp_path / "r.json").read_text())
    notes = [n for s in report["scenarios"] for n in s["notes"]]
    line = text.splitlines().index("bEngineOn := NOT SM402;") + 1  # the example's own line, wherever it moves
    assert [n for n in notes if "M8002" in n] == [
        f"{tmp_path / 'UITAMR_ExampleQ.st'}:{line}:18: M8002 is an ordinary internal relay on the q (the CPU never sets "
        "it); the FX3's special relay M8002 (ON in the first scan) is SM402 on the q"], result.output
    assert "Fx3Beside" not in result.output


@pytest.mark.parametrize("platform, call, dotted, st", [
    ("fx5u", "SP.SOCOPEN(TRUE, 'U0', 1, w[0], b[0]);", "SP.SOCOPEN", "SP_SOCOPEN"),
    ("fx5u", "SP.SOCSND(TRUE, 'U0', 1, w[0], w[2], b[0]);", "SP.SOCSND", "SP_SOCSND"),
    ("q", "ZP.OPEN(TRUE, 'U0', 1, w[0], b[0]);", "ZP.OPEN", "ZP_OPEN"),
    ("q", "G.OUTPUT(TRUE, 16#0, w[0], w[3], b[0]);", "G.OUTPUT", "G_OUTPUT"),
])
def test_an_instruction_in_its_ladder_spelling_is_one_error_that_gives_the_st_name(
        tmp_path, platform, call, dotted, st):
    """An integrator copies SP.SOCOPEN from the FX5 manual's ladder: one error that names
    the ST spelling (st-dialect.md §1), not 'undefined label SP' plus 'only labels ... can be
    called'."""
    path = write(tmp_path, program(call, "w : ARRAY[0..9] OF WORD; b : ARRAY[0..1] OF BOOL;"))
    done = run("--platform", platform, path)
    assert done.exit_code == 1
    assert errors(done.output) == [f"{path}:5:1: error: {dotted} is how ladder writes the instruction; ST writes "
                                   f"it with an underscore: {st}(...)"]
    member = write(tmp_path, program("fbX.o_bOK(1);", "fbX : TON;"), "m.st")  # a real label's member: as before
    assert "only labels, functions and instructions can be called" in run("--platform", platform, member).output


def test_a_scenario_that_sets_an_fx3_special_number_on_another_cpu_gets_the_st_warning(tmp_path):
    """[[inputs]] M8402 = true (or [initial] M8002) in an FX5U scenario sets an ordinary
    relay nothing reads: the warning check gives the same device in ST, at its key; the
    FX3U's own scenario says nothing."""
    text = ('platform = "fx5u"\n\n[initial]\nM8002 = true\n\n[[inputs]]\nat = "1s"\nset = { M8402 = true }\n')
    scenario = write(tmp_path, text, "s.toml")
    done = run(scenario)
    assert done.exit_code == 0, done.output  # warnings only
    warnings = [line for line in done.output.splitlines() if ": warning: " in line]
    assert warnings == [
        f"{scenario}:4:9: warning: initial.M8002: M8002 is an ordinary internal relay on the fx5u (the CPU never "
        "sets it); the FX3's special relay M8002 (ON in the first scan) is SM402 or SM8002 on the fx5u",
        f"{scenario}:8:9: warning: inputs[0].set: M8402 is an ordinary internal relay on the fx5u (the CPU never "
        "sets it); the FX3's M8402 (RS2 ch1 send request) is SM8561 on the fx5u (docs/instructions.md §8)"]
    fx3 = write(tmp_path, text.replace('"fx5u"', '"fx3u"'), "fx3.toml")
    assert run(fx3).output.splitlines()[-1].endswith(": 0 error(s), 0 warning(s)")


def test_a_scenario_without_platform_is_judged_for_an_fx3g_with_its_ranges(tmp_path):
    # ci.md: a file that names no platform is judged for --platform, as `uitamr verify
    # --platform fx3g` runs it: on the FX3G, with its ranges
    scenario = write(tmp_path, '[initial]\nX200 = true\n', "s.toml")
    on_fx3g = run("--platform", "fx3g", scenario)
    assert on_fx3g.exit_code == 1, on_fx3g.output
    assert errors(on_fx3g.output) == [f"{scenario}:2:8: error: initial.X200: device X200 does not exist on the fx3g: "
                                      "X runs X0..X177"]
    assert run("--platform", "fx3u", scenario).exit_code == 0  # the FX3U has X200
    # a file that names its own platform: verify --platform runs it on --platform's CPU, so
    # check judges it there too (it said 0 errors where verify refused X200 at its key)
    named = write(tmp_path, 'platform = "fx3u"\n\n[initial]\nX200 = true\n', "named.toml")
    on_fx3g = run("--platform", "fx3g", named)
    assert on_fx3g.exit_code == 1, on_fx3g.output
    assert errors(on_fx3g.output) == [f"{named}:4:8: error: initial.X200: device X200 does not exist on the fx3g: "
                                      "X runs X0..X177"]
    assert run(named).exit_code == 0  # without --platform: its own fx3u
    healthy = (ROOT / "plc" / "scenarios" / "fx3u-healthy.toml").read_text(encoding="utf-8")
    runnable = write(tmp_path, healthy.replace('"../', f'"{(ROOT / "plc").as_posix()}/') + "\n[initial]\nX200 = true\n",
                     "runnable.toml")
    x200 = f"{runnable}:{len(healthy.splitlines()) + 3}:8: "
    verified = CliRunner().invoke(main, ["verify", "--platform", "fx3g", "--scenario", str(runnable)])
    assert verified.exit_code == 2 and x200 + "initial.X200: device X200 does not exist on the fx3g" in verified.output
    assert errors(run("--platform", "fx3g", runnable).output)[0].startswith(x200 + "error: initial.X200")


def test_a_scenarios_own_channel_is_judged_for_the_platform_given(tmp_path):
    # verify --platform q attaches a platform = "fx3u" file's channel fx3:2 to the Q CPU and
    # refuses it at its key (exit 2); check --platform q said 0 errors
    (tmp_path / "N.st").write_text(program("x := x + 1;"), encoding="utf-8")
    named = write(tmp_path, 'sources = ["N.st"]\nplatform = "fx3u"\nchannel = "fx3:2"\nduration = "1s"\n', "c.toml")
    refusal = "channel: channel fx3:2 does not exist on the q CPU; the q CPU has q:1, q:2"
    verified = CliRunner().invoke(main, ["verify", "--platform", "q", "--scenario", str(named)])
    assert verified.exit_code == 2 and f"{named}:3:11: {refusal}" in verified.output, verified.output
    on_q = run("--platform", "q", named)
    assert on_q.exit_code == 1, on_q.output
    assert errors(on_q.output) == [f"{named}:3:11: error: {refusal}"]
    assert run("--platform", "fx3u", named).exit_code == 0 and run(named).exit_code == 0


def test_buffer_memory_past_the_model_is_a_load_error_at_its_place(tmp_path):
    """`verify` (through the loader) stopped at U0\\G30000 with "simulator fault while
    running this statement: IndexError(...)"; it is now the check's error at load."""
    import verifier
    from verifier.sim import LoadError

    path = write(tmp_path, program("x := U0\\G30000;"))
    with pytest.raises(LoadError) as err:
        verifier.load(path, cpu="q")
    assert str(err.value.diagnostics[0]).startswith(f"{path}:5:6: error: U0\\G30000: buffer memory word 30000")


LREAL_ON_FX3 = ("LREAL (FLOAT [Double Precision]) does not exist on the {cpu}: under GX Works2 "
                "only the Universal model QCPU has it; use REAL")


@pytest.mark.parametrize("platform", ["fx3u", "fx3g"])
def test_lreal_is_an_error_on_an_fx3(tmp_path, platform):
    """The QCPU structured programming manual's elementary data types give FLOAT (Double
    Precision) as 'used for the Universal model QCPU only': an FX3 project has none."""
    path = write(tmp_path, program("x := 1;", "x : INT; l : LREAL; a : ARRAY[0..1] OF LREAL;"))
    result = run("--platform", platform, path)
    assert result.exit_code == 1
    assert errors(result.output) == [f"{path}:3:16: error: {LREAL_ON_FX3.format(cpu=platform)}",
                                     f"{path}:3:42: error: {LREAL_ON_FX3.format(cpu=platform)}"]


def test_lreal_passes_on_q_and_fx5(tmp_path):
    path = write(tmp_path, program("l := 1.5;", "l : LREAL;"))
    assert run("--platform", "q", path).exit_code == 0
    assert run("--target", "gxworks3", "--platform", "fx5u", path).exit_code == 0


def test_scenario_files_alone_are_not_said_to_be_checked_for_gx_works2(tmp_path):
    """`uitamr check fx5u-healthy.toml` printed '1 file(s) checked for gxworks2', as if an
    FX5U scenario had been read in the FX3's dialect; each scenario is read for its own
    platform, so a run of scenario files alone names no dialect (one asked for still shows)."""
    fx5 = ROOT / "plc" / "scenarios" / "fx5u-healthy.toml"
    done = run(fx5)
    assert done.exit_code == 0, done.output
    assert done.output.splitlines()[-1] == "1 file(s) checked: 0 error(s), 0 warning(s)"
    assert run("--platform", "fx5u", fx5).output.splitlines()[-1] == \
        "1 file(s) checked for gxworks3 on the fx5u CPU: 0 error(s), 0 warning(s)"
    assert run("--target", "gxworks3", fx5).output.splitlines()[-1] == \
        "1 file(s) checked for gxworks3: 0 error(s), 0 warning(s)"
    st_file = write(tmp_path, program("x := 1;"))
    assert run(fx5, st_file).output.splitlines()[-1].startswith("2 file(s) checked for gxworks2:")


GX3_ONLY = """FUNCTION_BLOCK FB_A
VAR_OUTPUT_RETAIN
    o_wKeep : INT;
END_VAR
VAR
    wCount : INT := 5;
    uVal : UINT;
END_VAR
wCount := wCount + 1;
o_wKeep := wCount;
uVal := uVal;
END_FUNCTION_BLOCK
"""


@pytest.mark.parametrize("command", ["check", "export"])
@pytest.mark.parametrize("platform", ["fx3u", "fx3g", "q"])
def test_a_gx_works3_only_construct_under_a_gx_works2_cpu_is_not_told_to_use_gxworks3(tmp_path, command, platform):
    """import-gxworks2.md's own-program commands with an initial value: `--platform q` said
    'or use --target gxworks3', and following it was refused (exit 2: the Q is programmed in
    GX Works2). With a GX Works2 CPU named the messages give only what works there; without
    --platform they still offer GX Works3."""
    path = write(tmp_path, GX3_ONLY, "FB_A.st")
    args = ["--out", tmp_path / "out"] if command == "export" else []
    done = CliRunner().invoke(main, [command, "--platform", platform, *map(str, args), str(path)])
    assert done.exit_code == 1 and "Traceback" not in done.output
    found = errors(done.output)
    assert found == [f"{path}:2:1: error: VAR_OUTPUT_RETAIN exists only in GX Works3; use VAR_OUTPUT/VAR",
                     f"{path}:6:21: error: GX Works2 label tables have no initial value column: 'wCount' would "
                     "start at 0 on the PLC; set it in the program on the first scan or declare it VAR CONSTANT",
                     f"{path}:7:12: error: type UINT does not exist in GX Works2: GX Works2 has no UINT; use WORD"]
    assert not (tmp_path / "out").exists()
    free = run(path)
    assert sum("--target gxworks3" in line for line in errors(free.output)) == 3
