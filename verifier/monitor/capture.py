"""Captures: byte chunks with the host time they arrived, and the files that keep them.

The plain capture format (docs/commissioning.md) is one chunk or one frame per line:

    # anything after '#' is a comment
    0.000000 01 06 01 A0 00 00 88 14
    0.008250 rx 01 06 01 A0 00 00 88 14
    0.300 01 01 00 00 00 16 3D C4

a time in seconds (from any origin; only differences count), optionally `tx` (PLC to
robot) or `rx` (robot to PLC), then the bytes in hex (spaces optional between bytes). A
line without a direction is a chunk of the line's stream: the monitor splits chunks into
frames by silence and content as it does live. A last line `<time> end` says the line was
listened to, silent, until then (`uitamr monitor --capture` writes it): a replay judges
the capture as the live session did, up to its end - a reply still due, the bytes of a
frame left short by the silence - rather than as if listening stopped at the last byte.
A line `<time> silence` says the live session saw the line silent until then and ended a
frame there (bytes a pty or a converter hands over faster than the line would otherwise
be dated back into that silence and joined to the frame before).
A capture that cannot be read is an error naming file, line and column; nothing in it is
skipped silently.
"""
from __future__ import annotations

import json
import math
import re
from dataclasses import dataclass, fields, replace
from pathlib import Path
from typing import Any

from verifier import protocol
from verifier.amr.schema import LARGEST  # the largest number of seconds any setting holds
from verifier.digits import describe, foreign_digit
from verifier.place import Place
from verifier.textfile import UnreadableText, lone_cr_as_line_feed, read_utf8, shown_name, text_lines
from verifier.verify.conditions import ConditionError, parse_condition
from verifier.verify.report_trace import RUN_SETTINGS
from verifier.verify.result import RULE_EVENTS, LineEvent


@dataclass(frozen=True)
class Chunk:
    """Bytes as the host received them; `t_us` is when the read returned (the last byte's
    arrival, give or take the adapter's latency). `direction` is known only for captures
    that say it (our own traces, `tx`/`rx` lines). No bytes: nothing came until `t_us`
    (a live read that returned empty; a plain capture's `end` line)."""

    t_us: int
    data: bytes
    direction: str | None = None
    t_start_us: int | None = None  # a frame whose start is known exactly (our traces)
    tolerance_us: int | None = None  # a trace of host times (monitor --trace): their tolerance
    # a trace's end record: the rules' settings the run was judged with, as (RuleOptions
    # field, value): times in µs, and the response signal of a run that saw the program's
    # outputs (`uitamr verify`), with when it held ((began, stopped) µs; None: not seen)
    rules: tuple[tuple[str, Any], ...] = ()
    signal_held: tuple[tuple[int, int | None], ...] | None = None
    events: tuple[LineEvent, ...] = ()  # the run's event records (RULE_EVENTS), on its end record's chunk
    settings: protocol.Settings | None = None  # the end record's protocol settings
    cut_short: str | None = None  # the end record's: the monitor's port went away (ScenarioResult.cut_short)


def tolerance_hides_pacing(tolerance_us: int) -> bool:
    """A host-timing tolerance with which no UITAMR-PACING violation could be found (a
    period plus the tolerance must be under the pacing period): refused from --tolerance
    and from a trace's recorded tolerance alike."""
    return tolerance_us >= protocol.MIN_PERIOD_US


class CaptureError(Exception):
    """A capture file that cannot be read; the message is `file:line:col: what`, and `place`
    holds the place (None: a file that cannot be read at all, whose message names it alone)."""

    def __init__(self, place: Place | None, text: str, *, message: str | None = None):
        """`message`, when given, instead of `place: text` (a message that shows its place otherwise)."""
        super().__init__(message if message is not None else text if place is None else f"{place}: {text}")
        self.place = place

    def __reduce__(self):  # its place with it: the constructor takes it apart from the message
        return _capture_error, (self.place, str(self))


def _capture_error(place: Place | None, message: str) -> CaptureError:
    return CaptureError(place, "", message=message)


_TIME = re.compile(r"\s*([0-9]+(?:\.[0-9]*)?|\.[0-9]+)(?=\s|$)")
_HEX_PAIR = re.compile(r"[0-9A-Fa-f]{2}")


def parse_plain(text: str, name: str = "<capture>") -> list[Chunk]:
    """A plain capture's chunks (lines end at a line feed or a CRLF; `read_capture` reads a
    file with lone CRs too)."""
    chunks: list[Chunk] = []
    last_t: int | None = None
    end_line: int | None = None  # the line number of the `end` line
    for number, raw in enumerate(text_lines(text), start=1):
        line = raw.split("#", 1)[0].rstrip()
        if not line.strip():
            continue
        if end_line is not None:
            col = len(line) - len(line.lstrip()) + 1
            raise CaptureError(Place(name, number, col), f"the capture ended at its `end` line ({shown_name(name)}:{end_line}); "
                               "move this line before it, or remove the `end` line")
        foreign = foreign_digit(line)  # float() reads '٠.٥' as 0.5
        if foreign is not None:
            raise CaptureError(Place(name, number, foreign + 1), f"{describe(line[foreign])}")
        time_match = _TIME.match(line)
        if time_match is None:
            col = len(line) - len(line.lstrip()) + 1
            raise CaptureError(Place(name, number, col), "expected a time in seconds (e.g. 0.250) "
                               "at the start of the line")
        seconds = float(time_match.group(1))
        if seconds > LARGEST:  # the same bound as a trace record's time; 1e400 would not even be a number
            raise CaptureError(Place(name, number, time_match.start(1) + 1), f"time {time_match.group(1)} s is "
                               f"beyond {LARGEST:g} s; expected a time in seconds from 0 to {LARGEST:g}")
        t_us = round(seconds * 1_000_000)
        if last_t is not None and t_us < last_t:
            raise CaptureError(Place(name, number, time_match.start(1) + 1), f"time {time_match.group(1)} s is "
                               f"earlier than the line before ({last_t / 1_000_000:.6f} s); a capture "
                               "is in time order")
        pos = time_match.end()
        # `end`: listened to until then, and nothing follows; `silence`: the live session saw
        # the line silent until then and ended a frame there. Neither holds bytes
        keyword = re.match(r"\s+(end|silence)\b", line[pos:], re.IGNORECASE)
        if keyword is not None:
            rest = line[pos + keyword.end():]
            if rest.strip():
                col = pos + keyword.end() + len(rest) - len(rest.lstrip()) + 1
                what = ("an `end` line holds no bytes (it says until when the line was listened to); put the bytes "
                        "on a line of their own before it") if keyword.group(1).lower() == "end" else \
                    ("a `silence` line holds no bytes (it says the line was silent until then); put the bytes on a "
                     "line of their own after it")
                raise CaptureError(Place(name, number, col), what)
            chunks.append(Chunk(t_us, b""))
            last_t = t_us
            if keyword.group(1).lower() == "end":
                end_line = number
            continue
        direction = None
        word = re.match(r"\s+(tx|rx|TX|RX)\b", line[pos:])
        if word is not None:
            direction = word.group(1).lower()
            pos += word.end()
        data = bytearray()
        rest = line[pos:]
        i = 0
        while i < len(rest):
            if rest[i].isspace():
                i += 1
                continue
            pair = _HEX_PAIR.match(rest, i)
            if pair is None:
                raise CaptureError(Place(name, number, pos + i + 1), f"{rest[i:i + 2]!r} is not a byte in "
                                   "hex (two digits 0-9, A-F)")
            data.append(int(pair.group(), 16))
            i = pair.end()
        if not data:
            raise CaptureError(Place(name, number, len(line) + 1), "the line has a time but no bytes")
        chunks.append(Chunk(t_us, bytes(data), direction))
        last_t = t_us
    return chunks


def parse_trace(text: str, name: str = "<trace>") -> dict[str, list[Chunk]]:
    """Our JSONL trace (`uitamr verify --trace`, `uitamr monitor --trace`): frames with
    their direction, grouped by scenario, in file order (a record ends at a line feed or a
    CRLF; `read_capture` reads a file with lone CRs too). A run's end record (docs/verifier.md;
    a trace written before them has none) is a chunk with no bytes at its time, as a plain
    capture's `end` line is: the replay polls until then, as the run listened; the rules'
    settings and the program's outputs it carries, and the run's event records before it,
    ride on that chunk (`Chunk.rules`, `signal_held`, `events`). Nothing of a run follows its
    end record or lies after its `end` (an event record, a stretch the signal held)."""
    scenarios: dict[str, list[Chunk]] = {}
    ended: dict[str, int] = {}  # scenario -> the line of its end record
    # scenario -> its event records and their lines, until its end record
    events: dict[str, list[tuple[LineEvent, int]]] = {}
    first_event: dict[str, int] = {}  # scenario -> the line of its first event record
    for number, raw in enumerate(text_lines(text), start=1):
        if not raw.strip():
            continue
        try:
            record = json.loads(raw)
        except json.JSONDecodeError as exc:
            raise CaptureError(Place(name, number, exc.colno), f"not a JSON trace record: {exc.msg}") from None
        except ValueError:  # int() of more than 4300 digits
            raise CaptureError(Place(name, number, 1), "not a trace record: it holds a number too long to read "
                               "(more than 4300 digits)") from None
        except RecursionError:
            raise CaptureError(Place(name, number, 1), "not a trace record: arrays or objects nested thousands "
                               "deep") from None
        if not isinstance(record, dict):
            raise CaptureError(Place(name, number, 1), "a trace record is a JSON object")
        where = Place(name, number, 1)
        scenario = str(record.get("scenario", name))
        if scenario in ended:
            raise CaptureError(where, f"the run {scenario!r} ended at its end record ({name}:{ended[scenario]}); "
                               "move this record before it, or remove the end record")
        if "end" in record:
            chunks = scenarios.setdefault(scenario, [])
            end = _end_chunk(record, chunks, where)
            recorded = events.pop(scenario, [])
            within = [(event.t_us, Place(name, line, 1), f"the event record at {event.t_us / 1e6:g} s")
                      for event, line in recorded]
            for k, (began, stopped) in enumerate(end.signal_held or ()):
                # a stretch still holding at the end (stopped null) began after it
                last, held = (began, f"holding from {began / 1e6:g} s on") if stopped is None else \
                    (stopped, f"held until {stopped / 1e6:g} s")
                within.append((last, where, f"'response_signal_held' item {k + 1}, {held},"))
            _nothing_after_the_end(end.t_us, within, number, scenario)
            chunks.append(replace(end, events=tuple(event for event, _ in recorded)))
            ended[scenario] = number
            continue
        if "event" in record:
            events.setdefault(scenario, []).append((_event(record, where), number))
            first_event.setdefault(scenario, number)
            continue
        for key in ("t", "dir", "hex"):
            if key not in record:
                raise CaptureError(Place(name, number, 1), f"the record has no {key!r}")
        if record["dir"] not in ("tx", "rx"):
            raise CaptureError(where, f"'dir' is {record['dir']!r}; expected \"tx\" or \"rx\"")
        hex_text = record["hex"]
        if not isinstance(hex_text, str) or not hex_text.strip() or not _HEX_BYTES.fullmatch(hex_text):
            raise CaptureError(where, f"'hex' is {hex_text!r}; expected bytes in hex, two digits each, "
                               "e.g. \"01 06 01 A0 00 00 88 14\"")
        data = bytes.fromhex(hex_text)
        t_start = _seconds(record["t"], "t", where)
        t_end = _seconds(record["t_end"], "t_end", where) if record.get("t_end") is not None else t_start
        if t_end < t_start:
            raise CaptureError(where, f"'t_end' ({t_end:g} s) is before 't' ({t_start:g} s)")
        chunks = scenarios.setdefault(scenario, [])
        if chunks and round(t_start * 1_000_000) < chunks[-1].t_start_us:
            raise CaptureError(where, f"'t' ({t_start:g} s) is earlier than the record before of scenario "
                               f"{scenario!r} ({chunks[-1].t_start_us / 1_000_000:g} s); a trace is in time "
                               "order, and two runs in one trace need names of their own")
        tolerance = _seconds(record["tolerance"], "tolerance", where) if record.get("tolerance") is not None else None
        if tolerance is not None and tolerance_hides_pacing(round(tolerance * 1_000_000)):
            # what `--tolerance` refuses: a digit lost in a hand edit (20 for 0.020) would pass
            # a PLC pacing at 100 ms
            raise CaptureError(where, f"'tolerance' is {json.dumps(record['tolerance'])} s; a monitor records its "
                               f"--tolerance, which is below the pacing period of "
                               f"{protocol.MIN_PERIOD_US / 1_000_000:g} s")
        chunks.append(Chunk(round(t_end * 1_000_000), data, record["dir"], round(t_start * 1_000_000),
                            None if tolerance is None else round(tolerance * 1_000_000)))
    for scenario in events:  # what the end record would have carried to the replay
        raise CaptureError(Place(name, first_event[scenario], 1), f"the run {scenario!r} has event records but no end "
                           "record after them; a trace ends each run with its end record")
    return scenarios


def _nothing_after_the_end(end_us: int, records: list[tuple[int, Place, str]], end_line: int, scenario: str) -> None:
    """Refuse the first of `records` ((µs, place, what)) that lies after the run's end
    (`end_us`, its end record on line `end_line`): a run's events and the stretches its signal
    held are within it, so one after its end is a damaged or hand-edited trace, not the run."""
    for t_us, where, what in records:
        if t_us > end_us:
            raise CaptureError(where, f"{what} is after the end of the run {scenario!r} ({end_us / 1_000_000:g} s, "
                               f"its end record on line {end_line}); what a run records lies within it: correct "
                               "the time or the end record's 'end', or remove what comes after it")


def _event(record: dict, where: Place) -> LineEvent:
    """An event record (`{"scenario": ..., "t": seconds, "event": kind, "message": text}`): a
    line event the rules read that the frames do not show (RULE_EVENTS)."""
    other = sorted(set(record) - {"scenario", "t", "event", "message"})
    if other:
        raise CaptureError(where, "an event record holds only 'scenario', 't', 'event' and 'message'; it has "
                           f"{', '.join(map(repr, other))}")
    if record["event"] not in RULE_EVENTS:
        raise CaptureError(where, f"'event' is {json.dumps(record['event'])}; expected one of "
                           f"{', '.join(json.dumps(kind) for kind in RULE_EVENTS)}")
    message = record.get("message", "")
    if not isinstance(message, str):
        raise CaptureError(where, f"'message' is {json.dumps(message)}; expected a string")
    if "t" not in record:
        raise CaptureError(where, "the event record has no 't'")
    return LineEvent(round(_seconds(record["t"], "t", where) * 1_000_000), record["event"], message)


def _end_chunk(record: dict, chunks: list[Chunk], where: Place) -> Chunk:
    """A trace's end record (`{"scenario": ..., "end": seconds, "reply_timeout": seconds, ...}`,
    which every trace ends each run with): until when the line was listened to, as a chunk
    with no bytes, as a plain capture's `end` line is read; the rules' settings the run
    was judged with (`report_trace.RUN_SETTINGS`; a trace written before them has none); and
    a monitor's `cut_short`, when its port went away."""
    known = {"scenario", "end", *RUN_SETTINGS, "protocol", "cut_short", *_OUTPUTS}
    other = sorted(set(record) - known)
    if other:
        raise CaptureError(where, "an end record holds only 'scenario', 'end' (until when the line was listened "
                           f"to), the run's settings ({', '.join((*RUN_SETTINGS, 'protocol', *_OUTPUTS))}) and "
                           f"'cut_short' (the monitor's port went away); it has {', '.join(map(repr, other))}")
    end_us = round(_seconds(record["end"], "end", where) * 1_000_000)
    # a run may end while its last frame is still on the line (verify --duration cut it)
    if chunks and end_us < chunks[-1].t_start_us:
        raise CaptureError(where, f"'end' ({end_us / 1_000_000:g} s) is before the start of the record before "
                           f"({chunks[-1].t_start_us / 1_000_000:g} s); a trace is in time order")
    rules = tuple((field, _positive_us(record[key], key, where)) for key, field in RUN_SETTINGS.items() if key in record)
    settings = _protocol(record["protocol"], where) if "protocol" in record else None
    cut_short = record.get("cut_short")
    if cut_short is not None and not isinstance(cut_short, str):
        raise CaptureError(where, f"'cut_short' is {json.dumps(cut_short)}; expected the sentence the monitor said "
                           "when its port went away")
    if "response_signal" not in record:  # a line's run: the program's outputs were not seen
        stray = sorted(set(_OUTPUTS) & set(record))
        if stray:
            raise CaptureError(where, f"{stray[0]!r} without 'response_signal'; an end record that says the "
                               "program's outputs gives the signal (null: the run had none)")
        return Chunk(end_us, b"", rules=rules, settings=settings, cut_short=cut_short)
    return Chunk(end_us, b"", rules=rules + _signal(record, where), signal_held=_held(record, where),
                 settings=settings, cut_short=cut_short)


def _protocol(table, where: Place) -> protocol.Settings:
    """An end record's protocol settings (`{"address": 1, "field_order": "code-high", ...}`)."""
    names = tuple(field.name for field in fields(protocol.Settings))
    if not isinstance(table, dict):
        raise CaptureError(where, f"'protocol' is {json.dumps(table)}; expected an object of the protocol "
                           f"settings ({', '.join(names)})")
    other = sorted(set(table) - set(names))
    if other:
        raise CaptureError(where, f"'protocol' holds only {', '.join(names)}; it has {', '.join(map(repr, other))}")
    if isinstance(table.get("address"), bool):
        raise CaptureError(where, f"'protocol' address is {json.dumps(table['address'])}; expected 1-247")
    try:
        return protocol.Settings(**table)
    except ValueError as exc:
        raise CaptureError(where, f"'protocol': {exc}") from None


#: an end record's keys that say the program's outputs (a simulated run's)
_OUTPUTS = ("response_signal", "response_signal_hint", "response_signal_held")


def _signal(record: dict, where: Place) -> tuple[tuple[str, Any], ...]:
    """The response signal an end record names (None: the run had none) and the hint that
    says what the program has instead, as RuleOptions fields."""
    text, hint = record["response_signal"], record.get("response_signal_hint", "")
    if not isinstance(hint, str):
        raise CaptureError(where, f"'response_signal_hint' is {json.dumps(hint)}; expected a string")
    if text is None:
        return ("response_signal", None), ("response_signal_hint", hint)
    try:
        signal = parse_condition(text)
    except ConditionError as exc:
        raise CaptureError(where, f"'response_signal' is {json.dumps(text)}: {exc.message}") from None
    return ("response_signal", signal), ("response_signal_hint", hint)


def _held(record: dict, where: Place) -> tuple[tuple[int, int | None], ...]:
    """When the response signal held: [began, stopped] pairs in seconds, in time order,
    stopped null for the last when it still held at the end of the run."""
    held = record.get("response_signal_held", [])
    if record["response_signal"] is None and held:
        raise CaptureError(where, "'response_signal_held' without a 'response_signal'")
    expected = ("expected [[began, stopped], ...] in seconds, in time order, stopped null for a stretch still "
                "holding at the end")
    if not isinstance(held, list):
        raise CaptureError(where, f"'response_signal_held' is {json.dumps(held)}; {expected}")
    stretches: list[tuple[int, int | None]] = []
    last = 0
    for k, pair in enumerate(held):
        if not isinstance(pair, list) or len(pair) != 2 or (pair[1] is None and k != len(held) - 1):
            raise CaptureError(where, f"'response_signal_held' item {k + 1} is {json.dumps(pair)}; {expected}")
        began = round(_seconds(pair[0], "response_signal_held", where) * 1_000_000)
        stopped = None if pair[1] is None else round(_seconds(pair[1], "response_signal_held", where) * 1_000_000)
        if began < last or (stopped is not None and stopped <= began):
            raise CaptureError(where, f"'response_signal_held' item {k + 1} is {json.dumps(pair)}; {expected}")
        stretches.append((began, stopped))
        last = began if stopped is None else stopped
    return tuple(stretches)


_HEX_BYTES = re.compile(r"\s*(?:[0-9A-Fa-f]{2}\s*)*")


def _seconds(value, key: str, where: Place) -> float:
    """A trace record's time in seconds: a finite number (not true/false), not negative."""
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value) \
            or not 0 <= value <= LARGEST:
        raise CaptureError(where, f"{key!r} is {json.dumps(value)}; expected a time in seconds "
                           f"from 0 to {LARGEST:g}")
    return float(value)


def _positive_us(value, key: str, where: Place) -> int:
    """A rule's time in an end record, in µs: longer than 0, as a scenario's [rules] and
    --reply-timeout take it (a time-out of 0 took every reply as late)."""
    us = round(_seconds(value, key, where) * 1_000_000)
    if us <= 0:
        raise CaptureError(where, f"{key!r} is {json.dumps(value)}; expected a time in seconds longer than 0")
    return us


def read_capture(path: Path) -> dict[str, list[Chunk]]:
    """A capture file, plain or our JSONL trace (told apart by the first character that is
    not blank or a comment), as chunks per capture name."""
    try:
        # a classic Mac OS file too (a JSON trace's strings hold no raw CR)
        text = lone_cr_as_line_feed(read_utf8(path))
    except UnreadableText as exc:
        # bytes that are not text: `file: line L, column C (byte N): ...`, placed at them
        where = None if exc.place is None else exc.place.in_file(str(path))
        raise CaptureError(where, "", message=f"{path}: {exc}") from None
    first = _first_line(text)
    try:
        return _parse(text, str(path), path.stem)
    except CaptureError as exc:
        other = _other_kind(path, text, first)
        if other is None:
            raise
        raise CaptureError(exc.place, "", message=f"{exc}; {other}") from None


def _first_line(text: str) -> str:
    """The first line that is not blank or a comment, without its indentation."""
    return next((line.lstrip() for line in text_lines(text) if line.strip() and not line.lstrip().startswith("#")), "")


def _parse(text: str, file: str, name: str) -> dict[str, list[Chunk]]:
    """A capture's text as chunks per capture name: our JSONL trace (its first line that is
    not blank or a comment starts with '{'), else a plain capture, named `name`."""
    if _first_line(text).startswith("{"):
        return parse_trace(text, file)
    return {name: parse_plain(text, file)}


def capture_kind(text: str, name: str) -> str | None:
    """What `text` is when it reads as a capture that holds bytes: "a capture of `uitamr
    monitor --capture` (...)" or "a trace (JSON Lines) ..."; None for anything else (only
    comments or an `end` line tell nothing). For the commands that read other files: a
    capture given to them is named as such, not as a mistake at its first line."""
    text = lone_cr_as_line_feed(text)
    try:
        captures = _parse(text, name, name)
    except (CaptureError, RecursionError):
        return None
    if not any(chunk.data for chunks in captures.values() for chunk in chunks):
        return None
    return ("a trace (JSON Lines) of `uitamr verify` or `uitamr monitor`" if _first_line(text).startswith("{")
            else "a capture of `uitamr monitor --capture` (times and bytes on the line)")


def capture_instead(text: str, path: Path | str | None) -> str:
    """What to say after "not valid TOML" of a capture given as a scenario or a fault file
    (`--scenario site.txt`, `--faults site.txt`): what it is and what reads it; else ""."""
    what = capture_kind(text, str(path or "<scenario>"))
    return "" if what is None else f"; this is {what}: `uitamr replay {path or 'FILE'}` judges its frames"


def _other_kind(path: Path, text: str, first: str) -> str | None:
    """What a file that is no capture is, when it is one of the toolkit's other files (a
    scenario, ST source, a report), and what to give instead; None for anything else."""
    suffix = path.suffix.lower()
    instead = "replay reads a --trace file (JSON Lines) or a plain capture (docs/commissioning.md)"
    if suffix == ".toml":
        return f"this is a scenario file: run it with uitamr verify --scenario {path}; {instead}"
    if suffix == ".st":
        return f"this is ST source: run it with uitamr verify {path}; {instead}"
    if first.startswith("<"):
        kind = "--junit" if "<testsuite" in text[:4096] else "--html" if "<html" in text[:4096].lower() else None
        if kind:
            return f"this is a {kind} report; {instead}"
        return None
    if first.startswith("{"):
        try:
            data = json.loads(text)
        except (ValueError, RecursionError):  # a trace's lines (or its records nested too deep)
            return None
        if isinstance(data, dict) and "verdict" in data and "scenarios" in data:
            return f"this is a --json report; {instead}"
    return None


def format_plain(chunks: list[Chunk], comment: str = "", end_us: int | None = None) -> str:
    """The plain format of `chunks` (what `uitamr monitor --capture FILE` writes), with an
    `end` line at `end_us` when given (until when the line was listened to)."""
    lines = [f"# {line}" for line in comment.splitlines()]
    for chunk in chunks:
        if not chunk.data:  # the live session saw the line silent until then, and cut a frame there
            if end_us is None or chunk.t_us < end_us:  # (the `end` line says it of its own time)
                lines.append(f"{chunk.t_us / 1_000_000:.6f} silence")
            continue
        direction = f" {chunk.direction}" if chunk.direction else ""
        lines.append(f"{chunk.t_us / 1_000_000:.6f}{direction} {protocol.hex_bytes(chunk.data)}")
    if end_us is not None:
        lines.append(f"{end_us / 1_000_000:.6f} end")
    return "\n".join(lines) + "\n"
