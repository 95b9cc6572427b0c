"""The checker's advice names only conversions GX Works has: every `X_TO_Y` a message
tells the user to write is a function the same checker accepts for that editor (STRING
conversions are spelt STR: INT_TO_STR, STR_TO_INT; TIME has none to or from REAL)."""
from __future__ import annotations

import re

import pytest

from verifier import st
from verifier.st import library

TYPES = {
    "gxworks2": ["BOOL", "INT", "DINT", "WORD", "DWORD", "REAL", "TIME", "STRING"],
    "gxworks3": ["BOOL", "INT", "DINT", "UINT", "UDINT", "WORD", "DWORD", "REAL", "LREAL", "TIME",
                 "STRING", "WSTRING"],
}
OTHERS = ["ARRAY[0..1] OF INT", "TON"]      # no conversion at all: the advice must not invent one


def program(target: str) -> str:
    """Every mistake whose message offers a conversion, with every type of the editor."""
    names = {t: f"lbl{i}" for i, t in enumerate(TYPES[target] + OTHERS)}
    decls = "\n".join(f"    {v} : {t};" for t, v in names.items())
    i, r, w, b = names["INT"], names["REAL"], names["WORD"], names["BOOL"]
    body = []
    for a, va in names.items():
        body += [f"{va} := {vb};" for vb in names.values() if vb != va]      # assignment
        body += [f"{i} := {va} + {i};", f"{va} := {va} + {va};", f"{r} := {va} ** 2.0;",
                 f"{w} := {va} AND {w};", f"{r} := SQRT({va});", f"{w} := SHL({va}, 1);",
                 f"CASE {va} OF 1: {b} := TRUE; END_CASE;"]
    return f"PROGRAM Hints\nVAR\n{decls}\nEND_VAR\n" + "\n".join(body) + "\nEND_PROGRAM\n"


@pytest.mark.parametrize("target", sorted(TYPES))
def test_every_conversion_a_message_names_exists(target):
    source = st.parse(program(target), "t.st", target)
    assert source.diagnostics == []
    messages = [d.message for d in st.check([source], target)]
    named = {m for text in messages for m in re.findall(r"\b([A-Z]+_TO_[A-Z]+)\b", text)}
    assert len(named) > 20                        # the program does reach the hints
    missing = sorted(n for n in named if n not in library.STANDARD_FUNCTIONS
                     or target not in library.STANDARD_FUNCTIONS[n].targets)
    assert missing == [], [m for m in messages if any(n in m for n in missing)][:8]


def test_a_string_is_converted_with_str_and_time_is_not_called_a_bit_string():
    text = ("PROGRAM Hints\nVAR\n    i : INT;\n    s : STRING;\n    t : TIME;\nEND_VAR\n"
            "i := s;\nt := t + t;\nEND_PROGRAM\n")
    source = st.parse(text, "t.st", "gxworks2")
    messages = [str(d) for d in st.check([source], "gxworks2")]
    assert messages == [
        "t.st:7:6: error: assignment: STRING cannot be stored in INT without conversion; use STR_TO_INT(...)",
        "t.st:8:6: error: '+' needs INT, DINT or REAL operands, not TIME; arithmetic on TIME is not allowed "
        "(convert with TIME_TO_DINT, and back with DINT_TO_TIME)",
    ]


MISSPELT = """TYPE Pose : STRUCT
    wX : INT;
    wHeading : INT;
END_STRUCT END_TYPE
PROGRAM Typos
VAR
    fbRun : TON;
    bStart : BOOL;
    stPose : Pose;
    wOut : INT;
END_VAR
fbRun(IN := bStrat, PT := T#1s);
wOut := TIME_TO_INT(fbRun.ETT);
wOut := stPose.wHeadin;
fbRn(IN := TRUE);
wOut := wNothingLikeIt;
END_PROGRAM
"""


def test_a_misspelt_label_member_or_instance_gets_the_name_meant():
    """'undefined label' alone sent the integrator hunting through the VAR block for a
    typo: the label, structure member, FB output or instance spelt nearly so is named."""
    source = st.parse(MISSPELT, "typos.st", "gxworks2")
    assert source.diagnostics == []
    messages = {d.line: d.message for d in st.check([source], "gxworks2")}
    assert messages[12] == "undefined label 'bStrat'; did you mean 'bStart'?"
    assert messages[13] == "TON has no input or output 'ETT'; did you mean 'ET'?"
    assert messages[14] == "structure Pose has no member 'wHeadin'; did you mean 'wHeading'?"
    assert messages[15] == "unknown function or instruction 'fbRn'; did you mean 'fbRun'?"
    assert messages[16] == "undefined label 'wNothingLikeIt'; declare it in a VAR block"


def test_a_misspelt_label_that_reads_like_a_hex_device_is_still_the_label_meant():
    """A hex device written without its leading digit (`XA`) is told how to write it (X0A);
    a misspelt label that happens to read so (`bEd` for bEnd, `BAD`) is not sent to a device."""
    text = ("PROGRAM P\nVAR\n    bEnd : BOOL;\n    bOut : BOOL;\nEND_VAR\n"
            "bOut := bEd;\nbOut := XA;\nbOut := Bad;\nEND_PROGRAM\n")
    source = st.parse(text, "p.st", "gxworks2")
    messages = {d.line: d.message for d in st.check([source], "gxworks2")}
    assert messages[6] == "undefined label 'bEd'; did you mean 'bEnd'?"
    assert messages[7].startswith("undefined label 'XA'; for the device write X0A")
    assert messages[8] == "undefined label 'Bad'; declare it in a VAR block"


MISCALLED = """PROGRAM Calls
VAR
    bMove : BOOL;
    wA : INT;
    fbTimer : TON;
END_VAR
wA := MOVE2(wA);
wA := INT_TO_WROD(wA);
fbTimr(IN := bMove, PT := T#1s);
END_PROGRAM
"""


def test_an_unknown_call_is_told_a_callable_name_never_a_plain_label():
    """review s35: the did-you-mean of an unknown call looked among every label, so
    MOVE2(...) got "did you mean 'bMove'?" - a BOOL, which cannot be called - while the
    standard function the integrator mistyped (INT_TO_WROD) got no guess. Now a call is
    told an FB instance, a FUNCTION, a standard function or an instruction of its editor."""
    source = st.parse(MISCALLED, "calls.st", "gxworks2")
    assert source.diagnostics == []
    messages = {d.line: d.message for d in st.check([source], "gxworks2")}
    assert messages[7] == "unknown function or instruction 'MOVE2'; did you mean 'MOVE'?"
    assert messages[8] == "unknown function or instruction 'INT_TO_WROD'; did you mean 'INT_TO_WORD'?"
    assert messages[9] == "unknown function or instruction 'fbTimr'; did you mean 'fbTimer'?"
