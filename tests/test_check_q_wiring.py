"""A Q program adapted from UITAMR_ExampleQ for a QJ71C24N elsewhere (another slot, CH2) must
change the unit, the channel, the module's two input signals and the receive-setting words
together (docs/import-gxworks2.md section 5). Half of it done passed `uitamr check --platform
q` at 0 warnings; only `verify` showed it, as a frame 16 bytes long or replies never read.
`check` now names the signal or buffer-memory word that does not belong to the module and
channel the port drives, and the one to write."""
from __future__ import annotations

from pathlib import Path

from verifier import st

ROOT = Path(__file__).resolve().parents[1]

MAIN = """\
PROGRAM Main
VAR
    fbPort : UITAMR_PortQC24;
    uPort : ARRAY[0..39] OF WORD;
END_VAR
VAR CONSTANT
    C24_UNIT : WORD := 16#2;
    C24_CHANNEL : INT := 2;
END_VAR
IF SM402 THEN
    {w1} := 1;
    {w2} := 8;
    {w3} := 16#FFFF;
END_IF;
fbPort(i_bEN := TRUE, i_uUnit := C24_UNIT, i_wChannel := C24_CHANNEL, i_bReadReq := {req},
       i_bRecvErr := {err}, io_uPort := uPort);
END_PROGRAM
"""


def _library() -> list:
    """plc/core and plc/q, parsed for GX Works2."""
    return [st.parse(p.read_text(encoding="utf-8"), str(p), "gxworks2")
            for d in ("core", "q") for p in sorted((ROOT / "plc" / d).glob("*.st"))]


def _check(**devices: str) -> list[tuple[int, int, str]]:
    text = MAIN.format(**{"w1": "U2\\G310", "w2": "U2\\G324", "w3": "U2\\G325", "req": "X2A", "err": "X2B",
                          **devices})
    files = [st.parse(text, "Main.st", "gxworks2")]
    files += _library()
    return [(d.line, d.col, d.message) for d in st.check(files, "gxworks2") if d.file == "Main.st"]


def test_the_module_s_signals_and_words_of_the_channel_the_port_drives_are_not_warned():
    assert _check() == []


def test_a_read_request_or_abnormal_detection_of_another_channel_or_slot_is_warned_with_the_right_one():
    """X3 / X4 are CH1's signals of a module at X/Y000; the port drives CH2 of the module at
    X/Y020, whose are X2A / X2B: with X3 the port waits for a signal that never comes and every
    reply stays in the module."""
    found = _check(req="X3", err="X24")
    assert found == [
        (15, 85, "i_bReadReq := X3 is not the reception data read request of CH2 of the QJ71C24N at U2 "
                 "(X/Y020, from i_uUnit and i_wChannel): that is X2A (start + AH; C24 (Basic), "
                 "docs/instructions.md §9); pass X2A, or the port never reads what the module received"),
        (16, 22, "i_bRecvErr := X24 is not the reception abnormal detection of CH2 of the QJ71C24N at U2 "
                 "(X/Y020, from i_uUnit and i_wChannel): that is X2B (start + BH; C24 (Basic), "
                 "docs/instructions.md §9); pass X2B, or the port never reads what the module received")], found


def test_a_receive_setting_written_for_the_other_channel_or_module_is_warned_with_the_word_to_write():
    """CH1's words (G150 / G164 / G165) written for a port on CH2 leave CH2 in word units with the
    default count: every frame went out 16 bytes long. U0\\G... while the port drives U2 sets a
    module that is not there."""
    found = _check(w1="U2\\G150", w2="U0\\G324")
    assert found == [
        (11, 5, "U2\\G150 is the word/byte units (96H) of CH1 of the QJ71C24N at U2, but the port (fbPort at "
                "15:1) drives CH2 of U2: write U2\\G310 (136H) instead"),
        (12, 5, "U0\\G324 is the received data count (144H) of CH2 of the QJ71C24N at U0, but the port (fbPort "
                "at 15:1) drives CH2 of U2: write U2\\G324 (144H) instead")], found


TCP = """\
PROGRAM MainTcp
VAR
    fbPort : UITAMR_PortE71;
    uPort : ARRAY[0..39] OF WORD;
END_VAR
VAR CONSTANT
    E71_UNIT : STRING(4) := 'U2';
END_VAR
fbPort(i_bEN := TRUE, i_sUnit := E71_UNIT, i_wConnection := 1, i_udIpAddress := 16#C0A80332,
       i_uTcpPort := 4001, i_uLocalPort := 4002,
       i_uOpenSignal := {open}, i_uRecvSignal := {recv}, io_uPort := uPort);
END_PROGRAM
"""


def _check_tcp(open_signal: str, recv_signal: str) -> list[tuple[int, int, str]]:
    text = TCP.format(open=open_signal, recv=recv_signal)
    files = [st.parse(text, "MainTcp.st", "gxworks2")]
    files += _library()
    return [(d.line, d.col, d.message) for d in st.check(files, "gxworks2") if d.file == "MainTcp.st"]


def test_the_e71_s_status_words_of_another_module_or_swapped_are_warned_with_the_word_to_pass():
    """UITAMR_ExampleTcpQ moved to X/Y020 with E71_UNIT := 'U2' but U0\\G20480 kept: check said
    0 warnings and verify showed a stop sent 32 s late with no word why."""
    assert _check_tcp("U2\\G20480", "U2\\G20485") == []
    found = _check_tcp("U0\\G20480", "U2\\G20480")
    assert found == [
        (11, 25, "i_uOpenSignal := U0\\G20480 is not the open completion signal (5000H) of the QJ71E71 at U2 "
                 "(from i_sUnit := E71_UNIT, 'U2', the constant declared at 7:5): pass U2\\G20480 (the library's "
                 "buffer addresses, docs/instructions.md §13)"),
        (11, 53, "i_uRecvSignal := U2\\G20480 is not the fixed buffer reception status signal (5005H) of the "
                 "QJ71E71 at U2 (from i_sUnit := E71_UNIT, 'U2', the constant declared at 7:5): pass U2\\G20485 "
                 "(the library's buffer addresses, docs/instructions.md §13)")], found


RAW = """\
PROGRAM Raw
VAR
    uCtl : ARRAY[0..2] OF WORD;
    uSend : ARRAY[0..3] OF WORD;
    bDone : ARRAY[0..1] OF BOOL;
    bSend : BOOL;
    bBusy : BOOL;
END_VAR
uCtl[0] := 1;
uCtl[2] := 8;
bSend := X20;
bDone[1] := FALSE;
G_OUTPUT(bSend, 16#0, uCtl[0], uSend[0], bDone[0]);
{handling}
END_PROGRAM
"""


def _check_raw(handling: str) -> list[tuple[int, int, str]]:
    files = [st.parse(RAW.format(handling=handling), "Raw.st", "gxworks2")]
    return [(d.line, d.col, d.message) for d in st.check(files, "gxworks2") if d.file == "Raw.st"]


def test_completion_bits_of_a_dedicated_instruction_that_are_never_read_are_warned():
    """A send of one's own with G_OUTPUT held on by a level and its completion bits never read
    passed check at 0 warnings; on the PLC it sends again as soon as it completes (verify: one
    3200-byte frame) and an error completion goes unseen. Writing a bit is no reading of it."""
    assert _check_raw("bBusy := bSend;") == [
        (13, 42, "G_OUTPUT's completion bits bDone (done, error) are never read in Raw: the program cannot tell "
                 "when it has completed or whether it failed; wait for bDone[0] (done) before starting the next "
                 "one, and act on bDone[1] (error)")]
    assert _check_raw("bBusy := bSend AND NOT bDone[0];") == []


def test_a_module_written_as_in_ladder_says_how_st_writes_it():
    """`G_OUTPUT(X20, U0, ...)` as the ladder writes the module said "undefined label 'U0';
    declare it in a VAR block", and GX Works takes no label named U0 (a device letter)."""
    text = RAW.format(handling="").replace("16#0, uCtl[0]", "U2, uCtl[0]").replace("bDone[1] := FALSE;",
                                                                                  "bBusy := bDone[0];")
    files = [st.parse(text, "Raw.st", "gxworks2")]
    found = [(d.line, d.col, d.message) for d in st.check(files, "gxworks2") if d.file == "Raw.st"]
    assert found == [
        (13, 17, "undefined label 'U2'; ST does not write a module as U2 (ladder's Un): G_OUTPUT and G_INPUT "
                 "take its start I/O number without the last digit (16#2 for the module at X/Y020), ZP_OPEN and "
                 "the other ZP_ instructions the string 'U2'; U2\\G150 is its buffer memory")]


def test_a_word_of_a_module_the_program_drives_itself_is_not_judged():
    """CH1 of the same QJ71C24N read by the program's own G_INPUT (a barcode reader) while the
    robot's port drives CH2: its CH1 settings are no mistake."""
    text = MAIN.format(w1="U2\\G150", w2="U2\\G324", w3="U2\\G325", req="X2A", err="X2B").replace(
        "END_PROGRAM", "G_INPUT(X23, C24_UNIT, uIn[0], uData[0], bRead[0]);\nIF bRead[0] THEN uIn[1] := 0; END_IF;\n"
                       "END_PROGRAM").replace(
        "END_VAR\nVAR CONSTANT", "    uIn : ARRAY[0..3] OF WORD;\n    uData : ARRAY[0..7] OF WORD;\n"
                                 "    bRead : ARRAY[0..1] OF BOOL;\nEND_VAR\nVAR CONSTANT")
    files = [st.parse(text, "Main.st", "gxworks2")]
    files += _library()
    found = [(d.line, d.col, d.message) for d in st.check(files, "gxworks2") if d.file == "Main.st"]
    assert found == [], found


def test_unread_completion_bits_are_warned_once_at_their_first_use():
    text = RAW.format(handling="bBusy := bSend;\nG_INPUT(bSend, 16#0, uCtl[0], uSend[0], bDone[0]);")
    files = [st.parse(text, "Raw.st", "gxworks2")]
    found = [(d.line, d.col) for d in st.check(files, "gxworks2") if d.file == "Raw.st"]
    assert found == [(13, 42)], found


def test_a_hex_device_written_without_its_leading_digit_says_how_to_write_it():
    """The example's header and the port's label table said "XA (CH2)", as the QJ71C24N manual
    names the signal, and `uitamr check` answered "undefined label 'XA'; declare it in a VAR
    block": the device reader (and GX Works' ST) takes a hexadecimal device number only when
    it starts with a digit, so CH2's read request is X0A."""
    text = "PROGRAM P\nVAR b : BOOL; w : WORD; END_VAR\nb := XA;\nb := SB1F AND XB;\nw := W0;\nb := X0A;\nEND_PROGRAM\n"
    files = [st.parse(text, "P.st", "gxworks2")]
    found = [(d.line, d.col, d.message) for d in st.check(files, "gxworks2", platform="q") if d.file == "P.st"]
    assert found == [
        (3, 6, "undefined label 'XA'; for the device write X0A: a hexadecimal device number starts with a "
               "digit (X0A, as 16#0A; docs/st-dialect.md)"),
        (4, 15, "undefined label 'XB'; for the device write X0B: a hexadecimal device number starts with a "
                "digit (X0B, as 16#0B; docs/st-dialect.md)")]
