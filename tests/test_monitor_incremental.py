"""The monitor's live check judges each frame once and finds exactly what judging the whole
capture at once finds.

`MonitorSession.check` hands the rules only the frames the line has settled since the
last call (verifier/verify/rules/judge.py); `MonitorSession.violations` is the judgement of
the whole capture in one go (what `check` re-ran every half second before). Here the two
meet on real captures, on `uitamr verify`'s traffic with faults, on random byte streams
and timings (hypothesis) and on a burst streamed over TCP on 127.0.0.1: the same
violations in the same order, the same report bytes, every finding shown live exactly
once - and the rules look at each frame once, however often the session is checked.
"""
from __future__ import annotations

import json
import socket
import threading
from collections import Counter
from dataclasses import replace
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from monitor_helpers import WAIT_S, frame, uitamr
from verifier.monitor.capture import Chunk, read_capture
from verifier.monitor.framer import LineTiming
from verifier.monitor.session import PROVISIONAL_RULE, CaptureInfo, MonitorSession
from verifier.verify import report_json, report_junit
from verifier.verify.evidence import RuleOptions
from verifier.verify.runner import run_scenario
from verifier.verify.scenario import load_scenario
import procs

ROOT = Path(__file__).resolve().parent.parent
CAPTURES = Path(__file__).resolve().parent / "captures"
STOP, READ, POINT = frame("stop"), frame("read", "task"), frame("run-point", "2")
STATUS = bytes.fromhex("01 01 03 00 00 00 3C 4E")
EXCEPTION = bytes.fromhex("01 81 01 81 90")
#: what a line carries: requests, their replies, broken and foreign frames
POOL = [STOP, READ, POINT, STATUS, EXCEPTION, STOP[:-1] + b"\x15", READ[:5], b"\x02" + STOP[1:], b"\xA5\x5A"]


def live(chunks, *, tolerance_us=20_000, check_after=None, polls=(), **kw):
    """A session fed `chunks`, checked after each chunk whose index is in `check_after`
    (default: every chunk) and polled at `polls` (host times), as `uitamr monitor` does;
    the session and every finding its checks returned."""
    session = MonitorSession(CaptureInfo("test", "test"), timing=LineTiming(tolerance_us=tolerance_us), **kw)
    shown, polls = [], sorted(polls)
    for index, chunk in enumerate(chunks):
        while polls and polls[0] < chunk.t_us:
            session.poll(polls.pop(0))
            shown += session.check()
        session.feed(chunk)
        if check_after is None or index in check_after:
            shown += session.check()
    session.close()
    shown += session.check()
    return session, shown


def assert_same_as_the_whole(session: MonitorSession, shown: list) -> None:
    whole = session.violations()  # the whole capture judged at once
    result = session.result()
    assert result.violations == whole  # same violations, same order
    again = replace(result, violations=whole)
    assert json.dumps(report_json.to_dict([result])) == json.dumps(report_json.to_dict([again]))
    assert report_junit.ET.tostring(report_junit.to_element([result])) == \
        report_junit.ET.tostring(report_junit.to_element([again]))
    final = [v for found in whole.values() for v in found]
    # every finding shown live once: exactly, or (replies still failing) early, with its time and frames
    assert Counter(v for v in shown if v.rule != PROVISIONAL_RULE) == \
        Counter(v for v in final if v.rule != PROVISIONAL_RULE)
    # (early word of an overdue reply names the request alone: a late reply may join it)
    assert Counter((v.t_us, v.frames[:1]) for v in shown if v.rule == PROVISIONAL_RULE) == \
        Counter((v.t_us, v.frames[:1]) for v in final if v.rule == PROVISIONAL_RULE)
    # and the rules saw every frame once
    assert session.judged_frames == len(session.frames)


def test_the_bad_master_capture_checked_after_every_chunk():
    (chunks,) = read_capture(CAPTURES / "bad-master.txt").values()
    session, shown = live(chunks)
    assert Counter(v.rule for v in shown) == {"UITAMR-POWERON-STOP": 1, "UITAMR-PACING": 3, "UITAMR-CRC": 1}
    assert_same_as_the_whole(session, shown)


@pytest.mark.parametrize("name", ["fx3u-no-reply", "fx3u-bad-crc", "fx3u-late-reply", "fx3u-wrong-address",
                                  "fx3u-exception", "fx3u-garbage", "q-exception", "fx5u-healthy"])
@pytest.mark.parametrize("tolerance_us", [0, 20_000])
def test_verify_traffic_with_faults_checked_as_it_comes(name, tolerance_us):
    """The simulated PLC's traffic with the robot's faults (replies missing, late, broken
    for seconds: RESPONSE-HANDLING's episodes), as raw bytes, checked after every frame."""
    result = run_scenario(load_scenario(ROOT / "plc" / "scenarios" / f"{name}.toml"))
    chunks = [Chunk(f.t_end_us, f.data) for f in sorted(result.trace, key=lambda f: f.t_start_us)]
    session, shown = live(chunks, tolerance_us=tolerance_us,
                          options=RuleOptions(reply_timeout_us=300_000, response_within_us=1_000_000))
    assert_same_as_the_whole(session, shown)


def test_a_robot_that_stops_answering_is_told_while_it_goes_on():
    """Early word of replies failing for longer than the bound, before they recover; the
    finding is not shown again when the episode ends, and the report has its final words."""
    chunks = [Chunk(10_000, STOP), Chunk(20_000, STOP)]
    chunks += [Chunk(600_000 * i, READ) for i in range(1, 15)]  # no reply for 8.4 s
    chunks += [Chunk(9_000_000, READ), Chunk(9_012_000, STATUS)]
    session = MonitorSession(CaptureInfo("test", "test"))
    told_at = None
    shown = []
    for chunk in chunks:
        session.feed(chunk)
        found = session.check()
        if any(v.rule == PROVISIONAL_RULE for v in found) and told_at is None:
            told_at = chunk.t_us
        shown += found
    session.close()
    shown += session.check()
    (early,) = [v for v in shown if v.rule == PROVISIONAL_RULE]
    assert told_at is not None and told_at < 7_000_000  # 5 s after the first failure, not at the end
    assert "until the end of the run" in early.message
    (final,) = session.result().violations[PROVISIONAL_RULE]
    assert final.t_us == early.t_us and "until 9.0" in final.message
    assert_same_as_the_whole(session, shown)


@pytest.mark.parametrize("late_reply", [False, True])
def test_a_line_gone_silent_after_an_unanswered_request_is_told_while_it_lasts(late_reply):
    """The PLC asks, the robot does not answer, and nothing more comes: early word once the
    bound has passed (host time, polled), not only when the session stops. A late reply
    that comes after it joins the episode in the final words, and is not told twice."""
    session = MonitorSession(CaptureInfo("test", "test"))
    session.feed(Chunk(10_000, STOP))
    session.feed(Chunk(20_000, STOP))
    session.feed(Chunk(400_000, READ))
    shown, told_at = [], None
    for now in range(500_000, 12_000_001, 500_000):
        session.poll(now)
        found = session.check()
        if found and told_at is None:
            told_at = now
        shown += found
    if late_reply:
        session.feed(Chunk(12_100_000, STATUS))
        shown += session.check()
    session.close()
    shown += session.check()
    (early,) = shown
    assert early.rule == PROVISIONAL_RULE
    assert early.t_us == early.frames[0].t_end_us + 500_000  # the read's reply time-out ran out
    # the first poll at which the line has been silent past the 5 s bound for one longest
    # frame and the host's tolerance (a reply the host has not read yet could start before)
    assert told_at == 6_500_000
    assert "until the end of the run" in early.message
    (final,) = session.result().violations[PROVISIONAL_RULE]
    assert final.t_us == early.t_us and final.frames[0] == early.frames[0]
    assert ("late" in final.message) == late_reply
    assert_same_as_the_whole(session, shown)


def test_each_check_hands_the_rules_only_the_new_frames():
    """A long session checked after every chunk: the rules take each frame once, when it
    comes, not the whole capture again at every check (which made a 1 MB burst quadratic)."""
    pattern = [(0, STOP), (12_000, STOP), (300_000, READ), (312_000, STATUS)]
    chunks = [Chunk(600_000 * cycle + t + 10_000, data) for cycle in range(500) for t, data in pattern]
    session = MonitorSession(CaptureInfo("test", "test"))
    handed = []
    for chunk in chunks:
        before = session.judged_frames
        session.feed(chunk)
        session.check()
        handed.append(session.judged_frames - before)
    assert handed == [1] * 2000
    session.close()
    assert session.check() == [] and session.judged_frames == 2000


def test_overlapping_frames_of_a_trace_are_judged_as_a_whole_at_the_end():
    """A trace file's frames may overlap (a request before the previous one ended): later
    frames can change how earlier ones pair, so they are judged when the session ends."""
    chunks = [Chunk(8_333, STOP, "tx", 0), Chunk(20_000, STOP, "rx", 11_667), Chunk(15_000, READ, "tx", 6_667),
              Chunk(40_000, STATUS, "rx", 31_667), Chunk(400_000, POINT, "tx", 391_667)]
    session, shown = live(chunks, tolerance_us=0)
    assert Counter(v.rule for v in shown) == {"UITAMR-PACING": 1, "UITAMR-HALF-DUPLEX": 1, "UITAMR-ONE-AT-A-TIME": 1}
    assert_same_as_the_whole(session, shown)


chunk_lists = st.lists(
    st.tuples(st.sampled_from([0, 0, 500, 4_000, 9_000, 30_000, 120_000, 260_000, 600_000, 6_000_000]),
              st.lists(st.sampled_from(POOL), min_size=1, max_size=3), st.integers(0, 7)),
    max_size=60)


@settings(max_examples=300, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(chunk_lists, st.sets(st.integers(0, 60)), st.lists(st.integers(0, 20_000_000), max_size=5),
       st.sampled_from([0, 20_000]), st.sampled_from([100_000, 500_000]), st.sampled_from([800_000, 5_000_000]),
       st.booleans())
def test_random_lines_checked_at_random_times_give_the_whole_judgement(
        pieces, check_after, polls, tolerance_us, reply_timeout_us, within_us, from_power_on):
    """Frames, broken frames and noise, whole or split across chunks, in bursts and with
    pauses, checked and polled at random moments: the live findings and the final report
    are those of the whole capture judged at once."""
    t = 1_000
    chunks = []
    for gap, frames, cut in pieces:
        t += gap
        data = b"".join(frames)
        cut = min(cut, len(data) - 1)
        if cut:
            chunks.append(Chunk(t, data[:cut]))
            t += 1_000
        chunks.append(Chunk(t, data[cut:]))
    options = RuleOptions(reply_timeout_us=reply_timeout_us, response_within_us=within_us)
    session, shown = live(chunks, tolerance_us=tolerance_us, check_after=check_after, polls=polls,
                          options=options, from_power_on=from_power_on)
    assert_same_as_the_whole(session, shown)


def test_a_burst_over_tcp_is_judged_live_as_it_is_on_replay(tmp_path):
    """64 kB of frames written at once to a real TCP stream: the monitor's report (checked
    live as the chunks came) and the replay of its capture (judged at the end) agree.

    The stream ends the session (it closes the connection once all is sent), not the
    monitor's --duration: a monitor stopped after 5 s on a loaded host had read 3328 of
    the 4096 exchanges, and the frame count failed. The duration is only a bound."""
    payload = (STOP + STOP + READ + STATUS) * 2048
    server = socket.create_server(("127.0.0.1", 0))

    def stream():
        connection, _ = server.accept()
        with connection:
            connection.sendall(payload)  # then the close: the monitor reads to the end of the stream

    thread = threading.Thread(target=stream, daemon=True)
    thread.start()
    done = procs.run(uitamr("monitor", "--tcp", f"127.0.0.1:{server.getsockname()[1]}", "--duration", "240s",
                                 "--quiet", "--json", tmp_path / "m.json", "--capture", tmp_path / "c.txt"),
                     capture_output=True, text=True, timeout=300)
    thread.join(timeout=5)
    server.close()
    assert done.returncode == 1, done.stdout + done.stderr  # a burst breaks the pacing
    assert "the server closed the connection" in done.stdout, done.stdout  # the whole burst was read
    monitored = json.loads((tmp_path / "m.json").read_text())["scenarios"][0]
    assert monitored["frames"] == {"tx": 4096, "rx": 4096}
    done = procs.run(uitamr("replay", tmp_path / "c.txt", "--json", tmp_path / "r.json"),
                     capture_output=True, text=True, timeout=WAIT_S)
    assert done.returncode == 1, done.stdout + done.stderr
    replayed = json.loads((tmp_path / "r.json").read_text())["scenarios"][0]
    assert replayed["violations"] == monitored["violations"] and replayed["rules"] == monitored["rules"]
    assert monitored["rules"]["UITAMR-PACING"]["violations"] > 0
    (chunks,) = read_capture(tmp_path / "c.txt").values()
    session, shown = live(chunks, check_after=set(range(0, len(chunks), 3)))
    assert_same_as_the_whole(session, shown)
