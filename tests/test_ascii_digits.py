"""Numbers take the digits 0-9 only. Python's int(), float() and Decimal() read '١٢'
(Arabic-Indic) and '１２' (full-width) as 12, and `\\d` matches them: `uitamr frame stop
--address １２` printed the frame of robot 12. Every number the toolkit parses from text
(options, command words, captures, durations, conditions, scenario strings) refuses them
with an error that names the argument and the character: exit 2, no traceback."""
from __future__ import annotations

from pathlib import Path

import pytest

from test_cli_robustness import invoke
from verifier.digits import digit_problem
from verifier.verify.scenario import ScenarioError, parse_scenario

FULL_TWO = "２"  # U+FF12 FULLWIDTH DIGIT TWO
ARABIC_FIVE = "٥"  # U+0665 ARABIC-INDIC DIGIT FIVE


def test_the_message_names_the_character_and_the_digit_to_write():
    assert digit_problem("1" + FULL_TWO) == "'２' (U+FF12 FULLWIDTH DIGIT TWO) is not one of the digits 0-9 (write 2)"
    assert digit_problem("²") == "'²' (U+00B2 SUPERSCRIPT TWO) is not one of the digits 0-9 (write 2)"
    assert digit_problem("0x1F 250ms µs") is None


@pytest.mark.parametrize("args, argument, char", [
    # frame: the robot address, every command value, the words of `raw`
    (["frame", "stop", "--address", "1" + FULL_TWO], "'--address'", FULL_TWO),
    (["frame", "run-point", ARABIC_FIVE], "point number", ARABIC_FIVE),
    (["frame", "raw", "1", ARABIC_FIVE], "command", ARABIC_FIVE),
    (["frame", "raw", "0x" + FULL_TWO, "5"], "control code", FULL_TWO),
    (["frame", "speed", "trackless", FULL_TWO], "speed stage", FULL_TWO),
    (["frame", "collision-range", FULL_TWO], "anti-collision range", FULL_TWO),
    (["frame", "move", "x", "-" + FULL_TWO + ".5"], "distance", FULL_TWO),
    (["frame", "rotate", "0." + ARABIC_FIVE], "rotation", ARABIC_FIVE),
    (["frame", "--decode", "01 06 01 A0 00 00 88 1" + FULL_TWO], "--decode", FULL_TWO),
    # verify's numbers and durations (and the condition of --response-signal, below)
    (["verify", "--duration", FULL_TWO + "s", "--list-rules"], "'--duration'", FULL_TWO),
    (["verify", "--scan", "1" + FULL_TWO + "ms", "--list-rules"], "'--scan'", FULL_TWO),
    (["verify", "--seed", FULL_TWO, "--list-rules"], "'--seed'", FULL_TWO),
    (["verify", "--jobs", FULL_TWO, "--list-rules"], "'--jobs'", FULL_TWO),
    (["verify", "--violations", FULL_TWO, "--list-rules"], "'--violations'", FULL_TWO),
    # monitor and replay: durations ('٠' alone was taken as the zero tolerance) and the port
    (["replay", "--tolerance", "٠", "{capture}"], "'--tolerance'", "٠"),
    (["replay", "--tolerance", ARABIC_FIVE + "ms", "{capture}"], "'--tolerance'", ARABIC_FIVE),
    (["replay", "--reply-timeout", ARABIC_FIVE + "00ms", "{capture}"], "'--reply-timeout'", ARABIC_FIVE),
    (["monitor", "--tcp", "127.0.0.1:" + ARABIC_FIVE + "02", "--duration", "1s"], "--tcp", ARABIC_FIVE),
    (["monitor", "--tcp", "127.0.0.1:1", "--duration", FULL_TWO + "s"], "'--duration'", FULL_TWO),
    # emulate: the speed, the port, the numbers of seconds and milliseconds, the fault flags
    (["emulate", "--serial", "/dev/null", "--baud", "９６００", "--exit-after", "1"], "'--baud'", "９"),
    (["emulate", "--tcp", "０", "--exit-after", "1"], "--tcp", "０"),
    (["emulate", "--tcp", "0", "--exit-after", "0." + ARABIC_FIVE], "'--exit-after'", ARABIC_FIVE),
    (["emulate", "--tcp", "0", "--exit-after", "1", "--turnaround-ms", FULL_TWO], "'--turnaround-ms'", FULL_TWO),
    (["emulate", "--tcp", "0", "--exit-after", "1", "--anti-collision-at", FULL_TWO], "'--anti-collision-at'",
     FULL_TWO),
    (["emulate", "--tcp", "0", "--exit-after", "1", "--no-reply-on", FULL_TWO], "--no-reply-on", FULL_TWO),
    (["emulate", "--tcp", "0", "--exit-after", "1", "--exception-on", "3:" + FULL_TWO], "--exception-on", FULL_TWO),
    (["emulate", "--tcp", "0", "--exit-after", "1", "--late-reply-on", "3:" + FULL_TWO], "--late-reply-on",
     FULL_TWO),
])
def test_a_digit_other_than_0_to_9_on_the_command_line_is_a_usage_error(args, argument, char, tmp_path):
    capture = tmp_path / "c.txt"
    capture.write_text("0.000 tx 01 06 01 A0 00 00 88 14\n", encoding="utf-8")
    result = invoke(*[a.replace("{capture}", str(capture)) for a in args])
    assert result.exit_code == 2, result.output
    assert argument in result.output, result.output
    assert f"{char!r} (U+{ord(char):04X}" in result.output, result.output
    assert "Traceback" not in result.output


def test_the_response_signal_option_names_the_digit_and_its_column(tmp_path):
    program = tmp_path / "P.st"
    program.write_text("PROGRAM P\nVAR o_uState : INT; END_VAR\no_uState := 1;\nEND_PROGRAM\n", encoding="utf-8")
    result = invoke("verify", program, "--duration", "1s", "--response-signal", "o_uState = " + ARABIC_FIVE)
    assert result.exit_code == 2, result.output
    assert f"--response-signal: {ARABIC_FIVE!r} (U+0665 ARABIC-INDIC DIGIT FIVE) is not one of the digits 0-9 " \
           "(write 5) at column 12" in result.output


@pytest.mark.parametrize("line, col, char", [
    ("٠.٠٠٠ 01 06 01 A0 00 00 88 14", 1, "٠"),  # float() read it as 0.0
    ("0.00" + ARABIC_FIVE + " tx 01 06 01 A0 00 00 88 14", 5, ARABIC_FIVE),
])
def test_a_capture_time_with_another_script_s_digits_is_an_error_at_its_column(line, col, char, tmp_path):
    capture = tmp_path / "c.txt"
    capture.write_text("# a capture\n" + line + "\n", encoding="utf-8")
    result = invoke("replay", capture)
    assert result.exit_code == 2, result.output
    assert f"{capture}:2:{col}: {char!r} (U+{ord(char):04X}" in result.output


@pytest.mark.parametrize("text, key, place, char", [
    ('scan = "1' + FULL_TWO + 'ms"\n', "scan", (1, 8), FULL_TWO),
    ('[[expect]]\nwithin = "' + FULL_TWO + 's"\nthat = "o_bOK"\n', "expect[0].within", (2, 10), FULL_TWO),
    # the column of the digit itself inside the condition's string
    ('[[expect]]\nthat = "o_uState = ' + ARABIC_FIVE + '"\n', "expect[0].that", (2, 20), ARABIC_FIVE),
    ('[[expect]]\nthat = "wBuf[' + ARABIC_FIVE + '] = 1"\n', "expect[0].that", (2, 14), ARABIC_FIVE),
    ('[[expect]]\nsent = "run-point ' + ARABIC_FIVE + '"\n', "expect[0].sent", (2, 8), ARABIC_FIVE),
    ('watch = ["wBuf[' + FULL_TWO + ']"]\n', "watch[0]", (1, 10), FULL_TWO),
    ('[[inputs]]\nat = "1s"\nset = { "wBuf[' + FULL_TWO + ']" = 1 }\n', "inputs[0].set", (3, 9), FULL_TWO),
    # buffer memory G１６４ was taken for G164
    ("[initial]\n'U0\\G１６４' = 5\n", "initial.U0\\G１６４", (2, 1), "１"),
    ('[robot]\npoint_durations_s = { "' + ARABIC_FIVE + '" = 2.0 }\n', "robot.point_durations_s." + ARABIC_FIVE,
     (2, 23), ARABIC_FIVE),  # at the key, which is the mistake
])
def test_a_scenario_string_with_another_script_s_digits_names_key_place_and_character(text, key, place, char):
    with pytest.raises(ScenarioError) as caught:
        parse_scenario(text, Path("s.toml"))
    error = caught.value
    assert (error.key, (error.place.line, error.place.col)) == (key, place), str(error)
    assert f"{char!r} (U+{ord(char):04X}" in error.message
