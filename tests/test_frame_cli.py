"""`uitamr frame`: bytes for named commands, decoding with precise errors, exit codes."""
from __future__ import annotations

import shutil

import pytest
from click.testing import CliRunner
from hypothesis import given, settings as hypothesis_settings

from verifier.cli import main
from verifier.commands.frame import parse_hex
from verifier.protocol import encode, hex_bytes, with_crc, words_for
from verifier.protocol.strategies import requests
import procs


def run(*args: str):
    return CliRunner().invoke(main, ["frame", *args])


@pytest.mark.parametrize("args, expected", [
    (["stop"], "01 06 01 A0 00 00 88 14"),
    (["read", "task"], "01 01 00 00 00 16 BD C4"),
    (["move", "x", "-2.5"], "01 06 07 19 00 00 59 79"),
    (["move", "rear", "+1"], "01 06 08 0A 00 00 AB A8"),
    (["rotate", "-0.5"], "01 06 0D 32 00 00 2A A9"),
    (["--field-order", "code-low", "stop"], "01 06 A0 01 00 00 FA 0A"),
    # the words in one quoted argument, as a scenario's `sent = "run-point 1"` writes them:
    # was "unknown command 'run-point 1'; one of: ... run-point N"
    (["run-point 1"], "01 06 01 01 00 00 D9 F6"),
    (["speed trackless", "2"], "01 06 02 02 00 00 29 B2"),
])
def test_prints_exact_bytes(args, expected):
    result = run(*args)
    assert result.exit_code == 0, result.output
    assert result.output.strip() == expected


def test_settings_options_change_the_bytes():
    assert run("--codes-10-13", "hex", "rotate", "+1").output.split()[2] == "12"
    assert run("--codes-10-13", "decimal", "rotate", "+1").output.split()[2] == "0C"
    assert run("--status-order", "return", "read", "task").output.split()[3] == "02"
    assert run("--address", "7", "stop").output.split()[0] == "07"


@given(requests)
@hypothesis_settings(max_examples=40)
def test_every_request_prints_what_encode_gives(request):
    args = ["--address", str(request.address), *words_for(request)]
    result = run(*args)
    assert result.exit_code == 0, result.output
    assert result.output.strip() == hex_bytes(encode(request))


@pytest.mark.parametrize("args, message", [
    (["move", "x", "30"], "300 units of 0.1; one byte holds at most 255"),
    (["speed", "trackless", "5"], "speed stage must be 0-3, got 5"),
    (["frobnicate"], "unknown command 'frobnicate'"),
    ([], "give a COMMAND"),
    (["--adress", "2", "stop"], "no such option: --adress"),
    (["--address", "0", "stop"], "not in the range 1<=x<=247"),
    (["--decode", "zz"], "not a hex digit"),
    (["--decode", "010"], "odd number of hex digits"),
    (["--decode", "01 06", "--words"], "do not go with --decode"),
])
def test_user_errors_exit_2_without_traceback(args, message):
    result = run(*args)
    assert result.exit_code == 2, result.output
    assert message in result.output
    assert "Traceback" not in result.output


def test_decode_good_request():
    result = run("--decode", "01 06 01 A0 00 00 88 14")
    assert result.exit_code == 0
    assert "FC06 request: stop (01/A0)" in result.output
    assert "CRC 88 14 ok" in result.output


def test_decode_accepts_hex_without_spaces_and_unquoted():
    assert "stop (01/A0)" in run("--decode", "010601A0000088 14").output
    assert "stop (01/A0)" in run("--decode", "0x01,0x06,0x01,0xA0,0x00,0x00,0x88,0x14").output
    assert "stop (01/A0)" in run("--decode", "01", "06", "01", "A0", "00", "00", "88", "14").output


def test_decode_bad_crc_exits_1_and_names_byte():
    result = run("--decode", "01 06 01 A0 00 00 88 15")
    assert result.exit_code == 1
    assert "invalid frame: byte 6: bad CRC: expected 88 14 (CRC 0x1488), got 88 15" in result.output
    assert "the robot would stay silent" in result.output


def test_decode_unknown_function_says_what_robot_answers():
    result = run("--decode", "01 03 00 00 00 01 84 0A")
    assert result.exit_code == 1
    assert "byte 1: unknown function code 0x03" in result.output
    assert "answer with exception 01: 01 83 01 80 F0" in result.output


@pytest.mark.parametrize("function", [0x00, 0x80, 0x86, 0xFF])
def test_decode_a_function_code_no_master_sends_as_a_request(function):
    """00 and 80-FF with a good CRC, read as a request: `frame --decode` crashed with
    ValueError (00, 80: an exception reply to function 0 cannot be built) or promised an
    exception reply to function 06 (86), which a master would take for the real one."""
    data = with_crc(bytes((1, function, 0, 0, 0, 1)))
    result = run("--decode", hex_bytes(data), "--as", "request")
    assert result.exception is None or isinstance(result.exception, SystemExit), repr(result.exception)
    assert result.exit_code == 1, result.output
    assert (f"byte 1: function code 0x{function:02X} is not one a master sends (00 is not a Modbus function "
            "code, 80-FF are exception replies)") in result.output
    assert f"the robot would stay silent (no exception reply can answer function code 0x{function:02X})" \
        in result.output


def test_decode_short_frame():
    result = run("--decode", "01 06 01 A0 00 01")
    assert result.exit_code == 1
    assert "byte 6: too short for an FC06 (write single register) request: 6 bytes, expected 8" in result.output


def test_decode_reply_against_the_named_request():
    result = run("read", "task", "--decode", "01 01 03 00 00 01 FD 8E")
    assert result.exit_code == 0 and "task status: running (1)" in result.output
    result = run("read", "battery", "--decode", "01", "01", "03", "00", "00", "01", "FD", "8E")
    assert result.exit_code == 0 and "battery: low (1)" in result.output
    result = run("read", "task", "--decode", "01 01 03 00 00 05 FC 4D")
    assert result.exit_code == 1 and "byte 5: value 5 out of range for task status" in result.output
    result = run("stop", "--decode", "01 06 01 80 00 00 89 DE")
    assert result.exit_code == 1 and "does not echo the request" in result.output


def test_decode_exception_reply():
    result = run("--decode", "01 86 03 02 61")
    assert result.exit_code == 0
    assert "exception reply: exception 03 (illegal data value) to function 06" in result.output


def test_explain_shows_every_field():
    result = run("stop", "--explain")
    assert result.exit_code == 0
    lines = result.output.splitlines()
    assert lines[0] == "01 06 01 A0 00 00 88 14"
    assert lines[1] == "stop (01/A0)"
    text = result.output
    for needle in ("address (模塊地址)", "control code (控制代號)", "control command (控制指令)",
                   "value (always 0)", "0x1488: ok"):
        assert needle in text
    bad = run("--decode", "01 01 00 00 00 08 3C 0C", "--explain")
    assert bad.exit_code == 1 and "quantity" in bad.output and "must be 22" in bad.output


def test_parse_hex():
    assert parse_hex("01 06 01a0") == bytes.fromhex("010601A0")
    assert parse_hex("1 6") == b"\x01\x06"
    with pytest.raises(ValueError):
        parse_hex("")


def test_installed_entry_point_in_a_real_subprocess():
    uitamr = shutil.which("uitamr")
    assert uitamr, "the uitamr entry point is not installed (pip install -e '.[test]')"
    done = procs.run([uitamr, "frame", "stop"], capture_output=True, text=True, timeout=60)
    assert done.returncode == 0 and done.stdout.strip() == "01 06 01 A0 00 00 88 14"
    bad = procs.run([uitamr, "frame", "move", "x", "30"], capture_output=True, text=True, timeout=60)
    assert bad.returncode == 2 and "one byte holds at most 255" in bad.stderr
    assert "Traceback" not in bad.stderr
    decoded = procs.run([uitamr, "frame", "--decode", "01 06 01 A0 00 00 88 15"],
                        capture_output=True, text=True, timeout=60)
    assert decoded.returncode == 1 and "bad CRC" in decoded.stdout


def test_words_pack_two_bytes_per_register_low_byte_first():
    result = run("stop", "--words")
    assert result.exit_code == 0
    assert result.output.splitlines()[1] == "words (low byte first): H0601 HA001 H0000 H1488"
    from verifier.protocol.codec import packed_words
    assert packed_words(b"\x01\x86\x03\x02\x61") == [0x8601, 0x0203, 0x0061]


def test_decode_direction_and_settings():
    result = run("--decode", "01 06 01 A0 00 00 88 14", "--as", "reply")
    assert result.exit_code == 0 and "FC06 reply: echo: stop (01/A0)" in result.output
    result = run("--decode", "01 01 00 00 00 16 BD C4", "--as", "reply")
    assert result.exit_code == 1 and "byte 2: byte count must be 03" in result.output
    hex_rotate = run("--codes-10-13", "hex", "rotate", "+1").output.strip()
    assert run("--codes-10-13", "hex", "--decode", hex_rotate).exit_code == 0
    wrong = run("--decode", hex_rotate)
    assert wrong.exit_code == 1 and "codes_10_13=decimal" in wrong.output
    assert "read task status (query 2)" in run("--status-order", "return", "--decode", "01 01 00 02 00 16 1C 04").output


def test_as_request_with_a_command_checks_the_bytes_are_that_commands_request():
    same = run("read", "task", "--as", "request", "--decode", "01 01 00 00 00 16 BD C4")
    assert same.exit_code == 0, same.output
    assert "FC01 request: read task status (query 0)" in same.output
    assert same.output.splitlines()[-1] == "= the request of `read task`"
    other = run("read", "vehicle", "--as", "request", "--decode", "01 01 00 00 00 16 BD C4")
    assert other.exit_code == 1
    assert other.output.splitlines()[-1] == (
        "not the request of `read vehicle` (read vehicle status (query 1)): byte 3 differs; "
        "`read vehicle` is 01 01 00 01 00 16 EC 04")
    # the direction is really forced: a valid reply is an invalid request
    reply = run("read", "task", "--as", "request", "--decode", "01 01 03 00 00 01 FD 8E")
    assert reply.exit_code == 1 and "invalid frame: byte 2: query parameter" in reply.output
    unquoted = run("stop", "--as", "request", "--decode", "01", "06", "01", "A0", "00", "00", "88", "14")
    assert unquoted.exit_code == 0 and unquoted.output.splitlines()[-1] == "= the request of `stop`"


def test_a_command_with_as_reply_or_auto_reads_the_bytes_as_its_reply():
    for direction in ("reply", "auto"):
        result = run("read", "task", "--as", direction, "--decode", "01 01 03 00 00 01 FD 8E")
        assert result.exit_code == 0, result.output
        assert "FC01 reply: task status: running (1), error 00 normal" in result.output


@given(requests)
@hypothesis_settings(max_examples=30)
def test_every_request_decoded_as_request_matches_its_own_command(request):
    args = ["--address", str(request.address), *words_for(request), "--as", "request",
            "--decode", hex_bytes(encode(request))]
    result = run(*args)
    assert result.exit_code == 0, result.output
    assert result.output.splitlines()[-1].startswith("= the request of `")


def test_raw_and_negative_numbers_need_no_double_dash():
    assert run("raw", "12", "100").output.strip() == run("rotate", "+1").output.strip()
    assert run("raw", "0x01", "0xA0").output.strip() == "01 06 01 A0 00 00 88 14"
    assert run("move", "y", "-0.3").output.strip() == "01 06 0B 03 00 00 7B EE"
    result = run("raw", "1", "32")
    assert result.exit_code == 2 and "unknown robot command 0x20" in result.output


def test_a_command_byte_in_hex_without_0x_is_told_how_to_write_it():
    """The decoder prints the stop as "stop (01/A0)", protocol.md's table its byte as A0:
    `uitamr frame raw 1 A0` was refused with "must be a whole number (decimal, or hex as
    0x..)", which did not say what to type. It names it now, for GX Works' ways of writing
    hex too; a hex number without letters (16) stays decimal, as --help and protocol.md say."""
    for written in ("A0", "a0", "HA0", "16#A0", "A0h"):
        result = run("raw", "1", written)
        assert result.exit_code == 2, result.output
        assert (f"command {written!r} is hex: write it 0xA0 (or 160 in decimal); a number without 0x is read as "
                "decimal") in " ".join(result.output.split()), result.output
    stop = run("stop").output.strip()
    assert run("raw", "1", "0xA0").output.strip() == run("raw", "1", "160").output.strip() == stop
    assert "stop is raw 1 0xA0" in " ".join(run("--help").output.split())
    assert run("raw", "1", "16").output.strip() == run("run-point", "16").output.strip()
    # no byte read as hex either (1e3 = 0x1E3 = 483): not offered as one to write
    result = run("raw", "1", "1e3")
    assert result.exit_code == 2 and "0x1E3" not in result.output, result.output
    assert "must be a whole number (decimal, or hex as 0x..), got '1e3'" in " ".join(result.output.split())


def test_help_lists_every_command_form():
    result = run("--help")
    assert result.exit_code == 0
    for form in ("run-point N", "seek-tape", "follow-tape", "rotate-on-tape", "coordinate-reset",
                 "manual-mode", "speed trackless|magnetic", "collision-range", "jog", "move x|front|rear|y",
                 "rotate ±VALUE", "read task|vehicle|speed|battery", "raw CODE CMD"):
        assert form in result.output


def test_mbpoll_command_line():
    result = run("stop", "--mbpoll", "/dev/ttyUSB0")
    assert result.exit_code == 0
    assert result.output.splitlines()[1] == (
        "mbpoll -m rtu -b 9600 -d 8 -s 1 -P none -a 1 -0 -1 -t 4 -r 416 /dev/ttyUSB0 0")
    result = run("read", "battery", "--address", "3", "--mbpoll", "/dev/ttyUSB0")
    assert result.output.splitlines()[1] == (
        "mbpoll -m rtu -b 9600 -d 8 -s 1 -P none -a 3 -0 -1 -t 0 -r 3 -c 22 /dev/ttyUSB0")


@pytest.mark.parametrize("device", ["", "  "])
def test_mbpoll_with_an_empty_device_is_an_error_not_a_silent_nothing(device):
    """`--mbpoll "$PORT"` with PORT unset printed the frame without the mbpoll line and exited 0."""
    result = run("stop", "--mbpoll", device)
    assert result.exit_code == 2
    assert "--mbpoll" in result.output and "the device is empty" in result.output


def test_decode_names_a_modbus_tcp_frame_and_the_route_setting():
    """A frame copied from a Wireshark capture of a PLC or converter set to Modbus TCP: the
    decode says it is MBAP and what it would be as RTU."""
    from click.testing import CliRunner
    from verifier.cli import main

    done = CliRunner().invoke(main, ["frame", "--decode", "00 07 00 00 00 06 01 01 00 00 00 16"])
    assert done.exit_code == 1
    assert ("this is a Modbus TCP frame (MBAP header 00 07 00 00 00 06, unit 1; as RTU: read task status (query 0)): "
            "the robot's route carries Modbus RTU frames") in done.output
    plain = CliRunner().invoke(main, ["frame", "--decode", "01 06 01 A0 00 00 88 15"])  # a bad CRC: no such hint
    assert plain.exit_code == 1 and "Modbus TCP" not in plain.output


def test_an_rtu_frame_with_a_bad_crc_is_never_called_modbus_tcp():
    """An 8-byte RTU frame whose bytes 3-6 read 00 00 00 02 (read 2 coils from 0, a write of
    2 to register 0) fits an MBAP header with nothing after the unit but a function code; no
    Modbus TCP frame is that short (its PDU has a function code and data: 9 bytes at the
    least, an exception reply). With a bad CRC it was called a Modbus TCP frame and the
    converter blamed; it is the RTU frame with a bad CRC it is."""
    from click.testing import CliRunner
    from verifier.cli import main
    from verifier.protocol.describe import modbus_tcp_hint

    for frame in ("01 01 00 00 00 02 00 00", "01 06 00 00 00 02 12 34"):
        done = CliRunner().invoke(main, ["frame", "--decode", frame])
        assert done.exit_code == 1 and "bad CRC" in done.output
        assert "Modbus TCP" not in done.output, done.output
    assert modbus_tcp_hint(bytes.fromhex("00 01 00 00 00 03 01 81 02"))  # the shortest: an exception reply


@pytest.mark.parametrize("hex_text, said", [
    # a broadcast or a reserved address was decoded with "(a normal reply echoes these 8
    # bytes)": no slave answers either (protocol.md §8)
    ("00 06 01 A0 00 00 89 C5", "(broadcast: every robot on the line acts on it, none replies)"),
    ("00 01 00 00 00 16 BC 15", "(broadcast: no robot replies, so a read to address 0 returns nothing; Modbus "
                                "broadcasts only writes)"),
    ("F8 06 01 A0 00 00 9C 7D", "(address 248 is reserved: Modbus slave addresses are 1-247, so no robot "
                                "replies; the robot's default is 1)"),
])
def test_a_request_no_robot_answers_is_not_said_to_be_echoed(hex_text, said):
    result = run("--decode", hex_text)
    assert result.exit_code == 0, result.output
    lines = result.output.splitlines()
    assert lines[2] == said and "echoes" not in result.output


def test_a_request_to_the_robot_still_says_the_echo():
    assert run("--decode", "F7 06 01 A0 00 00 9C 82").output.splitlines()[2] == "(a normal reply echoes these 8 bytes)"


@pytest.mark.parametrize("args, hint", [
    # the CRC word sent high byte first: only "bad CRC: expected 88 14 ..., got 14 88"
    (["--decode", "01 06 01 A0 00 00 14 88"],
     "the CRC bytes are swapped: Modbus RTU sends the CRC low byte first (88 14), not 14 88; a send buffer "
     "that holds the CRC word high byte first sends them this way"),
    (["read", "task", "--decode", "01 01 03 00 00 01 8E FD"],
     "the CRC bytes are swapped: Modbus RTU sends the CRC low byte first (FD 8E), not 8E FD; a send buffer "
     "that holds the CRC word high byte first sends them this way"),
    # a whole frame and a stray byte, as a terminal shows them: only "too long ... 9 bytes"
    (["--decode", "01 06 01 A0 00 00 88 14 00"],
     "bytes 0-7 are a whole frame, FC06 request: stop (01/A0), CRC ok; 00 after it (byte 8) is extra: "
     "a second frame run together with it, or a stray byte of the line"),
    (["--decode", "00 01 06 01 A0 00 00 88 14"],
     "bytes 1-8 are a whole frame, FC06 request: stop (01/A0), CRC ok; 00 before it (byte 0) is extra: "
     "a second frame run together with it, or a stray byte of the line"),
    (["read", "task", "--decode", "01 01 03 00 00 01 FD 8E 01 01"],
     "bytes 0-7 are a whole frame, FC01 reply: task status: running (1), error 00 normal, CRC ok; 01 01 after "
     "it (byte 8 on) is extra: a second frame run together with it, or a stray byte of the line"),
])
def test_a_pasted_frame_says_what_went_wrong_with_it(args, hint):
    result = run(*args)
    assert result.exit_code == 1, result.output
    assert result.output.splitlines()[2] == hint


@pytest.mark.parametrize("hex_text", ["01 06 01 A0 00 00 88 15", "01 06 01 A0 00 00 88 15 00",
                                      "01 06 01 A0 00 00 00 00", "01 06 01 A0 00 00 88"])
def test_no_paste_hint_where_none_fits(hex_text):
    out = run("--decode", hex_text).output
    assert "swapped" not in out and "whole frame" not in out


@pytest.mark.parametrize("args", [["01", "06", "01", "A0", "00", "00", "88", "14"], ["01 06 01 A0 00 00 88 14"],
                                  ["010601A000008814"]])
def test_bytes_given_without_decode_say_to_decode_them(args):
    # was "unknown command '01'; one of: stop, pause, ..." (the whole command list)
    result = run(*args)
    assert result.exit_code == 2
    assert result.output.splitlines()[-1] == (
        f"Error: {' '.join(args)!r} is bytes, not a command: to decode them, uitamr frame --decode "
        f"\"{' '.join(' '.join(args).split())}\"")


def test_the_usage_line_names_the_command_the_help_text_speaks_of():
    # 'Usage: uitamr frame [OPTIONS] [WORDS]...' over a text about COMMAND and its list "Commands:"
    usage = CliRunner().invoke(main, ["frame", "--help"], prog_name="uitamr").output.splitlines()[0]
    assert usage == "Usage: uitamr frame [OPTIONS] [COMMAND]..."


@pytest.mark.parametrize("words, frame", [
    # what `--words` prints and a GX Works monitor shows for the send buffer: was
    # "not a hex digit: 'H' in 'H0601'"
    ("H0601 HA001 H0000 H1488", "01 06 01 A0 00 00 88 14"),
    ("h601,ha001,h0,h1488", "01 06 01 A0 00 00 88 14"),
    ("H0101 H0000 H1600 HC4BD", "01 01 00 00 00 16 BD C4"),
])
def test_the_words_of_a_plc_buffer_decode(words, frame):
    for args in (["--decode", words], ["--decode", *words.split()]):  # quoted, or not
        result = run(*args)
        assert result.exit_code == 0, result.output
        assert result.output.splitlines()[0] == frame


def test_the_padding_of_an_odd_count_in_words_is_left_out():
    result = run("--decode", "H8601 H0203 H0061")
    assert result.exit_code == 0, result.output
    assert result.output.splitlines()[:3] == [
        "01 86 03 02 61", "(the last word's high byte 00 is the padding after an odd byte count: left out)",
        "exception reply: exception 03 (illegal data value) to function 06"]


def test_words_and_bytes_mixed_are_refused_with_why():
    result = run("--decode", "H0601 A0 01 00 00 88 14")
    assert result.exit_code == 2
    assert result.output.splitlines()[-1] == ("Error: Invalid value for --decode: H words (H0601: two bytes, low byte "
                                              "first) and bytes mixed: give all of them one way")


def test_register_values_without_h_are_said_to_be_words():
    # `0601 A001 0000 1488` read off a monitor: only "bad CRC: expected 4E 7D"
    result = run("--decode", "0601 A001 0000 1488")
    assert result.exit_code == 1
    assert result.output.splitlines()[2] == (
        "read as 16-bit words, low byte first (as RS2 and the QJ71C24N hold a frame), these are FC06 request: "
        "stop (01/A0): give them as H0601 HA001 H0000 H1488, or as the bytes 01 06 01 A0 00 00 88 14")
