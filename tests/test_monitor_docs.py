"""docs/commissioning.md says what the monitor really does: its options exist, its defaults
are the code's, its example capture reads, its example view is what the monitor prints."""
from __future__ import annotations

import re
from pathlib import Path

from monitor_helpers import uitamr
from verifier.monitor.capture import parse_plain, read_capture
from verifier.monitor.framer import DEFAULT_TOLERANCE_US, LineTiming
from verifier.monitor.session import CaptureInfo, MonitorSession
from verifier.monitor.view import finding_lines, frame_line
from verifier import protocol
import procs

CAPTURES = Path(__file__).resolve().parent / "captures"
DOC = (Path(__file__).resolve().parent.parent / "docs" / "commissioning.md").read_text(encoding="utf-8")


def test_every_option_in_the_table_exists():
    helps = procs.run(uitamr("monitor", "--help"), capture_output=True, text=True, timeout=60).stdout
    helps += procs.run(uitamr("replay", "--help"), capture_output=True, text=True, timeout=60).stdout
    options = set(re.findall(r"\| `(--[a-z-]+)`", DOC)) | set(re.findall(r"`(--[a-z-]+)`", DOC))
    assert {"--tolerance", "--joined", "--capture", "--duration", "--reply-timeout"} <= options
    for option in options:
        assert option in helps, f"docs/commissioning.md names {option}, which monitor/replay do not have"


def test_the_default_tolerance_is_the_codes():
    assert f"**{DEFAULT_TOLERANCE_US // 1000} ms**" in DOC and f"`{DEFAULT_TOLERANCE_US // 1000}ms`" in DOC


def test_how_soon_a_finding_shows_is_the_codes():
    from verifier.commands.monitor import CHECK_EVERY_S

    assert f"at the next of the monitor's checks (every {CHECK_EVERY_S:g} s)" in " ".join(DOC.split())


def test_the_example_capture_reads():
    block = DOC.split("# uitamr monitor capture of /dev/ttyUSB0, 9600 8N1\n", 1)[1].split("```", 1)[0]
    session = MonitorSession(CaptureInfo("doc", "doc"))
    for chunk in parse_plain(block, "docs/commissioning.md"):
        session.feed(chunk)
    session.close()
    assert [(f.direction, f.t_start_us) for f in session.frames] == [("tx", 0), ("rx", 1097)]


def test_the_example_view_is_what_the_monitor_prints_for_the_bad_master():
    (chunks,) = read_capture(CAPTURES / "bad-master.txt").values()
    session = MonitorSession(CaptureInfo("doc", "doc"))
    for chunk in chunks:
        session.feed(chunk)
    session.close()
    lines, request = [], None
    for frame in session.frames[:4]:
        if frame.direction == "tx":
            request = protocol.decode_request(frame.data, protocol.DEFAULT_SETTINGS)
        lines.append(frame_line(frame, protocol.DEFAULT_SETTINGS, request if frame.direction == "rx" else None))
    for violation in session.check()[:2]:
        lines += finding_lines(violation)
    block = DOC.split("```\n     0.000 s  PLC → robot", 1)[1].split("```", 1)[0]
    assert ("     0.000 s  PLC → robot" + block).rstrip("\n").splitlines() == lines


def test_the_no_traffic_verdict_is_what_the_monitor_says():
    session = MonitorSession(CaptureInfo("doc", "/dev/ttyUSB0"))
    session.close()
    result = session.result(listened_us=600_000_000)
    assert f"```\nNO TRAFFIC: {result.no_traffic}\n```" in DOC


def test_the_cut_short_verdict_and_the_exit_table_are_the_monitors():
    """§2 quotes the last line of a session whose port went away after 5.2 s of 10 min with
    12 frames seen, and the start of the one that saw none, and its exit table lists each
    of the monitor's exit statuses."""
    from verifier.commands import monitor
    from verifier.monitor.capture import Chunk

    stop = protocol.encode(protocol.command_from_words(["stop"]), protocol.DEFAULT_SETTINGS)
    session = MonitorSession(CaptureInfo("doc", "/dev/ttyUSB0"))
    for k in range(12):
        session.feed(Chunk(300_000 * k + 8_400, stop))
    session.close()
    session.went_away(5_200_000, 600_000_000)
    assert f"```\nCUT SHORT: {session.result().cut_short}\n```" in DOC
    silent = MonitorSession(CaptureInfo("doc", "/dev/ttyUSB0"))
    silent.close()
    silent.went_away(5_200_000, 600_000_000)  # before one byte came: no traffic that says so
    quoted = re.search(r"`(no bytes were seen on /dev/ttyUSB0 in 5\.2 s, [^`]*) \.\.\.`", " ".join(DOC.split()))
    assert quoted and silent.result(listened_us=5_200_000).no_traffic.startswith(quoted.group(1))
    statuses = {monitor.EXIT_CLEAN: "frames were seen and no rule was broken", monitor.EXIT_FINDINGS: "findings",
                monitor.EXIT_UNUSABLE: "the port cannot be opened", monitor.EXIT_NO_TRAFFIC: "**no traffic**",
                monitor.EXIT_CUT_SHORT: "**cut short**"}
    table = DOC.split("| exit status | meaning |\n|---|---|\n", 1)[1].split("\n\n", 1)[0].splitlines()
    assert [row.split(" | ", 1)[0] for row in table] == [f"| {status}" for status in statuses]
    assert all(row.split(" | ", 1)[1].startswith(meaning) for row, meaning in zip(table, statuses.values()))


def test_a_plc_at_19200_read_at_9600_is_said_to_be_on_another_speed(tmp_path):
    """§2: a PLC at 19200 into a 9600 monitor gave only CRC and FORMAT findings ("unknown
    function code 0x08"), which §5's table sends to the PLC's CRC routine and frame builder;
    the note §2 quotes now points at the line's speed first. The bytes are what a 9600 8N1
    receiver reads (sampling mid-bit) of the stop and four status reads sent at 19200."""
    capture = tmp_path / "fast.txt"
    capture.write_text("0.3 28 08 08 68\n" + "".join(f"{0.3 * n:.1f} 18 08 68 AB\n" for n in range(2, 6))
                       + "2.5 end\n", encoding="utf-8")
    done = procs.run(uitamr("replay", capture), capture_output=True, text=True, timeout=60)
    note = re.search(r"note: (not one of .*)", done.stdout)
    assert note, done.stdout + done.stderr
    quoted = re.search(r"`(not one of the .*?)`", " ".join(DOC.split()))
    assert quoted and quoted.group(1) == note.group(1)
    good = procs.run(uitamr("replay", CAPTURES / "bad-master.txt"), capture_output=True, text=True, timeout=60)
    assert "not one of" not in good.stdout  # one bad CRC among good frames: the PLC's own
    capture.write_text("0.3 01 06 01 A0 00 00 14 88\n1.0 end\n", encoding="utf-8")  # CRC high byte first
    swapped = procs.run(uitamr("replay", capture), capture_output=True, text=True, timeout=60)
    assert "UITAMR-CRC" in swapped.stdout and "not one of" not in swapped.stdout  # the PLC's CRC, not the line


def test_a_monitor_trace_replays_to_the_monitors_findings(tmp_path):
    """commissioning.md §6 replays `monitor --trace` files. Their times are the host's, so
    the replay must allow the tolerance the monitor allowed: a PLC pacing at 240 ms passes
    the monitor (240 + 20 > 250) and its plain capture, and used to fail the replay of the
    monitor's own trace (tolerance 0: UITAMR-PACING twice)."""
    import json

    from verifier.monitor.capture import Chunk
    from verifier.verify import report_trace

    stop = protocol.encode(protocol.command_from_words(["stop"]), protocol.DEFAULT_SETTINGS)
    read = protocol.encode(protocol.command_from_words(["read", "task"]), protocol.DEFAULT_SETTINGS)
    idle = bytes.fromhex("01 01 03 00 00 00 3C 4E")
    chunks = [Chunk(8_400, stop), Chunk(23_400, stop), Chunk(248_400, read), Chunk(263_400, idle),
              Chunk(488_400, read), Chunk(503_400, idle)]
    session = MonitorSession(CaptureInfo("site", "/dev/ttyUSB0"))
    for chunk in chunks:
        session.feed(chunk)
    session.close()
    live = session.result()
    assert live.passed, [v.message for v in live.all_violations()]
    trace = tmp_path / "site.jsonl"
    report_trace.write([live], trace)
    report = tmp_path / "replay.json"
    done = procs.run(uitamr("replay", str(trace), "--json", str(report)), capture_output=True, text=True,
                     timeout=60)
    assert done.returncode == 0, done.stdout + done.stderr
    assert json.loads(report.read_text())["summary"]["violations"]["UITAMR-PACING"] == 0
    exact = procs.run(uitamr("replay", str(trace), "--tolerance", "0"), capture_output=True, text=True,
                      timeout=60)
    assert exact.returncode == 1 and "UITAMR-PACING ×2" in exact.stdout
    *frames, end = (json.loads(line) for line in trace.read_text().splitlines())
    assert all(record["tolerance"] == DEFAULT_TOLERANCE_US / 1e6 for record in frames)
    assert end == {"scenario": "site", "end": live.ended_us / 1e6,  # the end record: a time and settings, no frame
                   "reply_timeout": 0.5, "min_period": 0.25, "response_within": 5.0,
                   "protocol": {"address": 1, "field_order": "code-high", "codes_10_13": "decimal",
                                "status_order": "query", "manual_stop_counts_as_stop": False}}


def test_an_unreadable_capture_is_reported_as_section_6_quotes(tmp_path):
    """§6: file, line and column of the bad byte, the message, exit status 2."""
    quoted = re.search(r"\(`(uitamr replay: site\.txt:12:9: [^`]*)`\) and exit status 2", " ".join(DOC.split())).group(1)
    capture = tmp_path / "site.txt"
    capture.write_text("# comment\n" * 11 + "0.01 01 G0\n", encoding="utf-8")
    import os

    env = {**os.environ, "PYTHONPATH": str(Path(__file__).resolve().parents[1])}
    done = procs.run(uitamr("replay", "site.txt"), capture_output=True, text=True, timeout=60, cwd=tmp_path,
                     env=env)
    assert done.returncode == 2
    assert done.stderr.strip() == quoted


def test_an_exactly_timed_capture_is_not_said_to_be_timed_by_the_host(tmp_path):
    """§4: a capture with tx/rx lines (as a verify trace) has exact times, tolerance 0; its
    replay must not call them host times with "0 ms for the adapter's latency"."""
    capture = tmp_path / "exact.txt"
    capture.write_text("0.000000 tx 01 06 01 A0 00 00 88 14\n0.013333 rx 01 06 01 A0 00 00 88 14\n",
                       encoding="utf-8")
    exact = procs.run(uitamr("replay", capture), capture_output=True, text=True, timeout=60)
    assert exact.returncode == 0, exact.stdout + exact.stderr
    assert "timed by the host" not in exact.stdout
    assert "note: frames taken as exactly timed; timing rules allow 0 ms for latency (--tolerance)" in exact.stdout
    host = procs.run(uitamr("replay", CAPTURES / "bad-master.txt"), capture_output=True, text=True, timeout=60)
    assert "note: frames timed by the host; timing rules allow 20 ms for the adapter's latency (--tolerance)" \
        in host.stdout


def test_the_time_of_a_capture_line_is_when_its_last_byte_arrived():
    """The docs did not say whether a line's time is the start or the end of its bytes; a
    capture written by hand from a logic analyser's frame starts needs to know."""
    assert "The time is when the line's **last** byte arrived" in DOC
    session = MonitorSession(CaptureInfo("doc", "doc"), timing=LineTiming(tolerance_us=0))
    for chunk in parse_plain("0.100000 tx 01 06 01 A0 00 00 88 14\n"):
        session.feed(chunk)
    session.close()
    (frame,) = session.frames
    assert frame.t_end_us - frame.t_start_us == 8333  # 8 bytes at 9600 8N1, ending at the line's time


def test_how_soon_a_finding_is_printed_is_how_often_the_monitor_looks():
    """§3 said a one-frame finding is printed "as soon as" its request is on the line; the
    monitor judges what the line settled every CHECK_EVERY_S, so frames that came before a
    look are printed before the findings the look makes (as in the example view)."""
    from verifier.commands.monitor import CHECK_EVERY_S

    text = " ".join(DOC.split())
    assert CHECK_EVERY_S == 0.5
    assert "The monitor looks for findings twice a second" in text
    assert "a finding shows up to half a second after its frames" in text


def test_what_a_host_stall_does_is_what_the_framer_does():
    """The row on a stalled host said "a stall between reads cannot split a frame"; one
    read takes the bytes that waited together, but a stall while a frame is still arriving
    (half of it read, the rest read after the stall) cuts it once longer than t3.5 plus the
    tolerance, as the row now says."""
    from verifier.monitor.capture import Chunk
    from verifier.monitor.framer import Framer

    row = next(line for line in DOC.splitlines() if line.startswith("| the host does not run the monitor"))
    assert "cannot split" not in row
    assert "one longer than t3.5 plus the tolerance while a frame is still arriving cuts it in two" in row

    def frames(stall_us: int) -> list[bytes]:
        framer = Framer(LineTiming(9600, 10, DEFAULT_TOLERANCE_US))
        out = framer.feed(Chunk(4_170, protocol.STOP_FRAME[:4]))
        out += framer.feed(Chunk(4_170 + stall_us, protocol.STOP_FRAME[4:]))
        return [frame.data for frame in out + framer.poll(10_000_000)]

    assert frames(DEFAULT_TOLERANCE_US // 2) == [protocol.STOP_FRAME]
    assert frames(DEFAULT_TOLERANCE_US + 4_000 + 5_000) == [protocol.STOP_FRAME[:4], protocol.STOP_FRAME[4:]]
