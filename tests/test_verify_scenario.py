"""Scenario files, durations and conditions: strict loading with messages that point at the
file, the line and the key; and the judgement of expectations on sampled variables."""
from __future__ import annotations

from pathlib import Path

import pytest
from hypothesis import given, strategies as st

from verifier import protocol
from verifier.verify.conditions import ConditionError, parse_condition
from verifier.verify.durations import parse_duration_us
from verifier.verify.evidence import RunEvidence, Samples
from verifier.verify.expectations import judge
from verifier.verify.result import TraceRecord
from verifier.verify.scenario import ScenarioError, load_scenario, parse_scenario
from verifier.verify.traffic import analyse

# --- durations --------------------------------------------------------------------------------


@pytest.mark.parametrize("text, us", [
    ("250ms", 250_000), ("60s", 60_000_000), ("1.5 s", 1_500_000), ("2min", 120_000_000),
    ("500us", 500), ("0s", 0), (".5s", 500_000),
])
def test_durations(text, us):
    assert parse_duration_us(text) == us


@pytest.mark.parametrize("bad", ["5", 5, "5 sec", "-1s", "1.0000001s", "ms", ""])
def test_bad_durations_are_refused_with_an_example(bad):
    with pytest.raises(ValueError):
        parse_duration_us(bad)


@pytest.mark.parametrize("text, hint", [
    ("5sec", '; did you mean "5s"?'), ("250 msec", '; did you mean "250ms"?'), ("2 minutes", '; did you mean "2min"?'),
    ("1hr", '; did you mean "1h"?'), ("3m", '; did you mean "3min"?'), ("1.5 Seconds", '; did you mean "1.5s"?'),
    ("-1s", "; a duration counts forward (from power-on, or from the window's start): it cannot be negative"),
    ("5 parsecs", ""), ("soon", ""),
])
def test_a_duration_with_a_unit_spelt_otherwise_names_the_one_meant(text, hint):
    # '5sec' and '-1s' got only 'is not a duration: write a number and a unit'
    with pytest.raises(ValueError) as info:
        parse_duration_us(text)
    assert str(info.value).startswith(f"{text!r} is not a duration: write a number and a unit")
    assert str(info.value).endswith('e.g. "250ms" or "60s"' + hint)


@pytest.mark.parametrize("text, us, message", [
    # Fraction() read none of these: 'Exceeds the limit (4300 digits) for integer string conversion'
    ("9" * 5000 + "s", None, "a duration of 5000 digits is longer than any run: check the number"),
    ("0." + "0" * 5000 + "1s", None, "is finer than the virtual clock's microsecond"),
    ("0" * 5000 + "1s", 1_000_000, ""),
    ("1." + "0" * 5000 + "s", 1_000_000, ""),
])
def test_durations_with_thousands_of_digits(text, us, message):
    if us is not None:
        assert parse_duration_us(text) == us
    else:
        with pytest.raises(ValueError, match=message):
            parse_duration_us(text)


@given(st.integers(min_value=0, max_value=10**9))
def test_milliseconds_round_trip(ms):
    assert parse_duration_us(f"{ms}ms") == ms * 1000


# --- conditions -------------------------------------------------------------------------------


def test_conditions_read_like_st():
    condition = parse_condition("o_bErr AND o_uErrId = 16#0101")
    assert condition.names == {"o_bErr", "o_uErrId"}
    assert condition.holds({"o_bErr": True, "o_uErrId": 0x0101})
    assert not condition.holds({"o_bErr": True, "o_uErrId": 0x0102})
    assert parse_condition("NOT fb.o_bBusy OR (x >= 3 AND x <> 7)").holds({"fb.o_bBusy": True, "x": 5})
    assert parse_condition("a & b").holds({"a": True, "b": True})
    assert parse_condition("a XOR b").holds({"a": True, "b": False})
    assert parse_condition("w[2] = 2#1010").holds({"w[2]": 10})
    assert parse_condition("t > -1.5").holds({"t": 0})
    assert parse_condition("x = 1_000").holds({"x": 1000})
    assert parse_condition("a OR b AND c").holds({"a": True, "b": False, "c": False})  # AND binds tighter
    assert not parse_condition("(a OR b) AND c").holds({"a": True, "b": False, "c": False})


@pytest.mark.parametrize("text, column", [
    ("o_bOK AND", 10), ("a = = b", 5), ("(a", 3), ("a $ b", 3), ("", 1), ("a < b < c", 7),
])
def test_condition_errors_name_the_column(text, column):
    with pytest.raises(ConditionError) as info:
        parse_condition(text)
    assert info.value.column == column


def test_a_time_literal_with_a_space_in_a_condition_is_named_as_such():
    """`that = "fbTimer.ET > T#1h 30m"` said "unexpected '30' at column 10": the literal is
    named now, at its first character, with the spelling that reads (T#1h30m), as the ST
    checker names it."""
    for text, column, word, fixed in (("fbTimer.ET > T#1h 30m", 14, "T#1h 30m", "T#1h30m"),
                                      ("(t#1m  5s < et)", 2, "t#1m  5s", "t#1m5s"),
                                      ("et > TIME#2 s", 6, "TIME#2 s", "TIME#2s"),
                                      ("et > T#2\ts", 6, "T#2\ts", "T#2s")):
        with pytest.raises(ConditionError) as info:
            parse_condition(text)
        assert info.value.column == column, (text, info.value.message)
        blank = "a tab" if "\t" in word else "a space"  # the blank it holds, by name
        assert info.value.message == f"{word!r}: a TIME literal cannot hold {blank}: write {fixed}"
    assert parse_condition("fbTimer.ET > T#1h30m").holds({"fbTimer.ET": 5_400_001})


def test_a_time_literal_in_a_condition_reads_as_a_time_label_does():
    """An integrator's `that = "fbLampTmr.ET > T#1s"` on a TON of their own: the condition
    stopped at "unexpected character '#'", though TIME labels compare (in ms) and ST writes
    their values so; a unit GX Works does not know is named as the ST checker names it."""
    assert parse_condition("fbTimer.ET > T#1s").holds({"fbTimer.ET": 1010})
    assert not parse_condition("fbTimer.ET > T#1s").holds({"fbTimer.ET": 1000})
    assert parse_condition("t = TIME#1m30s AND u = t#-5ms AND v >= T#1.5S").holds({"t": 90_000, "u": -5, "v": 1500})
    for text, column in (("et > T#1sec", 6), ("et > T#500", 6), ("(T#2s5 < et)", 2)):
        with pytest.raises(ConditionError) as info:
            parse_condition(text)
        assert info.value.column == column and "is not a TIME literal: give every number its unit, d, h, m, s " \
            "or ms" in info.value.message, (text, info.value.message)


@pytest.mark.parametrize("text, column, literal", [
    ("fbMoveTmr.ET > 500ms", 16, "T#500ms"),
    ("et >= 1.5s AND Y0", 7, "T#1.5s"),
    ("et < 2sec", 6, "T#2s"),
    ("et > 2 s", 6, "T#2s"),  # a blank between number and unit: was "unexpected 's'"
    ("et > 1 h 30 m AND Y0", 6, "T#1h30m"),
])
def test_a_duration_without_t_in_a_condition_is_told_the_time_literal(text, column, literal):
    """Writing a station's scenario, `that = "fbMoveTmr.ET > 500ms"` (durations in the same
    file are written "500ms") got "unexpected 'ms' at column 19": neither the number's place
    nor that a condition writes a time T#500ms."""
    with pytest.raises(ConditionError) as info:
        parse_condition(text)
    assert info.value.column == column and f"a TIME literal is written {literal}" in info.value.message, \
        info.value.message


def test_a_duration_with_a_blank_before_its_unit_in_st_is_told_the_time_literal(tmp_path):
    """`PT := 2 s` in ST got lark's "unexpected 's'" and a list of tokens; it is the same
    mistake as `PT := 500ms` and now gets the same message, at the number; ST that is
    right (a FOR ... BY 2 DO, 2 MOD 3) is not taken for a duration."""
    from verifier import st

    bad = st.parse("PROGRAM P\nVAR\n    t : TON;\nEND_VAR\nt(IN := TRUE, PT := 2 s);\nEND_PROGRAM\n", "P.st")
    (diagnostic,) = [d for d in bad.diagnostics if d.is_error]
    assert (diagnostic.line, diagnostic.col) == (5, 21), diagnostic
    assert diagnostic.message == "'2 s' is a duration without T#: a TIME literal is written T#2s"
    good = st.parse("PROGRAM Q\nVAR\n    i : INT;\nEND_VAR\nFOR i := 1 TO 10 BY 2 DO\n    i := i;\n"
                    "END_FOR;\ni := 2 MOD 3;\nEND_PROGRAM\n", "Q.st")
    assert not [d for d in good.diagnostics + st.check([good]) if d.is_error]


def test_st_s_time_literal_as_a_scenario_duration_is_told_the_scenario_spelling():
    """`within = "T#2s"` (the ST spelling, as in the program's TONs) was refused with the
    general advice only; it now says what to write instead."""
    from verifier.verify.durations import parse_duration_us

    for text, meant in (("T#2s", '"2s"'), ("TIME#500ms", '"500ms"'), ("t#1m", '"1min"')):
        with pytest.raises(ValueError) as info:
            parse_duration_us(text)
        assert f"T# belongs to ST and to conditions, not to a scenario's durations; did you mean {meant}?" in \
            str(info.value), str(info.value)


@pytest.mark.parametrize("text, column, hint", [
    ("Y4 AND D20 = 0x0201", 14, "write 16#0201"),
    ("w = 0b1010", 5, "write 2#1010"),
    ("a == 1", 3, "write '='"),
    ("a != 1", 3, "write '<>'"),
    ("a && b", 3, "write 'AND'"),
    ("a || b", 3, "write 'OR'"),
    ("!a", 1, "write 'NOT'"),
])
def test_c_notation_in_a_condition_is_told_the_st_spelling(text, column, hint):
    """Writing a station's scenario, 'D20 = 0x0201' got "unexpected 'x0201' at column 15":
    neither the place of the number nor how ST writes hex."""
    with pytest.raises(ConditionError) as info:
        parse_condition(text)
    assert info.value.column == column and hint in info.value.message, info.value.message


@pytest.mark.parametrize("number", ["9" * 5000, "16#" + "F" * 5000, "1." + "9" * 5000, "T#" + "9" * 400 + "s",
                                    "TIME#1m" + "9" * 5000 + "ms"])
def test_a_number_of_thousands_of_digits_in_a_condition_says_so(number):
    # was "'99...9' is not a number" (int()'s 4300-digit limit), or read and judged as it was;
    # a TIME literal of 400 digits ended the verify run in an OverflowError traceback
    with pytest.raises(ConditionError) as info:
        parse_condition(f"x = {number}")
    assert info.value.column == 5 and "digits: no PLC label holds one this long" in info.value.message


@pytest.mark.parametrize("text, message", [
    ("(" * 150 + "TRUE" + ")" * 150, "nested too deeply"),
    ("NOT " * 1000 + "TRUE", "nested too deeply"),
    ("- " * 500 + "1 = 1", "nested too deeply"),
    (" AND ".join(["a"] * 3000), "too long: more than 200 operators"),
])
def test_absurdly_deep_conditions_are_errors_not_a_recursion_crash(text, message):
    with pytest.raises(ConditionError, match=message):
        parse_condition(text)


def test_conditions_at_the_nesting_limit_still_parse():
    assert parse_condition("(" * 50 + "a" + ")" * 50).holds({"a": True})
    assert parse_condition(" AND ".join(["a"] * 150)).holds({"a": True})


def test_numbers_in_robot_and_fault_settings_are_bounded():
    from verifier.amr.schema import ConfigError, as_number

    assert as_number(1e9, "x") == 1e9
    with pytest.raises(ConfigError, match="out of range"):
        as_number(1e308, "x")
    with pytest.raises(ConfigError, match="out of range"):
        as_number(-2e9, "x")


# --- scenario files ---------------------------------------------------------------------------

MINIMAL = """
name = "t"
program = "Main"
"""


def error_of(text: str, path: Path | None = None) -> ScenarioError:
    with pytest.raises(ScenarioError) as info:
        parse_scenario(text, path)
    return info.value


def test_a_minimal_scenario_takes_the_defaults():
    scenario = parse_scenario(MINIMAL)
    assert scenario.duration_us == 60_000_000 and scenario.scan_us == 10_000
    assert scenario.platform == "fx3u" and scenario.serial_channel == "fx3:1" and scenario.target == "gxworks2"
    assert str(scenario.options.response_signal) == "o_bErr" and not scenario.response_signal_given


def test_a_full_scenario(tmp_path):
    (tmp_path / "lib").mkdir()
    for name in ("A.st", "B.st"):
        (tmp_path / "lib" / name).write_text("")
    (tmp_path / "Main.st").write_text("")
    path = tmp_path / "s.toml"
    path.write_text("""
name = "full"
sources = ["lib/*.st", "Main.st"]
program = "Main"
platform = "fx5u"
duration = "30s"
scan = "5ms"
scan_jitter = "2ms"
seed = 7
watch = ["fb.o_wRetryCount"]
[protocol]
address = 3
[robot]
point_duration_s = 2.0
[[faults]]
kind = "no_reply"
at_s = 10.0
duration_s = 3.0
[[inputs]]
at = "1s"
set = { i_bStart = true, "fb.i_uPoint" = 3 }
pulse = "200ms"
[[expect]]
that = "o_bOK"
within = "10s"
[[expect]]
sent = "run-point 3"
[[expect]]
reached_point = 3
after = "1s"
within = "20s"
name = "point three"
[rules]
min_period = "260ms"
reply_timeout = "400ms"
[response_handling]
signal = "fb.o_bErr"
within = "3s"
""")
    scenario = load_scenario(path)
    assert [p.name for p in scenario.sources] == ["A.st", "B.st", "Main.st"]
    assert scenario.target == "gxworks3" and scenario.serial_channel == "fx5:1" and scenario.scan_jitter_us == 2000
    assert scenario.settings.address == 3 and scenario.robot.point_duration_s == 2.0
    assert scenario.faults[0].kind == "no_reply"
    assert scenario.inputs[0].values == {"i_bStart": True, "fb.i_uPoint": 3} and scenario.inputs[0].pulse_us == 200_000
    labels = [e.label for e in scenario.expectations]
    assert labels == ["o_bOK within 10 s", "sent run-point 3", "point three"]
    assert scenario.expectations[1].request == protocol.ControlRequest(3, protocol.ControlCode.ROBOT, 3)
    assert scenario.options.min_period_us == 260_000 and scenario.options.reply_timeout_us == 400_000
    assert str(scenario.options.response_signal) == "fb.o_bErr" and scenario.response_signal_given
    assert scenario.variables() == ["o_bOK", "fb.o_bErr", "i_bStart", "fb.i_uPoint", "fb.o_wRetryCount"]


def test_toml_syntax_errors_give_the_line(tmp_path):
    path = tmp_path / "bad.toml"
    path.write_text('name = "x"\nprogram "Main"\n')
    with pytest.raises(ScenarioError) as info:
        load_scenario(path)
    assert (info.value.place.line, info.value.place.col) == (2, 9)
    assert str(info.value).startswith(f"{path}:2:9: not valid TOML")


def test_unknown_keys_are_errors_with_their_line():
    error = error_of('program = "Main"\n\n[[expect]]\nthat = "a"\nwithn = "5s"\n', Path("s.toml"))
    assert error.key == "expect[0].withn" and (error.place.line, error.place.col) == (5, 1)
    assert str(error).startswith("s.toml:5:1: expect[0].withn: unknown key")


def test_the_nth_table_of_an_array_is_found():
    text = 'program = "M"\n[[expect]]\nthat = "a"\nwithin = "1s"\n[[expect]]\nthat = "b"\nwithin = "5"\n'
    error = error_of(text)
    assert error.key == "expect[1].within" and (error.place.line, error.place.col) == (7, 10) and "not a duration" in error.message


@pytest.mark.parametrize("text, key, words", [
    ('platform = "fx2n"', "platform", "unknown platform"),
    ('channel = "com1"', "channel", "unknown channel"),
    # was no place at all, from the simulator when the run started ('x.toml: channel fx3:1 does not exist ...')
    ('platform = "fx5u"\nchannel = "fx3:1"', "channel", "does not exist on the fx5u CPU; the fx5u CPU has fx5:1, fx5:2, adp:1"),
    ('platform = "q"\nchannel = "adp:1"', "channel", "does not exist on the q CPU; the q CPU has q:1, q:2"),
    ('channel = "fx5:1"', "channel", "the fx3u CPU; the fx3u CPU has fx3:1, fx3:2, adp:1 (fx3u is the default platform: "
                                     'set platform = "fx5u", the CPU that has fx5:1)'),
    ('duration = 60', "duration", "duration"),
    ('scan = "2s"\nduration = "1s"', "scan", "longer than the whole run"),
    ('seed = "x"', "seed", "whole number"),
    ('scan = "10ms"\nscan_jitter = "10ms"', "scan_jitter", "shorter than the scan time"),
    ('[protocol]\nfield_order = "sideways"', "protocol.field_order", "field_order"),
    ('[protocol]\nparity = "E"', "protocol.parity", "unknown key"),
    ('[robot]\nturnaround_ms = -1', "robot.turnaround_ms", "at least"),
    ('[[faults]]\nkind = "meteor"\nat_s = 1', "faults[0].kind", "unknown fault"),
    ('[[faults]]\nkind = "no_reply"', "faults[0]", "trigger"),
    ('[[faults]]\nkind = ["no_reply"]\nat_s = 1', "faults[0].kind", "expected a string"),
    ('[[inputs]]\nat = "1s"', "inputs[0]", "needs 'at'"),
    ('[[inputs]]\nat = "1s"\nset = { x = "on" }', "inputs[0].set.x", "true/false or a number"),
    ('[[inputs]]\nat = "1s"\nset = { x = 3 }\npulse = "1s"', "inputs[0].pulse", "no BOOL"),
    # a BOOL label set to 3 with a pulse was only "this input sets no BOOL", which it was meant to
    ('[[inputs]]\nat = "1s"\nset = { bLamp = 3 }\npulse = "1s"', "inputs[0].pulse",
     "only numbers (bLamp = 3): write true or false for a BOOL label, or leave out the pulse"),
    # was "inputs[0].pulse: ... this input sets no BOOL" at the pulse line: the 1 meant as a bit
    ('[[inputs]]\nat = "1s"\nset = { X0 = 1 }\npulse = "1s"', "inputs[0].set.X0",
     "is the number 1, and a pulse sets BOOL labels back after a while: write X0 = true for a bit"),
    ('[[inputs]]\nat = "1s"\nset = { x = 3, b = 0 }\npulse = "1s"', "inputs[0].set.b", "write b = false for a bit"),
    # a word device set to 1 with a pulse is no bit meant as a number: not told to write D0 = true
    ('[[inputs]]\nat = "1s"\nset = { D0 = 1 }\npulse = "1s"', "inputs[0].pulse", "this input sets no BOOL"),
    ('[[inputs]]\nat = "1s"\nset = { W1F = 0, SD8063 = 1 }\npulse = "1s"', "inputs[0].pulse", "no BOOL"),
    ('[[inputs]]\nat = "99s"\nset = { x = 3 }', "inputs[0].at", "after the end"),
    ('[[expect]]\nthat = "a"\nnever = "b"', "expect[0]", "exactly one"),
    ('[[expect]]\nthat = "a AND"', "expect[0].that", "column"),
    ('[[expect]]\nsent = "fly 3"', "expect[0].sent", "unknown command"),
    ('[[expect]]\nreached_point = 40', "expect[0].reached_point", "1-21"),
    ('[rules]\nmin_period = "0ms"', "rules.min_period", "longer than 0"),
    ('[response_handling]\nsignal = "o_bErr OR"', "response_handling.signal", "column"),
    ('watch = ["9lives"]', "watch[0]", "label path"),
    ('sources = ["nope/*.st"]', "sources[0]", "matches no file"),
    ('bogus = 1', "bogus", "unknown key"),
    ('name = " "', "name", "is empty"),  # was a run named '' in every report (a JUnit test case with no name)
])
def test_every_mistake_names_its_key(text, key, words):
    source = 'program = "Main"\n' + text + "\n"
    error = error_of(source, Path("x.toml"))
    assert error.key == key
    assert words in error.message
    place = error.place
    assert place is not None and 2 <= place.line <= 2 + text.count("\n")
    line = source.splitlines()[place.line - 1]
    assert 1 <= place.col <= len(line), "the column is on the line"
    assert str(error).startswith(f"{place}: {key}: ") and place.file == "x.toml"


def test_a_number_too_long_for_python_is_a_toml_error_at_its_place():
    # tomllib let int()'s ValueError (more than 4300 digits) through: a traceback
    error = error_of('program = "Main"\nseed = 1_' + "9" * 5000 + "\n", Path("x.toml"))
    assert (error.place.line, error.place.col) == (2, 8)
    assert str(error).startswith("x.toml:2:8: not valid TOML: a whole number of 5001 digits: too long to read")


def test_a_duration_of_another_type_is_shown_as_the_file_writes_it():
    # 'got True' (Python's spelling) for `within = true`; a bare number got no remedy
    error = error_of('program = "M"\n[[expect]]\nthat = "a"\nwithin = true\n', Path("x.toml"))
    assert str(error) == 'x.toml:4:10: expect[0].within: expected a duration such as "250ms" or "60s", got true'
    error = error_of('program = "M"\n[[expect]]\nthat = "a"\nwithin = 5\n', Path("x.toml"))
    assert str(error) == ('x.toml:4:10: expect[0].within: expected a duration such as "250ms" or "60s", got the '
                          'bare number 5: write it in quotes with its unit, e.g. "5s" or "5ms"')


@pytest.mark.parametrize("text, key, meant", [
    ('scna = "10ms"\n', "scna", "scan"),
    ('[[expect]]\ntaht = "a"\n', "expect[0].taht", "that"),
    ('[robot]\nbattery_percent = 80\n', "robot.battery_percent", "battery_pct"),
    ('[[faults]]\nkind = "no_reply"\nat = 3\n', "faults[0].at", "at_s"),
    ('[[inputs]]\nat = "1s"\nset = { a = true }\npluse = "1s"\n', "inputs[0].pluse", "pulse"),
    # a TOML key is case-sensitive, so 'SCAN' is unknown; the guess compared cases too and made none
    ('SCAN = "10ms"\n', "SCAN", "scan"),
])
def test_a_misspelt_key_names_the_key_probably_meant(text, key, meant):
    # the message listed every key there is (24 under [robot]) and left the search to the user
    error = error_of('program = "M"\n' + text, Path("s.toml"))
    assert f"{key}: unknown key; expected one of " in str(error)
    assert str(error).endswith(f"; did you mean '{meant}'?")


def test_an_unknown_key_like_none_there_is_gets_no_guess():
    error = error_of('program = "M"\n[rules]\nbogus = 1\n', Path("s.toml"))
    assert str(error).endswith("expected one of min_period, reply_timeout")


def test_an_input_after_the_run_says_the_run_length_and_what_to_do():
    # 'inputs[0].at: is at or after the end of the run' gave neither, unlike a late fault
    error = error_of('program = "M"\nduration = "20s"\n[[inputs]]\nat = "30s"\nset = { X0 = true }\n',
                     Path("x.toml"))
    assert str(error) == ("x.toml:4:6: inputs[0].at: is at or after the end of the run (20s): the input would never "
                          "be applied; make 'duration' longer")


@pytest.mark.parametrize("text, place", [
    # the ')' on the second line of a condition in three quotes: was 3:26, past the end of line 3
    ('[[expect]]\nthat = """Y0 AND\n   (Y1 OR ) """\n', (4, 11)),
    ('[[expect]]\nthat = """\nY0 AND\n   (Y1 OR ) """\n', (5, 11)),  # the newline after """ is not the value's
    ("[[expect]]\nthat = \'\'\'Y0 AND\n   (Y1 OR ) \'\'\'\n", (4, 11)),
    ('[[expect]]\nthat = "Y0 AND (Y1 OR )"\n', (3, 23)),
    ("[[expect]]\nthat = 'Y0 AND (Y1 OR )'\n", (3, 23)),
    # an escape (one character of the value, several in the file) was placed at the string's
    # start, 3:8: now at the character, whatever the escapes before it
    ('[[expect]]\nthat = "Y0 AND\\t(Y1 OR )"\n', (3, 24)),
    ('[[expect]]\nthat = "Y0\\u0020AND\\U00000020(Y1 OR )"\n', (3, 37)),
    ('[[expect]]\nthat = """Y0 \\\n    AND\\t(Y1 OR )"""\n', (4, 17)),  # a line-ending backslash
    ('[[expect]]\nthat = """Y0 \\   \n\n  AND (Y1\\tOR )"""\n', (5, 15)),  # ... trims blank lines too
])
def test_a_condition_that_does_not_parse_is_placed_where_it_fails_in_the_file(text, place):
    error = error_of('program = "M"\n' + text, Path("x.toml"))
    assert (error.place.line, error.place.col) == place, str(error)
    assert "found ')'" in str(error)


def test_reaching_a_point_the_robot_was_not_taught_is_an_impossible_expectation():
    # the run failed with 'accepted ..., but the robot never reported the task running'
    # and left the user to find the [robot] setting that made it so
    error = error_of('program = "M"\n[robot]\ntaught_points = [1, 2, 3]\n[[expect]]\nreached_point = 5\n',
                     Path("x.toml"))
    assert str(error) == ("x.toml:5:17: expect[0].reached_point: point 5 is not among the robot's taught_points "
                          "[1, 2, 3]: the robot accepts run-point 5 and does nothing, so it is never reached; add it "
                          "to [robot] taught_points")
    parse_scenario('program = "M"\n[robot]\ntaught_points = [1, 5]\n[[expect]]\nreached_point = 5\n')


@pytest.mark.parametrize("text, expected", [
    ('program = "M"\nduration = "20s"\nduration = "30s"\n',
     "x.toml:3:1: not valid TOML: 'duration' is given twice (first on line 2): keep one"),
    ('program = "M"\n[robot]\nbattery_pct = 50\n  battery_pct = 40\n',
     "x.toml:4:3: not valid TOML: 'battery_pct' is given twice (first on line 3): keep one"),
    # a line separator or a form feed in a comment is no new line for TOML (tomllib counts
    # line feeds): the lines are numbered so, not as str.splitlines numbers them
    ('program = "M"\n# a\u2028b\nduration = "20s"\nduration = "30s"\n',
     "x.toml:4:1: not valid TOML: 'duration' is given twice (first on line 3): keep one"),
    ('program = "M"\n# a\x85b\nduration = "20s"\nduration = "30s"\n',
     "x.toml:4:1: not valid TOML: 'duration' is given twice (first on line 3): keep one"),
])
def test_a_key_given_twice_is_named_with_its_first_line(text, expected):
    # tomllib's 'Cannot overwrite a value' at the end of the second value's line named
    # neither the key nor where it was given first
    assert str(error_of(text, Path("x.toml"))) == expected


@pytest.mark.parametrize("text, key, shown", [
    ('[[expect]]\nalways = "TRUE"\n', "expect[0].always", "TRUE"),  # passed whatever the program did
    ('[[expect]]\nnever = "FALSE"\n', "expect[0].never", "FALSE"),
    ('[[expect]]\nthat = "1 < 2"\n', "expect[0].that", "1 < 2"),
    ('[response_handling]\nsignal = "TRUE"\n', "response_handling.signal", "TRUE"),  # every failure 'noticed'
])
def test_a_condition_that_reads_no_label_is_an_error(text, key, shown):
    error = error_of('program = "M"\n' + text, Path("x.toml"))
    assert str(error).startswith(f"x.toml:3:")
    assert str(error).endswith(f"{key}: '{shown}' reads no label: it is the same at every moment and says nothing "
                               "about the program; name the program's labels (e.g. fbRobot.o_bErr) or devices (Y0)")


@pytest.mark.parametrize("text, place, message", [
    # each passed the check as reading a label, and then passed (or failed) whatever the program did
    ('[[expect]]\nthat = "Y7 AND NOT Y7"\n', "3:8: expect[0].that", "'Y7 AND NOT Y7' is FALSE whichever value Y7 takes"),
    ('[[expect]]\nnever = "X0 OR NOT X0"\n', "3:9: expect[0].never", "'X0 OR NOT X0' is TRUE whichever value X0 takes"),
    ('[[expect]]\nalways = "x1 = TRUE OR NOT X1"\n', "3:10: expect[0].always",
     "'x1 = TRUE OR NOT X1' is TRUE whichever value x1 takes"),  # ST labels: x1 is X1
    ('[[expect]]\nthat = """(a AND b)\n  XOR (b AND a)"""\n', "3:8: expect[0].that",
     "'(a AND b)\n  XOR (b AND a)' is FALSE whichever values a, b take"),
    ('[response_handling]\nsignal = "o_bErr OR NOT o_bErr"\n', "3:10: response_handling.signal",
     "'o_bErr OR NOT o_bErr' is TRUE whichever value o_bErr takes"),  # every failure 'noticed'
])
def test_a_condition_that_cannot_change_whatever_its_labels_is_an_error(text, place, message):
    error = error_of('program = "M"\n' + text, Path("x.toml"))
    assert str(error) == (f"x.toml:{place}: {message}: it is the same at every moment and says nothing about the "
                          "program; write what the program's labels must show")


@pytest.mark.parametrize("condition", [
    "X0 AND NOT X1", "a XOR b", "Y0 = Y1",  # can change
    "n = n", "n > 3 OR n <= 3", "n = 1 AND n = 2",  # numbers, or labels that may be: not decided, not guessed
    " AND ".join(f"(b{i} OR NOT b{i})" for i in range(11)),  # more labels than MAX_LABELS_DECIDED: not tried
])
def test_a_condition_that_can_change_or_is_not_decided_is_accepted(condition):
    parse_scenario(f'program = "M"\n[[expect]]\nthat = "{condition}"\n', Path("x.toml"))


def test_a_response_signal_option_that_cannot_change_is_refused():
    from verifier.commands.verify import _with_signal
    from verifier.verify.result import UnusableInput

    with pytest.raises(UnusableInput, match=r"^--response-signal: 'Y4 AND NOT Y4' is FALSE whichever value Y4 takes"):
        _with_signal(parse_scenario('program = "M"\n'), "Y4 AND NOT Y4")


def test_reaching_a_point_in_a_window_shorter_than_its_run_is_an_impossible_expectation():
    # the run failed with 'run-point 1 was running ... but did not finish' however right the program
    text = ('program = "M"\n[robot]\npoint_duration_s = 6.0\n[robot.point_durations_s]\n2 = 3.0\n'
            '[[expect]]\nreached_point = 1\nwithin = "5s"\n')
    error = error_of(text, Path("x.toml"))
    assert str(error) == ("x.toml:8:10: expect[0].within: point 1 takes the robot 6s ([robot] point_duration_s / "
                          "point_durations_s), longer than this window of 5s: it can never be reached in it; make "
                          "'within' longer")
    parse_scenario(text.replace("reached_point = 1", "reached_point = 2"))  # 3 s: may be reached in 5 s


def test_an_empty_expectation_name_is_an_error_at_its_line():
    # was accepted: the console then said "expected : 'Y0' became true at 0.570 s"
    error = error_of('program = "M"\n[[expect]]\nname = " "\nnever = "Y0"\n', Path("x.toml"))
    assert str(error) == ("x.toml:3:8: expect[0].name: is empty: name the expectation for the reports, "
                          "or leave 'name' out to have it described ('never Y0')")


def test_an_empty_program_name_is_an_error_at_its_line():
    # was "no PROGRAM '' in the sources" once the sources were loaded, naming no line
    error = error_of('name = "x"\nprogram = ""\n', Path("x.toml"))
    assert str(error).startswith("x.toml:2:11: program: is empty: give the name of the PROGRAM to run")


def test_a_missing_scenario_file(tmp_path):
    with pytest.raises(ScenarioError, match="no such scenario file"):
        load_scenario(tmp_path / "none.toml")


# --- expectations -----------------------------------------------------------------------------

S = protocol.Settings()


def _evidence(changes: dict[str, list[tuple[int, object]]], trace=(), end_us: int = 10_000_000) -> RunEvidence:
    samples = Samples(list(changes))
    moments = sorted({t for history in changes.values() for t, _ in history})
    for t in moments:
        samples.record(t, {n: v for n, h in changes.items() for tt, v in h if tt == t})
    return RunEvidence(S, list(trace), end_us, (), samples)


def _judge(text: str, evidence: RunEvidence):
    scenario = parse_scenario('program = "M"\nduration = "10s"\n' + text)
    traffic = analyse(evidence.trace, S, evidence.options)
    return [judge(e, evidence, traffic) for e in scenario.expectations]


def test_that_always_never():
    evidence = _evidence({"ok": [(0, False), (3_000_000, True), (6_000_000, False)], "n": [(0, 0), (5_000_000, 0x101)]})
    results = _judge(
        '[[expect]]\nthat = "ok"\nwithin = "4s"\n'
        '[[expect]]\nthat = "ok"\nwithin = "2s"\n'
        '[[expect]]\nalways = "ok"\nafter = "3s"\nwithin = "2s"\n'
        '[[expect]]\nalways = "ok"\nafter = "3s"\nwithin = "4s"\n'
        '[[expect]]\nnever = "n = 16#0101"\nwithin = "4s"\n'
        '[[expect]]\nnever = "n = 16#0101"\n'
        '[[expect]]\nthat = "ok"\nafter = "4s"\nwithin = "1s"\n',
        evidence,
    )
    assert [r.passed for r in results] == [True, False, True, False, True, False, True]
    assert results[0].t_us == 3_000_000
    # the values as ST writes them, as the condition does (was Python's 'ok = False')
    assert results[1].detail == "'ok' never became true between 0.000 s and 2.000 s (at the end: ok = FALSE)"
    assert results[3].detail == "'ok' was false at 6.000 s (ok = FALSE)"
    assert "became true at 5.000 s" in results[5].detail


def test_a_window_past_the_end_of_the_run_fails_with_advice():
    (result,) = _judge('[[expect]]\nthat = "ok"\nafter = "8s"\nwithin = "5s"\n', _evidence({"ok": [(0, True)]}))
    assert not result.passed and "make the scenario's duration longer" in result.detail


@pytest.mark.parametrize("kind, condition", [("that", "ok"), ("always", "ok"), ("never", "NOT ok")])
def test_a_window_that_opens_after_the_run_fails_with_advice(kind, condition):
    # `after` past the end with no `within` passed every kind: the window was empty
    evidence = _evidence({"ok": [(0, True)]}, end_us=10_000_000)
    (result,) = _judge(f'[[expect]]\n{kind} = "{condition}"\nafter = "12s"\n', evidence)
    assert not result.passed
    assert result.detail == ("the run ended at 10.000 s, before the window opened at 12.000 s: "
                             "make the scenario's duration longer")


def test_a_sent_or_reached_point_window_that_opens_after_the_run_fails():
    for text in ('sent = "stop"', "reached_point = 1"):
        (result,) = _judge(f'[[expect]]\n{text}\nafter = "10.5s"\n', _evidence({}))
        assert not result.passed and "before the window opened at 10.500 s" in result.detail


@pytest.mark.parametrize("kind, condition", [("that", "ok"), ("always", "ok"), ("never", "NOT ok")])
def test_a_window_that_opens_as_the_run_ends_is_not_said_to_open_after_it(kind, condition):
    # was "the run ended at 10.000 s, before the window opened at 10.000 s"
    (result,) = _judge(f'[[expect]]\n{kind} = "{condition}"\nafter = "10s"\n', _evidence({"ok": [(0, True)]}))
    assert not result.passed
    assert result.detail == ("the run ended at 10.000 s, the moment the window opened, leaving nothing to judge: "
                             "make the scenario's duration longer")


def _tx(t_ms, request):
    data = protocol.encode(request, S)
    return TraceRecord(t_ms * 1000, t_ms * 1000 + protocol.frame_time_us(8), "tx", data)


def _rx(request_frame, reply):
    data = protocol.encode(reply, S)
    start = request_frame.t_end_us + 5000
    return TraceRecord(start, start + protocol.frame_time_us(len(data)), "rx", data)


def _read(t_ms, value):
    request = _tx(t_ms, protocol.StatusRequest(1, protocol.Query.TASK))
    return [request, _rx(request, protocol.StatusReply(1, 0, value))]


def _control(t_ms, request):
    frame = _tx(t_ms, request)
    return [frame, _rx(frame, protocol.ControlReply.echo(request))]


STOP = protocol.ControlRequest(1, protocol.ControlCode.ROBOT, protocol.RobotCommand.STOP)
POINT3 = protocol.ControlRequest(1, protocol.ControlCode.ROBOT, 3)


def test_sent_and_reached_point():
    trace = _control(0, STOP) + _read(300, 0) + _control(600, POINT3) + _read(900, 1) + _read(1200, 1) + _read(1500, 0)
    results = _judge(
        '[robot]\npoint_duration_s = 0.5\n'  # as fast as the trace's robot: 1 s can hold the run
        '[[expect]]\nsent = "stop"\nwithin = "1s"\n'
        '[[expect]]\nsent = "run-point 4"\n'
        '[[expect]]\nreached_point = 3\nwithin = "2s"\n'
        '[[expect]]\nreached_point = 3\nwithin = "1s"\n',
        _evidence({}, trace),
    )
    assert [r.passed for r in results] == [True, False, True, False]
    assert "01 06 01 04 00 00" in results[1].detail
    assert "running" in results[3].detail and "did not finish" in results[3].detail


SPEED_STAGE_2 = protocol.ControlRequest(1, protocol.ControlCode.SPEED_TRACKLESS, 1)


def test_a_control_command_not_sent_names_what_was_sent_instead():
    # FB stage 2 (UITAMR_SetSpeed i_wStage) is 02/01 on the wire, 'speed trackless 1' in
    # the words: the finding only said 'trackless speed stage 3 (02/02) ... was not sent'
    trace = _control(0, STOP) + _read(300, 0) + _control(600, SPEED_STAGE_2) + _control(900, POINT3)
    results = _judge('[[expect]]\nsent = "speed trackless 2"\n'
                     '[[expect]]\nsent = "run-point 4"\n'
                     '[[expect]]\nsent = "read battery"\n', _evidence({}, trace))
    assert [r.passed for r in results] == [False, False, False]
    assert results[0].detail == ("trackless speed stage 3 (02/02) (01 06 02 02 00 00 29 B2) was not sent between "
                                 "0.000 s and 10.000 s; sent instead: trackless speed stage 2 (02/01) at 0.600 s")
    assert results[1].detail.endswith("; sent instead: stop (01/A0) at 0.000 s, run point/script 3 (01/03) at 0.900 s")
    assert "instead" not in results[2].detail  # the other reads would be noise


def test_a_request_sent_outside_the_window_says_when_it_went_out():
    """journey33b: a pause pressed while UITAMR_RunPoint waited for its point went out 5.8 s
    late, after the point had ended (it queued behind the run); the finding said only 'was
    not sent between 5.000 s and 6.000 s', as for a pause never sent at all."""
    PAUSE = protocol.ControlRequest(1, protocol.ControlCode.ROBOT, protocol.RobotCommand.PAUSE)
    trace = _control(0, STOP) + _control(600, POINT3) + _read(900, 1) + _read(1200, 0) + _control(1500, PAUSE)
    late, early = _judge('[[expect]]\nsent = "pause"\nafter = "0.7s"\nwithin = "0.5s"\n'
                         '[[expect]]\nsent = "stop"\nafter = "0.5s"\nwithin = "0.5s"\n', _evidence({}, trace))
    assert not late.passed and late.detail.endswith(
        "was not sent between 0.700 s and 1.200 s; it went out later, at 1.500 s (0.800 s after the window opened)")
    assert not early.passed and early.detail.endswith(
        "; sent instead: run point/script 3 (01/03) at 0.600 s; it went out before the window, last at 0.000 s")


def test_a_command_answered_with_an_exception_says_so():
    # 'was sent at 0.600 s but never answered' for a command the robot refused with an
    # exception: the user looked for a silent robot
    frame = _tx(600, POINT3)
    refused = protocol.encode(protocol.ExceptionReply(1, 0x06, 4), S)
    rx = TraceRecord(frame.t_end_us + 5000, frame.t_end_us + 5000 + protocol.frame_time_us(len(refused)), "rx", refused)
    (result,) = _judge('[[expect]]\nsent = "run-point 3"\n', _evidence({}, _control(0, STOP) + [frame, rx]))
    assert result.detail == ("run point/script 3 (01/03) was sent at 0.600 s but never answered between 0.000 s and "
                             "10.000 s (the first time: exception 04 (slave device failure) to function 06)")


def test_reached_point_needs_the_task_to_run_and_end_without_error():
    never_runs = _control(0, STOP) + _read(300, 0) + _control(600, POINT3) + _read(900, 0)
    (result,) = _judge('[[expect]]\nreached_point = 3\n', _evidence({}, never_runs))
    assert not result.passed and "never reported the task running" in result.detail
    request = _tx(1500, protocol.StatusRequest(1, protocol.Query.TASK))
    error_end = _control(0, STOP) + _control(600, POINT3) + _read(900, 1) + [
        request, _rx(request, protocol.StatusReply(1, 1, 0))]
    (result,) = _judge('[[expect]]\nreached_point = 3\n', _evidence({}, error_end))
    assert not result.passed and "error 01" in result.detail


def _error_read(t_ms, error):
    request = _tx(t_ms, protocol.StatusRequest(1, protocol.Query.TASK))
    return [request, _rx(request, protocol.StatusReply(1, error, 0))]


def test_reached_point_names_when_the_task_ended_not_the_last_status_read():
    # the robot keeps reporting error 01 on every later poll: the finding named the last
    # of them (8.900 s in a run where the obstacle stopped the task at 5.060 s)
    trace = (_control(0, STOP) + _control(600, POINT3) + _read(900, 1) + _error_read(1500, 1)
             + _error_read(1800, 1) + _error_read(2100, 1))
    (result,) = _judge('[[expect]]\nreached_point = 3\n', _evidence({}, trace))
    assert not result.passed
    assert result.detail == "the task of run-point 3 ended with error 01 at 1.500 s"


def test_a_task_stopped_by_an_error_is_not_reached_once_the_error_clears():
    # after error 01 ended the task, the next poll with the error gone ("idle, error 00")
    # counted as the point reached: the robot never got there
    trace = (_control(0, STOP) + _control(600, POINT3) + _read(900, 1) + _error_read(1500, 1)
             + _read(1800, 0))
    (result,) = _judge('[[expect]]\nreached_point = 3\n', _evidence({}, trace))
    assert not result.passed
    assert result.detail == "the task of run-point 3 ended with error 01 at 1.500 s"


# --- conditions: property test against Python's own evaluation ----------------------------------

_VALUES = {"a": True, "b": False, "n": 5, "fb.m": 0x101}
_atoms = st.sampled_from([("a", True), ("b", False), ("TRUE", True), ("FALSE", False)])
_numbers = st.sampled_from([("n", 5), ("fb.m", 0x101), ("16#0101", 0x101), ("5", 5), ("2#11", 3), ("-2", -2)])


@st.composite
def _comparison(draw):
    (left, lv), (right, rv) = draw(_numbers), draw(_numbers)
    op, fn = draw(st.sampled_from([("=", lambda x, y: x == y), ("<>", lambda x, y: x != y), ("<", lambda x, y: x < y),
                                   ("<=", lambda x, y: x <= y), (">", lambda x, y: x > y), (">=", lambda x, y: x >= y)]))
    return f"{left} {op} {right}", fn(lv, rv)


def _combine(children):
    def build(pair, op):
        (lt, lv), (rt, rv) = pair
        value = {"AND": lv and rv, "OR": lv or rv, "XOR": lv != rv}[op]
        return f"({lt} {op} {rt})", value

    negate = children.map(lambda c: (f"NOT ({c[0]})", not c[1]))
    binary = st.builds(build, st.tuples(children, children), st.sampled_from(["AND", "OR", "XOR"]))
    return negate | binary


@given(st.recursive(_atoms | _comparison(), _combine, max_leaves=12))
def test_conditions_evaluate_like_their_meaning(expression):
    text, expected = expression
    assert parse_condition(text).holds(_VALUES) == expected


def test_each_familys_channels_are_the_simulators():
    """One table (verifier.plcfacts.FAMILY_CHANNELS) says which serial channels each CPU
    family has, for the simulator and the scenario reader alike (which once kept a list of
    its own, once missing fx5:2): every channel offered belongs to a family, every family is
    a simulated CPU's, and adp:1 (the ADPRW MODBUS master) is on exactly the families the
    instruction registry runs ADPRW on."""
    from verifier import plcfacts
    from verifier.sim.cpu import PROFILES
    from verifier.sim.instructions import lookup

    families = {p.family for p in PROFILES.values()}
    assert set(plcfacts.FAMILY_CHANNELS) == families
    assert set().union(*plcfacts.FAMILY_CHANNELS.values()) == set(plcfacts.CHANNELS)
    for family, channels in plcfacts.FAMILY_CHANNELS.items():
        assert list(channels) == [c for c in plcfacts.CHANNELS if c in channels], family  # CHANNELS' order
        adprw, _ = lookup("ADPRW", family)
        assert ("adp:1" in channels) == (family in adprw.families), family


def test_reading_every_bundled_scenario_does_not_import_the_simulator():
    """Reading a scenario checks its `channel` (and `[initial]` buffer memory) as a run
    would, from verifier.plcfacts: a scenario that set `channel` once imported the
    simulator's compiler and runtime (about 25 verifier.sim modules) only to ask which
    channels its CPU has."""
    import subprocess
    import sys

    from verifier.bundled import plc_dir

    paths = sorted(str(p) for p in (plc_dir() / "scenarios").glob("*.toml"))
    assert any("channel" in Path(p).read_text(encoding="utf-8") for p in paths)  # the case that imported it
    code = ("import sys; from verifier.verify.scenario import load_scenario\n"
            "for path in sys.argv[1:]: load_scenario(path)\n"
            "print(sorted(m for m in sys.modules if m.startswith('verifier.sim')))")
    out = subprocess.run([sys.executable, "-c", code, *paths], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "[]"


def test_each_platforms_channels_are_its_simulated_cpus():
    """The channels a scenario accepts for a platform are those its simulated CPU has
    (`Project.serial_channels`), so a scenario the parser lets through attaches."""
    import verifier.sim
    from verifier.verify.scenario import CHANNELS, PLATFORMS

    for platform, (target, _) in PLATFORMS.items():
        project = verifier.sim.load(sources={"p.st": "PROGRAM P\nEND_PROGRAM\n"}, target=target, cpu=platform)
        accepted = []
        for channel in CHANNELS:
            try:
                parse_scenario(f'{MINIMAL}platform = "{platform}"\nchannel = "{channel}"\n')
            except ScenarioError as error:
                assert error.key == "channel" and "does not exist" in error.message, (platform, channel, error)
            else:
                accepted.append(channel)
        assert sorted(accepted) == sorted(project.serial_channels()), platform


@pytest.mark.parametrize("text, key, place", [
    # a sub-table by a dotted header: was the first line (1:1) or no place at all
    ('[robot]\nturnaround_ms = 5\n\n[robot.point_durations_s]\n3 = 2.0\n4 = "x"\n', "robot.point_durations_s.4", (6, 5)),
    ('name = "n"\n[robot.point_durations_s]\n3 = 2.0\n4 = "x"\n', "robot.point_durations_s.4", (4, 5)),
    ('[protocol]\naddress = 1\n[robot]\nturnaround_ms = 5\n[robot.point_poses]\n3 = [1.0, 2.0, "x"]\n',
     "robot.point_poses.3[2]", (6, 16)),
    ('[robot]\nturnaround_ms = 5\n[robot.point_poses]\n3 = [1.0, 2.0, 0.0]\n[protocol]\naddress = 1\n'
     '[robot.extra]\na = 1\n', "robot.extra", (7, 1)),  # an unknown sub-table: its own header
    # a sub-table of the last table of an array: was that table's [[...]] header
    ('[[inputs]]\nat = "1s"\n[inputs.set]\nX0 = true\nD100 = "x"\n', "inputs[0].set.D100", (5, 8)),
    ('[[inputs]]\nat = "1s"\nset = { X0 = true }\n[[inputs]]\nat = "2s"\n[inputs.set]\nX0 = true\nD100 = "x"\n',
     "inputs[1].set.D100", (8, 8)),
    ('[[inputs]]\nat = "1s"\n[inputs.set]\nX0 = true\n"a b" = 1\n', "inputs[0].set", (5, 1)),  # the label itself
    ('[[faults]]\nkind = "no_reply"\nat_s = 1.0\n\n[faults.x]\ny = 1\n', "faults[0].x", (5, 1)),
    ('[[faults]]\nkind = "no_reply"\nat_s = 1.0\n[[faults]]\nkind = "no_reply"\nat_s = 2.0\n[faults.x]\ny = 1\n',
     "faults[1].x", (7, 1)),
    # dotted keys inside a table, and at the top
    ('[robot]\nturnaround_ms = 5\npoint_durations_s.3 = 2.0\npoint_durations_s.4 = "x"\n',
     "robot.point_durations_s.4", (4, 23)),
    ('robot.point_durations_s.4 = "x"\n', "robot.point_durations_s.4", (1, 29)),
    # inline tables: the second table of an inline array on its own line (was the array's line)
    ('faults = [{ kind = "no_reply", at_s = 1.0 },\n  { kind = "x", at_s = 1.0 }]\n', "faults[1].kind", (2, 12)),
    ('[[inputs]]\nat = "1s"\nset = { X0 = true, "a b" = 1 }\n', "inputs[0].set", (3, 20)),
    ('[robot]\npoint_poses = { 3 = [1.0, 2.0, 0.0], 4 = [1.0, 2.0, "x"] }\n', "robot.point_poses.4[2]", (2, 53)),
    # a name that also stands in a comment or a string before it is not taken for the key
    ('# [robot.point_durations_s]\ndescription = """\n[robot.point_durations_s]\n4 = 1\n"""\n'
     '[robot.point_durations_s]\n4 = "x"\n', "robot.point_durations_s.4", (7, 5)),
])
def test_a_key_in_a_sub_table_is_placed_on_its_own_line(text, key, place):
    error = error_of(text, Path("s.toml"))
    assert (error.key, (error.place.line, error.place.col)) == (key, place), str(error)
    assert str(error).startswith(f"s.toml:{place[0]}:{place[1]}: {key}: ")


@pytest.mark.parametrize("text, place", [
    ('[robot]\npoint_duraton_s = 8.0\n', "s.toml:2:1: robot.point_duraton_s: unknown key"),
    ('[[faults]]\nkind = "no_reply"\nat = 3\n', "s.toml:3:1: faults[0].at: unknown key"),
    ('[[faults]]\nkind = "anti_collision"\nat_s = 1\ncount = 2\n',
     "s.toml:4:1: faults[0].count: not used by fault 'anti_collision'"),
    ('[robot]\npoint_duration_s = "8s"\n', "s.toml:2:20: robot.point_duration_s: "),  # a bad value: at the value
    # a point number that is no whole number (int() would read " 4", "+4", "4_0"): the key is the mistake
    ('[robot.point_durations_s]\n1 = 2.0\n"+4" = 6.0\n', "s.toml:3:1: robot.point_durations_s.+4: key '+4' must be"),
    ('[robot]\npoint_durations_s = { 1 = 2.0, "4_0" = 6.0 }\n',
     "s.toml:2:32: robot.point_durations_s.4_0: key '4_0' must be"),
])
def test_an_unknown_robot_or_fault_key_is_pointed_at_by_its_name(tmp_path, text, place):
    """scenarios.md: the column is the key itself for an unknown key - in [robot] and
    [[faults]] too, as at the top level and in [converter]; the emulator's fault files, which
    hold the same tables, say the same."""
    with pytest.raises(ScenarioError) as caught:
        parse_scenario(text, path=Path("s.toml"))
    assert str(caught.value).startswith(place), str(caught.value)
    from verifier.emulate.faultfile import FaultFileError, load_fault_file

    bench = tmp_path / "s.toml"
    bench.write_text(text, encoding="utf-8")
    with pytest.raises(FaultFileError) as caught:
        load_fault_file(bench)
    assert str(caught.value).startswith(str(tmp_path / place)), str(caught.value)


def test_a_time_literal_broken_across_lines_is_named_as_one_with_a_line_break():
    """`T#1h` at a line's end and `30m` on the next (a long ST line or a multi-line condition
    wrapped inside the literal) got "'30m' is a duration without T#: a TIME literal is written
    T#30m", advice that gives T#1h T#30m, another error; it is named as the one literal with a
    blank inside, at its first character, in ST and in a condition alike; the blank is named
    a line break, not a space (session 32 said 'cannot hold a space' for it)."""
    from verifier import st

    source = st.parse("PROGRAM P\nVAR\n    tDelay : TIME;\nEND_VAR\nIF tDelay > T#1h\n    30m THEN\n"
                      "    tDelay := T#0s;\nEND_IF;\nEND_PROGRAM\n", "p.st", "gxworks2")
    assert [(d.line, d.col, d.message) for d in source.diagnostics] == [
        (5, 13, "'T#1h\\n    30m': a TIME literal cannot hold a line break: write T#1h30m")]
    with pytest.raises(ConditionError) as info:
        parse_condition("Y0 AND\n  n > T#1h\n  30m")
    assert (info.value.column, info.value.message) == (
        14, "'T#1h\\n  30m': a TIME literal cannot hold a line break: write T#1h30m")


# --- every mistake of a file in one run ---------------------------------------------------------
SEVERAL_MISTAKES = '''name = "cell"
platform = "fx5u"
channel = "fx3:1"
duration = "20s"

[[faults]]
kind = "no-replies"
at_s = 2.0

[[inputs]]
at = "1s"
set = { X10 = "on" }

[[expect]]
that = "gbErrLamp"
within = 5

[[expect]]
sent = "stop"
within = "1s"
'''


def test_every_mistake_of_a_scenario_file_is_told_in_one_read(tmp_path):
    """An integrator's FX5U scenario with four mistakes (an FX3 channel, a fault kind spelt
    with a hyphen and plural, a string for a bit, a bare number for a duration) was refused
    at the first alone: four runs of `uitamr check` or of the CI job to clean up one file.
    Now each is told, at its line and column, in the file's order; the rest is read as before."""
    path = tmp_path / "cell.toml"
    path.write_text(SEVERAL_MISTAKES, encoding="utf-8")
    with pytest.raises(ScenarioError) as caught:
        load_scenario(path)
    errors = caught.value.errors
    assert [(e.key, e.place.line, e.place.col) for e in errors] == [
        ("channel", 3, 11), ("faults[0].kind", 7, 8), ("inputs[0].set.X10", 12, 15), ("expect[0].within", 16, 10)]
    assert "unknown fault 'no-replies'" in errors[1].message
    assert str(caught.value).splitlines() == [str(e) for e in errors]
    # the first is the error's own key and place, as for a file with one mistake
    assert (caught.value.key, caught.value.place) == ("channel", errors[0].place)


def test_uitamr_check_and_verify_list_every_mistake_of_a_scenario_file(tmp_path):
    from click.testing import CliRunner
    from verifier.commands.check import command as check
    from verifier.commands.verify import command as verify

    path = tmp_path / "cell.toml"
    path.write_text(SEVERAL_MISTAKES, encoding="utf-8")
    result = CliRunner().invoke(check, [str(path)])
    assert result.exit_code == 1
    places = [line.split(": error: ")[0].rsplit(":", 2)[1:] for line in result.output.splitlines() if ": error: " in line]
    assert places == [["3", "11"], ["7", "8"], ["12", "15"], ["16", "10"]], result.output
    assert "4 error(s)" in result.output
    xml = tmp_path / "r.xml"
    result = CliRunner().invoke(verify, ["--scenario", str(path), "--junit", str(xml)])
    assert result.exit_code == 2
    assert sum(line.startswith("error: ") for line in result.output.splitlines()) == 4, result.output
    assert xml.read_text(encoding="utf-8").count("<testcase") == 4


def test_a_duration_in_error_does_not_make_later_times_mistakes(tmp_path):
    """The run's length unknown (a mistake of its own), an input at 90 s is no mistake too."""
    path = tmp_path / "s.toml"
    path.write_text('duration = "2 minutes"\n[[inputs]]\nat = "90s"\nset = { X0 = true }\n', encoding="utf-8")
    with pytest.raises(ScenarioError) as caught:
        load_scenario(path)
    assert caught.value.key == "duration" and not hasattr(caught.value, "errors")


def test_two_mistakes_in_one_fault_input_or_expectation_are_both_told(tmp_path):
    """review34: scenarios.md says every mistake of a file is told in one run, but a table
    of [[faults]], [[inputs]] or [[expect]] stopped at its first: a misspelt fault kind hid
    `at` (for `at_s`) below it, a bare-number `at` hid the string given for a bit, an unknown
    command to expect hid a bare-number `after` - three mistakes found a run after the
    others. Now the independent keys of a table are each read and told."""
    path = tmp_path / "s.toml"
    path.write_text('duration = "20s"\n'
                    '[[faults]]\nkind = "no_replyy"\nat = "5s"\n'
                    '[[inputs]]\nat = 2\nset = { X0 = "yes", X1 = true }\n'
                    '[[expect]]\nsent = "pausee"\nafter = 6\n', encoding="utf-8")
    with pytest.raises(ScenarioError) as caught:
        load_scenario(path)
    assert [(e.key, e.place.line, e.place.col) for e in caught.value.errors] == [
        ("faults[0].kind", 3, 8), ("faults[0].at", 4, 1), ("inputs[0].at", 6, 6), ("inputs[0].set.X0", 7, 14),
        ("expect[0].sent", 9, 8), ("expect[0].after", 10, 9)]
    assert "did you mean 'at_s'?" in caught.value.errors[1].message
