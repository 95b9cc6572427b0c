"""`uitamr replay` of a `uitamr verify --trace` file gives verify's own rule findings
(docs/commissioning.md §4, docs/verifier.md `--trace FILE`): the trace carries what the
rules read besides the frames - the run's end, the rules' settings, the program's response
signal, the pauses inside PLC frames and a converter's drops."""
from __future__ import annotations

import json
import subprocess

import pytest

from monitor_helpers import uitamr
from test_verify_cli import PLC, back_to_back
from verifier.commands.verify import bundled_scenarios
import procs

RUN_S = 120  # a whole command over every bundled scenario (about 6 s of CPU)


def run(*args, expect=(0, 1)) -> subprocess.CompletedProcess:
    done = procs.run(uitamr(*args), capture_output=True, text=True, timeout=RUN_S)
    assert done.returncode in expect, done.stdout + done.stderr
    return done


def findings(report) -> list[list[tuple]]:
    """Each run's rule findings in a --json report, in run order: (rule, time, message)."""
    data = json.loads(report.read_text(encoding="utf-8"))
    return [[(v["rule"], v["t"], v["message"]) for v in s["violations"]] for s in data["scenarios"]]


def names(report) -> list[str]:
    return [s["name"] for s in json.loads(report.read_text(encoding="utf-8"))["scenarios"]]


def ends(report) -> list[float]:
    return [s["ended"] for s in json.loads(report.read_text(encoding="utf-8"))["scenarios"]]


def verify_then_replay(tmp_path, *verify_args):
    """`uitamr verify ... --trace` then `uitamr replay` of the trace, both with --json."""
    run("verify", *verify_args, "--trace", tmp_path / "v.jsonl", "--json", tmp_path / "v.json")
    run("replay", tmp_path / "v.jsonl", "--json", tmp_path / "r.json")
    return tmp_path / "v.json", tmp_path / "r.json"


def differences(verified, replayed) -> list[str]:
    """Each run whose replay found other rule findings than verify did, with what differed."""
    wanted, got = findings(verified), findings(replayed)
    assert len(wanted) == len(got)
    return [f"{name}: verify only {[f for f in found if f not in again]}, replay only {[f for f in again if f not in found]}"
            for name, found, again in zip(names(verified), wanted, got) if found != again]


def test_every_bundled_scenario_replays_to_the_findings_verify_made(tmp_path):
    """The bundled scenarios in one `uitamr verify --trace` (no arguments: the library's
    examples against all of them), the trace in one `uitamr replay`: each run's findings
    (rule, time, message) and its end are verify's. Before the trace carried the rules'
    settings and the response signal, FX3U ADPRW late reply (reply_timeout 400 ms) got a
    UITAMR-CYCLE finding at 3.03 s and FX3U bad CRC for 5 s a UITAMR-RESPONSE-HANDLING one at
    12.03 s (the program showed it in time), and every run ended at its last frame."""
    verified, replayed = verify_then_replay(tmp_path)
    assert len(findings(verified)) == len(bundled_scenarios()) == 74
    assert differences(verified, replayed) == []
    assert ends(replayed) == ends(verified)


def test_findings_from_pauses_inside_a_plc_frame_replay_alike(tmp_path):
    """Two requests 1.7 ms apart run together on the line: verify's UITAMR-CRC and
    UITAMR-FORMAT say so, from the pause the line saw inside the frame; the replay had only
    the 16-byte frame and said "too long for an FC06 request". The trace's event record of
    the pause gives the replay verify's words."""
    (tmp_path / "MAIN.st").write_text(back_to_back("16#F6D9"), encoding="utf-8")
    verified, replayed = verify_then_replay(tmp_path, tmp_path / "MAIN.st", "--platform", "fx3u", "--duration", "1s")
    assert {rule for rule, _, _ in findings(verified)[0]} == {"UITAMR-CRC", "UITAMR-FORMAT"}
    assert differences(verified, replayed) == []


def test_a_converters_drop_replays_as_a_lost_reply(tmp_path):
    """The converter drops the connection after forwarding a point command (9.2 s): the
    robot's echo is on the line but never reached the PLC, which sends the command again.
    Verify counts that as a retry; the replay saw the echo, took the command as answered and
    found UITAMR-CYCLE (a control command with no status read between). The trace's event
    record of the drop makes the exchange lost in the replay too."""
    text = (bundled_scenarios()[0].parent / "fx5u-tcp-dropped.toml").read_text(encoding="utf-8")
    scenario = tmp_path / "drop.toml"
    sources = bundled_scenarios()[0].parent.parent.as_posix()
    scenario.write_text(text.replace('drops = ["20s"]', 'drops = ["9.1s"]').replace('"../', f'"{sources}/'),
                        encoding="utf-8")
    verified, replayed = verify_then_replay(tmp_path, "--scenario", scenario, "--duration", "15s")
    assert findings(verified) == [[]]  # a retry, no finding (docs/verifier.md says so)
    assert differences(verified, replayed) == []
    assert '"event": "converter.dropped"' in (tmp_path / "v.jsonl").read_text(encoding="utf-8")


#: the stop once, with its CRC bytes wrong (89 14 for 88 14): the robot never answers, and the
#: program sends nothing more
STOP_WITH_A_BAD_CRC = back_to_back().replace("uSend[3] := 16#1488;", "uSend[3] := 16#1489;")


def test_a_trace_of_one_run_replays_under_its_scenarios_name(tmp_path):
    """An integrator's one scenario, `verify --trace`, then `replay` of the trace in CI: the
    replay's console line, JSON and JUnit test case were named after the trace file
    ('FAIL v.jsonl (v.jsonl)') while a trace of two runs kept each scenario's name - the
    name its verify JUnit test case had. A monitor's trace keeps its file's name
    (test_a_replay_of_the_monitors_trace_judges_as_the_live_session_did)."""
    verified, replayed = verify_then_replay(tmp_path, "--scenario", PLC / "scenarios" / "fx3u-bad-crc.toml",
                                            "--duration", "5s")
    assert names(replayed) == names(verified) == ["FX3U: one reply with a corrupted CRC"]


def test_a_silence_after_the_last_frame_is_judged_to_the_runs_end(tmp_path):
    """The program sends one request that is never answered, then nothing for the rest of
    the 8 s run: verify finds UITAMR-RESPONSE-HANDLING (the failure outlasted its 5 s
    bound). The trace ended at that frame, so the replay's run lasted 18 ms and the finding
    was gone; the end record carries the run's end."""
    (tmp_path / "MAIN.st").write_text(STOP_WITH_A_BAD_CRC, encoding="utf-8")
    verified, replayed = verify_then_replay(tmp_path, tmp_path / "MAIN.st", "--platform", "fx3u", "--duration", "8s")
    assert "UITAMR-RESPONSE-HANDLING" in {rule for rule, _, _ in findings(verified)[0]}
    assert differences(verified, replayed) == []
    assert ends(replayed) == ends(verified) == [8.0]


def test_a_response_signal_that_never_rose_replays_to_the_same_finding(tmp_path):
    """Bad CRCs for 5 s and a response signal the program never shows: verify's finding names
    it ("did not become true within 5 s"); the replay said only that the outputs are not on
    the line. Verify's trace records the signal and when it held (never), so the replay
    judges by it."""
    scenario = bundled_scenarios()[0].parent / "fx3u-bad-crc-persistent.toml"
    verified, replayed = verify_then_replay(tmp_path, "--scenario", scenario, "--duration", "20s",
                                            "--response-signal", "fbEngine.o_bErr AND fbEngine.o_bOK")
    messages = [message for rule, _, message in findings(verified)[0] if rule == "UITAMR-RESPONSE-HANDLING"]
    assert messages and "'fbEngine.o_bErr AND fbEngine.o_bOK' did not become true within 5 s" in messages[0]
    assert differences(verified, replayed) == []


FRAME = '{"scenario": "a", "t": 0.1, "t_end": 0.108, "dir": "tx", "hex": "01 06 01 A0 00 00 88 14"}'


@pytest.mark.parametrize("lines, message", [
    (['{"scenario": "a", "t": 0.2, "event": "collision", "message": ""}', '{"scenario": "a", "end": 1}'],
     "t.jsonl:2:1: 'event' is \"collision\"; expected one of \"gap\", \"converter.dropped\""),
    (['{"scenario": "a", "t": 0.2, "event": "gap", "message": "", "hex": "01"}', '{"scenario": "a", "end": 1}'],
     "t.jsonl:2:1: an event record holds only 'scenario', 't', 'event' and 'message'; it has 'hex'"),
    (['{"scenario": "a", "t": 0.2, "event": "gap", "message": ""}'],
     "t.jsonl:2:1: the run 'a' has event records but no end record after them"),
    (['{"scenario": "a", "end": 1, "response_signal": "o_bErr AND", "response_signal_held": []}'],
     "t.jsonl:2:1: 'response_signal' is \"o_bErr AND\": "),
    (['{"scenario": "a", "end": 1, "response_signal": "o_bErr", "response_signal_held": [[0.5, 0.4]]}'],
     "t.jsonl:2:1: 'response_signal_held' item 1 is [0.5, 0.4]; expected [[began, stopped], ...] in seconds"),
    (['{"scenario": "a", "end": 1, "response_signal_held": [[0.5, null]]}'],
     "t.jsonl:2:1: 'response_signal_held' without 'response_signal'"),
    # what a run records lies within it: an event or a stretch of the signal after the end
    # record's `end` is a damaged or hand-edited trace (they were taken silently)
    (['{"scenario": "a", "t": 0.2, "event": "gap", "message": ""}',
      '{"scenario": "a", "t": 5, "event": "gap", "message": ""}', '{"scenario": "a", "end": 1}'],
     "t.jsonl:3:1: the event record at 5 s is after the end of the run 'a' (1 s, its end record on line 4); "
     "what a run records lies within it: correct the time or the end record's 'end', or remove what comes after it"),
    (['{"scenario": "a", "end": 1, "response_signal": "o_bErr", "response_signal_held": [[0.5, 0.7], [2, 3]]}'],
     "t.jsonl:2:1: 'response_signal_held' item 2, held until 3 s, is after the end of the run 'a' (1 s, "),
    (['{"scenario": "a", "end": 1, "response_signal": "o_bErr", "response_signal_held": [[0.5, 1.5]]}'],
     "t.jsonl:2:1: 'response_signal_held' item 1, held until 1.5 s, is after the end of the run 'a' (1 s, "),
    (['{"scenario": "a", "end": 1, "response_signal": "o_bErr", "response_signal_held": [[1.2, null]]}'],
     # still holding at the end: it began after it (it was "held until 1.2 s", its start)
     "t.jsonl:2:1: 'response_signal_held' item 1, holding from 1.2 s on, is after the end of the run 'a' (1 s, "),
    (['{"scenario": "a", "end": 1, "protocol": {"address": 300}}'],
     "t.jsonl:2:1: 'protocol': robot address must be 1-247, got 300"),
    (['{"scenario": "a", "end": 1, "protocol": {"baud": 9600}}'],
     "t.jsonl:2:1: 'protocol' holds only address, field_order, codes_10_13, status_order, "
     "manual_stop_counts_as_stop; it has 'baud'"),
    (['{"scenario": "a", "end": 1, "reply_timeout": "400ms"}'],
     "t.jsonl:2:1: 'reply_timeout' is \"400ms\"; expected a time in seconds"),
    # a time-out of 0, which a scenario and --reply-timeout refuse, took every reply as late
    (['{"scenario": "a", "end": 1, "reply_timeout": 0}'],
     "t.jsonl:2:1: 'reply_timeout' is 0; expected a time in seconds longer than 0"),
    (['{"scenario": "a", "end": 1, "min_period": 1e-9}'],
     "t.jsonl:2:1: 'min_period' is 1e-09; expected a time in seconds longer than 0"),
])
def test_a_bad_record_of_what_the_rules_read_is_named_with_its_line(tmp_path, lines, message):
    path = tmp_path / "t.jsonl"
    path.write_text("\n".join([FRAME, *lines]) + "\n", encoding="utf-8")
    done = run("replay", path, expect=(2,))
    assert "Traceback" not in done.stderr
    assert done.stderr.startswith(f"uitamr replay: {path}:{message.split(':', 1)[1]}"), done.stderr


def test_events_and_signal_stretches_up_to_the_runs_end_are_taken(tmp_path):
    """The bound of the check above is the end itself: an event at the end, and a stretch
    that stops at the end or still holds from it, belong to the run (a verify run records
    none later: its events and samples are taken up to its end)."""
    path = tmp_path / "t.jsonl"
    path.write_text("\n".join([FRAME, '{"scenario": "a", "t": 1, "event": "gap", "message": "x"}',
                               '{"scenario": "a", "end": 1, "response_signal": "o_bErr", '
                               '"response_signal_held": [[0.2, 1], [1, null]]}']) + "\n", encoding="utf-8")
    done = run("replay", path)
    assert "Traceback" not in done.stderr and done.stderr == "", done.stderr


def test_a_reply_timeout_given_to_replay_is_taken_over_the_recorded_one(tmp_path):
    """The end record says the run was judged with 400 ms; --reply-timeout 500ms says
    otherwise and wins: the request at 0.1 s with its echo 450 ms later is then answered."""
    echo = '{"scenario": "a", "t": 0.558, "t_end": 0.566, "dir": "rx", "hex": "01 06 01 A0 00 00 88 14"}'
    path = tmp_path / "t.jsonl"
    path.write_text("\n".join([FRAME, echo, '{"scenario": "a", "end": 6, "reply_timeout": 0.4}']) + "\n",
                    encoding="utf-8")
    run("replay", path, "--json", tmp_path / "r.json")
    found = json.loads((tmp_path / "r.json").read_text())["scenarios"][0]["violations"]
    assert [(v["rule"], v["t"]) for v in found] == [("UITAMR-RESPONSE-HANDLING", 0.508)]  # 0.108 s + 400 ms
    assert "(late ×1)" in found[0]["message"]
    given = run("replay", path, "--reply-timeout", "500ms", "--json", tmp_path / "g.json")
    assert json.loads((tmp_path / "g.json").read_text())["scenarios"][0]["violations"] == [], given.stdout


def test_a_scenarios_protocol_settings_replay_alike(tmp_path):
    """A scenario whose robot is slave 2 ([protocol] address) while the program asks slave
    1: verify's UITAMR-FORMAT says so against slave 2. The replay judged against slave 1
    (its --address default) and found nothing; the end record carries the protocol settings,
    and an --address given to replay still wins."""
    text = (bundled_scenarios()[0].parent / "fx3u-healthy.toml").read_text(encoding="utf-8")
    sources = bundled_scenarios()[0].parent.parent.as_posix()
    scenario = tmp_path / "slave2.toml"
    scenario.write_text(text.replace('"../', f'"{sources}/') + "\n[protocol]\naddress = 2\n", encoding="utf-8")
    verified, replayed = verify_then_replay(tmp_path, "--scenario", scenario, "--duration", "2s")
    assert any("the robot is slave 2" in message for rule, _, message in findings(verified)[0] if rule == "UITAMR-FORMAT")
    assert differences(verified, replayed) == []
    run("replay", tmp_path / "v.jsonl", "--address", "1", "--json", tmp_path / "a1.json")
    assert not any(rule == "UITAMR-FORMAT" for rule, _, _ in findings(tmp_path / "a1.json")[0])


def test_a_monitors_reply_timeout_goes_with_its_trace(tmp_path):
    """`uitamr monitor --reply-timeout 400ms`: its trace's end record says 0.4 s, and the
    replay of the trace judges the 450 ms late echo as the monitor did (late), where the
    default 500 ms took it as answered."""
    from verifier.monitor.capture import Chunk
    from verifier.monitor.framer import LineTiming
    from verifier.monitor.session import CaptureInfo, MonitorSession
    from verifier.verify import report_trace
    from verifier.verify.evidence import RuleOptions

    stop = bytes.fromhex("01 06 01 A0 00 00 88 14")
    live = MonitorSession(CaptureInfo("site", "/dev/ttyUSB0"), options=RuleOptions(reply_timeout_us=400_000),
                          timing=LineTiming(tolerance_us=0))
    for chunk in (Chunk(8_333, stop, "tx", 0), Chunk(466_666, stop, "rx", 458_333), Chunk(6_000_000, b"")):
        live.feed(chunk)
    live.close()
    monitored = live.result()
    assert [v.rule for v in monitored.all_violations()] == ["UITAMR-RESPONSE-HANDLING"]
    report_trace.write([monitored], tmp_path / "site.jsonl")
    assert json.loads((tmp_path / "site.jsonl").read_text(encoding="utf-8").splitlines()[-1])["reply_timeout"] == 0.4
    run("replay", tmp_path / "site.jsonl", "--json", tmp_path / "r.json")
    assert findings(tmp_path / "r.json") == [[(v.rule, v.t_us / 1e6, v.message) for v in monitored.all_violations()]]


def test_a_run_cut_while_a_frame_is_on_the_line_replays(tmp_path):
    """`--duration 235ms` ends the run while the stop (0.230-0.238 s) is still going out: the
    trace holds the frame whole and the run's end before its end; the replay reads it (an end
    record is refused only before the start of the frame before it) and the run is 0.235 s
    long, as verify's was."""
    scenario = bundled_scenarios()[0].parent / "fx3u-healthy.toml"
    verified, replayed = verify_then_replay(tmp_path, "--scenario", scenario, "--duration", "235ms")
    *frames, end = (json.loads(line) for line in (tmp_path / "v.jsonl").read_text(encoding="utf-8").splitlines())
    assert frames[-1]["t"] < end["end"] == 0.235 < frames[-1]["t_end"]
    assert differences(verified, replayed) == []
    assert ends(replayed) == ends(verified) == [0.235]


def test_a_request_to_another_slave_says_where_to_set_the_address(tmp_path):
    """An integrator's second robot at address 2 (the program's ROBOT_ADDRESS changed, the
    scenario copied as it was): UITAMR-FORMAT said only "addressed to slave 2, the robot is
    slave 1", naming neither setting. It now names both: the scenario's [protocol] address
    (monitor's and replay's --address) and the program's."""
    text = (bundled_scenarios()[0].parent / "fx3u-healthy.toml").read_text(encoding="utf-8")
    sources = bundled_scenarios()[0].parent.parent.as_posix()
    scenario = tmp_path / "slave2.toml"
    scenario.write_text(text.replace('"../', f'"{sources}/') + "\n[protocol]\naddress = 2\n", encoding="utf-8")
    verified, replayed = verify_then_replay(tmp_path, "--scenario", scenario, "--duration", "2s")
    messages = {message for rule, _, message in findings(verified)[0] if rule == "UITAMR-FORMAT"}
    assert messages == {"byte 0: addressed to slave 1, the robot is slave 2: for a robot at 1 set address = 1 "
                        "under [protocol] in the scenario (--address 1 for monitor and replay); else make the "
                        "program send to 2 (the engine's i_wAddress)"}
    assert differences(verified, replayed) == []
