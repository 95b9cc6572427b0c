"""`uitamr frame`: the exact bytes of a robot command, or what some bytes mean.

All protocol knowledge comes from verifier.protocol; this module only reads the command
line and prints.
"""
from __future__ import annotations

import re
import shlex

import click

from verifier.protocol import (
    CommandError,
    ControlRequest,
    FrameError,
    Settings,
    StatusRequest,
    command_from_words,
    decode_frame,
    decode_reply,
    describe,
    encode,
    exception_reply_for,
    explain,
    explain_table,
    hex_bytes,
)
from verifier.protocol.codec import hex_words
from verifier.protocol.stream import frame_length_either_side
from verifier.protocol.describe import frame_kind, looks_like_reply, modbus_tcp_hint, paste_hint, who_answers
from verifier.protocol.names import USAGE
from verifier.commands.protocol_options import protocol_settings
from verifier.digits import digit_problem

EXIT_BAD_FRAME = 1
_HEX_WORD = re.compile(r"(0[xX]|[hH](?=[0-9a-fA-F]{1,4},?$))?[0-9a-fA-F]+,?")
#: a 16-bit word in MELSEC's hex constant notation, as `--words` prints it and a GX Works
#: device monitor shows a send buffer register: H0601 = bytes 01 06 (low byte first)
_MELSEC_WORD = re.compile(r"[hH]([0-9a-fA-F]{1,4})")

_EPILOG = "\b\nCommands:\n" + "\n".join(f"  {line}" for line in USAGE) + """

\b
Examples:
  uitamr frame stop                      -> 01 06 01 A0 00 00 88 14
  uitamr frame move x -2.5               (front, negative: code 07)
  uitamr frame move rear +1              (rear, positive: code 08)
  uitamr frame read task --explain
  uitamr frame --decode "01 06 01 A0 00 00 88 14"
  uitamr frame read task --decode "01 01 03 00 00 01 FD 8E"   (a reply to that read)
"""


def parse_hex(text: str) -> bytes:
    """Bytes from hex text: "01 06 01 A0", "0106 01a0", "0x01,0x06" and the like, or 16-bit
    words in MELSEC notation, low byte first: "H0601 HA001 H0000 H1488" (a PLC send buffer)."""
    words = [t for t in re.split(r"[\s,;]+", text) if t]
    if words and all(_MELSEC_WORD.fullmatch(w) for w in words):
        return bytes(b for w in words for b in int(w[1:], 16).to_bytes(2, "little"))
    if any(_MELSEC_WORD.fullmatch(w) for w in words):
        raise ValueError("H words (H0601: two bytes, low byte first) and bytes mixed: give all of them one way")
    cleaned = re.sub(r"0[xX]", " ", text)
    tokens = [t for t in re.split(r"[\s,;:\-]+", cleaned) if t]
    if not tokens:
        raise ValueError("no hex bytes given")
    out = bytearray()
    for token in tokens:
        bad = re.search(r"[^0-9a-fA-F]", token)
        if bad and (problem := digit_problem(bad.group())):  # '１２': the full-width digits
            raise ValueError(f"not a hex digit in {token!r}: {problem}")
        if bad:
            raise ValueError(f"not a hex digit: {bad.group()!r} in {token!r}")
        if len(token) % 2 and len(token) > 1:
            raise ValueError(f"odd number of hex digits in {token!r}: write bytes as pairs like 0A")
        out += bytes.fromhex(token.zfill(2))
    return bytes(out)


def _padded_words(text: str, data: bytes) -> bool:
    """H words of a frame with an odd byte count (a 5-byte exception reply): the last word's
    high byte is the 00 a send or receive buffer pads with, not a byte of the frame."""
    words = [t for t in re.split(r"[\s,;]+", text) if t]
    return (bool(words) and all(_MELSEC_WORD.fullmatch(w) for w in words) and data[-1:] == b"\x00"
            and frame_length_either_side(data[:2]) == len(data) - 1)


def _device(ctx, param, value: str | None) -> str | None:
    """--mbpoll's DEVICE: a blank one (`--mbpoll "$PORT"` with PORT unset) printed no mbpoll
    line at all and exited 0."""
    if value is not None and not value.strip():
        raise click.BadParameter("the device is empty: give the serial port mbpoll sends on, e.g. /dev/ttyUSB0")
    return value


@click.command(
    "frame",
    epilog=_EPILOG,
    context_settings={"ignore_unknown_options": True, "help_option_names": ["-h", "--help"]},
)
@click.argument("words", nargs=-1, type=click.UNPROCESSED, metavar="[COMMAND]...")
@protocol_settings
@click.option("--decode", "decode_hex", metavar="HEX",
              help="Decode these bytes instead: hex bytes (01 06 01 A0 ...), or a PLC buffer's 16-bit "
                   "words low byte first as --words prints them (H0601 HA001 ...). With COMMAND: as the "
                   "reply to that command, or with --as request as that command's request.")
@click.option("--as", "direction", type=click.Choice(["auto", "request", "reply"]), default="auto",
              show_default=True,
              help="With --decode: read the bytes as a request or a reply. With a COMMAND too, "
                   "--as request checks that the bytes are that command's request.")
@click.option("--explain", "explain_fields", is_flag=True, help="Also show every field of the frame.")
@click.option("--mbpoll", "mbpoll_device", metavar="DEVICE", callback=_device,
              help="Also print the mbpoll command line that sends this request on DEVICE "
                   "(for commissioning from a laptop on the RS-485 bus).")
@click.option("--words", "as_words", is_flag=True,
              help="Also print the frame as 16-bit words, two bytes per word, low byte first "
                   "(FX RS2 16-bit mode, QJ71C24N send area).")
def command(words, settings, decode_hex, direction, explain_fields,
            mbpoll_device, as_words):
    """Print the exact bytes (CRC included) of COMMAND, or decode bytes with --decode.

    Prints space-separated upper-case hex, ready to type into a PLC send buffer.
    A bad COMMAND or value exits 2; --decode of a bad frame explains it and exits 1.
    """
    address = settings.address
    for word in words:
        if word.startswith("--"):
            raise click.UsageError(f"no such option: {word}")
    if decode_hex is not None:
        words, decode_hex = _split_unquoted_hex(words, decode_hex, address)
    request = _request_from(words, address) if words else None
    if decode_hex is None:
        if request is None:
            raise click.UsageError("give a COMMAND (e.g. `uitamr frame stop`) or --decode HEX")
        _print_request(request, settings, explain_fields, as_words)
        if mbpoll_device is not None:
            click.echo(shlex.join(mbpoll_command(request, settings, mbpoll_device)))
        return
    if mbpoll_device is not None or as_words:
        raise click.UsageError("--mbpoll and --words print a COMMAND's request; they do not go with --decode")
    try:
        data = parse_hex(decode_hex)
    except ValueError as exc:
        raise click.BadParameter(str(exc), param_hint="--decode") from None
    note = None
    if _padded_words(decode_hex, data):
        data, note = data[:-1], "(the last word's high byte 00 is the padding after an odd byte count: left out)"
    if request is not None and direction == "request":
        _decode_and_print(data, settings, "request", None, explain_fields, note)
        _compare_with_command(data, request, settings, words)
        return
    if request is not None:
        direction = "reply"
    _decode_and_print(data, settings, None if direction == "auto" else direction, request, explain_fields, note)


def _compare_with_command(data: bytes, request, settings: Settings, words: tuple[str, ...]) -> None:
    """After a valid request was decoded: is it the request COMMAND makes? Exit 1 if not."""
    expected = encode(request, settings)
    named = " ".join(words)
    if data == expected:
        click.echo(f"= the request of `{named}`")
        return
    differ = next(i for i in range(min(len(data), len(expected))) if data[i] != expected[i])
    click.echo(f"not the request of `{named}` ({describe(request, settings)}): byte {differ} differs; "
               f"`{named}` is {hex_bytes(expected)}")
    raise SystemExit(EXIT_BAD_FRAME)


def _split_unquoted_hex(words: tuple[str, ...], decode_hex: str, address: int) -> tuple[tuple[str, ...], str]:
    """Take back the bytes of an unquoted ``--decode 01 06 ...`` that click left in WORDS.

    The command is the shortest leading run of words that names one; every word after
    it must look like hex to join the bytes.
    """
    for cut in range(len(words) + 1):
        head, tail = words[:cut], words[cut:]
        if not all(_HEX_WORD.fullmatch(w) for w in tail):
            continue
        if cut == 0:
            return (), " ".join((decode_hex, *tail))
        try:
            command_from_words(list(head), address=address)
        except CommandError:
            continue
        return head, " ".join((decode_hex, *tail))
    return words, decode_hex


def _request_from(words: tuple[str, ...], address: int):
    try:
        return command_from_words(list(words), address=address)
    except CommandError as exc:
        # `uitamr frame 01 06 01 A0 00 00 88 14`, --decode forgotten: "unknown command '01'; one of ..."
        tokens = " ".join(words).split()
        if (len(tokens) > 1 or len("".join(tokens)) >= 8) and all(_HEX_WORD.fullmatch(t) for t in tokens):
            raise click.UsageError(f"{' '.join(words)!r} is bytes, not a command: to decode them, "
                                   f"uitamr frame --decode \"{' '.join(tokens)}\"") from None
        raise click.UsageError(str(exc)) from None


def mbpoll_command(request, settings: Settings, device: str) -> list[str]:
    """mbpoll (libmodbus) arguments that put exactly ``encode(request, settings)`` on the line.

    FC06: one holding register (-t 4) written with one value; the register address is the
    16-bit field holding code and command, the value 0. FC01: 22 coils (-t 0 -c 22) from the
    query parameter. -0 makes references 0-based (PDU addresses), -1 polls once.
    """
    data = encode(request, settings)
    reference = int.from_bytes(data[2:4], "big")
    common = ["mbpoll", "-m", "rtu", "-b", "9600", "-d", "8", "-s", "1", "-P", "none",
              "-a", str(request.address), "-0", "-1"]
    if isinstance(request, ControlRequest):
        return common + ["-t", "4", "-r", str(reference), device, "0"]
    return common + ["-t", "0", "-r", str(reference), "-c", str(request.quantity), device]


def _print_request(request, settings: Settings, show_fields: bool, as_words: bool = False) -> None:
    try:
        data = encode(request, settings)
    except ValueError as exc:  # command_from_words already checked; settings cannot break it
        raise click.UsageError(str(exc)) from None
    click.echo(hex_bytes(data))
    if as_words:
        click.echo("words (low byte first): " + hex_words(data))
    if show_fields:
        click.echo(describe(request, settings))
        click.echo(explain_table(explain(data, settings, "request")))


def _decode_and_print(data: bytes, settings: Settings, direction, request, show_fields: bool,
                      note: str | None = None) -> None:
    click.echo(hex_bytes(data))
    if note:
        click.echo(note)
    try:
        if request is not None:
            frame = decode_reply(data, settings, request)
        else:
            frame = decode_frame(data, settings, direction)
    except FrameError as exc:
        click.echo(f"invalid frame: {exc}")
        hint = modbus_tcp_hint(data, settings) or paste_hint(data, exc, settings, direction, request)
        if hint:
            click.echo(hint)
        guessed = direction or ("reply" if request is not None or looks_like_reply(data) else "request")
        if guessed == "request":
            click.echo("the robot would " + _robot_answer(exc, settings))
        if show_fields:
            click.echo(explain_table(explain(data, settings, guessed)))
        raise SystemExit(EXIT_BAD_FRAME)
    click.echo(f"{frame_kind(frame)}: {describe(frame, settings)}")
    if isinstance(frame, (ControlRequest, StatusRequest)):
        said = who_answers(frame)
        if said:
            click.echo(said)
    click.echo(f"CRC {hex_bytes(data[-2:])} ok")
    if show_fields:
        kind = "request" if isinstance(frame, (ControlRequest, StatusRequest)) else "reply"
        click.echo(explain_table(explain(data, settings, kind)))


def _robot_answer(error: FrameError, settings: Settings) -> str:
    """What the robot does with a request the decoder refused: its exception reply, or why
    it stays silent (the decoder's `silence`, else the address's)."""
    reply = exception_reply_for(error, settings)
    if reply is not None:
        return f"answer with exception {int(reply.exception_code):02X}: {hex_bytes(encode(reply, settings))}"
    if error.silence == "function":
        return f"stay silent (no exception reply can answer function code 0x{error.function:02X})"
    if error.exception is not None and error.address == 0:
        return "stay silent (broadcast requests get no reply)"
    if error.exception is not None:
        return f"stay silent (address {error.address} is not this robot's {settings.address})"
    return "stay silent (Modbus RTU: a frame with a bad length or CRC is discarded)"
