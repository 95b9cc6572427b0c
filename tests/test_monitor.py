"""`uitamr monitor` and `uitamr replay`: the verifier's rules on a real line and on a capture.

Real parts: socat pty pairs joined into one line (tests/linebus.py) carrying `uitamr
emulate --serial` driven by mbpoll, by a deliberately bad master and by the simulated
PLC's own requests; a TCP stream on 127.0.0.1; noise on the line. The pure core (capture
format, framer, request/reply classification) is tested on its own, by hypothesis too.
"""
from __future__ import annotations

import json
import random
import re
import select
import signal
import socket
import os
import subprocess
import threading
import time
import warnings
import xml.etree.ElementTree as ET
from collections import Counter
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from linebus import LineBus, pty_cable
from monitor_helpers import (BAD_MASTER_FINDINGS, SETTINGS, WAIT_S, Master, bad_master, diagnosis, findings,
                             frame, start, uitamr, wait_for_line)
from verifier import protocol
from verifier.amr import Robot
from verifier.commands.frame import mbpoll_command
from verifier.monitor.capture import CaptureError, Chunk, format_plain, parse_plain, read_capture
from verifier.monitor.framer import MAX_FRAME, Framer, LineTiming
from verifier.protocol.stream import frame_length_either_side
from verifier.monitor.session import CaptureInfo, MonitorSession
from verifier.verify.runner import run_scenario
from verifier.verify.scenario import load_scenario
import procs

ROOT = Path(__file__).resolve().parent.parent
CAPTURES = Path(__file__).resolve().parent / "captures"
STOP, READ = frame("stop"), frame("read", "task")


#: the rules' and the protocol's settings a trace's end record carries, at their defaults (docs/verifier.md)
RULES_RECORDED = {"reply_timeout": 0.5, "min_period": 0.25, "response_within": 5.0,
                  "protocol": {"address": 1, "field_order": "code-high", "codes_10_13": "decimal",
                               "status_order": "query", "manual_stop_counts_as_stop": False}}


def session_of(chunks, tolerance_us: int = 20_000, end_us: int | None = None, **kw) -> MonitorSession:
    """A session fed as `uitamr monitor` feeds it: each chunk as it came; with `end_us`, the
    poll at the end of listening (a read that returned nothing); then the close."""
    session = MonitorSession(CaptureInfo("test", "test"), timing=LineTiming(tolerance_us=tolerance_us), **kw)
    for chunk in chunks:
        session.feed(chunk)
    if end_us is not None:
        session.poll(end_us)
    session.close()
    return session


def rules_of(session: MonitorSession) -> Counter:
    return Counter(v.rule for found in session.violations().values() for v in found)


# --------------------------------------------------------------------- the plain capture format
def test_plain_capture_reads_chunks_and_frames_with_directions():
    chunks = parse_plain("# a comment\n0.5 01 06 01 A0 00 00 88 14  # stop\n\n0.5083 rx 0106 01A0 0000 8814\n")
    assert chunks == [Chunk(500_000, STOP), Chunk(508_300, STOP, "rx")]
    assert parse_plain(format_plain(chunks, "round trip")) == chunks


@pytest.mark.parametrize("text, where", [
    ("0.1 01 06\nx 01\n", "c.txt:2:1: expected a time in seconds"),
    ("0.1 01 0G\n", "c.txt:1:8: '0G' is not a byte in hex"),
    ("0.1 01 6\n", "c.txt:1:8: '6' is not a byte in hex"),
    ("0.2 01\n0.1 02\n", "c.txt:2:1: time 0.1 s is earlier than the line before"),
    ("0.1   # nothing\n", "c.txt:1:4: the line has a time but no bytes"),
    ("0.1 01\n 1" + "0" * 400 + " 02\n", "c.txt:2:2: time 1000"),  # was an OverflowError traceback
    ("1000000001 01\n", "c.txt:1:1: time 1000000001 s is beyond 1e+09 s; expected a time in seconds"),
    ("0.1 01\n0.2 end 02\n", "c.txt:2:9: an `end` line holds no bytes"),
    ("0.1 01\n0.2 end\n# after\n 0.3 02\n", "c.txt:4:2: the capture ended at its `end` line (c.txt:2)"),
    ("0.2 01\n0.1 end\n", "c.txt:2:1: time 0.1 s is earlier than the line before"),
    ("0.1 01\n0.2 silence 02\n", "c.txt:2:13: a `silence` line holds no bytes"),
    ("0.2 01\n0.1 silence\n", "c.txt:2:1: time 0.1 s is earlier than the line before"),
])
def test_a_bad_capture_is_named_with_file_line_and_column(text, where):
    with pytest.raises(CaptureError) as caught:
        parse_plain(text, "c.txt")
    assert str(caught.value).startswith(where)


def test_an_end_line_says_until_when_the_line_was_listened_to():
    chunks = parse_plain("0.5 01 06 01 A0 00 00 88 14\n2.25 END  # the monitor stopped\n")
    assert chunks == [Chunk(500_000, STOP), Chunk(2_250_000, b"")]
    assert format_plain(chunks[:1], end_us=2_250_000).endswith("0.500000 01 06 01 A0 00 00 88 14\n2.250000 end\n")
    assert parse_plain(format_plain(chunks[:1], end_us=2_250_000)) == chunks


def _judged(session: MonitorSession) -> tuple:
    result = session.result()
    return ([(f.t_start_us, f.t_end_us, f.direction, f.data) for f in result.trace], result.duration_us,
            {rule: [(v.t_us, v.message) for v in found] for rule, found in result.violations.items()},
            result.notes)


@settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.lists(st.tuples(st.integers(0, 400_000), st.binary(min_size=1, max_size=12)), min_size=1, max_size=12),
       st.integers(0, 3_000_000), st.integers(0, 30_000))
def test_a_replay_of_the_monitors_capture_judges_as_the_live_session_did(pieces, listened_after_us, tolerance_us):
    """The capture is the line's only record: its replay must give the live session's
    frames, findings, duration and notes. A replay used to stop at the last byte: a frame
    left short by the line's silence was "cut by the end of the capture", a reply still
    due was never judged overdue, and the run was seconds shorter."""
    t, chunks = 0, []
    for gap, data in pieces:
        t += gap
        chunks.append(Chunk(t, data))
    live = session_of(chunks, tolerance_us, end_us=t + listened_after_us)
    text = format_plain(live.chunks, "site", end_us=live.last_us)
    replayed = session_of(parse_plain(text), tolerance_us)
    assert _judged(replayed) == _judged(live)


@settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.lists(st.tuples(st.integers(1, 60_000), st.binary(min_size=1, max_size=12), st.integers(0, 100)),
                min_size=1, max_size=12), st.integers(0, 30_000))
def test_a_replay_of_the_monitors_capture_cuts_where_the_live_session_saw_silence(pieces, tolerance_us):
    """Live, the monitor polls between reads (every 2 ms) and a poll that finds the line
    silent for t3.5 ends the frame; a replay of the capture dates each chunk's bytes back to
    back before its arrival. A pty or a TCP converter hands bytes over faster than the
    line, so a chunk that came after the silence was dated back into it, and the replay
    joined it to the frame before: an FC03 request and its exception reply 8 ms later were
    two frames live, one garbled frame (an extra UITAMR-CRC) in the replay. Each piece:
    the gap before a chunk, the chunk, and where in that gap (percent) the live session
    polled."""
    t, live = 0, MonitorSession(CaptureInfo("test", "test"), timing=LineTiming(tolerance_us=tolerance_us))
    for gap, data, polled_at in pieces:
        live.poll(t + gap * polled_at // 100)
        t += gap
        live.feed(Chunk(t, data))
    live.poll(t + 50_000)
    live.close()
    text = format_plain(live.chunks, "site", end_us=live.last_us)
    assert _judged(session_of(parse_plain(text), tolerance_us)) == _judged(live), text


def test_an_fc03_request_and_its_exception_reply_over_a_pty_replay_as_two_frames():
    """The case seen on the bench: the emulator's exception reply came over the pty 8 ms
    after the FC03 request's last byte; the monitor had polled in between."""
    request, reply = bytes.fromhex("01 03 00 00 00 01 84 0A"), bytes.fromhex("01 83 01 80 F0")
    live = MonitorSession(CaptureInfo("test", "test"), timing=LineTiming())
    live.feed(Chunk(1_000_000, request))
    live.poll(1_004_200)
    live.feed(Chunk(1_008_100, reply))
    live.poll(1_500_000)
    live.close()
    text = format_plain(live.chunks, "site", end_us=live.last_us)
    assert text.splitlines()[2:] == ["0.012533 silence", "0.016433 01 83 01 80 F0", "0.508333 end"]
    replayed = session_of(parse_plain(text))
    assert [f.data for f in replayed.result().trace] == [request, reply]
    assert rules_of(replayed) == rules_of(live) == Counter({"UITAMR-FORMAT": 1})


def test_a_capture_with_its_end_line_replays_the_silence_after_the_last_bytes(tmp_path):
    """The live session saw three bytes of a reply, then 2 s of silence: a short frame,
    judged. Without the `end` line the replay took them for a frame the end cut."""
    chunks = [Chunk(10_000, STOP), Chunk(21_000, STOP), Chunk(500_000, READ), Chunk(520_000, b"\x01\x01\x00")]
    live = session_of(chunks, 20_000, end_us=2_520_000)
    assert live.frames[-1].data == b"\x01\x01\x00" and live.cut_off == b""
    capture = tmp_path / "site.txt"
    capture.write_text(format_plain(live.chunks, end_us=live.last_us), encoding="utf-8")
    done = procs.run(uitamr("replay", capture, "--json", tmp_path / "r.json"), capture_output=True, text=True,
                     timeout=WAIT_S)
    assert "were not judged" not in done.stdout, done.stdout + done.stderr
    replayed = json.loads((tmp_path / "r.json").read_text())["scenarios"][0]
    assert replayed["duration"] == pytest.approx(live.last_us / 1_000_000) == pytest.approx(2.518333)
    assert _judged(session_of(parse_plain(capture.read_text(encoding="utf-8")))) == _judged(live)


def _no_reply_at_the_end() -> MonitorSession:
    """A live session: the stop and its echo, a read the robot never answers, then the
    monitor listens on, silent, for 9.5 s (the failure outlasts RESPONSE-HANDLING's 5 s)."""
    return session_of([Chunk(10_000, STOP), Chunk(21_000, STOP), Chunk(500_000, READ)], 20_000, end_us=10_000_000)


def test_a_replay_of_the_monitors_trace_judges_as_the_live_session_did(tmp_path):
    """A `monitor --trace` file ended at its last frame: its replay ended the run there, so
    a request at the end with no reply was never judged overdue (the live session's
    UITAMR-RESPONSE-HANDLING finding was gone, exit 0) and the run was 0.5 s, not 10 s.
    The trace now ends each run with an end record, read as a capture's `end` line is."""
    from verifier.monitor.capture import parse_trace
    from verifier.verify import report_trace

    live = _no_reply_at_the_end()
    assert [v.rule for found in live.result().violations.values() for v in found] == ["UITAMR-RESPONSE-HANDLING"]
    trace = tmp_path / "site.jsonl"
    report_trace.write([live.result()], trace)
    assert json.loads(trace.read_text(encoding="utf-8").splitlines()[-1]) == {"scenario": "test", "end": 9.998333,
                                                                              **RULES_RECORDED}
    done = procs.run(uitamr("replay", trace, "--json", tmp_path / "r.json", "--trace", tmp_path / "r.jsonl"),
                     capture_output=True, text=True, timeout=WAIT_S)
    assert done.returncode == 1, done.stdout + done.stderr
    replayed = json.loads((tmp_path / "r.json").read_text())["scenarios"][0]
    assert replayed["duration"] == pytest.approx(9.998333)
    assert [(v["rule"], v["message"]) for v in replayed["violations"]] == [
        (v.rule, v.message) for found in live.result().violations.values() for v in found]
    assert _judged(session_of(parse_trace(trace.read_text(encoding="utf-8"))["test"], 20_000)) == _judged(live)
    # the replay's own trace ends where the live session did, so it replays alike again
    assert json.loads((tmp_path / "r.jsonl").read_text().splitlines()[-1]) == {"scenario": "site.jsonl",
                                                                                "end": 9.998333, **RULES_RECORDED}


def test_a_replay_of_a_trace_keeps_its_times_when_the_first_frame_came_in_pieces(tmp_path):
    """A loaded host read the first request in two pieces, 15 ms apart: live, that frame
    starts 9.8 ms after the first byte (the session's 0). The replay of the monitor's trace
    took its first frame's start for 0, so every time (the POWERON-STOP finding, the run's
    length) came out 9.8 ms early (a way the real-line replay tests can differ from the
    live run under load, as they once did in the duration)."""
    from verifier.monitor.capture import parse_trace
    from verifier.verify import report_trace

    run_point = frame("run-point", "1")
    live = session_of([Chunk(1_000_000, run_point[:3]), Chunk(1_015_000, run_point[3:]), Chunk(1_030_000, run_point),
                       Chunk(1_300_000, STOP), Chunk(1_315_000, STOP)], 20_000, end_us=4_000_000)
    assert live.frames[0].t_start_us > 0
    trace = tmp_path / "site.jsonl"
    report_trace.write([live.result()], trace)
    replayed = session_of(parse_trace(trace.read_text(encoding="utf-8"))["test"], 20_000)
    assert _judged(replayed) == _judged(live)


def test_a_monitors_trace_never_starts_before_0_so_its_replay_reads_it(tmp_path):
    """The first request came in two pieces 0.5 ms apart (a TCP converter or a pty delivers
    faster than the line), the first piece of two bytes: the first byte's start, estimated
    in whole µs, came out 1 µs before the session's 0, the trace said `"t": -1e-06` and
    `uitamr replay` refused the monitor's own trace (exit 2, "expected a time in seconds
    from 0")."""
    from verifier.monitor.capture import parse_trace
    from verifier.verify import report_trace

    live = session_of([Chunk(1_000_000, STOP[:2]), Chunk(1_000_500, STOP[2:]), Chunk(1_020_000, STOP)], 20_000,
                      end_us=3_000_000)
    assert live.frames[0].t_start_us == 0
    trace = tmp_path / "site.jsonl"
    report_trace.write([live.result()], trace)
    assert json.loads(trace.read_text(encoding="utf-8").splitlines()[0])["t"] == 0
    replayed = session_of(parse_trace(trace.read_text(encoding="utf-8"))["test"], 20_000)
    assert _judged(replayed) == _judged(live)
    done = procs.run(uitamr("replay", trace, "--json", tmp_path / "r.json"), capture_output=True, text=True,
                     timeout=WAIT_S)
    assert done.returncode == 0, done.stdout + done.stderr


def test_a_trace_without_its_end_record_still_replays(tmp_path):
    """A trace written before the end record (these are _no_reply_at_the_end's frames):
    the run ends at the last frame, as it did."""
    trace = tmp_path / "old.jsonl"
    trace.write_text(
        '{"scenario": "site", "t": 0.0, "t_end": 0.008333, "dir": "tx", "hex": "01 06 01 A0 00 00 88 14", '
        '"meaning": "stop (01/A0)", "origin": null, "tolerance": 0.02, "rules": []}\n'
        '{"scenario": "site", "t": 0.011, "t_end": 0.019333, "dir": "rx", "hex": "01 06 01 A0 00 00 88 14", '
        '"meaning": "echo: stop (01/A0)", "origin": null, "tolerance": 0.02, "rules": []}\n'
        '{"scenario": "site", "t": 0.49, "t_end": 0.498333, "dir": "tx", "hex": "01 01 00 00 00 16 BD C4", '
        '"meaning": "read task status (query 0)", "origin": null, "tolerance": 0.02, "rules": []}\n',
        encoding="utf-8")
    done = procs.run(uitamr("replay", trace, "--json", tmp_path / "r.json"), capture_output=True, text=True,
                     timeout=WAIT_S)
    assert done.returncode == 0, done.stdout + done.stderr
    replayed = json.loads((tmp_path / "r.json").read_text())["scenarios"][0]
    assert replayed["duration"] == pytest.approx(0.498333) and replayed["violations"] == []



def test_an_end_record_cut_short_with_no_frame_before_it_is_no_traffic_alone(tmp_path):
    """A trace whose end record says the port went away but that holds no frame (written by
    hand: the monitor writes no end record without frames, and a port gone before one byte is
    NO TRAFFIC) replayed NO TRAFFIC, yet its JSON kept `cut_short` ('the 2 frame(s) before it
    were verified') and its JUnit two errors, no traffic and cut short, of one capture: the
    reports said both that nothing and that frames were verified. Nothing was: no traffic alone."""
    trace = tmp_path / "t.jsonl"
    said = ("tcp 127.0.0.1:4001 went away after 0.5 s of the 600 s asked: the 2 frame(s) before it were verified, "
            "but the run is not the whole session; check the converter")
    trace.write_text(json.dumps({"scenario": "m", "end": 0.5, "cut_short": said}) + "\n", encoding="utf-8")
    done = procs.run(uitamr("replay", trace, "--json", tmp_path / "r.json", "--junit", tmp_path / "r.xml"),
                     capture_output=True, text=True, timeout=WAIT_S)
    assert done.returncode == 3, done.stdout + done.stderr
    replayed = json.loads((tmp_path / "r.json").read_text())["scenarios"][0]
    assert replayed["verdict"] == "no-traffic" and replayed["cut_short"] is None, replayed
    assert [e.get("type") for e in ET.parse(tmp_path / "r.xml").getroot().iter("error")] == ["no-traffic"]

@pytest.mark.parametrize("lines, message", [
    (['{"scenario": "a", "end": 0.5, "t": 0.1}'],
     "t.jsonl:2:1: an end record holds only 'scenario', 'end' (until when the line was listened to), the run's "
     "settings (reply_timeout, min_period, response_within, protocol, response_signal, response_signal_hint, "
     "response_signal_held) and 'cut_short' (the monitor's port went away); it has 't'"),
    (['{"scenario": "a", "end": 0.5, "cut_short": true}'],
     "t.jsonl:2:1: 'cut_short' is true; expected the sentence the monitor said when its port went away"),
    (['{"scenario": "a", "end": 0.05}'], "t.jsonl:2:1: 'end' (0.05 s) is before the start of the record before (0.1 s)"),
    (['{"scenario": "a", "end": -1}'], "t.jsonl:2:1: 'end' is -1; expected a time in seconds"),
    (['{"scenario": "a", "end": 0.5}', '{"scenario": "a", "t": 0.6, "dir": "tx", "hex": "01"}'],
     "t.jsonl:3:1: the run 'a' ended at its end record ({path}:2); move this record before it"),
])
def test_a_bad_end_record_is_named_with_its_line(tmp_path, lines, message):
    path = tmp_path / "t.jsonl"
    first = '{"scenario": "a", "t": 0.1, "t_end": 0.108, "dir": "tx", "hex": "01 06 01 A0 00 00 88 14"}'
    path.write_text("\n".join([first, *lines]) + "\n", encoding="utf-8")
    done = procs.run(uitamr("replay", path), capture_output=True, text=True, timeout=WAIT_S)
    assert done.returncode == 2 and "Traceback" not in done.stderr, done.stderr
    assert done.stderr.startswith(f"uitamr replay: {tmp_path}/{message.format(path=path)}"), done.stderr


def test_each_run_of_a_trace_has_its_own_end(tmp_path):
    path = tmp_path / "t.jsonl"
    path.write_text('{"scenario": "a", "t": 0.1, "t_end": 0.108, "dir": "tx", "hex": "01 06 01 A0 00 00 88 14"}\n'
                    '{"scenario": "a", "end": 2.5}\n'
                    '{"scenario": "b", "t": 0.1, "t_end": 0.108, "dir": "tx", "hex": "01 06 01 A0 00 00 88 14"}\n',
                    encoding="utf-8")
    loaded = read_capture(path)
    assert [(c.t_us, c.data) for c in loaded["a"]] == [(108_000, STOP), (2_500_000, b"")]
    assert [(c.t_us, c.data) for c in loaded["b"]] == [(108_000, STOP)]


def test_a_bad_trace_record_is_named_with_its_line(tmp_path):
    path = tmp_path / "t.jsonl"
    path.write_text('{"t": 0.1, "t_end": 0.108, "dir": "tx", "hex": "01 06 01 A0 00 00 88 14"}\n{"t": 0.2, \n',
                    encoding="utf-8")
    with pytest.raises(CaptureError, match=r"t.jsonl:2:\d+: not a JSON trace record"):
        read_capture(path)
    done = procs.run(uitamr("replay", path), capture_output=True, text=True, timeout=WAIT_S)
    assert done.returncode == 2 and "t.jsonl:2:" in done.stderr and "Traceback" not in done.stderr


# --------------------------------------------------------------------- framing and direction
def test_a_frame_in_two_chunks_with_a_usb_pause_is_one_frame():
    framer = Framer(LineTiming(tolerance_us=20_000))
    assert framer.feed(Chunk(10_000, STOP[:3])) == []
    (whole,) = framer.feed(Chunk(26_000, STOP[3:]))  # 16 ms later: the adapter's latency timer
    assert whole.data == STOP


def test_a_frame_whose_first_byte_came_alone_is_one_frame():
    """The latency timer ran out one byte into a request: that byte alone, the rest 16 ms
    later. One byte does not tell its frame's length, so it waits as an incomplete frame
    does (t3.5 plus the tolerance), not only t3.5: it was cut off as a 1-byte frame, and
    the rest judged as a frame of its own (CRC and FORMAT findings against a good PLC)."""
    session = session_of([Chunk(10_000, STOP[:1]), Chunk(26_000, STOP[1:]), Chunk(40_000, STOP)])
    assert [(f.direction, f.data) for f in session.frames] == [("tx", STOP), ("rx", STOP)]
    assert not rules_of(session)


def ftdi_chunks(trace, latency_us: int, phase_us: int) -> list[Chunk]:
    """The bytes of a wire trace as an FTDI adapter hands them to the host (AN232B-04):
    each byte is in its buffer once its 10 bits are on the wire; the buffer goes to the
    host when the latency timer runs out (every `latency_us`, from `phase_us`) or at 62
    bytes, so a chunk may end anywhere in a frame."""
    chunks, buffer, deliver_at = [], bytearray(), 0
    for frame in sorted(trace, key=lambda f: f.t_start_us):
        byte_us = (frame.t_end_us - frame.t_start_us) / len(frame.data)
        for k, byte in enumerate(frame.data):
            arrived = round(frame.t_start_us + (k + 1) * byte_us)
            if buffer and arrived > deliver_at:
                chunks.append(Chunk(deliver_at, bytes(buffer)))
                buffer.clear()
            if not buffer:
                deliver_at = phase_us + ((arrived - phase_us) // latency_us + 1) * latency_us
            buffer.append(byte)
            if len(buffer) == 62:
                chunks.append(Chunk(arrived, bytes(buffer)))
                buffer.clear()
    if buffer:
        chunks.append(Chunk(deliver_at, bytes(buffer)))
    return chunks


@pytest.mark.parametrize("phase_us", [0, 3_000, 7_500, 11_000, 15_500])
def test_a_compliant_plc_behind_an_ftdi_adapter_at_its_default_latency_timer_has_no_finding(phase_us):
    """commissioning.md: the default tolerance (20 ms) covers an FTDI adapter at its default
    16 ms latency timer. The simulated PLC's traffic (fx3u-healthy, no rule broken), handed
    over as such an adapter hands it: the same frames as on the wire, and no finding. (A
    first byte delivered alone broke about one frame in ten into CRC and FORMAT findings.)"""
    result = run_scenario(load_scenario(ROOT / "plc" / "scenarios" / "fx3u-healthy.toml"))
    chunks = ftdi_chunks(result.trace, 16_000, phase_us)
    assert any(len(c.data) == 1 for c in chunks)  # the case that broke frames is in the stream
    session = session_of(chunks)
    wire = [(f.direction, f.data) for f in sorted(result.trace, key=lambda f: f.t_start_us)]
    assert [(f.direction, f.data) for f in session.frames] == wire
    assert not rules_of(session)


def test_a_chunk_that_ends_one_byte_into_the_reply_does_not_break_it():
    reply = bytes.fromhex("01 01 03 00 00 00 3C 4E")
    session = session_of([Chunk(20_000, READ + reply[:1]), Chunk(36_000, reply[1:])])  # 16 ms latency
    assert [(f.direction, f.data) for f in session.frames] == [("tx", READ), ("rx", reply)]


def test_a_valid_frame_with_garbage_after_it_is_one_frame_as_on_the_wire():
    reply = bytes.fromhex("01 01 03 00 00 00 3C 4E")
    session = session_of([Chunk(20_000, READ), Chunk(40_000, reply + b"\xA5\x5A\xFF")])
    assert [f.data for f in session.frames] == [READ, reply + b"\xA5\x5A\xFF"]


def test_a_request_and_its_reply_in_one_chunk_are_two_frames():
    reply = protocol.encode(protocol.StatusReply(1, protocol.Query.TASK, 0, 0), SETTINGS) \
        if hasattr(protocol, "StatusReply") and False else bytes.fromhex("01 01 03 00 00 00 3C 4E")
    session = session_of([Chunk(30_000, READ + reply)])
    assert [(f.direction, f.data) for f in session.frames] == [("tx", READ), ("rx", reply)]
    assert session.frames[0].t_end_us <= session.frames[1].t_start_us


def test_the_fc06_echo_is_the_reply_and_a_hasty_master_is_a_master():
    session = session_of([Chunk(8_000, STOP), Chunk(20_000, STOP), Chunk(60_000, STOP)])
    assert [f.direction for f in session.frames] == ["tx", "rx", "tx"]
    rules = rules_of(session)
    assert rules["UITAMR-PACING"] == 1  # the second stop request came 52 ms after the first


def test_a_wrong_status_request_inside_the_reply_window_is_the_plcs_and_its_exception_the_robots():
    """Seen on a bench line: a stop with swapped CRC bytes (the robot stays silent), 400 ms
    later a status read asking for 23 coils, and the robot's exception 03. The read came
    inside the stop's reply window, so it was taken for a broken reply, and the exception
    for a request (a FORMAT finding against the PLC for the robot's bytes)."""
    bad_stop = STOP[:6] + STOP[7:5:-1]
    wrong_read = protocol.with_crc(READ[:5] + b"\x17")
    exception = protocol.with_crc(b"\x01\x81\x03")
    session = session_of([Chunk(10_000, bad_stop), Chunk(410_000, wrong_read), Chunk(420_000, exception)])
    assert [(f.direction, f.data) for f in session.frames] == [
        ("tx", bad_stop), ("tx", wrong_read), ("rx", exception)]
    formats = [v.message for v in session.violations().get("UITAMR-FORMAT", [])]
    assert len(formats) == 1 and "quantity" in formats[0]


def test_an_exception_answers_the_request_after_an_unanswered_bad_crc_one():
    """The robot stays silent to a request with a bad CRC, so the exception that follows
    the next request answers that one: it was paired with the bad-CRC request instead,
    and the next read was blamed (ONE-AT-A-TIME) for not waiting for a reply that came."""
    bad_stop = STOP[:6] + STOP[7:5:-1]
    wrong_read = protocol.with_crc(READ[:5] + b"\x17")
    exception = protocol.with_crc(b"\x01\x81\x03")
    reply = bytes.fromhex("01 01 03 00 00 00 3C 4E")
    session = session_of([Chunk(10_000, STOP), Chunk(20_000, STOP), Chunk(350_000, READ), Chunk(360_000, reply),
                          Chunk(700_000, bad_stop), Chunk(1_100_000, wrong_read), Chunk(1_106_000, exception),
                          Chunk(1_500_000, READ), Chunk(1_506_000, reply)])
    assert [f.direction for f in session.frames] == ["tx", "rx", "tx", "rx", "tx", "tx", "rx", "tx", "rx"]
    rules = rules_of(session)
    assert rules["UITAMR-ONE-AT-A-TIME"] == 1  # the wrong read, 400 ms after the bad stop: too early
    (one,) = session.violations()["UITAMR-ONE-AT-A-TIME"]
    assert one.t_us < 1_200_000


def test_a_status_read_repeated_to_a_silent_robot_is_a_request_not_its_echo():
    """An FC01 reply carries a byte count, so a frame equal to the status read is never
    its reply (only FC06 replies echo the request)."""
    session = session_of([Chunk(10_000, READ), Chunk(310_000, READ)])
    assert [f.direction for f in session.frames] == ["tx", "tx"]


def test_an_exception_reply_after_the_reply_time_out_is_the_robots():
    wrong_read = protocol.with_crc(READ[:5] + b"\x17")
    exception = protocol.with_crc(b"\x01\x81\x03")
    session = session_of([Chunk(10_000, wrong_read), Chunk(900_000, exception)])
    assert [f.direction for f in session.frames] == ["tx", "rx"]


def test_a_silent_robot_finding_says_what_to_check_on_site():
    """The commonest site fault, a robot that never answers: the finding said only to check
    the PLC program's error output, not what commissioning.md §5 says to look at."""
    session = session_of([Chunk(10_000 + k * 600_000, STOP) for k in range(12)])
    (finding,) = session.violations()["UITAMR-RESPONSE-HANDLING"]
    assert "no reply" in finding.message and "o_bErr" in finding.message
    assert "its power, its address (the requests go to slave 1), the pair's wiring and polarity (A, B, GND)" \
        in finding.message


def test_a_timing_finding_against_noise_says_the_frame_may_be_noise():
    """Noise (or bytes at a wrong baud rate) is taken for a request: the PLC's next request
    then broke PACING or ONE-AT-A-TIME "after the previous request", sending the engineer
    to the PLC's pace and time-out settings. The message now says the previous frame had
    a bad CRC and may not be the PLC's."""
    echo = STOP
    noise = bytes.fromhex("E0 00 F8 80 00 00 78 E0 F8 80")
    session = session_of([Chunk(10_000, STOP), Chunk(20_000, echo), Chunk(450_000, noise), Chunk(600_000, READ)])
    found = session.violations()
    (pacing,) = found["UITAMR-PACING"]
    (one,) = found["UITAMR-ONE-AT-A-TIME"]
    for finding in (pacing, one):
        assert "(the previous frame, E0 00 F8 80 00 00 78 E0 F8 80, has a bad CRC: if the PLC did not send it, " \
               "it is noise on the line or a wrong baud rate - see its UITAMR-CRC finding)" in finding.message
    # a real request with a good CRC before: no such words
    session = session_of([Chunk(10_000, STOP), Chunk(160_000, READ)])
    (pacing,) = session.violations()["UITAMR-PACING"]
    assert "noise" not in pacing.message


def test_unknown_bytes_end_at_the_silence():
    session = session_of([Chunk(1_000, b"\x01\x99\x00"), Chunk(50_000, STOP)])
    assert [f.data for f in session.frames] == [b"\x01\x99\x00", STOP]
    assert rules_of(session)["UITAMR-FORMAT"] + rules_of(session)["UITAMR-CRC"] >= 1


@settings(max_examples=200, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.lists(st.tuples(st.integers(0, 400_000), st.binary(min_size=1, max_size=40)), max_size=40),
       st.integers(0, 30_000))
def test_any_byte_stream_gives_frames_and_findings_never_a_crash(pieces, tolerance_us):
    """Noise, broken frames, floods: every byte ends up in exactly one frame, frames do
    not overlap, and the rules judge them (findings, never an exception) - but for the
    start of a frame the end of the capture cut short, which is noted, not judged."""
    t = 0
    chunks = []
    for gap, data in pieces:
        t += gap
        chunks.append(Chunk(t, data))
    session = session_of(chunks, tolerance_us)
    cut = session.cut_off
    assert b"".join(f.data for f in session.frames) + cut == b"".join(c.data for c in chunks)
    assert not cut or len(cut) < frame_length_either_side(cut)
    for before, after in zip(session.frames, session.frames[1:]):
        assert before.t_end_us <= after.t_start_us or before.t_end_us <= after.t_end_us
    session.check()
    session.result()


# --------------------------------------------------------------------- a capture on one long line
class _CountsShifts:
    """A list or bytearray that counts the items a deletion at its front moves down: what
    dropping the bytes of cut frames costs."""

    shifted = 0

    def __delitem__(self, index):
        if isinstance(index, slice) and not index.start and index.stop:
            self.shifted += max(len(self) - index.stop, 0)
        super().__delitem__(index)


class _ShiftCountingList(_CountsShifts, list):
    pass


class _ShiftCountingBytes(_CountsShifts, bytearray):
    pass


def _shifted_cutting_one_chunk(pairs: int) -> int:
    """Items moved while a framer cuts `pairs` exchanges (request and reply) that came in
    one chunk, as a capture written on one line gives them; its frames are checked too."""
    reply = bytes.fromhex("01 01 03 00 00 00 3C 4E")
    framer = Framer(LineTiming(tolerance_us=20_000))
    framer._buffer, framer._arrivals = _ShiftCountingBytes(), _ShiftCountingList()
    frames = framer.feed(Chunk(10_000_000, (READ + reply) * pairs)) + framer.flush()
    assert [f.data for f in frames] == [READ, reply] * pairs
    assert all(before.t_end_us <= after.t_start_us for before, after in zip(frames, frames[1:]))
    return framer._buffer.shifted + framer._arrivals.shifted


def test_frames_cut_from_one_long_chunk_cost_in_proportion_to_its_length():
    """A capture of hours on one line is one chunk of megabytes. Each frame cut from it
    dropped its bytes from the front of the buffer, moving all the bytes after it: 8 times
    the bytes cost 64 times the moves (a 6 MB line replayed in ~40 s, a 0.5 MB one in 2 s).
    Counted, not timed: the moves grow no faster than the chunk."""
    one, eight = _shifted_cutting_one_chunk(1_000), _shifted_cutting_one_chunk(8_000)
    assert eight <= 8 * one + MAX_FRAME, (one, eight)


def test_a_capture_on_one_line_has_the_findings_of_the_same_bytes_over_many_lines(tmp_path):
    """The same bytes, once as one line and once a frame a line timed as the one line's
    bytes arrive: the same frames, the same findings, word for word."""
    trace = run_scenario(load_scenario(ROOT / "plc" / "scenarios" / "fx3u-late-reply.toml")).trace
    frames = [f.data for f in sorted(trace, key=lambda f: f.t_start_us)]
    data, end_us, timing = b"".join(frames), 5_000_000, LineTiming()
    one = tmp_path / "one.txt"
    one.write_text(f"{end_us / 1e6:.6f} {protocol.hex_bytes(data)}\n", encoding="utf-8")
    lines, sent = [], 0
    for frame_bytes in frames:
        sent += len(frame_bytes)
        lines.append(Chunk(end_us - timing.frame_us(len(data) - sent), frame_bytes))
    many = tmp_path / "many.txt"
    many.write_text(format_plain(lines), encoding="utf-8")
    reports = []
    for capture in (one, many):
        report = tmp_path / f"{capture.stem}.json"
        done = procs.run(uitamr("replay", capture, "--json", report), capture_output=True, text=True,
                         timeout=WAIT_S)
        assert done.returncode == 1, done.stdout + done.stderr  # squeezed together: the pacing rule fails
        reports.append(json.loads(report.read_text())["scenarios"][0])
    assert reports[0]["violations"] and reports[0]["violations"] == reports[1]["violations"]
    assert reports[0]["rules"] == reports[1]["rules"]


def test_a_capture_replay_cannot_read_is_a_junit_error_at_its_place(tmp_path):
    """Exit 2 with --junit left no report for the CI server to show (or the last run's)."""
    capture, report = tmp_path / "c.txt", tmp_path / "r.xml"
    capture.write_text("0.1 01 0G\n", encoding="utf-8")
    done = procs.run(uitamr("replay", capture, "--junit", report), capture_output=True, text=True,
                     timeout=WAIT_S)
    assert done.returncode == 2 and f"{capture}:1:8: '0G' is not a byte in hex" in done.stderr, done.stderr
    root = ET.parse(report).getroot()
    assert (root.get("name"), root.get("errors")) == ("uitamr replay", "1")
    (case,) = root.findall("./testsuite/testcase")
    assert (case.get("classname"), case.get("file")) == ("uitamr.replay.input", str(capture))
    assert case.find("error").get("message").startswith(f"{capture}:1:8: '0G' is not a byte in hex")


def test_a_bad_byte_far_into_a_long_line_is_named_by_its_column(tmp_path):
    capture = tmp_path / "c.txt"
    good = "0.000000 " + "01 06 01 A0 00 00 88 14 " * 100_000  # 2.4 MB on one line
    capture.write_text("# one line\n" + good + "0G 01\n", encoding="utf-8")
    done = procs.run(uitamr("replay", capture), capture_output=True, text=True, timeout=WAIT_S)
    assert done.returncode == 2, done.stdout + done.stderr
    assert f"{capture}:2:{len(good) + 1}: '0G' is not a byte in hex" in done.stderr


# --------------------------------------------------------------------- same rules as `uitamr verify`
@pytest.mark.parametrize("name", ["fx3u-healthy", "fx3u-no-reply", "fx3u-bad-crc", "fx3u-late-reply",
                                  "fx3u-wrong-address", "fx3u-exception", "fx3u-garbage", "q-exception",
                                  "fx3u-panel-all-commands", "fx5u-healthy"])
def test_a_verify_trace_as_raw_bytes_gets_the_same_frames_and_verdicts(name):
    """The simulated PLC's traffic, as the host would see it with no latency (each frame
    a chunk): the monitor finds the same frames, sides and rule results as `verify`
    (RESPONSE-HANDLING aside: a capture cannot see the PLC's outputs)."""
    result = run_scenario(load_scenario(ROOT / "plc" / "scenarios" / f"{name}.toml"))
    assert_the_monitor_judges_as_verify(result)


def assert_the_monitor_judges_as_verify(result) -> None:
    """`result`'s trace as raw bytes, each frame a chunk: the monitor finds the same frames
    and sides, and the same violations per rule at the same times, as `verify` did."""
    chunks = [Chunk(f.t_end_us, f.data) for f in sorted(result.trace, key=lambda f: f.t_start_us)]
    session = session_of(chunks, tolerance_us=0)
    expected = [(f.t_start_us, f.direction, f.data) for f in sorted(result.trace, key=lambda f: f.t_start_us)]
    got = [(f.t_start_us + session._origin_us, f.direction, f.data) for f in session.frames]
    assert [(d, x) for _, d, x in got] == [(d, x) for _, d, x in expected]
    judged = {rule: [v.t_us for v in found] for rule, found in session.violations(result.ended_us).items()}
    wanted = {rule: [v.t_us - session._origin_us for v in found] for rule, found in result.violations.items()}
    judged.pop("UITAMR-RESPONSE-HANDLING")
    wanted.pop("UITAMR-RESPONSE-HANDLING")
    assert judged == wanted


def _bad_crc(request) -> bytes:
    data = bytearray(protocol.encode(request, protocol.DEFAULT_SETTINGS))
    data[6] ^= 0x10
    return bytes(data)


_SEQ_STOP = protocol.command_from_words("stop")
_SEQ_READ = protocol.command_from_words("read task")
_SEQ_POINT = protocol.command_from_words("run-point 3")
#: programs that break rules (tests/test_verify_pipeline.py's sequencer): what verify finds
_BREAKING = {
    "cycle": ({"UITAMR-CYCLE"}, dict(frames=[_SEQ_STOP, _SEQ_POINT, _SEQ_READ])),
    "poweron-stop": ({"UITAMR-POWERON-STOP"}, dict(frames=[_SEQ_READ, _SEQ_POINT, _SEQ_READ, _SEQ_STOP])),
    "pacing": ({"UITAMR-PACING"}, dict(frames=[_SEQ_STOP, _SEQ_READ, _SEQ_READ], period="T#200ms")),
    "format": ({"UITAMR-FORMAT"}, dict(frames=[_SEQ_STOP, protocol.with_crc(bytes.fromhex("010100000008")),
                                               _SEQ_READ])),
    "crc": ({"UITAMR-CRC"}, dict(frames=[_SEQ_STOP, _bad_crc(_SEQ_READ)])),
    "one-at-a-time": ({"UITAMR-ONE-AT-A-TIME", "UITAMR-HALF-DUPLEX"},
                      dict(frames=[_SEQ_STOP, _SEQ_READ, _SEQ_READ, _SEQ_READ],
                           faults=[{"kind": "no_reply", "at_s": 0.5, "duration_s": 0.5}])),
}


@pytest.mark.parametrize("name", sorted(_BREAKING))
def test_a_program_that_breaks_a_rule_is_judged_by_the_monitor_as_by_verify(name, tmp_path):
    """The comparison above on programs that break the rules: the bundled scenarios break
    none, so there it shows only that the monitor blames nothing verify does not."""
    from test_verify_pipeline import run_sequence

    broken, sequence = _BREAKING[name]
    result = run_sequence(tmp_path, **sequence)
    assert {rule for rule, found in result.violations.items() if found} == broken
    assert_the_monitor_judges_as_verify(result)


def test_replay_of_a_verify_trace_file(tmp_path):
    trace = tmp_path / "t.jsonl"
    done = procs.run(uitamr("verify", "--scenario", ROOT / "plc/scenarios/fx3u-healthy.toml",
                                 "--trace", trace),
                     capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stdout + done.stderr
    report = tmp_path / "r.json"
    done = procs.run(uitamr("replay", trace, "--json", report, "--junit", tmp_path / "r.xml",
                                 "--html", tmp_path / "r.html", "--trace", tmp_path / "r.jsonl"),
                     capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stdout + done.stderr
    data = json.loads(report.read_text())
    assert data["verdict"] == "pass" and data["scenarios"][0]["violations"] == []
    *original, verify_end = [json.loads(line) for line in trace.read_text().splitlines()]
    *again, end = [json.loads(line) for line in (tmp_path / "r.jsonl").read_text().splitlines()]
    assert [(r["dir"], r["hex"], r["meaning"]) for r in again] == [(r["dir"], r["hex"], r["meaning"]) for r in original]
    # verify's run ended at 60 s of virtual time, and the replay's run there too; the replay's
    # own trace says so again, with the rules' settings and the program's outputs verify recorded
    assert verify_end["end"] == data["scenarios"][0]["duration"] == 60.0
    assert end == dict(verify_end, scenario=again[0]["scenario"])
    assert "<svg" in (tmp_path / "r.html").read_text()


# --------------------------------------------------------------------- the bad master
def test_the_saved_bad_master_capture_has_exactly_its_findings(tmp_path):
    report = tmp_path / "r.json"
    done = procs.run(uitamr("replay", CAPTURES / "bad-master.txt", "--json", report),
                     capture_output=True, text=True, timeout=WAIT_S)
    assert done.returncode == 1, done.stdout + done.stderr
    assert findings(report) == Counter(BAD_MASTER_FINDINGS)


@pytest.fixture
def line(tmp_path):
    bus = LineBus(tmp_path)
    robot = start("emulate", "--serial", bus.robot)
    try:
        wait_for_line(robot, "listening")
        yield bus
    finally:
        robot.terminate()
        procs.finish(robot, WAIT_S)
        bus.close()


def monitor_on(bus: LineBus, tmp_path: Path, *extra) -> subprocess.Popen:
    monitor = start("monitor", "--serial", bus.tap, "--json", tmp_path / "m.json", *extra)
    wait_for_line(monitor, "listening")
    return monitor


@pytest.fixture
def bare_line(tmp_path):
    """A line with nothing on its robot end: the test answers for the robot (Master's `robot`)."""
    bus = LineBus(tmp_path)
    try:
        yield bus
    finally:
        bus.close()


@pytest.mark.serial
def test_a_bad_master_on_a_real_line_gets_exactly_its_findings(tmp_path):
    """The robot is the emulator's model answered in-process (Master's `robot`): with a
    `uitamr emulate` process the host stalled 230 ms or more, the master's next request
    went out after the late reply and broke no pacing - 1 to 2 runs in 30 on a loaded
    2-core host found 2 UITAMR-PACING, not 3. The emulator on the line: the test after this one.

    The monitor is a process the host can stall too: a request it reads 130 ms late is no
    longer 100 ms after the previous one. Other findings while that was measured (the
    master woke late, or the monitor saw other gaps than were written: `_host_stalls`)
    prove nothing and the attempt runs again on a fresh line; other findings with no stall
    fail at once, and so do three stalled attempts."""
    stalled = []
    for attempt in range(3):
        folder = tmp_path / f"attempt{attempt}"
        folder.mkdir()
        line = LineBus(folder)
        try:
            monitor = monitor_on(line, folder, "--duration", "3s", "--capture", folder / "c.txt", "--junit",
                                 folder / "m.xml", "--html", folder / "m.html", "--trace", folder / "m.jsonl")
            master = bad_master(line, Robot(SETTINGS))
            out, err = procs.finish(monitor, WAIT_S)
        finally:
            line.close()
        seen = diagnosis(out, err, folder / "c.txt", master)
        assert monitor.returncode == 1 and (folder / "m.json").exists(), seen
        if findings(folder / "m.json") == Counter(BAD_MASTER_FINDINGS):
            break
        stalls = _host_stalls(master, folder / "m.jsonl")
        assert stalls, f"{findings(folder / 'm.json')} with no host stall measured\n{seen}"
        stalled.append(f"attempt {attempt + 1}: " + "; ".join(stalls))
    else:
        pytest.fail("the host stalled the master or the monitor in every attempt:\n" + "\n".join(stalled))
    if stalled:
        warnings.warn("host stalls before the attempt that counted: " + " | ".join(stalled))
    live, summary = out.split("\nFAIL monitor ", 1)
    # each finding was printed live (its time, rule, message and frames), before the summary
    assert re.search(r"^0\.000 s  UITAMR-POWERON-STOP: the first control command after power-on is run "
                     r"point/script 1 \(01/01\)", live, re.M), out
    assert re.search(r"^ +0\.000 s  PLC → robot  01 06 01 01 00 00 D9 F6  run point/script 1", live, re.M), out
    assert Counter(re.findall(r"^\d+\.\d{3} s  (UITAMR-[A-Z-]+): ", live, re.M)) == Counter(BAD_MASTER_FINDINGS)
    assert "<testcase" in (folder / "m.xml").read_text() and "<svg" in (folder / "m.html").read_text()
    done = procs.run(uitamr("replay", folder / "c.txt", "--json", folder / "r.json"),
                     capture_output=True, text=True, timeout=WAIT_S)
    assert done.returncode == 1 and findings(folder / "r.json") == Counter(BAD_MASTER_FINDINGS), done.stdout + done.stderr
    # the replay of the capture is the live session's judgement: frames, findings, notes and
    # how long the line was listened to (the capture's `end` line); only the names differ
    live_run, replayed = (json.loads((folder / name).read_text())["scenarios"][0] for name in ("m.json", "r.json"))
    differing = {key for key in live_run if live_run[key] != replayed[key]}
    assert differing == {"name", "file", "description", "channel"}, {k: (live_run[k], replayed[k]) for k in differing}
    # so is the replay of the monitor's --trace (its end record: the run lasted the 3 s
    # listened to, not until the last frame at 1.6 s)
    done = procs.run(uitamr("replay", folder / "m.jsonl", "--json", folder / "t.json"),
                     capture_output=True, text=True, timeout=WAIT_S)
    assert done.returncode == 1, done.stdout + done.stderr
    replayed = json.loads((folder / "t.json").read_text())["scenarios"][0]
    differing = {key for key in live_run if live_run[key] != replayed[key]}
    assert differing == {"name", "file", "description", "channel"}, {k: (live_run[k], replayed[k]) for k in differing}


class EmulatedLine:
    """One real-time attempt's fresh line (LineBus) in `folder`, with `uitamr emulate` on its
    robot end, listening; on leaving, the emulator is stopped (its log in `log`) and the
    line closed."""

    def __init__(self, folder: Path):
        folder.mkdir()
        self.folder, self.log = folder, ""
        self.bus = LineBus(folder)
        self.robot = start("emulate", "--serial", self.bus.robot)

    def __enter__(self) -> "EmulatedLine":
        try:
            wait_for_line(self.robot, "listening")
        except BaseException:
            self.__exit__()
            raise
        return self

    def __exit__(self, *_exc) -> None:
        try:
            self.robot.terminate()
            self.log, _ = procs.finish(self.robot, WAIT_S)
        finally:
            self.bus.close()


@pytest.mark.serial
def test_the_emulator_answering_the_bad_master_is_seen_reply_for_reply(tmp_path):
    """`uitamr emulate` on the line answers the bad master, and the monitor on the tap sees
    every request the master wrote and every reply the emulator logged it sent, in order,
    and the findings that do not depend on when the host ran the emulator (how many
    requests broke the pacing does: a reply the host held back delays the next request).

    Real time: the host stalled the emulator 1.5 s (SIGSTOP) from the bad stop on, so it
    read the bad stop and the stop after it in one read, as one frame, and answered neither
    stop nor the last read: 3 replies for 5. An attempt that fails while the host
    demonstrably stalled it (`_emulator_stalls`) runs again on a fresh line; a failure
    without a stall fails at once, and so do three stalled attempts."""
    stalled = []
    for attempt in range(3):
        with EmulatedLine(tmp_path / f"attempt{attempt}") as line:
            folder, bus = line.folder, line.bus
            monitor = monitor_on(bus, folder, "--duration", "3s", "--trace", folder / "m.jsonl")
            master = bad_master(bus)
            out, err = procs.finish(monitor, WAIT_S)
        log = line.log
        seen = diagnosis(out, err, master=master) + "\n--- emulator ---\n" + log
        try:
            _seen_reply_for_reply(monitor.returncode, folder, master, log, seen)
        except AssertionError as failure:
            stalls = _emulator_stalls(master, log)
            if not stalls:
                raise
            stalled.append(f"attempt {attempt + 1}: " + "; ".join(stalls) + f"\n{failure}")
            continue
        if stalled:
            warnings.warn("host stalls before the clean attempt: " + " | ".join(s.splitlines()[0] for s in stalled))
        return
    pytest.fail("every attempt failed while the host measurably stalled it: a host too loaded, or an "
                "emulator or monitor that is wrong - the attempts:\n" + "\n".join(stalled))


def _seen_reply_for_reply(returncode: int, folder: Path, master: Master, log: str, seen: str) -> None:
    assert returncode == 1 and (folder / "m.json").exists(), seen
    found = findings(folder / "m.json")
    assert (found["UITAMR-POWERON-STOP"], found["UITAMR-CRC"]) == (1, 1), seen
    records = [json.loads(r) for r in (folder / "m.jsonl").read_text(encoding="utf-8").splitlines()]
    requests = [bytes.fromhex(r["hex"]) for r in records if r.get("dir") == "tx"]
    replies = [r["hex"] for r in records if r.get("dir") == "rx"]
    assert requests == [bytes.fromhex(w.split(" wrote ")[1]) for w in master.log if " wrote " in w], seen
    sent = re.findall(r"^ *\d+\.\d{3} s  -> ((?:[0-9A-F]{2} )*[0-9A-F]{2})  ", log, re.M)
    assert len(sent) == 5 and replies == sent, seen  # the bad stop gets none


def _emulator_stalls(master: Master, log: str) -> list[str]:
    """How the host stalled a run against `uitamr emulate`, as measured apart from what is
    tested: the master woke late or waited in vain for a reply (Master.stalls), or the
    emulator read the requests further apart or closer than the master wrote them (the
    times of its own log's `<-` lines: it dates bytes when it reads them, so a stalled
    emulator reads late). (An emulator that read another number of frames than were
    written is no stall by itself: it could be wrong.)"""
    read_at = [float(t) for t in re.findall(r"^ *(\d+\.\d{3}) s  <- ", log, re.M)]
    return master.stalls + [f"emulator: {gap}" for gap in _gaps_seen_otherwise(master.sent_at, read_at)]


@pytest.mark.serial
def test_a_request_left_unanswered_on_a_real_line_replays_from_the_trace_as_judged_live(bare_line, tmp_path):
    """The last request gets no reply (a bad CRC: the robot ignores it) and the monitor
    listens on: live, the failure lasts past RESPONSE-HANDLING's 5 s. The replay of the
    monitor's --trace ended at that request, so the finding was gone and the run 5 s
    shorter; with the trace's end record it is the live judgement. The test answers for the
    robot (Master's `robot`): the stop's echo is never late, whatever the host does."""
    monitor = monitor_on(bare_line, tmp_path, "--duration", "8s", "--trace", tmp_path / "m.jsonl")
    master = Master(bare_line, Robot(SETTINGS))
    try:
        stop = frame("stop")
        master.send(stop)
        master.at(0.3)
        master.send(stop[:-1] + bytes([stop[-1] ^ 0x01]), reply_length=None)
    finally:
        master.close()
    out, err = procs.finish(monitor, WAIT_S)
    seen = diagnosis(out, err, master=master)  # exit 1 with no m.json was a traceback: its stderr says which
    assert monitor.returncode == 1 and (tmp_path / "m.json").exists(), seen
    assert findings(tmp_path / "m.json")["UITAMR-RESPONSE-HANDLING"] == 1, seen
    done = procs.run(uitamr("replay", tmp_path / "m.jsonl", "--json", tmp_path / "r.json"),
                     capture_output=True, text=True, timeout=WAIT_S)
    assert done.returncode == 1, done.stdout + done.stderr
    live_run, replayed = (json.loads((tmp_path / name).read_text())["scenarios"][0] for name in ("m.json", "r.json"))
    differing = {key for key in live_run if live_run[key] != replayed[key]}
    assert differing == {"name", "file", "description", "channel"}, {k: (live_run[k], replayed[k]) for k in differing}


@pytest.mark.serial
def test_a_capture_of_a_real_line_replays_to_the_live_findings_when_bytes_come_faster_than_the_line(bare_line, tmp_path):
    """Over ptys bytes arrive faster than at 9600 bit/s: an FC03 request and its exception
    reply 8 ms later (as `uitamr emulate` answers it) were two frames live, the monitor
    having seen the silence between them, and one garbled frame in the replay of its
    --capture (an extra UITAMR-CRC). A host that stalls the monitor over the 8 ms hands it
    both in one read, which live and replay then judge alike: the test holds either way."""
    monitor = monitor_on(bare_line, tmp_path, "--duration", "3s", "--joined", "--capture", tmp_path / "m.txt")
    bare_line.from_plc(bytes.fromhex("01 03 00 00 00 01 84 0A"))
    time.sleep(0.008)
    bare_line.from_robot(bytes.fromhex("01 83 01 80 F0"))
    out, err = procs.finish(monitor, WAIT_S)
    seen = diagnosis(out, err, capture=tmp_path / "m.txt")
    assert monitor.returncode == 1 and (tmp_path / "m.json").exists(), seen
    done = procs.run(uitamr("replay", tmp_path / "m.txt", "--json", tmp_path / "r.json"),
                     capture_output=True, text=True, timeout=WAIT_S)
    assert done.returncode == 1, done.stdout + done.stderr
    assert findings(tmp_path / "r.json") == findings(tmp_path / "m.json"), seen + done.stdout


@pytest.mark.serial
def test_mbpoll_and_the_emulator_seen_by_the_monitor(line, tmp_path):
    """Three mbpoll runs, 400 ms or more apart (the pacing), answered by `uitamr emulate`:
    the monitor sees them all and passes. It is stopped with Ctrl-C once it printed the
    third reply: it listened 4 s, and on a loaded host three mbpoll processes and the
    pauses between them may take longer than that (the last exchange would go unseen)."""
    monitor = monitor_on(line, tmp_path, "--duration", "120s")
    printed: list[str] = []
    for request in (protocol.command_from_words("stop"), protocol.command_from_words("read task"),
                    protocol.command_from_words("read battery")):
        done = procs.run(mbpoll_command(request, SETTINGS, line.plc), capture_output=True, text=True,
                         timeout=WAIT_S)
        assert done.returncode == 0, done.stdout + done.stderr
        wait_for_line(monitor, "robot → PLC", seen=printed)  # its reply, on the tap
        time.sleep(0.4)
    monitor.send_signal(signal.SIGINT)
    out, err = procs.finish(monitor, WAIT_S)
    out = "".join(printed) + out
    assert monitor.returncode == 0, out + err
    assert "PLC → robot  01 06 01 A0 00 00 88 14    stop (01/A0)" in out
    assert "robot → PLC  01 06 01 A0 00 00 88 14    echo: stop (01/A0)" in out
    assert "battery" in out
    report = json.loads((tmp_path / "m.json").read_text())
    assert report["verdict"] == "pass"
    assert report["scenarios"][0]["frames"] == {"tx": 3, "rx": 3}


def _host_stalls(master: Master, trace: Path) -> list[str]:
    """How the host stalled a real-time run, as measured apart from what is tested: the
    master woke late or waited in vain for a reply (Master.stalls), or the monitor saw two
    requests further apart or closer than the master wrote them (its tap was not run). The
    requests seen are the monitor's --trace's. They were read off its console, where a
    finding prints its frames again: a run with findings never had its gaps compared, and
    a stalled tap failed at once as a monitor that is wrong. (A monitor that saw another
    number of requests than were written is wrong: that is no stall.)"""
    return master.stalls + _gaps_seen_otherwise(master.sent_at, _trace_times(trace, "tx"))


@pytest.mark.serial
def test_the_simulated_plc_driving_the_emulator_is_compliant(tmp_path):
    """The requests of `uitamr verify`'s FX3U example, sent at their times on the real
    line to the emulated robot: the monitor finds nothing to blame.

    Real time on a loaded host: an attempt with findings while the host demonstrably
    stalled it (measured by the master and by comparing what it wrote with what the
    monitor saw, `_host_stalls`) proves nothing and runs again on a fresh line. Findings
    without a stall fail at once; three stalled attempts fail too, with what was measured
    (an emulator that never answers is measured as a stall too: it fails that way)."""
    result = run_scenario(load_scenario(ROOT / "plc" / "scenarios" / "fx3u-healthy.toml"))
    requests = [f for f in result.trace if f.direction == "tx" and f.t_start_us < 4_000_000]
    assert len(requests) >= 8
    stalled = []
    for attempt in range(3):
        with EmulatedLine(tmp_path / f"attempt{attempt}") as line:
            folder, bus = line.folder, line.bus
            monitor = monitor_on(bus, folder, "--duration", "5.5s", "--tolerance", "50ms",  # host scheduling
                                 "--trace", folder / "m.jsonl", "--capture", folder / "c.txt")
            master = Master(bus)
            try:
                for request in requests:
                    master.at(request.t_start_us / 1_000_000)
                    master.send(request.data)
            finally:
                master.close()
            out, err = procs.finish(monitor, WAIT_S)
        seen = diagnosis(out, err, folder / "c.txt", master)
        assert (folder / "m.json").exists(), seen
        clean = monitor.returncode == 0 and findings(folder / "m.json") == Counter()
        stalls = _host_stalls(master, folder / "m.jsonl")
        if not clean and stalls:  # findings the host's stall can explain: this attempt proves nothing
            stalled.append(f"attempt {attempt + 1}: " + "; ".join(stalls) + "\n" + seen)
            continue
        assert monitor.returncode == 0, seen
        assert findings(folder / "m.json") == Counter(), seen
        assert out.count("PLC → robot") == len(requests), seen
        if stalled:  # shown in the run's warnings summary: how often the host got in the way
            warnings.warn("host stalls before the clean attempt: " + " | ".join(s.splitlines()[0] for s in stalled))
        return
    pytest.fail("every attempt had findings while the master measured a stall (it woke late, the emulator "
                "did not answer in 200 ms, or the monitor saw other gaps than were written): a host too "
                "loaded, or an emulator or monitor that is wrong - the attempts:\n" + "\n".join(stalled))


@pytest.mark.serial
def test_noise_on_the_line_gives_findings_not_a_crash(line, tmp_path):
    monitor = monitor_on(line, tmp_path, "--duration", "3s")
    master = Master(line)
    rng = random.Random(7)
    try:
        master.send(STOP)
        time.sleep(0.3)
        line.noise(bytes(rng.randrange(256) for _ in range(37)))
        time.sleep(0.3)
        line.noise(STOP[:5])  # a broken frame
        time.sleep(0.4)
        master.send(READ)
    finally:
        master.close()
    out, err = procs.finish(monitor, WAIT_S)
    assert monitor.returncode == 1, out + err
    assert "Traceback" not in out + err
    assert findings(tmp_path / "m.json")  # something to show


def _monitor_that_saw_the_stop(bus: LineBus, tmp_path: Path, *extra) -> subprocess.Popen:
    """A monitor (with --json m.json and `extra`) on the line, once the stop and its echo passed.
    The test answers for the robot (Master's `robot`): a `uitamr emulate` process the host
    stalled past the 500 ms reply time-out would make the echo late, a finding, and no pass."""
    monitor = monitor_on(bus, tmp_path, *extra)
    master = Master(bus, Robot(SETTINGS))
    try:
        master.send(STOP)
    finally:
        master.close()
    # Ctrl-C once the monitor has the echo: half a second's sleep was no proof that it had
    # read it, and a monitor the host stalled as long was stopped with the echo unread
    wait_for_line(monitor, "echo: stop")
    return monitor


@pytest.mark.serial
def test_ctrl_c_stops_the_monitor_and_the_reports_are_written(bare_line, tmp_path):
    monitor = _monitor_that_saw_the_stop(bare_line, tmp_path, "--capture", tmp_path / "c.txt")
    monitor.send_signal(signal.SIGINT)
    out, err = procs.finish(monitor, WAIT_S)
    assert monitor.returncode == 0, out + err
    assert json.loads((tmp_path / "m.json").read_text())["verdict"] == "pass"
    (chunks,) = read_capture(tmp_path / "c.txt").values()
    assert b"".join(c.data for c in chunks) == STOP + STOP  # the request and its echo


@pytest.mark.serial
def test_a_second_ctrl_c_while_the_reports_are_written_loses_none_of_them(bare_line, tmp_path):
    """Pressed again because the monitor seemed slow to stop, Ctrl-C met the default handler
    (it was put back once the port was closed): a KeyboardInterrupt while the reports were
    written, "Aborted!", an exit status of 1 or death by SIGINT rather than the session's 0,
    and of the five files only the capture. Here Ctrl-C is pressed until the capture is there."""
    files = {"--junit": "m.xml", "--html": "m.html", "--trace": "m.jsonl", "--capture": "c.txt"}
    monitor = _monitor_that_saw_the_stop(bare_line, tmp_path, *[a for option, name in files.items()
                                                                for a in (option, tmp_path / name)])
    while monitor.poll() is None and not (tmp_path / "c.txt").exists():
        monitor.send_signal(signal.SIGINT)
        time.sleep(0.005)
    out, err = procs.finish(monitor, WAIT_S)
    assert monitor.returncode == 0, out + err
    assert "Traceback" not in err and "Aborted" not in err and "KeyboardInterrupt" not in err, err
    assert [name for name in ["m.json", *files.values()] if not (tmp_path / name).exists()] == []
    assert json.loads((tmp_path / "m.json").read_text())["verdict"] == "pass"


def test_a_frame_waiting_whole_on_the_port_is_one_chunk_so_a_host_stall_cannot_split_it():
    """The monitor waits for a frame's first byte, then reads the rest. It took the rest in
    a read of its own: a host that stalled the monitor between the two reads for 31 ms or
    more (a loaded machine) gave the 7 bytes a later time, the framer took that as a
    silence after the first byte, and one stop command was judged as a 1-byte frame and a
    7-byte one. The bytes already waiting come with the first one, in one chunk."""
    from verifier.monitor.sources import SerialSource

    controller, device = os.openpty()
    source = SerialSource(os.ttyname(device), 9600, 8, "N", 1)
    source.port.timeout = WAIT_S  # the read waits for the first byte, as on a quiet line
    writer = threading.Timer(0.2, os.write, (controller, STOP))  # the whole frame at once, once the read waits
    try:
        writer.start()
        chunk = source.read()
    finally:
        writer.join()
        source.close()
        os.close(device)
        os.close(controller)
    assert chunk is not None and chunk.data == STOP
    # what a stall between two reads of it made of the frame
    split = session_of([Chunk(0, STOP[:1]), Chunk(40_000, STOP[1:])])
    assert split.frames[0].data == STOP[:1]


# --------------------------------------------------------------------- the converter route (TCP)
class BadMasterStream:
    """A TCP server on 127.0.0.1 that streams the bad master's line to the one client that
    connects, frame by frame at the capture's gaps (what a serial-to-Ethernet converter on a
    second tap does) from `lead_s` after the connection, stays `linger_s` and closes.

    The host cannot make another line of it: each frame goes in one send (the capture has
    each frame's first byte apart, and a stream thread the host stalled 30 ms between the
    two sends would cut the frame in two, CRC and FORMAT findings), and each waits its gap
    after the previous one as it was really sent (on a schedule from the first, a late frame
    made the gap to the next one shorter: the stop comes 350 ms before the last read, 120 ms
    of margin against the pacing; 4 UITAMR-PACING, not 3, were seen under load). A stall can
    still lengthen a gap: `stalls` says when the stream woke late, `sent` when each frame
    went (monotonic seconds, bytes)."""

    def __init__(self, linger_s: float = 0.3, lead_s: float = 0.0):
        (chunks,) = read_capture(CAPTURES / "bad-master.txt").values()
        self.frames: list[tuple[int, bytes]] = []  # (capture time of its last byte, bytes)
        for chunk in chunks:  # a frame's chunks: no silence of t3.5 between them
            if self.frames and chunk.t_us - self.frames[-1][0] < protocol.T3_5_US:
                self.frames[-1] = (chunk.t_us, self.frames[-1][1] + chunk.data)
            else:
                self.frames.append((chunk.t_us, chunk.data))
        self.sent: list[tuple[float, bytes]] = []
        self.stalls: list[str] = []
        self.server = socket.create_server(("127.0.0.1", 0))
        self.port = self.server.getsockname()[1]
        self.linger_s, self.lead_s = linger_s, lead_s
        self.thread = threading.Thread(target=self._stream, daemon=True)
        self.thread.start()

    def _stream(self):
        connection, _ = self.server.accept()
        with connection:
            time.sleep(self.lead_s)
            previous_us = None
            for t_us, data in self.frames:
                if previous_us is not None:
                    due = self.sent[-1][0] + (t_us - previous_us) / 1_000_000
                    if due > time.monotonic():
                        time.sleep(due - time.monotonic())
                    if time.monotonic() - due > Master.LATE_S:
                        self.stalls.append(f"frame {len(self.sent) + 1} went {(time.monotonic() - due) * 1000:.0f} ms "
                                           "late")
                self.sent.append((time.monotonic(), data))
                connection.sendall(data)
                previous_us = t_us
            time.sleep(self.linger_s)

    def close(self):
        self.thread.join(timeout=5)
        self.server.close()


def _gaps_seen_otherwise(sent_at: list[float], seen_at: list[float]) -> list[str]:
    """Where frames the monitor saw came further apart or closer than they were sent (more
    than the host allowance Master.LATE_S): the monitor was not run (seconds, in order)."""
    stalls = []
    if len(seen_at) == len(sent_at):
        for k in range(1, len(seen_at)):
            sent, saw = sent_at[k] - sent_at[k - 1], seen_at[k] - seen_at[k - 1]
            if abs(saw - sent) > Master.LATE_S:
                stalls.append(f"frames {k} and {k + 1}: sent {sent * 1000:.0f} ms apart, seen {saw * 1000:.0f} ms apart")
    return stalls


def _trace_times(trace: Path, *directions: str) -> list[float]:
    """The times of the frames of a monitor's --trace, of the `directions` given."""
    records = [json.loads(line) for line in trace.read_text(encoding="utf-8").splitlines()] if trace.exists() else []
    return [r["t"] for r in records if r.get("dir") in directions]


def monitor_the_bad_master_stream(folder: Path, source: str, *extra, **stream_options):
    """`uitamr monitor` on a BadMasterStream, its --json and --trace in attempt folders under
    `folder`, until it found the bad master's findings: (the monitor's run, the stream, the
    attempt's folder). Other findings while the host demonstrably stalled the stream or the
    monitor (the stream woke late, or the monitor saw other gaps than were sent) prove
    nothing and the attempt runs again; other findings with no stall fail at once, and so
    do three stalled attempts. `source` is --tcp or --serial's value, with {port} in it."""
    stalled = []
    for attempt in range(3):
        attempt_folder = folder / f"attempt{attempt}"
        attempt_folder.mkdir(parents=True)
        stream = BadMasterStream(**stream_options)
        option = "--tcp" if source.startswith("127.") else "--serial"
        done = procs.run(uitamr("monitor", option, source.format(port=stream.port), *extra,
                                     "--json", attempt_folder / "m.json", "--trace", attempt_folder / "m.jsonl"),
                         capture_output=True, text=True, timeout=60)
        stream.close()
        seen = "\n".join([done.stdout, "--- monitor stderr ---", done.stderr or "(empty)",
                          "stream sent (s): " + ", ".join(f"{t - stream.sent[0][0]:.3f}" for t, _ in stream.sent)])
        assert done.returncode == 1 and (attempt_folder / "m.json").exists(), seen
        if findings(attempt_folder / "m.json") == Counter(BAD_MASTER_FINDINGS):
            if stalled:
                warnings.warn("host stalls before the attempt that counted: " + " | ".join(stalled))
            return done, stream, attempt_folder
        stalls = stream.stalls + _gaps_seen_otherwise([t for t, _ in stream.sent],
                                                     _trace_times(attempt_folder / "m.jsonl", "tx", "rx"))
        assert stalls, f"{findings(attempt_folder / 'm.json')} with no host stall measured\n{seen}"
        stalled.append(f"attempt {attempt + 1}: " + "; ".join(stalls))
    pytest.fail("the host stalled the stream or the monitor in every attempt:\n" + "\n".join(stalled))


def test_monitor_on_a_tcp_stream(tmp_path):
    """The monitor connects to a converter's TCP stream of the bad master's line."""
    done, stream, _ = monitor_the_bad_master_stream(tmp_path, "127.0.0.1:{port}", "--duration", "10s")
    assert "the server closed the connection" in done.stdout  # ended by the stream, reports still written
    assert f"reading, connected to tcp 127.0.0.1:{stream.port}" in done.stdout  # a client, not a listener


def _makers(folder: Path) -> tuple:
    """What the reports in `folder` say made them: the page's title and heading, the JUnit
    suites' names and first test case's class, the JSON's tool."""
    import xml.etree.ElementTree as ET

    page = (folder / "r.html").read_text(encoding="utf-8")
    suites = ET.parse(folder / "r.xml").getroot()
    return (re.search(r"<title>([^:<]*):", page).group(1), re.search(r"<h1>([^<]*)</h1>", page).group(1),
            suites.get("name"), suites.find("testsuite").get("name"), suites.find("testsuite/testcase").get("classname"),
            json.loads((folder / "r.json").read_text())["tool"]["name"])


def test_the_reports_name_the_command_that_made_them(tmp_path):
    """A capture's reports (`uitamr monitor`, `uitamr replay`) said "uitamr verify" in the
    page's heading, the JUnit suite and the JSON's tool, as if a simulated run made them."""
    reports = lambda folder: ("--html", folder / "r.html", "--junit", folder / "r.xml", "--json", folder / "r.json")
    (tmp_path / "monitor").mkdir()
    stream = BadMasterStream()
    done = procs.run(uitamr("monitor", "--tcp", f"127.0.0.1:{stream.port}", "--duration", "10s",
                                 "--capture", tmp_path / "c.txt", *reports(tmp_path / "monitor")),
                     capture_output=True, text=True, timeout=60)
    stream.close()
    assert done.returncode == 1, done.stdout + done.stderr
    assert _makers(tmp_path / "monitor") == ("uitamr monitor",) * 4 + ("uitamr.monitor.line", "uitamr monitor")
    (tmp_path / "replay").mkdir()
    done = procs.run(uitamr("replay", tmp_path / "c.txt", *reports(tmp_path / "replay")),
                     capture_output=True, text=True, timeout=60)
    assert done.returncode == 1, done.stdout + done.stderr
    assert _makers(tmp_path / "replay") == ("uitamr replay",) * 4 + ("uitamr.replay.line", "uitamr replay")
    (tmp_path / "verify").mkdir()  # a simulated run's stay as they were
    done = procs.run(uitamr("verify", "--scenario", ROOT / "plc" / "scenarios" / "fx3u-healthy.toml",
                                 "--duration", "2s", *reports(tmp_path / "verify")),
                     capture_output=True, text=True, timeout=120)
    assert done.returncode in (0, 1), done.stdout + done.stderr
    assert _makers(tmp_path / "verify") == ("uitamr verify",) * 4 + ("uitamr.verify.fx3u", "uitamr verify")


def test_replay_of_another_of_the_toolkits_files_says_what_it_is(tmp_path):
    """`uitamr replay` given a scenario, ST source or a report said only "expected a time in
    seconds at the start of the line": it says what the file is, and what to give instead."""
    from click.testing import CliRunner

    from verifier.cli import main

    report = tmp_path / "r"
    made = CliRunner().invoke(main, ["replay", str(CAPTURES / "bad-master.txt"), "--json", f"{report}.json",
                                     "--html", f"{report}.html", "--junit", f"{report}.xml"])
    assert made.exit_code == 1, made.output
    scenario = ROOT / "plc" / "scenarios" / "fx3u-healthy.toml"
    source = ROOT / "plc" / "core" / "UITAMR_Engine.st"
    instead = "replay reads a --trace file (JSON Lines) or a plain capture (docs/commissioning.md)"
    cases = [(scenario, f"{scenario}:1:1: ", f"this is a scenario file: run it with uitamr verify --scenario {scenario}"),
             (source, f"{source}:1:1: ", f"this is ST source: run it with uitamr verify {source}"),
             (f"{report}.json", f"{report}.json:1:2: ", "this is a --json report"),
             (f"{report}.html", f"{report}.html:1:1: ", "this is a --html report"),
             (f"{report}.xml", f"{report}.xml:1:1: ", "this is a --junit report")]
    for path, place, what in cases:
        done = CliRunner().invoke(main, ["replay", str(path)])
        assert done.exit_code == 2, done.output
        assert done.stderr.startswith(f"uitamr replay: {place}") and done.stderr.endswith(f"; {what}; {instead}\n"), \
            done.stderr
    (tmp_path / "notes.txt").write_text("hello\n", encoding="utf-8")  # anything else: the place alone
    done = CliRunner().invoke(main, ["replay", str(tmp_path / "notes.txt")])
    assert done.stderr == (f"uitamr replay: {tmp_path / 'notes.txt'}:1:1: expected a time in seconds (e.g. 0.250) at "
                           "the start of the line\n")


def test_monitor_serial_takes_a_pyserial_url(tmp_path):
    """--serial takes pyserial URLs as well as device names: socket:// reads the same
    stream through pyserial's own URL handler, and finds the bad master's findings. (The
    stream starts 0.3 s after the connection: pyserial's socket:// open empties the
    socket, and would drop bytes already sent, as a monitor started mid-frame would.)"""
    done, stream, _ = monitor_the_bad_master_stream(tmp_path, "socket://127.0.0.1:{port}", "--duration", "3s",
                                                    linger_s=1.0, lead_s=0.3)
    assert f"listening on socket://127.0.0.1:{stream.port} (9600 8N1" in done.stdout


def test_on_a_terminal_a_rich_panel_counts_frames_and_findings_under_the_lines(tmp_path):
    """The live console view: the monitor's output is a terminal (a pty), so a rich panel
    under the frame lines counts requests, replies and findings per rule while it runs;
    the frames and findings are still printed as lines above it."""
    import pty

    stream = BadMasterStream(linger_s=1.0)  # the panel refreshes 4 times a second: let it show the last counts
    terminal, end = pty.openpty()
    monitor = procs.spawn(uitamr("monitor", "--tcp", f"127.0.0.1:{stream.port}", "--duration", "10s"),
                          stdin=end, stdout=end, stderr=end,
                          env={**os.environ, "COLUMNS": "160", "LINES": "40", "TERM": "xterm"})
    os.close(end)
    out = b""
    deadline = time.monotonic() + WAIT_S
    while time.monotonic() < deadline:
        ready, _, _ = select.select([terminal], [], [], 0.2)
        if ready:
            try:
                data = os.read(terminal, 65536)
            except OSError:  # the monitor closed its end
                break
            if not data:
                break
            out += data
        elif monitor.poll() is not None:
            break
    os.close(terminal)
    monitor.wait(timeout=WAIT_S)
    stream.close()
    text = re.sub(r"\x1b\[[0-9;?]*[A-Za-z]", "", out.decode("utf-8", errors="replace"))
    assert monitor.returncode == 1, text
    assert f"uitamr monitor — tcp 127.0.0.1:{stream.port} (Ctrl-C stops and writes the reports)" in text
    rows = re.findall(r"│ (\d+) +│ (\d+) +│ ([^│]*?) +│", text)
    assert ("0", "0", "none") in rows  # the panel is there from the start ...
    # ... and counts (the PACING count depends on the host keeping the stream's 100 ms gaps)
    assert any(row[:2] == ("6", "5") and "UITAMR-CRC ×1" in row[2] and "UITAMR-POWERON-STOP ×1" in row[2]
               for row in rows), rows
    assert "01 06 01 01 00 00 D9 F6    run point/script 1 (01/01)" in text  # the frame lines above it
    assert "0.000 s  UITAMR-POWERON-STOP: the first control command" in text  # a finding line above it


def _dropped_inside_a_frame(tmp_path: Path, partial: bytes, *before: bytes, stalled_if=lambda done: True):
    """`uitamr monitor --tcp` (with --json, --junit and --capture in an attempt's folder) on
    a converter that streams `before` (6 ms apart) and, 0.3 s on, closes the connection
    `partial` bytes into a frame: (the monitor's run, the attempt's folder, the port). The
    cut bytes go out with the connection's end in one segment (MSG_MORE, then the
    shutdown): a host stall before the shutdown could let the monitor see them end by
    silence instead - measured, and an attempt where it came and `stalled_if` the run
    runs again."""
    for attempt in range(3):
        server = socket.create_server(("127.0.0.1", 0))
        port = server.getsockname()[1]
        gap = []

        def stream():
            connection, _ = server.accept()
            with connection:
                for data in before:
                    connection.sendall(data)
                    time.sleep(0.006)
                time.sleep(0.3)
                sent = time.monotonic()
                connection.send(partial, socket.MSG_MORE)
                connection.shutdown(socket.SHUT_WR)
                gap.append(time.monotonic() - sent)

        thread = threading.Thread(target=stream, daemon=True)
        thread.start()
        folder = tmp_path / f"attempt{attempt}"
        folder.mkdir()
        done = procs.run(uitamr("monitor", "--tcp", f"127.0.0.1:{port}", "--duration", "10s",
                                "--json", folder / "m.json", "--junit", folder / "m.xml", "--capture", folder / "c.txt"),
                         capture_output=True, text=True, timeout=60)
        thread.join(timeout=5)
        server.close()
        if gap and gap[0] > 0.02 and stalled_if(done):
            continue  # the server thread stalled between the bytes and the shutdown
        return done, folder, port
    pytest.fail("the stream's server thread stalled in every attempt")


def test_a_converter_that_drops_the_connection_inside_a_frame_is_not_the_plcs_short_frame(tmp_path):
    """Seen on the converter route: the converter closed the connection five bytes into a
    status read. Those bytes were cut by the end of the capture, not sent short by the
    PLC: no CRC and FORMAT findings (exit 1) against a healthy PLC, but a note, live and in
    the replay of the capture."""
    done, folder, _ = _dropped_inside_a_frame(tmp_path, READ[:5], STOP, STOP,  # the stop and its echo
                                              stalled_if=lambda done: done.returncode == 1)
    # no finding; the closed connection made it a session cut short (exit 4), not a pass
    assert done.returncode == 4, done.stdout + done.stderr
    note = "the capture ended inside a frame: its first 5 byte(s) (01 01 00 00 00) were not judged"
    assert "the server closed the connection" in done.stdout and note in done.stdout
    report = json.loads((folder / "m.json").read_text())
    assert report["verdict"] == "cut-short" and note in report["scenarios"][0]["notes"]
    # the plain capture does not carry the cut (commissioning.md §6): its frames pass
    replayed = procs.run(uitamr("replay", folder / "c.txt"), capture_output=True, text=True,
                         timeout=WAIT_S)
    assert replayed.returncode == 0 and note in replayed.stdout, replayed.stdout + replayed.stderr


def test_a_port_that_went_away_after_a_few_bytes_and_no_frame_says_it_saw_them(tmp_path):
    """The converter closed the connection five bytes into the first frame: nothing was
    verified (exit 3), but the headline said 'no bytes were seen on ... before it went
    away' while the note beside it named the five bytes cut. It says what came now, live
    and in the replay of the capture that holds them."""
    done, folder, port = _dropped_inside_a_frame(tmp_path, READ[:5], stalled_if=lambda done: done.returncode != 3)
    assert done.returncode == 3, done.stdout + done.stderr
    assert re.search(rf"^NO TRAFFIC: only 5 byte\(s\) \(01 01 00 00 00\), no whole frame, were seen on tcp "
                     rf"127\.0\.0\.1:{port} in \d+\.\d s, before it went away: check that the converter streams",
                     done.stdout, re.M), done.stdout
    assert "no bytes were seen" not in done.stdout
    assert "its first 5 byte(s) (01 01 00 00 00) were not judged" in done.stdout  # the note, as before
    report = json.loads((folder / "m.json").read_text())
    assert report["verdict"] == "no-traffic" and report["scenarios"][0]["no_traffic"].startswith("only 5 byte(s)")
    replayed = procs.run(uitamr("replay", folder / "c.txt"), capture_output=True, text=True, timeout=WAIT_S)
    assert replayed.returncode == 3, replayed.stdout + replayed.stderr
    assert (f"NO TRAFFIC: {folder / 'c.txt'} holds only 5 byte(s) (01 01 00 00 00), no whole frame, so nothing "
            "was verified") in replayed.stdout, replayed.stdout


def test_a_monitor_test_case_names_no_port_as_its_file(tmp_path):
    """A monitor's JUnit test case had file="tcp 127.0.0.1:PORT" (or "/dev/ttyUSB0"): no
    file of the repository, which a JUnit action (GitHub, GitLab) annotates or links as
    one. It has no `file` now (the port is in its name); a replay's names its capture file."""
    server = socket.create_server(("127.0.0.1", 0))
    port = server.getsockname()[1]
    thread = threading.Thread(target=lambda: server.accept()[0].recv(1), daemon=True)  # connects, sends nothing
    thread.start()
    done = procs.run(uitamr("monitor", "--tcp", f"127.0.0.1:{port}", "--duration", "1s", "--junit", tmp_path / "m.xml"),
                     capture_output=True, text=True, timeout=WAIT_S)
    server.close()
    assert done.returncode == 3, done.stdout + done.stderr
    (case,) = ET.parse(tmp_path / "m.xml").getroot().iter("testcase")
    assert (case.get("name"), case.get("file"), case.get("line")) == (f"monitor tcp 127.0.0.1:{port}", None, None)
    capture = tmp_path / "c.txt"
    capture.write_text(f"0.1 {protocol.hex_bytes(STOP)}\n0.106 {protocol.hex_bytes(STOP)}\n", encoding="utf-8")
    done = procs.run(uitamr("replay", capture, "--junit", tmp_path / "r.xml"), capture_output=True, text=True,
                     timeout=WAIT_S)
    assert done.returncode == 0, done.stdout + done.stderr
    (case,) = ET.parse(tmp_path / "r.xml").getroot().iter("testcase")
    assert case.get("file") == str(capture)


def test_a_capture_that_ends_inside_a_frame_leaves_that_frame_unjudged():
    session = session_of([Chunk(10_000, STOP), Chunk(20_000, STOP), Chunk(320_000, READ[:6])])
    assert [f.data for f in session.frames] == [STOP, STOP] and session.cut_off == READ[:6]
    assert not rules_of(session)
    # bytes of no known frame are judged at the end, as before: they may be the PLC's
    session = session_of([Chunk(10_000, STOP), Chunk(20_000, STOP), Chunk(320_000, b"\x01\x99\x00")])
    assert session.frames[-1].data == b"\x01\x99\x00" and session.cut_off == b""


# --------------------------------------------------------------------- no traffic: nothing verified
def test_a_tcp_stream_that_carries_nothing_is_no_traffic_not_a_pass(tmp_path):
    """A converter port that streams no bytes (wrong port, its serial side miswired or at
    another baud): the monitor verified nothing, so it does not pass - exit 3, and every
    report says so."""
    server = socket.create_server(("127.0.0.1", 0))
    port = server.getsockname()[1]
    thread = threading.Thread(target=lambda: server.accept()[0].recv(1), daemon=True)  # connects, sends nothing
    thread.start()
    done = procs.run(uitamr("monitor", "--tcp", f"127.0.0.1:{port}", "--duration", "1s",
                                 "--json", tmp_path / "m.json", "--junit", tmp_path / "m.xml",
                                 "--html", tmp_path / "m.html", "--trace", tmp_path / "m.jsonl"),
                     capture_output=True, text=True, timeout=WAIT_S)
    server.close()
    assert done.returncode == 3, done.stdout + done.stderr
    (verdict,) = [line for line in done.stdout.splitlines() if line.startswith("NO TRAFFIC:")]
    assert verdict.startswith(f"NO TRAFFIC: no bytes were seen on tcp 127.0.0.1:{port} in 1.0 s: check that the "
                              "converter streams the line to this port"), done.stdout
    assert "9600 8N1" in verdict and "PASS" not in done.stdout and "Traceback" not in done.stderr
    report = json.loads((tmp_path / "m.json").read_text())
    assert report["verdict"] == "no-traffic" and report["scenarios"][0]["verdict"] == "no-traffic"
    assert report["scenarios"][0]["no_traffic"] == verdict.removeprefix("NO TRAFFIC: ")
    assert report["summary"]["passed"] == 0 and report["summary"]["no_traffic"] == 1
    assert report["scenarios"][0]["ended"] == 1.0  # its --duration (test_a_host_stall_at_the_deadline_...)
    junit = (tmp_path / "m.xml").read_text()
    assert 'errors="1"' in junit and 'type="no-traffic"' in junit and "no bytes were seen" in junit
    html = (tmp_path / "m.html").read_text()
    assert '<span class="badge no-traffic" id="verdict">NO TRAFFIC</span>' in html and "<b>No traffic:</b>" in html
    assert (tmp_path / "m.jsonl").read_text() == ""


def test_a_host_stall_at_the_deadline_is_not_time_listened(tmp_path):
    """A monitor the host did not run when its --duration ran out (here stopped with
    SIGSTOP for 1.5 s from its start, as a loaded PC does for a moment) noticed the deadline
    late and said "no bytes were seen on ... in 1.5 s" for --duration 1s, and its report's
    `ended` said 1.5 (so a NO TRAFFIC test expecting "in 1.0 s" could fail on a loaded
    host). Ended by its duration, it listened its duration."""
    server = socket.create_server(("127.0.0.1", 0))
    port = server.getsockname()[1]
    thread = threading.Thread(target=lambda: server.accept()[0].recv(1), daemon=True)  # connects, sends nothing
    thread.start()
    monitor = start("monitor", "--tcp", f"127.0.0.1:{port}", "--duration", "1s", "--json", tmp_path / "m.json")
    wait_for_line(monitor, "reading, connected")
    monitor.send_signal(signal.SIGSTOP)
    time.sleep(1.5)  # the stall: past the deadline however late the SIGSTOP came
    monitor.send_signal(signal.SIGCONT)
    out, err = procs.finish(monitor, WAIT_S)
    server.close()
    assert monitor.returncode == 3, out + err
    assert f"no bytes were seen on tcp 127.0.0.1:{port} in 1.0 s:" in out, out
    assert json.loads((tmp_path / "m.json").read_text())["scenarios"][0]["ended"] == 1.0
    # as commissioning.md's row on a stalled host says
    assert "A stall when `--duration` runs out does not count as time listened" in \
        (ROOT / "docs" / "commissioning.md").read_text(encoding="utf-8")


@pytest.mark.serial
def test_a_silent_serial_line_names_the_port_and_the_line_settings(tmp_path):
    bus = LineBus(tmp_path)
    try:
        done = procs.run(uitamr("monitor", "--serial", bus.tap, "--duration", "1s", "--baud", "19200",
                                     "--framing", "8E1", "--json", tmp_path / "m.json"),
                         capture_output=True, text=True, timeout=WAIT_S)
    finally:
        bus.close()
    assert done.returncode == 3, done.stdout + done.stderr
    assert (f"NO TRAFFIC: no bytes were seen on {bus.tap} in 1.0 s: check the wiring (A, B, GND), the port "
            "name and 19200 8E1") in done.stdout
    assert json.loads((tmp_path / "m.json").read_text())["verdict"] == "no-traffic"


def test_replay_of_a_capture_with_no_bytes_is_no_traffic_and_findings_come_first(tmp_path):
    empty = tmp_path / "site.txt"
    empty.write_text("# uitamr monitor capture of /dev/ttyUSB0, 9600 8N1\n", encoding="utf-8")
    done = procs.run(uitamr("replay", empty, "--json", tmp_path / "r.json"), capture_output=True, text=True,
                     timeout=WAIT_S)
    assert done.returncode == 3, done.stdout + done.stderr
    assert f"NO TRAFFIC: {empty} holds no bytes, so nothing was verified" in done.stdout
    assert json.loads((tmp_path / "r.json").read_text())["verdict"] == "no-traffic"
    done = procs.run(uitamr("replay", empty, CAPTURES / "bad-master.txt", "--json", tmp_path / "r.json"),
                     capture_output=True, text=True, timeout=WAIT_S)
    assert done.returncode == 1, done.stdout + done.stderr  # a rule broken outranks a capture with nothing
    assert "FAIL: 1 of 2 capture(s) failed, 1 saw no traffic" in done.stdout
    report = json.loads((tmp_path / "r.json").read_text())
    assert report["verdict"] == "fail" and [s["verdict"] for s in report["scenarios"]] == ["no-traffic", "fail"]
    # counted as the console counts them: passed + failed + no_traffic = scenarios
    assert {key: report["summary"][key] for key in ("scenarios", "passed", "failed", "no_traffic")} == {
        "scenarios": 2, "passed": 0, "failed": 1, "no_traffic": 1}


def test_a_port_that_cannot_be_opened_exits_2_with_its_name(tmp_path):
    done = procs.run(uitamr("monitor", "--serial", tmp_path / "nope"), capture_output=True, text=True,
                     timeout=WAIT_S)
    assert done.returncode == 2 and "nope" in done.stderr and "Traceback" not in done.stderr
    done = procs.run(uitamr("monitor", "--tcp", "127.0.0.1:1"), capture_output=True, text=True,
                     timeout=WAIT_S)
    assert done.returncode == 2 and "127.0.0.1:1" in done.stderr
    # a converter that refuses: was the socket's bare "Connection refused", nothing to check named
    assert ("cannot connect to 127.0.0.1:1: refused: nothing accepts connections on that port; check the address "
            "and port (the converter's web page), that it is set to TCP server and is on") in done.stderr, done.stderr


# --------------------------------------------------------------------- a port that went away: cut short
def _every_report(folder: Path) -> list:
    return ["--json", folder / "m.json", "--junit", folder / "m.xml", "--html", folder / "m.html",
            "--trace", folder / "m.jsonl", "--capture", folder / "c.txt"]


def assert_every_report_says_cut_short(folder: Path, out: str, source: str, asked: str, frames: int) -> str:
    """A session whose port went away after `frames` frame(s) that broke no rule: its
    console's verdict line says CUT SHORT, how long it ran of the `asked` --duration and
    what to check, and every report written by `_every_report` says the same; the sentence."""
    (verdict,) = [line for line in out.splitlines() if line.startswith("CUT SHORT:")]
    said = verdict.removeprefix("CUT SHORT: ")
    assert re.fullmatch(rf"{re.escape(str(source))} went away after \d+\.\d s of the {asked} s asked: the {frames} "
                        r"frame\(s\) before it were verified, but the run is not the whole session; check .+, then "
                        "monitor the whole session again", said), said
    assert "PASS" not in out
    report = json.loads((folder / "m.json").read_text())
    assert report["verdict"] == report["scenarios"][0]["verdict"] == "cut-short"
    assert report["scenarios"][0]["cut_short"] == said and report["scenarios"][0]["no_traffic"] is None
    assert {key: report["summary"][key] for key in ("passed", "failed", "no_traffic", "cut_short")} == {
        "passed": 0, "failed": 0, "no_traffic": 0, "cut_short": 1}
    junit = ET.parse(folder / "m.xml").getroot()
    (error,) = junit.iter("error")  # CI shows the session as not passed, with the sentence
    assert (error.get("type"), error.get("message"), error.text) == ("cut-short", f"cut short: {said}", said)
    assert junit.get("errors") == "1" and junit.get("failures") == "0"
    html = (folder / "m.html").read_text()
    assert '<span class="badge cut-short" id="verdict">CUT SHORT</span>' in html and "<b>Cut short:</b>" in html
    assert json.loads((folder / "m.jsonl").read_text().splitlines()[-1])["cut_short"] == said  # the end record
    return said


def assert_the_replay_of_the_trace_is_cut_short(folder: Path, said: str) -> None:
    """`uitamr replay` of the session's trace: its end record says the port went away, so
    the replay is cut short too (exit 4, the same sentence); the plain capture cannot say it
    (commissioning.md §6): its replay judges the frames alone."""
    replayed = procs.run(uitamr("replay", folder / "m.jsonl", "--json", folder / "r.json"), capture_output=True,
                         text=True, timeout=WAIT_S)
    assert replayed.returncode == 4, replayed.stdout + replayed.stderr
    assert f"CUT SHORT: {said}" in replayed.stdout
    assert json.loads((folder / "r.json").read_text())["scenarios"][0]["cut_short"] == said
    plain = procs.run(uitamr("replay", folder / "c.txt"), capture_output=True, text=True, timeout=WAIT_S)
    assert plain.returncode == 0, plain.stdout + plain.stderr


def _unplugged(folder: Path, sent: bytes, *options) -> tuple[int, str, str]:
    """`uitamr monitor --serial` with `options` on the tap of a socat pty pair in `folder`
    (folder/tap): `sent` written from the line's end (and shown by the monitor), then the
    tap's adapter pulled out (socat ended); the monitor's exit status, stdout and stderr."""
    monitor = None
    with pty_cable(folder, "tap", "line") as socat:
        try:
            monitor = start("monitor", "--serial", folder / "tap", *options)
            wait_for_line(monitor, "listening")
            with open(folder / "line", "wb", buffering=0) as plc:
                if sent:
                    plc.write(sent)
                    wait_for_line(monitor, "PLC → robot")
                socat.terminate()  # the adapter is pulled out
                socat.wait(timeout=WAIT_S)
            out, err = monitor.communicate(timeout=WAIT_S)
        finally:
            if monitor is not None and monitor.poll() is None:
                monitor.kill()
                monitor.wait(timeout=WAIT_S)
    return monitor.returncode, out, err


@pytest.mark.serial
def test_an_adapter_unplugged_mid_session_is_cut_short_not_a_pass(tmp_path):
    """The tap's USB adapter unplugged (its socat pty pair ended) while the monitor listened:
    the session ends, the reports and the capture are written, and the reason says what
    happened, not pyserial's "device reports readiness to read but returned no data (device
    disconnected or multiple access on port?)" (the port is locked: nobody else reads it).
    The stop command seen broke no rule, and the session exited 0, a PASS: a scripted
    `monitor --duration 60s ... && echo accepted` accepted a few seconds of the minute.
    It is cut short now: exit 4, and every report says so (commissioning.md §2)."""
    tap = tmp_path / "tap"
    returncode, out, err = _unplugged(tmp_path, STOP, "--duration", "60s", *_every_report(tmp_path))
    gone = (f"{tap}: the port went away: the USB adapter was unplugged or lost power (or the program that made the "
            "pty ended); plug it back in and start again")
    assert f"stopped: {gone}" in out, out + err
    assert "multiple access" not in out + err and "Traceback" not in err
    report = json.loads((tmp_path / "m.json").read_text())
    assert f"the capture ended early: {gone}" in report["scenarios"][0]["notes"], report["scenarios"][0]["notes"]
    assert f"# the capture ended early: {gone}" in (tmp_path / "c.txt").read_text()
    assert returncode == 4, out + err
    said = assert_every_report_says_cut_short(tmp_path, out, tap, "60", 1)
    assert "check the USB adapter's cable and power" in said
    assert_the_replay_of_the_trace_is_cut_short(tmp_path, said)


@pytest.mark.serial
def test_an_adapter_unplugged_before_a_byte_came_is_no_traffic_that_says_so(tmp_path):
    """Unplugged before the line sent anything: nothing was verified (exit 3, as a silent
    session), and the sentence says the port went away - it was "no bytes were seen ...:
    check the wiring" alone, as if the monitor had listened all along."""
    tap = tmp_path / "tap"
    returncode, out, err = _unplugged(tmp_path, b"", "--duration", "60s", "--json", tmp_path / "m.json")
    assert returncode == 3, out + err
    assert re.search(rf"NO TRAFFIC: no bytes were seen on {re.escape(str(tap))} in \d+\.\d s, before it went away: "
                     r"check the wiring \(A, B, GND\)", out), out
    report = json.loads((tmp_path / "m.json").read_text())
    assert report["verdict"] == "no-traffic" and report["scenarios"][0]["cut_short"] is None
    assert report["summary"]["cut_short"] == 0


def _converter(*frames: bytes, reset: bool = False):
    """A TCP server on 127.0.0.1 that streams `frames` 20 ms apart to the one client it
    accepts, waits 0.3 s and closes the connection (`reset`: with a TCP RST): (port,
    server, thread)."""
    import struct

    server = socket.create_server(("127.0.0.1", 0))

    def stream():
        connection, _ = server.accept()
        for data in frames:
            connection.sendall(data)
            time.sleep(0.02)
        time.sleep(0.3)
        if reset:
            connection.setsockopt(socket.SOL_SOCKET, socket.SO_LINGER, struct.pack("ii", 1, 0))
        connection.close()

    thread = threading.Thread(target=stream, daemon=True)
    thread.start()
    return server.getsockname()[1], server, thread


@pytest.mark.parametrize("reset", [False, True], ids=["closed", "reset"])
def test_a_converter_that_ends_the_stream_with_clean_frames_is_cut_short(tmp_path, reset):
    """The converter closed (or reset) the connection 0.4 s into a --duration 10min session
    whose frames broke no rule: it exited 0, a PASS of a session that was not listened to.
    Cut short now: exit 4, with how long it ran of the 600 s asked, in every report, and in
    the replay of its trace."""
    port, server, thread = _converter(STOP, STOP, reset=reset)
    done = procs.run(uitamr("monitor", "--tcp", f"127.0.0.1:{port}", "--duration", "10min",
                            *_every_report(tmp_path)), capture_output=True, text=True, timeout=60)
    thread.join(timeout=5)
    server.close()
    assert done.returncode == 4, done.stdout + done.stderr
    said = assert_every_report_says_cut_short(tmp_path, done.stdout, f"tcp 127.0.0.1:{port}", "600", 2)
    assert "check the converter (its power, its network" in said
    assert_the_replay_of_the_trace_is_cut_short(tmp_path, said)


def test_findings_before_the_converter_closed_still_fail(tmp_path):
    """Findings win over the cut: a run point before the stop (UITAMR-POWERON-STOP), then the
    converter closed the connection: exit 1, FAIL; the reports still say the run was cut
    short (the JSON's cut_short, an error beside the rule's failure in the JUnit), and
    without --duration the sentence says it went away before Ctrl-C."""
    run_point = frame("run-point", "1")
    port, server, thread = _converter(run_point, run_point)
    done = procs.run(uitamr("monitor", "--tcp", f"127.0.0.1:{port}", *_every_report(tmp_path)),
                     capture_output=True, text=True, timeout=60)
    thread.join(timeout=5)
    server.close()
    assert done.returncode == 1, done.stdout + done.stderr
    assert "FAIL: 1 of 1 capture(s) failed" in done.stdout and "CUT SHORT:" not in done.stdout
    report = json.loads((tmp_path / "m.json").read_text())
    assert report["verdict"] == report["scenarios"][0]["verdict"] == "fail"
    assert report["summary"]["cut_short"] == 0 and report["summary"]["failed"] == 1
    said = report["scenarios"][0]["cut_short"]
    assert said.startswith(f"tcp 127.0.0.1:{port} went away after ") and " s before Ctrl-C: the 2 frame(s)" in said
    junit = ET.parse(tmp_path / "m.xml").getroot()
    assert [(e.tag, e.get("type")) for e in junit.find(".//testcase") if e.tag in ("failure", "error")] == [
        ("error", "cut-short"), ("failure", "UITAMR-POWERON-STOP")]
    replayed = procs.run(uitamr("replay", tmp_path / "m.jsonl"), capture_output=True, text=True, timeout=WAIT_S)
    assert replayed.returncode == 1, replayed.stdout + replayed.stderr


@pytest.mark.serial
def test_a_read_of_a_port_that_went_away_is_the_end_of_the_capture_not_a_traceback(tmp_path):
    """The tap's adapter unplugged between two reads: pyserial's in_waiting (an ioctl) raised
    OSError (EIO), which went past the monitor's handler - a traceback and no report, no
    capture (seen 2 runs in 4 with the tap's socat ended mid-session, on a loaded PC). Here
    that moment for sure: the port is open, its pty pair gone, and the next read comes."""
    from verifier.monitor.sources import SerialSource, SourceError

    tap = tmp_path / "tap"
    with pty_cable(tmp_path, "tap", "line") as socat:
        source = SerialSource(str(tap), 9600, 8, "N", 1)
        socat.terminate()
        socat.wait(timeout=WAIT_S)
        with pytest.raises(SourceError) as raised:
            source.read()
        source.close()
    assert str(raised.value) == (f"{tap}: the port went away: the USB adapter was unplugged or lost power (or the "
                                 "program that made the pty ended); plug it back in and start again")


@pytest.mark.serial
def test_a_port_another_reader_holds_is_refused_not_shared(tmp_path):
    """Seen on the bench: a monitor started on the port `uitamr emulate` was serving read
    a share of its bytes, lost the port and called it NO TRAFFIC with "check the wiring".
    Two readers of one port each get only part of the line: the second one is refused."""
    bus = LineBus(tmp_path)
    robot = start("emulate", "--serial", bus.robot)
    first = None
    try:
        wait_for_line(robot, "listening")
        done = procs.run(uitamr("monitor", "--serial", bus.robot, "--duration", "1s"), capture_output=True,
                         text=True, timeout=WAIT_S)
        assert done.returncode == 2, done.stdout + done.stderr
        assert f"cannot open {bus.robot}: another program has it open and locked" in done.stderr
        first = start("monitor", "--serial", bus.tap, "--duration", "20s")
        wait_for_line(first, "listening")
        done = procs.run(uitamr("monitor", "--serial", bus.tap, "--duration", "1s"), capture_output=True,
                         text=True, timeout=WAIT_S)
        assert done.returncode == 2 and "another uitamr monitor?" in done.stderr, done.stdout + done.stderr
    finally:
        for process in (robot, first):
            if process is not None:
                process.send_signal(signal.SIGINT)
                procs.finish(process, WAIT_S)
        bus.close()


def test_an_empty_port_name_is_named_as_empty():
    done = procs.run(uitamr("monitor", "--serial", "", "--duration", "1s"), capture_output=True, text=True,
                     timeout=WAIT_S)
    assert done.returncode == 2 and "the port name is empty" in done.stderr and "Traceback" not in done.stderr


@pytest.mark.parametrize("record, message", [
    ('{"t": NaN, "dir": "tx", "hex": "01"}', "'t' is NaN; expected a time in seconds from 0 to 1e+09"),
    ('{"t": 1e400, "dir": "tx", "hex": "01"}', "'t' is Infinity; expected a time in seconds"),
    ('{"t": true, "dir": "tx", "hex": "01"}', "'t' is true; expected a time in seconds"),
    ('{"t": "x", "dir": "tx", "hex": "01"}', "'t' is \"x\"; expected a time in seconds"),
    ('{"t": 0.2, "t_end": 0.1, "dir": "tx", "hex": "01"}', "'t_end' (0.1 s) is before 't' (0.2 s)"),
    ('{"t": 0.1, "dir": "tx", "hex": "ZZ"}', "'hex' is 'ZZ'; expected bytes in hex"),
    ('{"t": 0.1, "dir": "tx", "hex": 5}', "'hex' is 5; expected bytes in hex"),
    ('{"t": 0.1, "dir": "tx", "hex": " "}', "'hex' is ' '; expected bytes in hex"),  # was judged as a 0-byte frame
    # were a ValueError (int() reads at most 4300 digits) and a RecursionError from json.loads
    ('{"t": ' + "9" * 5000 + ', "dir": "tx", "hex": "01"}', "not a trace record: it holds a number too long"),
    ('{"t": 0, "x": ' + "[" * 100_000 + "]" * 100_000 + "}", "not a trace record: arrays or objects nested"),
])
def test_a_trace_record_with_a_bad_value_names_the_key(tmp_path, record, message):
    path = tmp_path / "t.jsonl"
    path.write_text(record + "\n", encoding="utf-8")
    with pytest.raises(CaptureError) as caught:
        read_capture(path)
    assert str(caught.value).startswith(f"{path}:1:1: {message}")


def test_a_trace_out_of_time_order_is_an_error_not_a_reply_before_its_request(tmp_path):
    """A hand-edited or merged trace whose records go back in time was replayed as it
    stood: the reply came out 0.5 s before power-on and the run passed."""
    path = tmp_path / "t.jsonl"
    path.write_text('{"t": 1.0, "dir": "tx", "hex": "01 06 01 A0 00 00 88 14"}\n'
                    '{"t": 0.5, "dir": "rx", "hex": "01 06 01 A0 00 00 88 14"}\n', encoding="utf-8")
    done = procs.run(uitamr("replay", path), capture_output=True, text=True, timeout=WAIT_S)
    assert done.returncode == 2 and "Traceback" not in done.stderr
    assert f"{path}:2:1: 't' (0.5 s) is earlier than the record before of scenario '{path}' (1 s)" in done.stderr
    # each scenario of a trace has its own time line
    path.write_text('{"scenario": "a", "t": 1.0, "dir": "tx", "hex": "01 06 01 A0 00 00 88 14"}\n'
                    '{"scenario": "b", "t": 0.5, "dir": "tx", "hex": "01 06 01 A0 00 00 88 14"}\n', encoding="utf-8")
    assert set(read_capture(path)) == {"a", "b"}


def test_replay_refuses_to_write_a_report_over_its_own_capture(tmp_path):
    path = tmp_path / "t.jsonl"
    text = '{"t": 0.1, "t_end": 0.108, "dir": "tx", "hex": "01 06 01 A0 00 00 88 14"}\n'
    path.write_text(text, encoding="utf-8")
    done = procs.run(uitamr("replay", path, "--trace", path), capture_output=True, text=True, timeout=WAIT_S)
    assert done.returncode == 2 and "is one of the run's input files" in done.stderr
    assert path.read_text(encoding="utf-8") == text


def test_the_reports_of_a_capture_do_not_describe_a_simulated_run(tmp_path):
    """commissioning.md: the monitor and replay write "the same reports as verify". A
    replay's JUnit said "program None on line (capture), 1.306 s of virtual time, scan 0
    ms, seed 0" and its page "program ? ... virtual time · scan 0 ms · seed 0": a ticket
    with a site capture read as a simulation with no program. They now say what was
    judged: the PLC on the line, and how long the capture is."""
    import xml.etree.ElementTree as ET

    junit, html = tmp_path / "site.xml", tmp_path / "site.html"
    done = procs.run(uitamr("replay", CAPTURES / "bad-master.txt", "--junit", junit, "--html", html),
                     capture_output=True, text=True, timeout=WAIT_S)
    assert done.returncode == 1, done.stdout + done.stderr
    (out,) = [element.text for element in ET.parse(junit).iter("system-out")]
    assert out.splitlines()[1] == "the PLC on the line (capture), 1.306 s of traffic"
    page = html.read_text(encoding="utf-8")
    for wrong in ("program <code>?</code>", "virtual time", "scan 0 ms", "seed 0"):
        assert wrong not in page, wrong
    assert "the PLC on the line (capture) · 1.306 s of traffic ·" in " ".join(page.split())
    # a line at another speed: the page said "bytes at 9600 8N1" whatever --baud was
    fast = procs.run(uitamr("replay", CAPTURES / "bad-master.txt", "--baud", "19200", "--junit", junit,
                                 "--html", html), capture_output=True, text=True, timeout=WAIT_S)
    assert fast.returncode == 1, fast.stdout + fast.stderr
    page = " ".join(html.read_text(encoding="utf-8").split())
    assert "9600" not in page and "traffic captured on " in page and " at 19200 8N1" in page
    healthy = ROOT / "plc" / "scenarios" / "fx3u-healthy.toml"
    verified = procs.run(uitamr("verify", "--scenario", healthy, "--duration", "2s", "--junit", junit,
                                     "--html", html), capture_output=True, text=True, timeout=120)
    assert verified.returncode == 1, verified.stdout + verified.stderr  # expectations past 2 s fail
    (out,) = [element.text for element in ET.parse(junit).iter("system-out")]
    assert "program UITAMR_ExampleFx3 on fx3u (fx3:1), 2.000 s of virtual time, scan 10 ms, seed 0" in out
    assert "virtual time" in html.read_text(encoding="utf-8")


def test_a_capture_named_with_control_characters_does_not_restyle_the_terminal(tmp_path):
    """The run's name was shown escaped, but its file path beside it was printed raw: a
    file name holding ESC [31m turned the console red, a newline split the verdict line."""
    path = tmp_path / "site\x1b[31m\nred.txt"
    path.write_text("0.1 01 06 01 A0 00 00 88 14\n", encoding="utf-8")
    done = procs.run(uitamr("replay", path), capture_output=True, text=True, timeout=WAIT_S)
    assert done.returncode == 0, done.stderr
    assert "\x1b" not in done.stdout and "site\\x1b[31m\\x0ared.txt" in done.stdout


def test_a_named_pipe_is_not_read_as_a_capture(tmp_path):
    fifo = tmp_path / "c.txt"
    os.mkfifo(fifo)
    done = procs.run(uitamr("replay", fifo), capture_output=True, text=True, timeout=WAIT_S)
    assert done.returncode == 2 and "not a regular file" in done.stderr


@pytest.mark.serial
def test_a_capture_that_cannot_be_written_is_an_error_not_a_traceback(line, tmp_path):
    """/proc/version exists in a folder that exists, so it passes the check before the
    session, and only fails at the write at its end."""
    monitor = monitor_on(line, tmp_path, "--duration", "1s", "--capture", "/proc/version")
    out, err = procs.finish(monitor, WAIT_S)
    assert monitor.returncode == 2 and "Traceback" not in err
    assert "uitamr monitor: cannot write the capture /proc/version" in err
    assert (tmp_path / "m.json").exists()  # the reports are written first


@pytest.mark.serial
def test_the_capture_is_written_even_when_a_report_cannot_be(bare_line, tmp_path):
    """The line's bytes cannot be had again; a report can, from the capture (`uitamr
    replay`). A --json in a folder that exists but cannot be written used to end the
    command before the capture was written: the capture was lost."""
    monitor = start("monitor", "--serial", bare_line.tap, "--duration", "60s", "--json", "/proc/m.json",
                    "--capture", tmp_path / "c.txt")
    wait_for_line(monitor, "listening")
    master = Master(bare_line, Robot(SETTINGS))
    master.send(STOP)
    master.close()
    # stopped once it has the echo: with a 2 s --duration, a host that held the test back
    # that long would leave the capture empty
    wait_for_line(monitor, "echo: stop")
    monitor.send_signal(signal.SIGINT)
    out, err = procs.finish(monitor, WAIT_S)
    assert monitor.returncode == 2 and "Traceback" not in err
    assert "cannot write /proc/m.json" in err
    chunks = parse_plain((tmp_path / "c.txt").read_text(encoding="utf-8"))
    assert b"".join(c.data for c in chunks) == STOP + STOP  # the capture holds the stop and its echo


def test_an_html_report_of_a_capture_spanning_years_stays_small(tmp_path):
    """A tick every 10 s over a 1e9 s gap was 100 million ticks: the run never ended."""
    from verifier.verify import report_html

    path = tmp_path / "gap.jsonl"
    path.write_text('{"t": 0, "dir": "tx", "hex": "01 06 01 A0 00 00 88 14"}\n'
                    '{"t": 999999999, "dir": "tx", "hex": "01 06 01 A0 00 00 88 14"}\n', encoding="utf-8")
    done = procs.run(uitamr("replay", path, "--html", tmp_path / "r.html"), capture_output=True, text=True,
                     timeout=WAIT_S)
    assert done.returncode in (0, 1), done.stderr
    assert (tmp_path / "r.html").stat().st_size < 2_000_000
    assert report_html.MAJOR_TICKS_AT_MOST == 5000


def sent_onto_the_line(line_end: int) -> bytes:
    """What the monitor wrote to the pty that stands for the adapter: its other end's bytes."""
    os.set_blocking(line_end, False)
    try:
        return os.read(line_end, 4096)
    except BlockingIOError:
        return b""


@pytest.fixture
def adapter_pty():
    """(the line's end, the port's name): a pty stands for the USB adapter, its other end
    reads what would go onto the robot's line."""
    line_end, port_end = os.openpty()
    try:
        yield line_end, os.ttyname(port_end)
    finally:
        os.close(line_end)
        os.close(port_end)


def _refused_monitor(*args) -> subprocess.CompletedProcess:
    done = procs.run(uitamr("monitor", *args, "--duration", "1s"), capture_output=True, text=True,
                     timeout=WAIT_S)
    assert done.returncode == 2, done.stdout + done.stderr
    return done


@pytest.mark.serial
def test_a_report_or_capture_named_as_the_port_is_refused_not_sent_onto_the_line(adapter_pty):
    """`uitamr monitor --serial /dev/ttyUSB0 --capture /dev/ttyUSB0` (the port typed twice)
    wrote the capture's text onto the robot's line - the monitor that "never transmits" - and
    said "wrote /dev/ttyUSB0"."""
    line_end, port = adapter_pty
    for option in ("--capture", "--json"):
        done = _refused_monitor("--serial", port, option, port)
        assert f"{port} is the port the monitor listens on, and the monitor never writes to the line" in done.stderr
        assert sent_onto_the_line(line_end) == b""


def test_a_report_named_as_the_port_is_the_junits_error_and_a_junit_named_so_is_not_written(tmp_path, adapter_pty):
    """The refusal of a report named as the port is a command-line mistake like click's own:
    it goes into --junit's file (CI shows it), unless that file is the port itself, which
    would send the JUnit's XML onto the robot's line."""
    line_end, port = adapter_pty
    report = tmp_path / "m.xml"
    _refused_monitor("--serial", port, "--json", port, "--junit", str(report))
    error = ET.parse(report).getroot().find(".//testcase/error")
    assert error is not None and "is the port the monitor listens on" in error.get("message")
    done = _refused_monitor("--serial", port, "--junit", port)
    assert f"{port} is the port the monitor listens on" in done.stderr
    assert sent_onto_the_line(line_end) == b""


def test_replay_of_a_serial_port_points_to_the_monitor():
    """`uitamr replay /dev/ttyUSB0`, the port given to the command that reads captures, said
    only "cannot read: not a regular file (a character device)"."""
    line_end, port_end = os.openpty()
    port = os.ttyname(port_end)
    try:
        done = procs.run(uitamr("replay", port), capture_output=True, text=True, timeout=WAIT_S)
    finally:
        os.close(line_end)
        os.close(port_end)
    assert done.returncode == 2 and "Traceback" not in done.stderr
    assert (f"uitamr replay: {port}: cannot read: not a regular file (a character device): a serial port, not a "
            f"capture; `uitamr monitor --serial {port}` listens on it") in done.stderr, done.stderr


def test_a_capture_named_with_a_newline_keeps_its_end_line_message_on_one_line():
    """The `end` line's message named the file a second time by hand, the raw name: a capture
    named `t<LF>c.txt` broke it into two lines though its place (Place) showed the name escaped."""
    with pytest.raises(CaptureError) as caught:
        parse_plain("0.1 01\n0.2 end\n 0.3 02\n", "t\nc.txt")
    assert str(caught.value).startswith("t\\x0ac.txt:3:2: the capture ended at its `end` line (t\\x0ac.txt:2)")


def test_a_converter_that_resets_the_stream_is_said_with_what_to_check(tmp_path):
    """`monitor --tcp` to a converter that reset its connection (restarted, lost power, dropped
    this client: a TCP RST) ended with the socket's own words, '...: Connection reset by
    peer'; it now says what happened and what to check, and still writes its reports."""
    import struct

    server = socket.create_server(("127.0.0.1", 0))
    port = server.getsockname()[1]

    def reset_after_some_bytes():
        connection, _ = server.accept()
        connection.sendall(frame("read", "task"))  # a status request: something was seen
        time.sleep(0.5)
        connection.setsockopt(socket.SOL_SOCKET, socket.SO_LINGER, struct.pack("ii", 1, 0))
        connection.close()  # linger 0: the close sends RST, not FIN

    thread = threading.Thread(target=reset_after_some_bytes, daemon=True)
    thread.start()
    done = procs.run(uitamr("monitor", "--tcp", f"127.0.0.1:{port}", "--duration", "30s",
                            "--json", tmp_path / "m.json"), capture_output=True, text=True, timeout=60)
    thread.join(10)
    server.close()
    said = done.stdout + done.stderr
    assert "Traceback" not in said and "Connection reset by peer" not in said, said
    assert (f"tcp 127.0.0.1:{port}: the server reset the connection: the converter restarted, lost power or "
            "dropped this client; check it and start again") in said, said
    assert (tmp_path / "m.json").exists(), said
