"""What users hand `uitamr verify` besides the scenario's own keys: sources as files, folders
and (absolute) globs; labels checked against the program with file, line and key; run-time
limits; and reports that name the program that ran. Small programs keep these fast."""
from __future__ import annotations

import json
from pathlib import Path

import pytest
from click.testing import CliRunner

from verifier.commands import verify as verify_command
from verifier.verify.scenario import ScenarioError, load_scenario

PROGRAM = """\
PROGRAM Main
VAR
    w : INT;
    u : WORD;
    b : BOOL;
    r : REAL;
    arr : ARRAY[0..2] OF INT;
    tmr : TON;
END_VAR
w := w + 0;
END_PROGRAM
"""


def invoke(*args):
    return CliRunner().invoke(verify_command.command, [str(a) for a in args], catch_exceptions=False)


@pytest.fixture
def program(tmp_path) -> Path:
    folder = tmp_path / "src" / "app"
    folder.mkdir(parents=True)
    (folder / "Main.st").write_text(PROGRAM, encoding="utf-8")
    return folder / "Main.st"


# --- sources --------------------------------------------------------------------------------

def test_sources_take_absolute_globs_and_folders(tmp_path, program):
    other = tmp_path / "lib"
    other.mkdir()
    (other / "A.st").write_text("FUNCTION A : INT\nA := 1;\nEND_FUNCTION\n", encoding="utf-8")
    scenario = tmp_path / "s.toml"
    scenario.write_text(f'sources = ["{tmp_path.as_posix()}/src/*/*.st", "lib"]\n', encoding="utf-8")
    assert load_scenario(scenario).sources == (program.resolve(), (other / "A.st").resolve())
    scenario.write_text('sources = ["src"]\n', encoding="utf-8")  # a folder: its .st files, recursively
    assert load_scenario(scenario).sources == (program.resolve(),)


def test_sources_keep_the_path_they_were_reached_by(tmp_path, monkeypatch):
    """A source reached through a symlinked folder keeps that path (what reports show, as
    the user wrote it), made absolute; named twice, through the link and directly, it is
    one source. `..` is folded away only where it names the same file."""
    from verifier.verify.sources import unique

    outside = tmp_path / "outside"
    (outside / "deep" / "folder").mkdir(parents=True)
    (outside / "deep" / "A.st").write_text("FUNCTION A : INT\nA := 1;\nEND_FUNCTION\n", encoding="utf-8")
    project = tmp_path / "project"
    (project / "ci").mkdir(parents=True)
    (project / "lib").symlink_to(outside / "deep", target_is_directory=True)
    (project / "up").symlink_to(outside / "deep" / "folder", target_is_directory=True)
    monkeypatch.chdir(project)
    assert unique([Path("ci/../lib/A.st"), outside / "deep" / "A.st", project / "lib" / "A.st"]) == \
        (project / "lib" / "A.st",)
    # up/.. is outside/deep, where A.st is; folded, project/A.st would be no file at all
    assert unique([Path("up/../A.st")]) == (project / "up" / ".." / "A.st",)
    scenario = project / "ci" / "s.toml"
    scenario.write_text('sources = ["../lib/*.st"]\n', encoding="utf-8")
    assert load_scenario(scenario).sources == (project / "lib" / "A.st",)


@pytest.mark.parametrize("given, shown", [
    ("lib/A.st", "lib/A.st"),                  # through the symlink: as given, not where it leads
    ("{project}/lib/A.st", "lib/A.st"),        # absolute, inside the working folder
    ("ci/../lib/A.st", "lib/A.st"),            # `..` folded: the same file
    ("up/../A.st", "up/../A.st"),              # not folded: after a symlinked folder `..` leads elsewhere
    ("{outside}/deep/A.st", "{outside}/deep/A.st"),  # outside the working folder: as given
    ("../outside/deep/A.st", "../outside/deep/A.st"),
    ("{tmp}/back/project/ci/s.toml", "ci/s.toml"),   # from outside through a link back in: where it is
])
def test_report_paths_are_relative_to_the_working_folder_as_the_user_reached_them(tmp_path, given, shown):
    from verifier.textfile import shown_path

    outside = tmp_path / "outside"
    (outside / "deep" / "folder").mkdir(parents=True)
    (outside / "deep" / "A.st").write_text("", encoding="utf-8")
    project = tmp_path / "project"
    (project / "ci").mkdir(parents=True)
    (project / "ci" / "s.toml").write_text("", encoding="utf-8")
    (project / "lib").symlink_to(outside / "deep", target_is_directory=True)
    (project / "up").symlink_to(outside / "deep" / "folder", target_is_directory=True)
    (tmp_path / "back").symlink_to(tmp_path, target_is_directory=True)
    names = {"project": project, "outside": outside, "tmp": tmp_path}
    assert shown_path(given.format(**names), project) == shown.format(**names)


@pytest.mark.parametrize("entry, words", [
    ("/nowhere/at/all/*.st", "'/nowhere/at/all/*.st' matches no file"),
    ("empty", "holds no .st file"),
    ("missing.st", "no such file or folder"),
])
def test_sources_that_name_nothing_are_errors_at_their_line(tmp_path, entry, words):
    (tmp_path / "empty").mkdir()
    scenario = tmp_path / "s.toml"
    scenario.write_text(f'name = "x"\n\nsources = ["{entry}"]\n', encoding="utf-8")
    with pytest.raises(ScenarioError) as info:
        load_scenario(scenario)
    assert str(info.value).startswith(f"{scenario}:3:12: sources[0]: ") and words in str(info.value)


def test_the_command_line_takes_folders(tmp_path, program):
    report = tmp_path / "r.json"
    result = invoke(tmp_path / "src", "--duration", "1s", "--json", report)
    assert result.exit_code == 1, result.output  # runs (and fails: Main never sends the stop)
    scenario = json.loads(report.read_text())["scenarios"][0]
    assert scenario["sources"] == [str(program.resolve())]
    assert scenario["notes"] == ["the program sent nothing on fx3:1 in the whole run"]
    result = invoke(tmp_path / "nothing")
    assert result.exit_code == 2 and "no such file or folder" in result.output
    folder = tmp_path / "scenarios"
    folder.mkdir()
    for name in ("a", "b"):
        (folder / f"{name}.toml").write_text(f'name = "{name}"\nduration = "1s"\n', encoding="utf-8")
    result = invoke(tmp_path / "src", "--scenario", folder, "--json", report)  # a folder of scenarios
    assert [s["name"] for s in json.loads(report.read_text())["scenarios"]] == ["a", "b"]
    result = invoke(tmp_path / "src", "--scenario", tmp_path / "src")
    assert result.exit_code == 2 and "holds no scenario (.toml) file" in result.output


def test_a_folder_given_in_the_wrong_place_says_where_it_goes(tmp_path, program):
    """`uitamr verify plc/scenarios` said "holds no .st file" and `--scenario plc/core` "holds no
    scenario (.toml) file", with nothing on what the folder does hold: they say it, and where
    to give the folder instead - which then runs."""
    folder = tmp_path / "scenarios"
    folder.mkdir()
    (folder / "a.toml").write_text('name = "a"\nduration = "1s"\n', encoding="utf-8")
    result = invoke(folder)
    assert result.exit_code == 2
    assert (f"error: the folder {folder} holds no .st file but 1 scenario (.toml) file(s): give it as --scenario "
            f"{folder} (with the .st files, if the scenarios name none, as SOURCES)") in " ".join(result.output.split())
    result = invoke("--scenario", tmp_path / "src")
    assert result.exit_code == 2
    assert (f"error: the folder {tmp_path / 'src'} holds no scenario (.toml) file but 1 .st file(s): give it without "
            f"--scenario, as SOURCES (uitamr verify {tmp_path / 'src'} ...)") in " ".join(result.output.split())
    ran = invoke(tmp_path / "src", "--scenario", folder, "--json", tmp_path / "r.json")  # as told: it runs
    assert [s["name"] for s in json.loads((tmp_path / "r.json").read_text())["scenarios"]] == ["a"], ran.output


def test_the_reports_name_the_program_chosen_for_the_user(tmp_path, program):
    """No --program and no 'program': the only PROGRAM runs, and every report says which."""
    json_path, html = tmp_path / "r.json", tmp_path / "r.html"
    result = invoke(program, "--duration", "1s", "--json", json_path, "--html", html)
    assert json.loads(json_path.read_text())["scenarios"][0]["program"] == "Main"
    assert "program <code>Main</code>" in html.read_text()
    assert "Main on fx3u" in result.output


# --- labels ---------------------------------------------------------------------------------

def _run_scenario(tmp_path, program, body: str):
    scenario = tmp_path / "s.toml"
    scenario.write_text('program = "Main"\nduration = "1s"\n' + body, encoding="utf-8")
    return invoke(program, "--scenario", scenario), scenario


@pytest.mark.parametrize("body, line, key, message", [
    # a label in a condition: at the label itself, inside the string
    ('\n[[expect]]\nthat = "nosuch.label"\n', "5:9", "expect[0].that", "the program Main has no label 'nosuch.label'"),
    ('\n[[expect]]\nthat = "b"\n[[expect]]\nnever = "tmr.QQ"\n', "7:10", "expect[1].never",
     "no label 'tmr.QQ' in the program Main: tmr has no member 'QQ'"),
    # the one the program lacks, not the condition's first (was 5:8 for either)
    ('\n[[expect]]\nthat = "b AND (w > 1 OR nosuch.label)"\n', "5:25", "expect[0].that",
     "the program Main has no label 'nosuch.label'"),
    ('watch = ["w", "arr[7]"]\n', "3:15", "watch[1]", "no label 'arr[7]' in the program Main: arr has no element [7]"),
    # the label's own name in the table, not the table's brace (5:7)
    ('[[inputs]]\nat = "0s"\nset = { nosuch = true }\n', "5:9", "inputs[0].set", "the program Main has no label 'nosuch'"),
    ('[response_handling]\nsignal = "bErr"\n', "4:11", "response_handling.signal", "the program Main has no label 'bErr'"),
])
def test_unknown_labels_name_file_line_and_key_once(tmp_path, program, body, line, key, message):
    result, scenario = _run_scenario(tmp_path, program, body)
    assert result.exit_code == 2
    assert result.output.strip().splitlines()[-1] == f"error: {scenario}:{line}: {key}: {message}"


@pytest.mark.parametrize("body, words", [
    ('[[expect]]\nthat = "w"\n', "w is a number, not a condition"),
    ('[[expect]]\nalways = "b AND w"\n', "AND joins BOOLs, but w is a number"),
    ('[[expect]]\nnever = "NOT u"\n', "NOT needs a BOOL, but u is a number"),
    ('[[expect]]\nthat = "b = 1"\n', "b is a BOOL and 1 a number"),
    ('[[expect]]\nthat = "b > FALSE"\n', "BOOLs are compared with = or <> only"),
    ('[[inputs]]\nat = "0s"\nset = { X0 = 5 }\n', "X0 is a BOOL (a bit): set it to true or false, not 5"),
    ('[[inputs]]\nat = "0s"\nset = { b = 1 }\n', "b is a BOOL (a bit)"),
    ('[[inputs]]\nat = "0s"\nset = { w = true }\n', "w is a number: set it to a number, not true"),
    ('[[inputs]]\nat = "0s"\nset = { D100 = 99999 }\n', "99999 does not fit D100"),
    ('[[inputs]]\nat = "0s"\nset = { w = 40000 }\n', "40000 does not fit w"),
    ('[[inputs]]\nat = "0s"\nset = { u = -1 }\n', "-1 does not fit u"),
    ('[[inputs]]\nat = "0s"\nset = { w = 1.5 }\n', "got the float 1.5"),
    # int(inf) in the device write was an OverflowError traceback; nan said "cannot convert float NaN to integer"
    ('[[inputs]]\nat = "0s"\nset = { D100 = inf }\n', "D100 is a word device: give a whole number -32768..65535, not inf"),
    ('[[inputs]]\nat = "0s"\nset = { D100 = nan }\n', "D100 is a word device: give a whole number"),
])
def test_labels_of_the_wrong_type_are_refused(tmp_path, program, body, words):
    result, scenario = _run_scenario(tmp_path, program, body)
    assert result.exit_code == 2, result.output
    line = 4 if body.startswith("[[expect]]") else 5  # the line of `that`/`set`
    last = body.splitlines()[-1]
    col = last.index("= ") + 3 if body.startswith("[[expect]]") else last.index("{ ") + 3  # its value; the label
    assert f"{scenario}:{line}:{col}: " in result.output and words in result.output


def test_an_input_to_a_constant_is_refused_not_a_traceback(tmp_path):
    """The trial write was put back in a `finally` that wrote to the constant again: an
    AttributeError traceback instead of the error at the input's line."""
    source = tmp_path / "Main.st"
    source.write_text("PROGRAM Main\nVAR CONSTANT\n    MAX_W : INT := 3;\nEND_VAR\nVAR\n    w : INT;\nEND_VAR\n"
                      "w := MAX_W;\nEND_PROGRAM\n", encoding="utf-8")
    result, scenario = _run_scenario(tmp_path, source, '[[inputs]]\nat = "0s"\nset = { MAX_W = 5 }\n')
    assert result.exit_code == 2, result.output
    assert f"{scenario}:5:9: inputs[0].set: Main.MAX_W is a constant" in result.output


@pytest.mark.parametrize("value", ["true", "5"])
def test_an_input_to_a_string_says_it_is_a_string(tmp_path, value):
    """`s = true` said 's is a number: set it to a number', and `s = 5` 'MAIN.s is a STRING;
    got 5': a STRING cannot be set from a scenario at all, and neither said so."""
    source = tmp_path / "Main.st"
    source.write_text("PROGRAM Main\nVAR\n    s : STRING[10];\n    w : INT;\nEND_VAR\nw := LEN(s);\nEND_PROGRAM\n",
                      encoding="utf-8")
    result, scenario = _run_scenario(tmp_path, source, f'[[inputs]]\nat = "0s"\nset = {{ s = {value} }}\n')
    assert result.exit_code == 2, result.output
    assert f"{scenario}:5:9: inputs[0].set: s is a STRING: an input sets BOOL and number labels only" in result.output


@pytest.mark.parametrize("body", ['[[expect]]\nthat = "s < 5"\n', '[[expect]]\nnever = "s"\n',
                                  '[response_handling]\nsignal = "w > 0 AND s = 1"\n'])
def test_a_condition_on_a_string_says_it_is_a_string(tmp_path, body):
    """`s < 5` on a STRING passed the type check as a number and stopped the run with a
    TypeError traceback; `never = "s"` said 's is a number'."""
    source = tmp_path / "Main.st"
    source.write_text("PROGRAM Main\nVAR\n    s : STRING[10];\n    w : INT;\nEND_VAR\nw := LEN(s);\nEND_PROGRAM\n",
                      encoding="utf-8")
    result, scenario = _run_scenario(tmp_path, source, body)
    assert result.exit_code == 2, result.output
    assert f"{scenario}:4:" in result.output
    assert "s is a STRING: a condition reads BOOL and number labels only" in result.output


def test_values_that_fit_are_accepted(tmp_path, program):
    body = ('watch = ["w", "u", "D100", "r"]\n[[inputs]]\nat = "0s"\n'
            'set = { w = -32768, u = 65535, D100 = 0xFFFF, r = 0.1, X0 = true, b = true }\n'
            '[[expect]]\nthat = "b AND w = -32768 AND D100 = -1 AND X0 = TRUE AND NOT (u < 65535)"\nwithin = "100ms"\n')
    result, _ = _run_scenario(tmp_path, program, body)
    assert result.exit_code == 0, result.output


# --- limits ---------------------------------------------------------------------------------

def test_run_and_scan_times_must_make_sense(tmp_path, program):
    result = invoke(program, "--scan", "0ms")
    assert result.exit_code == 2 and "'0ms' must be longer than 0" in result.output
    result = invoke(program, "--duration", "1000h")
    assert result.exit_code == 2 and "longer than the limit of 24h" in result.output
    scenario = tmp_path / "s.toml"
    scenario.write_text('duration = "25h"\n', encoding="utf-8")
    with pytest.raises(ScenarioError, match=r"s.toml:1:12: duration: longer than the limit of 24h"):
        load_scenario(scenario)


def test_progress_lines_show_in_ci_logs(program, monkeypatch):
    """Not on a terminal there is no progress bar, so a long run prints a line now and then."""
    monkeypatch.setattr(verify_command, "PLAIN_PROGRESS_EVERY_S", 0.0)
    result = invoke(program, "--duration", "3s")
    assert "verify: 33% of 3.000 s virtual time done" in result.output


# --- PLC-side settings before the first scan --------------------------------------------------

Q_PROGRAM = """\
PROGRAM QMain
VAR
    wCount : INT;
    wEnd : INT;
    bDone : BOOL;
END_VAR
IF NOT bDone THEN
    wCount := U0\\G164;
    wEnd := D100;
    bDone := TRUE;
END_IF;
END_PROGRAM
"""


def test_initial_devices_and_buffer_memory_are_there_at_the_first_scan(tmp_path):
    (tmp_path / "QMain.st").write_text(Q_PROGRAM, encoding="utf-8")
    scenario = tmp_path / "s.toml"
    scenario.write_text(
        'sources = ["QMain.st"]\nplatform = "q"\nduration = "100ms"\n'
        '[initial]\n\'U0\\G164\' = 8\nD100 = 0xFFFF\n'
        '[[expect]]\nalways = "wCount = 8 AND wEnd = -1 OR NOT bDone"\n'
        '[[expect]]\nthat = "wCount = 8"\nwithin = "20ms"\n', encoding="utf-8")
    result = invoke("--scenario", scenario)
    assert result.exit_code == 0, result.output


@pytest.mark.parametrize("body, key, words", [
    ("[initial]\nlabel = 1\n", "initial.label", "is not a device"),
    ("[initial]\n'U0\\G99999' = 1\n", "initial.U0\\G99999", "buffer memory ends at"),
    ("[initial]\n'U0\\G1' = true\n", "initial.U0\\G1", "holds words"),
    ("[initial]\n'U0\\G1' = 70000\n", "initial.U0\\G1", "whole number"),
    ("[initial]\nD1 = 1.5\n", "initial.D1", "whole number"),
    ('[[c24]]\nchannel = 3\n', "c24[0].channel", "1..2"),
    ('[[c24]]\nno_reception = 5\n', "c24[0].no_reception", "expected a duration"),
    ('[[c24]]\nbaud = 9600\n', "c24[0].baud", "unknown key"),
    ('[[c24]]\nno_reception_format = 2\n', "c24[0].no_reception_format", "0..1"),
    ('[[c24]]\nchannel = 1\n[[c24]]\nunit = 0\n', "c24[1]", "U0 channel 1 is already set in c24[0]"),
])
def test_plc_settings_mistakes_name_their_key(tmp_path, body, key, words):
    scenario = tmp_path / "s.toml"
    scenario.write_text('platform = "q"\n' + body, encoding="utf-8")
    with pytest.raises(ScenarioError) as info:
        load_scenario(scenario)
    assert info.value.key == key and words in info.value.message and info.value.place is not None


def test_c24_settings_need_the_q_platform(tmp_path, program):
    scenario = tmp_path / "s.toml"
    scenario.write_text('platform = "fx3u"\n\n[[c24]]\nno_reception = "5ms"\n', encoding="utf-8")
    with pytest.raises(ScenarioError, match=r":3:1: c24\[0\]: the QJ71C24N is a Q-series module"):
        load_scenario(scenario)
    scenario.write_text('platform = "q"\nduration = "1s"\n\n[initial]\nD99999 = 1\n', encoding="utf-8")
    result = invoke(program, "--scenario", scenario)  # the q has no D99999: found on the loaded CPU
    assert result.exit_code == 2 and f"{scenario}:5:10: initial.D99999: device D99999 does not exist on the q: D runs" in result.output


def test_the_bundled_q_exception_scenario_needs_the_no_reception_time():
    """q-exception.toml passes (test_plc_scenarios runs it); without its [[c24]] key the
    5-byte exception stays in the module and the scenario fails — the key does the work."""
    from dataclasses import replace

    from verifier.commands.verify import bundled_plc_dir
    from verifier.verify.runner import run_scenario

    scenario = load_scenario(bundled_plc_dir() / "scenarios" / "q-exception.toml")
    assert scenario.c24 and scenario.c24[0].no_reception_us == 5000
    result = run_scenario(replace(scenario, c24=(), duration_us=6_000_000,
                                  expectations=scenario.expectations[:2]))
    assert [e.passed for e in result.expectations] == [True, False]


def test_a_bundled_scenario_aimed_at_user_sources_keeps_robot_faults_and_c24_only(program):
    from dataclasses import replace

    from verifier.commands.verify import bundled_plc_dir
    from verifier.verify.matrix import for_user_sources

    bundled = load_scenario(bundled_plc_dir() / "scenarios" / "q-exception.toml")
    mine = for_user_sources(bundled, (program,), None, None)
    assert (mine.robot, mine.faults, mine.settings) == (bundled.robot, bundled.faults, bundled.settings)
    # the C24 settings are the installation's: made for the module the program drives
    assert mine.c24 == tuple(replace(c24, unit=None) for c24 in bundled.c24)
    assert (mine.sources, mine.program, mine.inputs, mine.watch) == ((program,), None, (), ())
    assert [e.label for e in mine.expectations] == ["sent stop within 5 s"]
    assert str(mine.options.response_signal) == "o_bErr" and not mine.response_signal_given
    (note,) = mine.notes
    assert "C24 settings" in note and "3 operator input(s), 4 expectation(s)" in note


def test_an_o_bErr_that_is_not_a_bool_is_not_taken_as_the_default_signal(tmp_path):
    odd = tmp_path / "Odd.st"
    odd.write_text("PROGRAM Odd\nVAR\n    o_bErr : INT;\nEND_VAR\no_bErr := 1;\nEND_PROGRAM\n", encoding="utf-8")
    result = invoke(odd, "--duration", "1s")
    assert result.exit_code == 1 and "error:" not in result.output  # runs; fails only on the power-on stop
    result = invoke(odd, "--duration", "1s", "--response-signal", "o_bErr")
    assert result.exit_code == 2 and "--response-signal: o_bErr is a number, not a condition" in result.output


# --- inputs the program never sees -------------------------------------------------------------

PUSHBUTTONS = """\
PROGRAM Main
VAR
    bStartPb : BOOL;
    bPulse : BOOL;
    bLamp : BOOL;
    bMode : BOOL;
    nStarts : INT;
    nPulses : INT;
    fbLatch : Latch;
END_VAR
bLamp := nStarts > 0;
Y2 := bLamp;
(* a pushbutton label reset after the program acted on it *)
IF bStartPb THEN
    nStarts := nStarts + 1;
    bStartPb := FALSE;
END_IF;
(* read, then reset in every scan: a one-scan pulse *)
IF bPulse THEN
    nPulses := nPulses + 1;
END_IF;
bPulse := FALSE;
fbLatch(i_bSet := bMode, i_bReset := X1);
Y0 := fbLatch.o_bOn;
IF bMode THEN
    Y1 := TRUE;
END_IF;
END_PROGRAM
"""

LATCH = """\
FUNCTION_BLOCK Latch
VAR_INPUT
    i_bSet : BOOL;
    i_bReset : BOOL;
END_VAR
VAR_OUTPUT
    o_bOn : BOOL;
END_VAR
VAR
    bState : BOOL;
END_VAR
IF i_bSet THEN
    bState := TRUE;
END_IF;
IF i_bReset THEN
    bState := FALSE;
END_IF;
o_bOn := bState;
END_FUNCTION_BLOCK
"""


def test_an_input_the_program_overwrites_before_reading_it_is_noted_at_both_places(tmp_path, monkeypatch):
    """An [[inputs]] entry on a label the program assigns in every scan before it reads it
    did nothing, and the run said nothing: the user thought the button was pressed. A note
    names the input's place and the ST that overwrites it. Labels the program reads, resets
    only sometimes (a pushbutton reset after acting on it) or resets after reading (a
    one-scan pulse) are not noted, nor is a device a call might reach (Y0 after fbLatch)."""
    (tmp_path / "Main.st").write_text(PUSHBUTTONS, encoding="utf-8")
    (tmp_path / "Latch.st").write_text(LATCH, encoding="utf-8")
    (tmp_path / "s.toml").write_text(
        'sources = ["Main.st", "Latch.st"]\nprogram = "Main"\nduration = "1s"\n'
        '[[inputs]]\nat = "100ms"\n'
        'set = { bLamp = true, "fbLatch.i_bSet" = true, "fbLatch.o_bOn" = true, Y2 = true }\n'
        '[[inputs]]\nat = "200ms"\n'
        'set = { bStartPb = true, bPulse = true, bMode = true, X1 = true, Y0 = true, Y1 = true, '
        '"fbLatch.bState" = true }\n'
        '[[expect]]\nthat = "nStarts = 1 AND nPulses = 1"\n', encoding="utf-8")
    monkeypatch.chdir(tmp_path)
    result = invoke("--scenario", "s.toml", "--json", "r.json")
    assert result.exit_code == 0, result.output
    (run,) = json.loads((tmp_path / "r.json").read_text())["scenarios"]
    assert [note for note in run["notes"] if "does nothing" in note] == [
        "s.toml:6:9: inputs[0].set: bLamp = true does nothing: the program overwrites bLamp in every scan before "
        "reading it, at Main.st:11:1 (bLamp := nStarts > 0;)",
        "s.toml:6:23: inputs[0].set: fbLatch.i_bSet = true does nothing: the program overwrites fbLatch.i_bSet in "
        "every scan before reading it, at Main.st:23:9 (i_bSet := bMode); set bMode instead",
        "s.toml:6:48: inputs[0].set: fbLatch.o_bOn = true does nothing: the program overwrites fbLatch.o_bOn in "
        "every scan before reading it, at Latch.st:18:1 (o_bOn := bState;)",
        "s.toml:6:72: inputs[0].set: Y2 = true does nothing: the program overwrites Y2 in every scan before "
        "reading it, at Main.st:12:1 (Y2 := bLamp;)",  # not 'set bLamp instead': it is overwritten too
    ]
    assert "note: s.toml:6:9: inputs[0].set: bLamp = true does nothing" in result.output


def test_the_note_never_says_set_a_label_no_input_can_keep(tmp_path, monkeypatch):
    """'set X instead' names what the program copies into the input's label; a constant
    (which an input may not set) or a VAR_TEMP (set afresh at the start of every scan, so
    an input on it does nothing either) is no way to reach the program: not offered."""
    (tmp_path / "Main.st").write_text(
        "PROGRAM Main\nVAR\n    n, m, k : INT;\n    b : BOOL;\n    tmr : TON;\nEND_VAR\nVAR CONSTANT\n    cMax : INT := 5;\nEND_VAR\n"
        "VAR_TEMP\n    nTemp : INT;\nEND_VAR\n"
        "n := cMax;\nm := nTemp;\nk := D10;\nb := tmr.Q;\ntmr(IN := X1, PT := T#1s);\nY0 := n > m + k OR b;\n"
        "END_PROGRAM\n", encoding="utf-8")
    (tmp_path / "s.toml").write_text(
        'sources = ["Main.st"]\nprogram = "Main"\nduration = "1s"\n'
        '[[inputs]]\nat = "100ms"\nset = { n = 1, m = 2, k = 3, b = true }\n[[expect]]\nthat = "Y0"\n',
        encoding="utf-8")
    monkeypatch.chdir(tmp_path)
    result = invoke("--scenario", "s.toml", "--json", "r.json")
    (run,) = json.loads((tmp_path / "r.json").read_text())["scenarios"]
    notes = [note for note in run["notes"] if "does nothing" in note]
    assert [note.split(": ")[2].split(" =")[0] for note in notes] == ["n", "m", "k", "b"], result.output
    assert notes[0].endswith("(n := cMax;)") and notes[1].endswith("(m := nTemp;)"), notes
    assert notes[2].endswith("(k := D10;); set D10 instead"), notes  # a device an input can set
    assert notes[3].endswith("(b := tmr.Q;)"), notes  # an FB's output: its next call writes it again


def test_no_bundled_scenario_has_an_input_its_program_never_sees():
    """The bundled examples' inputs: buttons (X0, X20...) read through FB calls, an address
    register (D202), a setting label (bUseRs232): none is noted."""
    import verifier
    from verifier.verify.overwritten import overwritten_input_notes

    projects = {}
    scenarios = [load_scenario(path) for path in sorted((Path(__file__).parent.parent / "plc" / "scenarios").glob("*.toml"))]
    assert sum(len(s.inputs) for s in scenarios) > 60
    for scenario in scenarios:
        key = (scenario.sources, scenario.platform, scenario.program)
        if key not in projects:
            projects[key] = verifier.load(*[str(p) for p in scenario.sources], target=scenario.target,
                                          cpu=scenario.platform, programs=[scenario.program])
        assert overwritten_input_notes(scenario, projects[key].files, scenario.program, lambda o, c: o) == [], scenario.path


def test_the_documented_note_on_the_fx3u_example_is_what_verify_prints(tmp_path, monkeypatch):
    """docs/scenarios.md: pressing fbCycle.i_bStart instead of X0 in the FX3U example."""
    plc = Path(__file__).parent.parent / "plc"
    text = (plc / "scenarios" / "fx3u-healthy.toml").read_text(encoding="utf-8")
    assert text.splitlines()[15] == "set = { X0 = true }"  # line 16, as the documented note says
    # Y0 too: assigned after the example's FB calls, which the search does not see through (no note)
    text = text.replace("set = { X0 = true }", 'set = { "fbCycle.i_bStart" = true, Y0 = true }')
    text = text.replace('"../', f'"{plc.as_posix()}/')
    (tmp_path / "s.toml").write_text(text, encoding="utf-8")
    monkeypatch.chdir(plc.parent)  # the ST files as the reports show them, relative to the working folder
    result = invoke("--scenario", tmp_path / "s.toml", "--duration", "3s", "--json", tmp_path / "r.json")
    (note,) = [n for n in json.loads((tmp_path / "r.json").read_text())["scenarios"][0]["notes"] if "does nothing" in n]
    assert note.startswith(f"{tmp_path / 's.toml'}:16:9: ")
    documented = " ".join((plc.parent / "docs" / "scenarios.md").read_text(encoding="utf-8").split())
    assert f"`s.toml:16:9: {note.split(':16:9: ', 1)[1]}`" in documented, note
    assert "note: " + note in result.output


@pytest.mark.parametrize("body, name, line", [
    ("x := FALSE;\nIF x THEN n := 1; END_IF;", "x", 8),  # assigned first: the input is gone
    ("X_UP := TRUE;", "x_up", 8),  # ST labels: x_up is X_UP
    ("arr[2] := 0;", "arr[2]", 8),
    ("x := x OR y;", "x", None),  # reads itself first
    ("IF y THEN RETURN; END_IF;\nx := TRUE;", "x", None),  # the assignment may not run
    ("arr[n] := 0;\narr[2] := 1;", "arr[2]", None),  # any element, then: it may be read before
    ("w.3 := TRUE;\nw := 0;", "w", None),  # a bit of it first: the search gives up (a miss, no false alarm)
    ("n := arr[2] + 1;\narr[2] := 0;", "arr[2]", None),
    ("BMOV(TRUE, arr[0], 3, buf[0]);\nbuf[2] := 0;", "buf[2]", None),  # an operand reaches a block
    ("tmr(IN := y, PT := T#1s);", "tmr.Q", None),  # a standard FB: no ST body to follow
    ("tmr(IN := y, PT := T#1s);", "tmr.PT", 8),  # ... but the call assigns its inputs
    ("tmr(IN := y, PT := T#1s);", "tmr.ET", None),
    ("g := TRUE;", "g", None),  # a global label: any POU may read it
    ("n := 1;\nY3 := y;", "Y3", 9),  # a device, before any call
    ("y := NOT y;\nY3 := y;", "Y3", 9),
    ("BMOV(TRUE, arr[0], 3, buf[0]);\nY3 := y;", "Y3", None),  # any call may reach a device
    ("IF y THEN x := TRUE; END_IF;\nx := FALSE;", "x", None),  # an IF that names it: given up (a miss)
    ("x := FALSE;", "X0", None),  # a label is not the device of the same name
    ("Y10 := y;", "Y8", None),  # on the FX3U Y10 is octal: compared as written, never confused
    ("Y010 := y;", "Y10", 8),
    # an output's destination is written after the call: its index is read (the input seen)
    ("tmr(IN := y, PT := T#1s, Q => bits[n]);\nn := 0;", "n", None),
    ("tmr(IN := y, PT := T#1s, Q => bits[n]);\nbits[2] := FALSE;", "bits[2]", None),
    ("tmr(IN := y, PT := T#1s, Q => bits[2]);\nn := 0;", "n", 9),
    # an index register is read by the device it modifies
    ("n := D100Z0;\nZ0 := 0;", "Z0", None),
    ("D100Z0 := n;\nZ0 := 0;", "Z0", None),
    # a module number is compared as a number, as the simulator reads it (U00 is U0)
    ("n := U00\\G10;\nU0\\G10 := 1;", "U0\\G10", None),
    ("U00\\G10 := n;", "U0\\G10", 8),
])
def test_what_counts_as_overwritten_before_read(tmp_path, body, name, line):
    import verifier
    from verifier.verify.overwritten import first_overwrite

    (tmp_path / "Main.st").write_text(
        "PROGRAM Main\nVAR\n    x, y, X_UP : BOOL;\n    n, w : INT;\n    arr, buf : ARRAY[0..3] OF INT;\n"
        "    tmr : TON; bits : ARRAY[0..3] OF BOOL;\nEND_VAR\n" + body + "\nEND_PROGRAM\n", encoding="utf-8")  # the body from line 8
    (tmp_path / "Globals.st").write_text("VAR_GLOBAL\n    g : BOOL;\nEND_VAR\n", encoding="utf-8")
    project = verifier.load(str(tmp_path / "Main.st"), str(tmp_path / "Globals.st"), target="gxworks2", cpu="fx3u")
    found = first_overwrite(project.files, "Main", name)
    assert (found.span.line if found is not None else None) == line, found


@pytest.mark.parametrize("separator", ["\x0c", "\u2028", "\x1c", "\x85"])
def test_the_note_quotes_the_overwriting_statement_past_a_line_separator_in_a_comment(tmp_path, monkeypatch, separator):
    """A form feed or a Unicode line separator inside a comment is no new line for the ST
    parser (it counts line feeds, textfile.text_lines): the statement the note quotes is the
    one at the line it names, not the line after it (str.splitlines broke at them too)."""
    notes, output = _does_nothing_notes(tmp_path, monkeypatch, "Main.st", f"(* page{separator}break *)\n")
    assert notes == ["s.toml:6:9: inputs[0].set: b = true does nothing: the program overwrites b in every scan "
                     "before reading it, at Main.st:7:1 (b := n > 0;)"], output


def _does_nothing_notes(tmp_path, monkeypatch, source: str, before: str = "") -> tuple[list[str], str]:
    """The 'does nothing' notes (and the console) of a run that sets b, which the program
    in `source` (`before` put ahead of its statements) overwrites before reading it."""
    (tmp_path / source).write_text(
        f"PROGRAM Main\nVAR\n    b : BOOL;\n    n : INT;\nEND_VAR\n{before}b := n > 0;\nn := n + 1;\n"
        "Y0 := b;\nEND_PROGRAM\n", encoding="utf-8")
    (tmp_path / "s.toml").write_text(
        f'sources = [{json.dumps(source)}]\nprogram = "Main"\nduration = "1s"\n'
        '[[inputs]]\nat = "100ms"\nset = { b = true }\n[[expect]]\nthat = "Y0"\n', encoding="utf-8")
    monkeypatch.chdir(tmp_path)
    result = invoke("--scenario", "s.toml", "--json", "r.json")
    (run,) = json.loads((tmp_path / "r.json").read_text())["scenarios"]
    return [note for note in run["notes"] if "does nothing" in note], result.output


def _load_error(*diagnostics):
    from verifier.sim.errors import LoadError
    from verifier.st.ast import Diagnostic

    return LoadError([Diagnostic(*d) for d in diagnostics])


def test_the_error_compared_across_platforms_is_the_first_diagnostics_whole_line():
    """infer_platform compares each platform's first diagnostic, read back from the message's
    second line: a file name that holds a line break gave only its head ('odd'), the same for
    every mistake in that file. Now the diagnostic's own line, from the data (the name's
    line break shown escaped, as every file:line:col line shows it: textfile.shown_name)."""
    from verifier.verify.platform import _first_error

    error = _load_error(("odd\nname.st", 5, 6, "error", "undefined label 'y'"))
    assert _first_error(error) == "odd\\x0aname.st:5:6: error: undefined label 'y'"
    assert _first_error(_load_error()) == str(_load_error())  # no diagnostic: the message


def test_a_warning_before_the_errors_is_still_the_one_compared(monkeypatch):
    """LoadError.located() gives errors only; the line compared across platforms stays the
    first diagnostic's, a warning too: two platforms whose first warning is the same (and
    whose errors differ) are one ST mistake, as before, said at the first error's place."""
    from verifier.verify import platform as platform_module

    loads = {"fx3u": _load_error(("M.st", 1, 1, "warning", "w"), ("M.st", 5, 6, "error", "a")),
             "fx5u": _load_error(("M.st", 1, 1, "warning", "w"), ("M.st", 7, 8, "error", "b"))}
    assert platform_module._first_error(loads["fx3u"]) == "M.st:1:1: warning: w"
    monkeypatch.setattr(platform_module, "platforms_that_load", lambda sources: ([], loads))
    with pytest.raises(platform_module.UnusableInput) as raised:
        platform_module.infer_platform((Path("M.st"),))
    assert str(raised.value) == "the sources do not load: M.st:5:6: error: a"
    assert str(raised.value.place) == "M.st:5:6"


def test_the_overwritten_input_note_shows_a_source_named_with_a_newline_on_its_line(tmp_path, monkeypatch):
    """The note's 'at file:line:col' was built by hand from the span's raw file name, so a
    source named `Ma<LF>in.st` broke the note into two lines where every other message shows
    the name escaped (textfile.shown_name, `Ma\\x0ain.st`)."""
    notes, output = _does_nothing_notes(tmp_path, monkeypatch, "Ma\nin.st")
    assert notes == ["s.toml:6:9: inputs[0].set: b = true does nothing: the program overwrites b in every scan "
                     "before reading it, at Ma\\x0ain.st:6:1 (b := n > 0;)"], output


def test_the_cpu_note_shows_a_source_named_with_a_newline_on_its_line(tmp_path, monkeypatch):
    """The run's CPU notes (M8002 on a Q) built their 'file:line:col' by hand from the raw
    file name: a source named `Ma<LF>in.st` broke the note into two lines."""
    (tmp_path / "Ma\nin.st").write_text("PROGRAM MAIN\nIF M8002 THEN\n    Y0 := TRUE;\nEND_IF;\nEND_PROGRAM\n",
                                        encoding="utf-8")
    monkeypatch.chdir(tmp_path)
    result = invoke("Ma\nin.st", "--platform", "q", "--duration", "1s")
    assert "    note: Ma\\x0ain.st:2:4: M8002 is an ordinary internal relay on the q" in result.output, result.output
    assert "\nin.st:2:4" not in result.output


def test_a_place_in_st_is_relative_in_a_folder_whose_name_holds_a_colon(tmp_path, monkeypatch):
    """runner._relative split 'file:line:col' at the first ':', so in a working folder named
    'x:y' (and on Windows, 'C:\\...', in every one) the note kept the ST file's absolute path
    where it names it relative to the working folder: 'at /tmp/.../x:y/Main.st:6:1'."""
    folder = tmp_path / "x:y"
    folder.mkdir()
    notes, output = _does_nothing_notes(folder, monkeypatch, "Main.st")
    assert notes == ["s.toml:6:9: inputs[0].set: b = true does nothing: the program overwrites b in every scan "
                     "before reading it, at Main.st:6:1 (b := n > 0;)"], output
