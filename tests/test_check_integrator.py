"""Mistakes an integrator makes in a program of their own around the library, that GX Works
imports without a word and the PLC then runs wrong: `uitamr check` warns at the place.

Found writing a station program (journey32b) from the docs alone: an FB instance called
twice in a scan, and i_/o_ label names whose type letters name another type."""
from __future__ import annotations

import subprocess
import sys
from pathlib import Path

from verifier import st

ROOT = Path(__file__).resolve().parents[1]

TWICE = """\
PROGRAM Station
VAR
    fbBatt : UITAMR_ReadStatus;
    fbTmr : TON;
    uMbx : ARRAY[0..15] OF WORD;
    bRead : BOOL;
    bVehicle : BOOL;
END_VAR
fbBatt(i_bEN := TRUE, i_bExecute := bRead, i_wQuery := 3, io_uMbx := uMbx);
fbBatt(i_bEN := TRUE, i_bExecute := bVehicle, i_wQuery := 1, io_uMbx := uMbx);
IF bRead THEN
    fbTmr(IN := TRUE, PT := T#1s);
ELSE
    fbTmr(IN := FALSE, PT := T#1s);
END_IF;
END_PROGRAM
"""


def _check(text: str, *more: Path, target: str = "gxworks3"):
    files = [st.parse(text, "Station.st", target)]
    files += [st.parse(p.read_text(encoding="utf-8"), str(p), target) for d in more for p in sorted(d.glob("*.st"))]
    return [d for d in st.check(files, target) if d.file == "Station.st"]


def test_an_fb_instance_called_twice_in_every_scan_is_warned_at_the_second_call():
    """A second use of a command FB given to the same instance (fbBatt for the battery and
    for the vehicle status) passed `uitamr check` at 0 warnings; under verify the station
    never reached "at station" and raised no fault: the second call saw the first one's
    edge and outputs. Calls in the branches of an IF (one a scan) are not warned."""
    diags = _check(TWICE, ROOT / "plc" / "core")
    assert [(d.line, d.col, d.severity) for d in diags] == [(10, 1, "warning")], [str(d) for d in diags]
    assert "FB instance 'fbBatt' is called a second time in every scan (first at 9:1)" in diags[0].message
    assert "(e.g. fbBatt2 : UITAMR_ReadStatus)" in diags[0].message


def test_type_letters_that_name_another_type_are_warned_with_the_name_to_give():
    """`i_bPoint : INT`, `o_uCount : INT`, `i_wSpeed : WORD` passed `uitamr check`, though
    plc-library.md says the labels follow the convention's letters "which uitamr check
    enforces" (it enforced GX Works' naming rules only)."""
    text = """\
FUNCTION_BLOCK FB_Helper
VAR_INPUT
    i_bPoint : INT;
    i_wSpeed : WORD;
    i_udIp : DWORD;
    i_xOther : INT;
    i_eRange : REAL;
END_VAR
VAR_IN_OUT
    io_wMbx : ARRAY[0..15] OF WORD;
END_VAR
VAR_OUTPUT
    o_uCount : INT;
    o_wWide : DINT;
END_VAR
o_uCount := i_bPoint;
END_FUNCTION_BLOCK
"""
    got = {(d.line, d.message.split("rename it ")[-1] if "rename it" in d.message else d.message)
           for d in _check(text) if "type letter" in d.message}
    assert got == {(3, "i_wPoint"), (4, "i_uSpeed"), (10, "io_uMbx"), (13, "o_wCount"),
                   (14, "label 'o_wWide' is DINT (Double Word [Signed]), but its type letter 'w' stands for "
                        "Word[Signed] in Mitsubishi's FB-library label names (docs/plc-library.md): give it the "
                        "letters of its type, or another type")}, got


def test_the_library_and_the_examples_stay_at_no_warning_on_each_platform():
    for platform, folders in (("fx3u", ["plc/fx3", "plc/examples/fx3"]), ("fx5u", ["plc/fx5", "plc/examples/fx5"]),
                              ("q", ["plc/q", "plc/examples/q"])):
        out = subprocess.run([sys.executable, "-m", "verifier.cli", "check", "--platform", platform, "plc/core",
                              "plc/examples/common", *folders], cwd=ROOT, capture_output=True, text=True)
        assert out.returncode == 0 and out.stdout.strip().endswith("0 error(s), 0 warning(s)"), out.stdout


def test_the_letters_check_judges_are_the_ones_the_library_page_lists():
    """plc-library.md's list of type letters is what `uitamr check` warns by: a letter added
    to one and not the other would warn at names the page allows, or let through one it
    forbids."""
    import re

    from verifier.st.check import TYPE_LETTERS

    text = " ".join((ROOT / "docs" / "plc-library.md").read_text(encoding="utf-8").split())
    listed = re.search(r"\(`i_`/`o_`/`io_` \+ type letters: (.*?)\) and GX Works' naming rules", text).group(1)
    assert dict(item.split(" ", 1) for item in listed.split(", ")) == TYPE_LETTERS


def test_a_reset_call_before_the_use_of_the_same_instance_is_not_warned():
    """`fbTmr(IN := FALSE); fbTmr(IN := bRun, PT := T#1s);` restarts a timer in one scan (the
    IEC idiom; the same with i_bExecute := FALSE re-arms a command FB's edge): one use, not
    two, and the warning's advice (a second instance) would break the restart. A third
    call after the use is still a second use, named at the use after the reset."""
    text = """\
PROGRAM Station
VAR
    fbTmr : TON;
    bRun : BOOL;
    bOther : BOOL;
END_VAR
fbTmr(IN := FALSE, PT := T#1s);
fbTmr(IN := bRun, PT := T#1s);
bOther := fbTmr.Q;
fbTmr(IN := bOther, PT := T#2s);
END_PROGRAM
"""
    diags = _check(text)
    assert [(d.line, d.col, d.severity) for d in diags] == [(10, 1, "warning")], [str(d) for d in diags]
    assert "FB instance 'fbTmr' is called a second time in every scan (first at 8:1)" in diags[0].message
    # FALSE to an input that does not start the work (an option) is a second use all the same
    option = """\
PROGRAM Station
VAR
    fbSpeed : UITAMR_SetSpeed;
    uMbx : ARRAY[0..15] OF WORD;
    bSlow : BOOL;
    bFast : BOOL;
END_VAR
fbSpeed(i_bEN := TRUE, i_bExecute := bSlow, i_bMagnetic := FALSE, i_wStage := 1, io_uMbx := uMbx);
fbSpeed(i_bEN := TRUE, i_bExecute := bFast, i_bMagnetic := FALSE, i_wStage := 3, io_uMbx := uMbx);
END_PROGRAM
"""
    diags = _check(option, ROOT / "plc" / "core")
    assert [(d.line, d.col) for d in diags] == [(9, 1)], [str(d) for d in diags]


def test_letters_the_page_marks_unconfirmed_are_not_judged():
    """Mitsubishi's manuals use more letters than the judged list (`pb_dPositAdr`, a signed
    position, in the FX5 Simple Motion examples), but no Mitsubishi page states their data
    types: plc-library.md names them UNCONFIRMED and not judged, and check gives no warning
    at them whatever the type (a warning it could not cite would be a guess)."""
    import re

    from verifier.st.check import TYPE_LETTERS

    text = " ".join((ROOT / "docs" / "plc-library.md").read_text(encoding="utf-8").split())
    said = re.search(r"\*\*UNCONFIRMED\*\*, not judged: (.*?) a warning on them could not be cited", text)
    assert said is not None, "plc-library.md no longer says which letters are not judged"
    letters = set(re.findall(r"`([a-z]+)`", re.sub(r"\(`pb_.*?\)|`[a-z]+[A-Z]\w*`", "", said.group(1))))
    assert {"d", "dw", "lr", "le", "bn", "un", "st", "stn"} <= letters, letters
    assert not letters & set(TYPE_LETTERS), letters & set(TYPE_LETTERS)
    names = [f"i_{letter}Value{n}" for n, letter in enumerate(sorted(letters))]
    text = "FUNCTION_BLOCK FB_Helper\nVAR_INPUT\n" + "".join(f"    {n} : BOOL;\n" for n in names) + \
        "END_VAR\nVAR_OUTPUT\n    o_bDone : BOOL;\nEND_VAR\no_bDone := " + " OR ".join(names) + ";\nEND_FUNCTION_BLOCK\n"
    assert [str(d) for d in _check(text) if "type letter" in d.message] == []


#: two calls of a timer with a RETURN of the statement list between them
AFTER_RETURN = """\
PROGRAM Station
VAR
    fbTmr : TON;
    bRun : BOOL;
END_VAR
fbTmr(IN := bRun, PT := T#1s);
RETURN;
fbTmr(IN := bRun, PT := T#2s);
END_PROGRAM
"""


def test_a_second_call_after_an_early_return_is_warned_for_the_scans_that_pass_it():
    """`fbTmr(...); IF bStop THEN RETURN; END_IF; fbTmr(...);` was warned 'called a second
    time in every scan', though in the scans that take the RETURN only the first call runs.
    The two calls still share the instance in every other scan, so it stays a warning, said
    for those scans with the RETURN's place. After a RETURN of the statement list itself the
    second call never runs: not judged."""
    text = """\
PROGRAM Station
VAR
    fbTmr : TON;
    bRun : BOOL;
    bStop : BOOL;
    bFault : BOOL;
END_VAR
fbTmr(IN := bRun, PT := T#1s);
IF bStop THEN
    RETURN;
END_IF;
fbTmr(IN := bRun, PT := T#2s);
CASE 1 OF
    1: IF bFault THEN RETURN; END_IF;
END_CASE;
fbTmr(IN := bStop, PT := T#3s);
END_PROGRAM
"""
    diags = _check(text)
    assert [(d.line, d.col) for d in diags] == [(12, 1), (16, 1)], [str(d) for d in diags]
    assert ("FB instance 'fbTmr' is called a second time in the same scan whenever the RETURN at 10:5 is "
            "not taken (first at 8:1)") in diags[0].message, diags[0].message
    assert ("called a second time in the same scan whenever the RETURNs at 10:5, 14:23 are not taken "
            "(first at 8:1)") in diags[1].message, diags[1].message
    dead = AFTER_RETURN
    assert [str(d) for d in _check(dead) if "second time" in d.message] == []
    # an IF whose every branch returns is that RETURN too; one without an ELSE is not
    both = dead.replace("RETURN;", "IF bRun THEN\n    RETURN;\nELSE\n    RETURN;\nEND_IF;")
    assert [str(d) for d in _check(both) if "second time" in d.message] == []
    one = dead.replace("RETURN;", "IF bRun THEN\n    RETURN;\nELSIF NOT bRun THEN\n    RETURN;\nEND_IF;")
    assert [(d.line, d.col) for d in _check(one) if "second time" in d.message] == [(12, 1)]


def test_an_iec_counters_reset_before_its_use_is_not_warned():
    """`fbCnt(R := TRUE); fbCnt(CU := bPulse, R := FALSE, PV := 10);` (a counter cleared and
    counted on in one scan, the counters' form of the timer restart) was warned as a second
    use: only FALSE to IN/EN/i_bEN/i_bExecute counted as a reset. R or LD given TRUE sets the
    count whatever the call's other inputs, so it is a reset too, when the use gives the
    input back (an input keeps its value: left out, it holds the counter at 0 in the use,
    still warned). A user FB's `i_bReset := TRUE` is a use: its body is its own."""
    text = """\
FUNCTION_BLOCK FB_Seq
VAR_INPUT
    i_bReset : BOOL;
    i_bExecute : BOOL;
END_VAR
VAR_OUTPUT
    o_bDone : BOOL;
END_VAR
o_bDone := i_bExecute AND NOT i_bReset;
END_FUNCTION_BLOCK

PROGRAM Station
VAR
    fbCnt : CTU;
    fbDown : CTD;
    fbBoth : CTUD;
    fbHeld : CTU;
    fbSeq : FB_Seq;
    bPulse : BOOL;
END_VAR
fbCnt(R := TRUE);
fbCnt(CU := bPulse, R := FALSE, PV := 10);
fbDown(CD := FALSE, LD := TRUE, PV := 5);
fbDown(CD := bPulse, LD := FALSE);
fbBoth(LD := TRUE, PV := 3);
fbBoth(CU := bPulse, CD := FALSE, LD := FALSE, R := FALSE);
fbHeld(R := TRUE);
fbHeld(CU := bPulse, PV := 10);
fbSeq(i_bReset := TRUE);
fbSeq(i_bReset := FALSE, i_bExecute := bPulse);
END_PROGRAM
"""
    diags = _check(text)
    assert [(d.line, d.col) for d in diags] == [(28, 1), (30, 1)], [str(d) for d in diags]
    assert "FB instance 'fbHeld' is called a second time in every scan (first at 27:1)" in diags[0].message
    assert "FB instance 'fbSeq' is called a second time in every scan (first at 29:1)" in diags[1].message


ONLY_UNDER_IF = """\
PROGRAM Cell
VAR
    fbStop : UITAMR_Stop;
    fbRun : UITAMR_RunPoint;
    fbPause : UITAMR_Pause;
    uMbx : ARRAY[0..15] OF WORD;
    bStop : BOOL;
    bGo : BOOL;
    bHold : BOOL;
END_VAR
IF bStop THEN
    fbStop(i_bEN := TRUE, i_bExecute := TRUE, io_uMbx := uMbx);
END_IF;
IF bGo THEN
    fbRun(i_bEN := TRUE, i_bExecute := TRUE, i_wPoint := 3, io_uMbx := uMbx);
ELSE
    fbRun(i_bEN := TRUE, i_bExecute := FALSE, i_wPoint := 3, io_uMbx := uMbx);
END_IF;
fbPause(i_bEN := bHold, i_bExecute := TRUE, io_uMbx := uMbx);
END_PROGRAM
"""


def test_a_command_fb_called_only_under_a_condition_or_on_a_constant_true_is_warned():
    """journey33b: `IF X1 THEN fbStop(i_bEN := TRUE, i_bExecute := TRUE, ...)` passed `uitamr
    check` at 0 warnings, stopped the robot once under verify and never again (the second
    press was no rising edge: the instance had not run while X1 was off), and verify said
    only that the stop was not sent. `i_bEN := X3, i_bExecute := TRUE` (the button on the
    wrong input) sent nothing at all. A call in every branch of an IF with an ELSE is a call
    on every scan, and TRUE there is the edge the ELSE's FALSE makes: not warned."""
    diags = _check(ONLY_UNDER_IF, ROOT / "plc" / "core")
    assert [(d.line, d.col, d.severity) for d in diags] == [(12, 5, "warning"), (19, 39, "warning")], \
        [str(d) for d in diags]
    assert "FB instance 'fbStop' is called only under a condition" in diags[0].message
    assert "a second press sends nothing" in diags[0].message
    assert "call it on every scan, outside the IF, and give the condition to i_bExecute" in diags[0].message
    assert diags[1].message.startswith("i_bExecute := TRUE on every scan: 'fbPause' starts on a rising edge")
    assert "TRUE to i_bEN" in diags[1].message


def test_a_command_fb_called_after_an_early_return_is_warned_as_one_under_a_condition():
    """`IF NOT X1 THEN RETURN; END_IF; fbStop(i_bEN := TRUE, i_bExecute := TRUE, ...);` is the
    IF of the test above written as a guard: fbStop runs only in the scans that pass the
    RETURN, sees no falling edge and stops the robot once. It was taken for a call on every
    scan and warned 'i_bExecute := TRUE on every scan' (the advice, i_bExecute := X1 behind the
    same RETURN, left the instance seeing TRUE alone), and with the button on i_bExecute not
    at all. Both are warned now as called only in the scans that do not take the RETURN, with
    its place; a call before the RETURN, or in every branch before one, stays a call on every
    scan, and a call after a RETURN of the statement list never runs and is not judged."""
    guarded = ONLY_UNDER_IF.replace("""IF bStop THEN
    fbStop(i_bEN := TRUE, i_bExecute := TRUE, io_uMbx := uMbx);
END_IF;""", """IF NOT bStop THEN
    RETURN;
END_IF;
fbStop(i_bEN := TRUE, i_bExecute := TRUE, io_uMbx := uMbx);""")
    diags = _check(guarded, ROOT / "plc" / "core")
    stop = [d for d in diags if "'fbStop'" in d.message]
    assert [(d.line, d.col) for d in stop] == [(14, 1)], [str(d) for d in diags]
    assert stop[0].message.startswith("FB instance 'fbStop' is called only in the scans that do not take the "
                                      "RETURN at 12:5: it sees i_bExecute"), stop[0].message
    assert "call it on every scan, before the RETURN, and give the condition to i_bExecute" in stop[0].message
    button = guarded.replace("fbStop(i_bEN := TRUE, i_bExecute := TRUE", "fbStop(i_bEN := TRUE, i_bExecute := bStop")
    assert [(d.line, d.col) for d in _check(button, ROOT / "plc" / "core") if "'fbStop'" in d.message] == [(14, 1)]
    # the call before the RETURN runs in every scan; so does one in every branch before a RETURN
    before = button.replace("IF NOT bStop THEN\n    RETURN;\nEND_IF;\nfbStop(i_bEN := TRUE, i_bExecute := bStop, "
                            "io_uMbx := uMbx);", "fbStop(i_bEN := TRUE, i_bExecute := bStop, io_uMbx := uMbx);\n"
                            "IF NOT bStop THEN\n    RETURN;\nEND_IF;")
    assert before != button and [str(d) for d in _check(before, ROOT / "plc" / "core") if "'fbStop'" in d.message] == []
    branches = button.replace("IF NOT bStop THEN\n    RETURN;\nEND_IF;\nfbStop(i_bEN := TRUE, i_bExecute := bStop, "
                              "io_uMbx := uMbx);", "IF NOT bStop THEN\n    fbStop(i_bEN := TRUE, i_bExecute := bStop, "
                              "io_uMbx := uMbx);\n    RETURN;\nELSE\n    fbStop(i_bEN := TRUE, i_bExecute := bStop, "
                              "io_uMbx := uMbx);\nEND_IF;")
    assert branches != button
    assert [str(d) for d in _check(branches, ROOT / "plc" / "core") if "'fbStop'" in d.message] == []
    dead = button.replace("IF NOT bStop THEN\n    RETURN;\nEND_IF;", "RETURN;")
    assert dead != button and [str(d) for d in _check(dead, ROOT / "plc" / "core") if "'fbStop'" in d.message] == []


def test_a_return_in_a_repeat_loop_ends_what_runs():
    """A REPEAT's body runs once at least, so 'REPEAT RETURN; UNTIL TRUE END_REPEAT;' between
    two calls of an instance always leaves the POU: the second call was warned 'whenever the
    RETURN at 8:5 is not taken', of a RETURN that is always taken. It now ends what runs, as a
    plain RETURN does; an EXIT before the RETURN leaves the loop first, and the RETURN stays
    one the scan may pass."""
    text = AFTER_RETURN.replace("RETURN;", "REPEAT\n    RETURN;\nUNTIL bRun END_REPEAT;")
    assert [str(d) for d in _check(text) if "second time" in d.message] == []
    exits = text.replace("    RETURN;", "    IF bRun THEN\n        EXIT;\n    END_IF;\n    RETURN;")
    assert [(d.line, d.col) for d in _check(exits) if "second time" in d.message] == [(13, 1)]
    assert "whenever the RETURN at 11:5 is not taken" in [d.message for d in _check(exits)][-1]


def test_reading_an_fb_s_internal_instance_or_label_says_it_is_internal_and_what_to_read():
    """`fbRun.fbCmd.o_uErrDetail` (UITAMR_RunPoint's internal UITAMR_Command) was refused as
    "has no input or output 'fbCmd'", as if the name were a typo: the message now says it is an
    internal instance (VAR), which GX Works does not let a program read either, lists the
    outputs to read instead, and that a scenario may watch it (the verifier reads internals)."""
    text = """\
PROGRAM Station
VAR
    fbRun : UITAMR_RunPoint;
    uMbx : ARRAY[0..15] OF WORD;
    uDetail : WORD;
    bBad : BOOL;
END_VAR
fbRun(i_bEN := TRUE, i_bExecute := TRUE, i_wPoint := 3, io_uMbx := uMbx);
uDetail := fbRun.fbCmd.o_uErrDetail;
bBad := fbRun.bParamErr;
uDetail := fbRun.o_uNope;
END_PROGRAM
"""
    found = {d.line: d.message for d in _check(text, ROOT / "plc" / "core")}
    outputs = "read its outputs instead (o_bENO, o_bBusy, o_bOK, o_bErr, o_uErrId)"
    assert found[9].startswith("UITAMR_RunPoint has no input or output 'fbCmd': 'fbCmd' is an internal "
                               "instance of UITAMR_Command (VAR) of UITAMR_RunPoint"), found
    assert outputs in found[9] and "call UITAMR_Command in the program itself" in found[9]
    assert "as GX Works does" in found[9] and "A scenario's watch and conditions may read" in found[9]
    assert "'bParamErr' is an internal label (VAR) of UITAMR_RunPoint" in found[10] and outputs in found[10]
    assert found[11] == "UITAMR_RunPoint has no input or output 'o_uNope'"  # a typo stays a typo


def _ranges_the_library_checks() -> dict[tuple[str, str], tuple[int, int, int]]:
    """(FB, input) -> (lo, hi, code), read from plc/: each FB's own range check of an input
    (`bParamErr := (i_wPoint < POINT_MIN) OR (i_wPoint > POINT_MAX);`, `(i_wConnection >=
    CONN_MIN) AND (i_wConnection <= CONN_MAX)`, `(i_wChannel = CH1) OR (i_wChannel = CH2)`),
    its constants resolved, and the error code its header gives for a parameter out of range
    (16#0301) or an invalid channel / connection number (16#0304)."""
    import re

    forms = [r"\((i_\w+) < (\w+)\) OR \(\1 > (\w+)\)", r"\((i_\w+) >= (\w+)\) AND \(\1 <= (\w+)\)",
             r"\((i_\w+) = (\w+)\) OR \(\1 = (\w+)\)"]
    found = {}
    for path in sorted((ROOT / "plc").glob("*/*.st")):
        text = path.read_text(encoding="utf-8")
        fb = re.search(r"^FUNCTION_BLOCK (\w+)", text, re.M)
        if fb is None:
            continue
        constants = {n: int(v) for n, v in re.findall(r"^\s*(\w+) : INT := (-?\d+);", text, re.M)}
        header = text[:text.index("*)")]
        for form in forms:
            for name, lo, hi in re.findall(form, text):
                if name.startswith("i_e"):  # a REAL (UITAMR_SetCollisionRange): 4 values, no range to warn
                    continue
                lo, hi = constants[lo], constants[hi]
                if "=" in form and "<" not in form:  # two values: a range only when they are adjacent
                    assert hi == lo + 1, (path, name)
                codes = [c for c in (0x0301, 0x0304) if f"16#{c:04X}" in header]
                if not codes:  # no parameter check: UITAMR_ParseReply's received length (16#0105)
                    continue
                assert len(codes) == 1, (path, name, codes)
                code = codes[0]
                found[(fb.group(1).upper(), name.upper())] = (lo, hi, code)
    return found


def test_the_input_ranges_check_warns_on_are_the_ones_the_library_s_st_checks():
    """The table `uitamr check` warns from is held to plc/: a range changed in an FB (or a new
    FB that checks one) without the table fails here."""
    from verifier.st.library import LIBRARY_INPUT_RANGES

    assert LIBRARY_INPUT_RANGES == _ranges_the_library_checks()


def test_a_constant_out_of_the_range_a_library_fb_checks_is_warned():
    """`i_wPoint := 25` on UITAMR_RunPoint (points 1..21) or `i_wChannel := 3` on UITAMR_PortFx3
    passed `uitamr check` without a word and ended at run time with o_bErr (16#0301 / 16#0304):
    a constant outside the FB's range is now warned at the value; one inside is not."""
    text = """\
PROGRAM Station
VAR
    fbRun : UITAMR_RunPoint;
    fbPort : UITAMR_PortFx3;
    uMbx : ARRAY[0..15] OF WORD;
    uPort : ARRAY[0..39] OF WORD;
    bGo : BOOL;
END_VAR
fbPort(i_bEN := TRUE, i_wChannel := 3, i_bRs232 := FALSE, io_uPort := uPort);
fbRun(i_bEN := TRUE, i_bExecute := bGo, i_wPoint := 25, io_uMbx := uMbx);
fbRun(i_bEN := TRUE, i_bExecute := bGo, i_wPoint := 21, io_uMbx := uMbx);
END_PROGRAM
"""
    found = [(d.line, d.col, d.message) for d in _check(text, ROOT / "plc" / "core", ROOT / "plc" / "fx3",
                                                          target="gxworks2")
             if "is outside" in d.message]
    assert found == [
        (9, 37, "i_wChannel := 3 is outside 1..2, the range UITAMR_PortFx3 accepts: it ends with o_bErr and "
                "o_uErrId 16#0304 instead of running (see its header); give a value in 1..2"),
        (10, 53, "i_wPoint := 25 is outside 1..21, the range UITAMR_RunPoint accepts: it ends with o_bErr and "
                 "o_uErrId 16#0301 instead of running (see its header); give a value in 1..21")], found


def test_a_constant_label_out_of_the_range_a_library_fb_checks_is_warned_with_its_declaration():
    """UITAMR_ExampleQ passes its channel as a VAR CONSTANT label (`i_wChannel := C24_CHANNEL`),
    and so did a program adapted from it: with `C24_CHANNEL : INT := 3` `uitamr check --platform
    q` said 0 warnings (only a literal was judged) and verify only that nothing was sent. The
    label's constant value is judged now, at the argument, naming the declaration to change;
    a VAR label (not constant: the program may assign it) and a constant inside the range are not."""
    text = """\
PROGRAM Station
VAR
    fbPort : UITAMR_PortQC24;
    fbRun : UITAMR_RunPoint;
    uMbx : ARRAY[0..15] OF WORD;
    uPort : ARRAY[0..39] OF WORD;
    wPoint : INT := 30;
END_VAR
VAR CONSTANT
    C24_CHANNEL : INT := 3;
    LAST_POINT : INT := 21;
END_VAR
fbPort(i_bEN := TRUE, i_uUnit := 16#0, i_wChannel := C24_CHANNEL, i_bReadReq := X3, i_bRecvErr := X4,
       io_uPort := uPort);
fbRun(i_bEN := TRUE, i_bExecute := X20, i_wPoint := LAST_POINT, io_uMbx := uMbx);
fbRun(i_bEN := TRUE, i_bExecute := X21, i_wPoint := wPoint, io_uMbx := uMbx);
END_PROGRAM
"""
    found = [(d.line, d.col, d.message) for d in _check(text, ROOT / "plc" / "core", ROOT / "plc" / "q",
                                                          target="gxworks2")
             if "is outside" in d.message]
    assert found == [
        (13, 54, "i_wChannel := C24_CHANNEL (3, the constant declared at 10:5) is outside 1..2, the range "
                 "UITAMR_PortQC24 accepts: it ends with o_bErr and o_uErrId 16#0304 instead of running "
                 "(see its header); give a value in 1..2")], found


def test_a_global_constant_out_of_range_is_named_with_the_file_that_declares_it():
    """A VAR_GLOBAL CONSTANT (the global label file) used as a library FB's input: the
    message gave its line:col only, read as a place in the program's own file."""
    globals_text = "VAR_GLOBAL CONSTANT\n    G_CHANNEL : INT := 3;\nEND_VAR\n"
    text = """\
PROGRAM Station
VAR
    fbPort : UITAMR_PortFx3;
    uPort : ARRAY[0..39] OF WORD;
END_VAR
VAR_EXTERNAL CONSTANT
    G_CHANNEL : INT;
END_VAR
fbPort(i_bEN := TRUE, i_wChannel := G_CHANNEL, i_bRs232 := FALSE, io_uPort := uPort);
END_PROGRAM
"""
    target = "gxworks2"
    files = [st.parse(text, "Station.st", target), st.parse(globals_text, "GlobalLabels.st", target)]
    files += [st.parse(p.read_text(encoding="utf-8"), str(p), target)
              for d in (ROOT / "plc" / "core", ROOT / "plc" / "fx3") for p in sorted(d.glob("*.st"))]
    found = [(d.file, d.line, d.col, d.message) for d in st.check(files, target) if "is outside" in d.message]
    assert found == [
        ("Station.st", 9, 37, "i_wChannel := G_CHANNEL (3, the constant declared at GlobalLabels.st:2:5) is "
                              "outside 1..2, the range UITAMR_PortFx3 accepts: it ends with o_bErr and o_uErrId "
                              "16#0304 instead of running (see its header); give a value in 1..2")], found


def test_a_pause_or_stop_called_under_a_condition_is_told_it_loses_its_result():
    """review34: UITAMR_Pause posts to the priority slot, the stop's. Called only in a
    manual-mode IF, a pause whose result came while the IF was false left it there, and
    UITAMR_Stop then ended with 16#0303 after 30 s, unsent; check warned so. s35: the stop
    now takes such a result over (test_plc_commands.py), so that warning told of a danger
    that is gone; what is still true is said instead: a pause or a stop called so loses its
    result to the next priority request and ends with 16#0316."""
    text = """\
PROGRAM Station
VAR
    fbPause : UITAMR_Pause;
    fbStop : UITAMR_Stop;
    uMbx : ARRAY[0..15] OF WORD;
END_VAR
IF X7 THEN
    fbPause(i_bEN := TRUE, i_bExecute := X3, io_uMbx := uMbx);
    fbStop(i_bEN := TRUE, i_bExecute := X1, io_uMbx := uMbx);
END_IF;
END_PROGRAM
"""
    found = [d.message for d in _check(text, ROOT / "plc" / "core", target="gxworks2") if "only under" in d.message]
    assert len(found) == 2, found
    pause, stop = found
    assert pause.endswith("; a UITAMR_Pause not called when its result comes loses it to the next stop, pause "
                          "or resume, which takes the priority slot over: it then ends with 16#0316"), pause
    assert stop.endswith("; a UITAMR_Stop not called when its result comes loses it to the next stop, pause "
                         "or resume, which takes the priority slot over: it then ends with 16#0316"), stop
    assert "16#0303" not in pause + stop
