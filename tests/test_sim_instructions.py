"""MELSEC instruction models against the manuals' own examples and against a scripted
endpoint: CRC, MOV/BMOV/FMOV/SET/RST, RS2 (FX3 and FX5), G_OUTPUT/G_INPUT, ADPRW."""
from __future__ import annotations

import pytest

from sim_helpers import FakeEndpoint, load_st
from verifier.protocol import crc16, with_crc

MANUAL_FRAME = [0x01, 0x03, 0x03, 0x02, 0x00, 0x14]  # FX3U FNC 188 example -> 41E4H
STATUS_REPLY = bytes.fromhex("0101030000003c4e")  # a status reply (FC01, 3 data bytes 0) with its CRC: 8 bytes


def packed(data: list[int]) -> list[int]:
    """Bytes two per word, low byte first."""
    data = data + [0] * (len(data) % 2)
    return [data[i] | (data[i + 1] << 8) for i in range(0, len(data), 2)]


# ----------------------------------------------------------------------------- CRC
CRC_FB = """
FUNCTION_BLOCK FB_CRC
VAR_INPUT bRun : BOOL; wLen : INT; END_VAR
VAR uBuf : ARRAY[0..7] OF WORD; uOut : ARRAY[0..1] OF WORD; END_VAR
CRC(bRun, uBuf[0], wLen, uOut[0]);
END_FUNCTION_BLOCK
"""


def test_crc_16_bit_mode_manual_example():
    project = load_st(CRC_FB)
    fb = project.instance("FB_CRC")
    fb.uBuf = packed(MANUAL_FRAME)
    fb.bRun, fb.wLen = True, 6
    fb.scan()
    assert fb.uOut[0] == 0x41E4


def test_crc_8_bit_mode_uses_low_bytes_and_splits_the_result():
    project = load_st(CRC_FB)
    project.devices["M8161"] = True
    fb = project.instance("FB_CRC")
    fb.uBuf = MANUAL_FRAME
    fb.bRun, fb.wLen = True, 6
    fb.scan()
    assert list(fb.uOut) == [0xE4, 0x41]


def test_fx5_crc_with_sm8161():
    project = load_st(CRC_FB, target="gxworks3")
    project.devices["SM8161"] = True
    fb = project.instance("FB_CRC")
    fb.uBuf = MANUAL_FRAME
    fb.bRun, fb.wLen = True, 6
    fb.scan()
    assert list(fb.uOut) == [0xE4, 0x41]


def test_crc_not_executed_when_en_is_false_and_n_checked():
    project = load_st(CRC_FB)
    fb = project.instance("FB_CRC")
    fb.uBuf = packed(MANUAL_FRAME)
    fb.wLen = 6
    fb.scan()
    assert fb.uOut[0] == 0
    fb.bRun, fb.wLen = True, 0
    fb.scan()
    assert project.devices["M8067"] is True
    assert "outside 1..256" in project.diagnostics[0].message


def test_crc_block_running_past_the_array_is_reported():
    project = load_st(CRC_FB)
    fb = project.instance("FB_CRC")
    fb.bRun, fb.wLen = True, 17  # 9 words from an 8-word array
    with pytest.raises(Exception) as err:
        fb.scan()
    assert "past the end" in str(err.value)
    assert "t.st:5:" in str(err.value)


def test_mov_bmov_fmov_set_rst():
    src = """
PROGRAM P
VAR a : ARRAY[0..3] OF INT := [1, 2, 3, 4]; b : ARRAY[0..3] OF INT; x : INT; bit : BOOL; END_VAR
MOV(TRUE, 42, x);
BMOV(TRUE, a[1], 3, b[0]);
FMOV(TRUE, 7, 2, D10);
SET(TRUE, bit);
SET(TRUE, M5);
RST(TRUE, D11);
SET(TRUE, D12.F);
SET(TRUE, w.3);
RST(TRUE, w.0);
END_PROGRAM
""".replace("bit : BOOL; END_VAR", "bit : BOOL; w : WORD := 1; END_VAR")
    project = load_st(src, target="gxworks3")  # initial values: GX Works3 dialect (FX5U)
    project.run_programs(["P"], scans=1)
    p = project.program("P")
    assert p.x == 42 and list(p.b) == [2, 3, 4, 0] and p.bit is True
    assert project.devices["D10"] == 7 and project.devices["D11"] == 0 and project.devices["M5"] is True
    assert project.devices["D12"] == -32768 and p.w == 8


# ----------------------------------------------------------------------------- RS2 (FX3)
RS2_PROG = """
PROGRAM P
VAR
    uSend : ARRAY[0..3] OF WORD;
    uRecv : ARRAY[0..3] OF WORD;
    bStart : BOOL;
END_VAR
IF M8002 THEN
    D8400 := 16#1C81;   (* 9600 8N1 RS-485 *)
    D8409 := 5;         (* 50 ms *)
END_IF;
IF bStart THEN
    M8402 := TRUE;
    bStart := FALSE;
END_IF;
RS2(NOT M8002, uSend[0], 8, 8, 1, uRecv[0]);
END_PROGRAM
"""


def rs2_project(endpoint):
    project = load_st(RS2_PROG, scan_ms=10)
    project.attach_serial("fx3:1", endpoint)
    project.run_programs(["P"], scans=2)
    return project, project.program("P")


def test_rs2_sends_low_byte_first_and_clears_m8402_after_the_last_byte():
    ep = FakeEndpoint()
    project, p = rs2_project(ep)
    p.uSend = packed([0x01, 0x06, 0x01, 0xA0, 0x00, 0x00, 0x88, 0x14])
    p.bStart = True
    project.run_programs(["P"], scans=1)   # t = 20 ms: flag set, RS2 sends
    (data, t_us, origin) = ep.sent[0]
    assert data == bytes.fromhex("010601a000008814")
    assert t_us == 20_000
    assert origin == "t.st:13:5"             # where M8402 was set
    assert project.devices["M8402"] is True
    project.run_programs(["P"], scans=1)     # t = 30 ms: 8 bytes take 8.333 ms
    assert project.devices["M8402"] is False
    assert project.serial_log("fx3:1")[0].t_end_us == 20_000 + 8333


def test_the_serial_log_can_be_turned_off_and_the_count_goes_on():
    """uitamr verify turns the channels' log off (its line records every frame); the
    count the idle check compares keeps counting, and asking for the log says why not."""
    ep = FakeEndpoint()
    project, p = rs2_project(ep)
    project.keep_serial_log(False)
    p.uSend = packed([0x01, 0x06, 0x01, 0xA0, 0x00, 0x00, 0x88, 0x14])
    p.bStart = True
    project.run_programs(["P"], scans=2)
    channel = project.rt.channel("fx3:1")
    assert len(ep.sent) == 1 and channel.sent == [] and channel.sent_count == 1
    with pytest.raises(RuntimeError, match="serial log is off"):
        project.serial_log("fx3:1")
    project.keep_serial_log(True)
    assert project.serial_log("fx3:1") == []


def test_rs2_receives_by_count_then_waits_for_m8403_reset():
    ep = FakeEndpoint()
    project, p = rs2_project(ep)
    ep.reply_at(25_000, STATUS_REPLY)  # last byte at 33.3 ms
    project.run_programs(["P"], scans=3)     # scans at 20, 30, 40 ms
    assert project.devices["M8403"] is True
    assert project.devices["D8403"] == 8
    assert list(p.uRecv) == packed(list(STATUS_REPLY))
    ep.reply_at(45_000, b"\x99")             # arrives while M8403 is still ON
    project.run_programs(["P"], scans=1)
    assert project.devices["D8403"] == 8
    assert "discarded" in project.diagnostics[-1].message
    project.devices["M8403"] = False         # the program resets it...
    project.run_programs(["P"], scans=1)
    assert project.devices["D8403"] == 0     # ...and the count goes with it


def test_bytes_discarded_for_a_reception_never_rearmed_name_the_rs2_call_and_the_fix():
    # the diagnostic named no place and no remedy: a program that forgets to reset M8403
    # only saw "6 received byte(s) discarded because M8403 was still ON" in the JSON report
    ep = FakeEndpoint()
    project, p = rs2_project(ep)
    ep.reply_at(25_000, STATUS_REPLY)
    project.run_programs(["P"], scans=3)
    ep.reply_at(45_000, b"\x99")
    project.run_programs(["P"], scans=1)
    last = project.diagnostics[-1]
    assert last.location == "t.st:16:1"      # the RS2 call
    assert last.message == ("RS2 fx3:1: 1 received byte(s) discarded because M8403 was still ON: reset M8403 "
                            "(receive complete) once the received data is read, or RS2 receives nothing more "
                            "(docs/instructions.md §7)")


def test_bytes_after_a_reply_of_a_program_that_rearms_are_not_called_a_missing_reset():
    """Found running an own station program under the bundled garbage and late-reply fault
    sets: the library's port resets M8403 after every reply, yet the one stray burst after
    a reply was reported as "discarded because M8403 was still ON: reset M8403 ... or RS2
    receives nothing more", pointing at the library's RS2 call as if it never re-armed.
    Once the program has reset M8403, the message says what happened instead."""
    ep = FakeEndpoint()
    project, p = rs2_project(ep)
    ep.reply_at(25_000, STATUS_REPLY)
    project.run_programs(["P"], scans=3)
    project.devices["M8403"] = False         # the program reads the reply and re-arms
    project.run_programs(["P"], scans=1)
    ep.reply_at(55_000, STATUS_REPLY)   # last byte at 63.3 ms
    project.run_programs(["P"], scans=2)
    assert project.devices["M8403"] is True
    ep.reply_at(75_000, b"\x99\x98")        # noise right after the reply, before the reset
    project.run_programs(["P"], scans=2)
    last = project.diagnostics[-1]
    assert last.location == "t.st:16:1"
    assert last.message == ("RS2 fx3:1: 2 received byte(s) discarded because they came while M8403 was ON after a "
                            "complete reception, before the program reset it: bytes right after a complete reply "
                            "(a late reply, noise) are lost so, as on the CPU; the program last reset M8403 at "
                            "0.050 s: if it resets it after every reception, the receptions after them go on; if "
                            "not, reset it once the received data is read (docs/instructions.md §7)")


def test_bytes_dropped_long_after_the_last_reset_say_when_that_was():
    """Seen by the final read: a program that reset M8403 once and then stopped was told
    "the program does reset M8403, so the receptions after them go on" of a reply 2 s
    later. The message now gives the time of the last reset, which shows the program has
    stopped, and the advice to reset it."""
    ep = FakeEndpoint()
    project, p = rs2_project(ep)
    ep.reply_at(25_000, STATUS_REPLY)
    project.run_programs(["P"], scans=3)
    project.devices["M8403"] = False         # re-armed once...
    project.run_programs(["P"], scans=1)
    ep.reply_at(55_000, STATUS_REPLY)
    project.run_programs(["P"], scans=2)     # ...and never again
    ep.reply_at(2_000_000, STATUS_REPLY)
    project.run_programs(["P"], ms=2100)
    last = project.diagnostics[-1]
    assert "8 received byte(s) discarded" in last.message
    assert "the program last reset M8403 at 0.050 s" in last.message
    assert "if not, reset it once the received data is read" in last.message


def test_rs2_receive_ends_on_the_d8409_time_out():
    ep = FakeEndpoint()
    project, p = rs2_project(ep)
    ep.reply_at(25_000, bytes.fromhex("0181025d90"))  # 5-byte exception reply
    project.run_programs(["P"], scans=4)     # last byte at 30.2 ms; time-out 50 ms later
    assert project.devices["M8403"] is False
    project.run_programs(["P"], scans=4)     # t = 80 ms: 80.2 not reached yet
    project.run_programs(["P"], scans=1)     # t = 90 ms
    assert project.devices["M8403"] is True
    assert project.devices["M8409"] is True
    assert project.devices["D8403"] == 5


def test_rs2_warns_about_a_wrong_communication_format():
    ep = FakeEndpoint()
    project = load_st(RS2_PROG.replace("16#1C81", "16#1C91"))  # 19200
    project.attach_serial("fx3:1", ep)
    project.run_programs(["P"], scans=2)
    project.program("P").bStart = True
    project.run_programs(["P"], scans=1)
    assert any("19200 8N1" in d.message for d in project.diagnostics)
    # the RS-232 route's format is named too, not only the RS-485 ones
    assert any("H0081 on its RS-232 route" in d.message for d in project.diagnostics)


def test_rs2_takes_the_rs232_format_without_a_warning():
    ep = FakeEndpoint()
    project = load_st(RS2_PROG.replace("16#1C81", "16#0081"))  # 9600 8N1, RS-232C
    project.attach_serial("fx3:1", ep)
    project.run_programs(["P"], scans=2)
    project.program("P").bStart = True
    project.run_programs(["P"], scans=1)
    assert ep.sent and not project.diagnostics


def test_fx5_rs2_uses_its_own_devices():
    src = """
PROGRAM P
VAR uSend : ARRAY[0..3] OF WORD := [16#0201, 16#0403]; uRecv : ARRAY[0..3] OF WORD; END_VAR
IF SM402 THEN SM8561 := TRUE; END_IF;
RS2(TRUE, uSend[0], 4, 2, 1, uRecv[0]);
END_PROGRAM
"""
    project = load_st(src, target="gxworks3")
    ep = FakeEndpoint()
    project.attach_serial("fx5:1", ep)
    ep.reply_at(1000, b"\xAA\xBB")
    project.run_programs(["P"], scans=2)
    assert ep.sent[0][0] == b"\x01\x02\x03\x04"
    assert project.devices["SM8561"] is False
    assert project.devices["SM8562"] is True
    assert project.program("P").uRecv[0] == 0xBBAA


# ----------------------------------------------------------------------------- QJ71C24N
C24_PROG = """
PROGRAM P
VAR
    uOutCtl : ARRAY[0..2] OF WORD; uInCtl : ARRAY[0..3] OF WORD;
    uSend : ARRAY[0..3] OF WORD; uRecv : ARRAY[0..3] OF WORD;
    bOutDone, bInDone : ARRAY[0..1] OF BOOL; bGo : BOOL; nDone : INT;
END_VAR
uOutCtl[0] := 1; uOutCtl[2] := 4;
uInCtl[0] := 1; uInCtl[3] := 4;
G_OUTPUT(bGo, 16#0, uOutCtl, uSend, bOutDone);
bGo := FALSE;
G_INPUT(X3, 16#0, uInCtl, uRecv, bInDone);
IF bOutDone[0] THEN nDone := nDone + 1; END_IF;
END_PROGRAM
"""


def test_c24_output_and_input_with_buffer_memory_settings():
    project = load_st(C24_PROG, cpu="q")
    ep = FakeEndpoint()
    project.attach_serial("q:1", ep)
    buf = project.c24_buffer(0)
    p = project.program("P")
    p.uSend = packed(list(bytes.fromhex("010100000016bdc4")))
    p.bGo = True
    project.run_programs(["P"], scans=1)
    assert ep.sent[0][0] == bytes.fromhex("010100000016bdc4")  # 4 words, word units
    assert buf[0xA4] == 511 and buf[0xA5] == 0x0D0A       # the module's defaults
    buf[0xA4] = 4                                          # receive 4 words
    buf[0xA5] = -1                                         # FFFFH: no end code
    ep.reply_at(15_000, STATUS_REPLY)
    project.run_programs(["P"], scans=3)
    assert p.nDone == 1                                    # done bit ON for one scan
    assert list(p.uRecv) == packed(list(STATUS_REPLY))
    assert p.uInCtl[2] == 4 and p.uInCtl[1] == 0
    assert project.devices["X3"] is False                  # read request cleared


# ----------------------------------------------------------------------------- ADPRW
def adprw_started(src: str, **options):
    """Program P loaded with a scripted endpoint on adp:1, bRun set and one scan run."""
    project = load_st(src, **options)
    ep = FakeEndpoint()
    project.attach_serial("adp:1", ep)
    p = project.program("P")
    p.bRun = True
    project.run_programs(["P"], scans=1)
    return project, ep, p


def test_adprw_fx3_fc06_sends_the_frame_and_signals_completion():
    src = """
PROGRAM P
VAR uData : ARRAY[0..1] OF WORD; bRun : BOOL; nDone : INT; END_VAR
ADPRW(bRun, 1, 6, 16#01A0, 0, uData[0]);
IF bRun AND M8029 THEN nDone := nDone + 1; bRun := FALSE; END_IF;  (* M8029 read right after the call *)
END_PROGRAM
"""
    project, ep, p = adprw_started(src)
    assert ep.sent[0][0] == with_crc(bytes([1, 6, 1, 0xA0, 0, 0]))
    ep.reply_at(10_000, ep.sent[0][0])
    project.run_programs(["P"], scans=3)
    assert p.nDone == 1 and project.devices["D8402"] == 0 and project.devices["M8063"] is False
    assert project.devices["M8402"] is False and project.devices["M8403"] is False


def test_adprw_fx3_completion_is_reported_before_anything_is_sent_again():
    """QA 8: the scan whose ADPRW execution reports completion through M8029 must not start a
    second transaction, or a program that drops the execution condition on M8029 (read right
    after the call, as the FX3 port does) sends every frame twice, one scan apart."""
    src = """
PROGRAM P
VAR uData : ARRAY[0..1] OF WORD; bRun : BOOL; bComplete : BOOL; nDone : INT; END_VAR
ADPRW(bRun, 1, 6, 16#01A0, 0, uData[0]);
bComplete := bRun AND M8029;
IF bComplete THEN nDone := nDone + 1; bRun := FALSE; END_IF;
END_PROGRAM
"""
    project, ep, p = adprw_started(src)
    assert len(ep.sent) == 1
    ep.reply_at(ep.sent[0][1] + 12_000, ep.sent[0][0])    # the echo, 12 ms after the request
    for _ in range(100):                                   # one second of 10 ms scans
        project.run_programs(["P"], scans=1)
        if p.bComplete:
            assert len(ep.sent) == 1                      # the completing scan sent nothing
    assert p.nDone == 1 and len(ep.sent) == 1             # one frame, one completion
    # an execution condition kept ON after the completion starts the next transaction at
    # the execution after the one that reported (docs/instructions.md, ADPRW)
    p.bRun = True
    project.run_programs(["P"], scans=1)
    assert len(ep.sent) == 2 and ep.sent[1][0] == ep.sent[0][0]


ADPRW_FX3_ERRORS = """
PROGRAM P
VAR uData : ARRAY[0..1] OF WORD; bRun : BOOL; nDone : INT; END_VAR
ADPRW(bRun, 1, 1, 0, 22, uData[0]);
IF bRun AND M8029 THEN nDone := nDone + 1; bRun := FALSE; END_IF;
END_PROGRAM
"""


@pytest.mark.parametrize("reply, code, details", [
    (None, 211, 0),                                              # communication time-out
    (bytes.fromhex("0181040000"), 205, 0),                       # CRC/LRC error
    (with_crc(bytes([1, 0x81, 4])), 212, 0x8104),                # exception: H abnormal fc, L code
    (with_crc(bytes([2, 1, 3, 0, 0, 0])), 213, 0x0102),          # slave mismatch: H requested, L received
    (with_crc(bytes([1, 6, 1, 0xA0, 0, 0])), 214, 0x0106),       # function mismatch
    (with_crc(bytes([1, 1, 2, 0, 0])) + b"\0", 207, 2),          # byte count 2 for 22 coils
])
def test_adprw_fx3_error_codes_are_those_of_the_modbus_manual(reply, code, details):
    """FX3U MODBUS Serial Communication Edition §12.6: D8402 holds the MODBUS error code
    (211 time-out, 212 exception, 205 CRC, 207 length, 213/214 mismatch), D8403 its details,
    M8063 ON and D8063 = 6321. The simulator used to write codes of its own (1, 2, 3, 104H),
    so a program checked here reacted to codes a real FX3U never writes. The same list's
    "Related Devices" column turns M8402 and M8403 ON with them (ch1); the simulator left
    them OFF, so a program watching M8402 for a MODBUS error never saw one here."""
    project, ep, p = adprw_started(ADPRW_FX3_ERRORS)
    assert project.devices["M8402"] is False and project.devices["M8403"] is False
    if reply is not None:
        ep.reply_at(ep.sent[0][1] + 12_000, reply)
    project.run_programs(["P"], ms=3500)                   # D8409 = 0: 3 s
    assert p.nDone == 1 and len(ep.sent) == 1
    assert project.devices["D8402"] == code
    assert project.devices["D8403"] == details
    assert project.devices["M8063"] is True and project.devices["D8063"] == 6321
    assert project.devices["M8402"] is True and project.devices["M8403"] is True


def test_adprw_fx3_a_good_transaction_keeps_the_last_error_code():
    """FX-MB 6.1: D8402/D8403 are cleared at power-on and STOP->RUN only. The simulator
    wrote 0 into D8402 after every good transaction, so a program showing the last error
    lost it here and not on the PLC."""
    project, ep, p = adprw_started(ADPRW_FX3_ERRORS)
    project.run_programs(["P"], ms=3500)                   # no reply: 211
    assert project.devices["D8402"] == 211
    p.bRun = True
    project.run_programs(["P"], scans=1)
    ep.reply_at(ep.sent[-1][1] + 12_000, with_crc(bytes([1, 1, 3, 0, 0, 0])))
    project.run_programs(["P"], scans=5)
    assert p.nDone == 2 and project.devices["D8402"] == 211


def test_adprw_fx5_fc01_unpacks_coils_and_reports_time_out():
    src = """
PROGRAM P
VAR uData : ARRAY[0..1] OF WORD; bDone : ARRAY[0..1] OF BOOL; bRun : BOOL; nErr : INT; END_VAR
ADPRW(bRun, 1, 1, 0, 22, uData[0], bDone[0]);
IF bDone[1] THEN nErr := nErr + 1; END_IF;
IF bDone[0] THEN bRun := FALSE; END_IF;
END_PROGRAM
"""
    project, ep, p = adprw_started(src, target="gxworks3")
    reply = with_crc(bytes([1, 1, 3, 0x34, 0x12, 0x2A]))
    ep.reply_at(10_000, reply)
    project.run_programs(["P"], scans=3)
    assert list(p.uData) == [0x1234, 0x2A & 0x3F]
    assert p.nErr == 0
    p.bRun = True                         # second request: nobody answers
    project.run_programs(["P"], ms=350)   # the slave response time-out import-gxworks3.md sets: 400 ms
    assert p.nErr == 0
    project.run_programs(["P"], ms=100)
    assert p.nErr == 1
    assert project.devices["SD8500"] == 1
    assert crc16(ep.sent[-1][0][:-2]) == int.from_bytes(ep.sent[-1][0][-2:], "little")


def test_more_data_instructions():
    src = """
PROGRAM P
VAR
    w : WORD := 16#1234; v : WORD := 16#00FF; i : INT := 32767; d : DINT;
    b : BOOL; bEdge : BOOL; nRise, nFall : INT;
END_VAR
DMOV(TRUE, 100000, D0);
DMOV(TRUE, -2, d);
CML(TRUE, v, D2);
XCH(TRUE, w, v);
SWAP(TRUE, D3);
INC(TRUE, i);
DEC(TRUE, D4);
WAND(TRUE, 16#0FF0, 16#00FF, D5);
WOR(TRUE, 16#0F00, 16#00F0, D6);
WXOR(TRUE, 16#FFFF, 16#00FF, D7);
BCD(TRUE, 1234, D8);
BIN(TRUE, 16#0987, D9);
ZRST(TRUE, M10, M12);
OUT(b, M20);
PLS(bEdge, M21);
PLF(bEdge, M22);
IF M21 THEN nRise := nRise + 1; END_IF;
IF M22 THEN nFall := nFall + 1; END_IF;
END_PROGRAM
"""
    project = load_st(src, target="gxworks3")  # initial values: GX Works3 dialect (FX5U)
    dev = project.devices
    dev["D3"] = 0x1234
    for m in ("M10", "M11", "M12", "M13"):
        dev[m] = True
    project.run_programs(["P"], scans=1)
    p = project.program("P")
    assert (dev["D0"] & 0xFFFF) | ((dev["D1"] & 0xFFFF) << 16) == 100000
    assert p.d == -2
    assert dev["D2"] & 0xFFFF == 0xFF00
    assert (p.w, p.v) == (0x00FF, 0x1234)
    assert dev["D3"] == 0x3412
    assert p.i == -32768 and dev["D4"] == -1
    assert (dev["D5"], dev["D6"], dev["D7"]) == (0x00F0, 0x0FF0, 0xFF00 - 0x10000)
    assert (dev["D8"], dev["D9"]) == (0x1234, 987)
    assert [dev[m] for m in ("M10", "M11", "M12", "M13")] == [False, False, False, True]
    assert dev["M20"] is False
    p.b = True
    p.bEdge = True
    project.run_programs(["P"], scans=3)
    assert dev["M20"] is True and p.nRise == 1 and p.nFall == 0
    p.bEdge = False
    project.run_programs(["P"], scans=3)
    assert p.nRise == 1 and p.nFall == 1


def test_send_request_set_by_instruction_is_the_origin():
    src = """
PROGRAM P
VAR uSend : ARRAY[0..3] OF WORD; uRecv : ARRAY[0..3] OF WORD; END_VAR
IF M8002 THEN D8400 := 16#1C81; END_IF;
SET(NOT M8002 AND NOT M8402, M8402);
RS2(NOT M8002, uSend[0], 2, 2, 1, uRecv[0]);
END_PROGRAM
"""
    project = load_st(src)
    ep = FakeEndpoint()
    project.attach_serial("fx3:1", ep)
    project.run_programs(["P"], scans=2)
    assert ep.sent[0][2] == "t.st:5:1"


def test_rs2_manual_example_d100_k4_d200_k20_k1():
    """FX-COM F-66: RS2 D100 K4 D200 K20 K1 sends 31H 32H 33H 34H from D100 low, D100
    high, D101 low, D101 high (the figure's data area, without header/terminator)."""
    src = """
PROGRAM P
IF M8002 THEN D8400 := 16#1C81; D100 := 16#3231; D101 := 16#3433; M8402 := TRUE; END_IF;
RS2(NOT M8002, D100, 4, 20, 1, D200);
END_PROGRAM
"""
    project = load_st(src)
    ep = FakeEndpoint()
    project.attach_serial("fx3:1", ep)
    ep.reply_at(15_000, b"5678")  # the figure's receive side: 35H 36H 37H 38H
    project.run_programs(["P"], scans=2)
    assert ep.sent[0][0] == b"1234"
    project.devices["D8409"] = 2  # 20 ms time-out: fewer than n = 20 bytes arrive
    project.run_programs(["P"], scans=4)
    assert project.devices["M8403"] is True and project.devices["D8403"] == 4
    assert (project.devices["D200"], project.devices["D201"]) == (0x3635, 0x3837)


def test_rs2_channel_2_uses_the_ch2_devices():
    src = """
PROGRAM P
VAR uSend : ARRAY[0..1] OF WORD; uRecv : ARRAY[0..1] OF WORD; END_VAR
IF M8002 THEN D8420 := 16#1C81; D8429 := 1; M8422 := TRUE; uSend[0] := 16#0201; END_IF;
RS2(NOT M8002, uSend[0], 2, 4, 2, uRecv[0]);
END_PROGRAM
"""
    project = load_st(src, cpu="fx3g")
    ep = FakeEndpoint()
    project.attach_serial("fx3:2", ep)
    ep.reply_at(12_000, b"\x07")
    project.run_programs(["P"], scans=5)  # one byte, then 10 ms of silence: time-out
    assert ep.sent[0][0] == b"\x01\x02"
    dev = project.devices
    assert (dev["M8422"], dev["M8423"], dev["M8429"], dev["D8423"]) == (False, True, True, 1)
    assert project.program("P").uRecv[0] == 0x0007
