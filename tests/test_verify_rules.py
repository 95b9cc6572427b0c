"""Each compliance rule on hand-built traces: one that keeps it, one (or more) that breaks it.

The rules are pure functions over a trace, so these tests need no simulator; the
end-to-end tests in test_verify_pipeline.py run real ST through the whole chain.
"""
from __future__ import annotations

from dataclasses import replace

import pytest
from hypothesis import given, settings as hsettings, strategies as st

from verifier import protocol
from verifier.verify.conditions import parse_condition
from verifier.verify.evidence import RuleOptions, RunEvidence, Samples
from verifier.verify.result import TraceRecord
from verifier.verify.rules import RULES, RULES_BY_ID, check_all

S = protocol.Settings()
STOP = protocol.ControlRequest(1, protocol.ControlCode.ROBOT, protocol.RobotCommand.STOP)
POINT3 = protocol.ControlRequest(1, protocol.ControlCode.ROBOT, 3)
READ_TASK = protocol.StatusRequest(1, protocol.Query.TASK)
MS = 1000
TURNAROUND = 5 * MS


def _frame(direction: str, t_us: int, data: bytes, origin: str | None = None) -> TraceRecord:
    return TraceRecord(t_us, t_us + protocol.frame_time_us(len(data)), direction, data, origin)


def tx(t_ms: float, request, *, origin: str | None = "Main.st:12:5") -> TraceRecord:
    data = request if isinstance(request, bytes) else protocol.encode(request, S)
    return _frame("tx", int(t_ms * MS), data, origin)


def rx(t_us: int, reply) -> TraceRecord:
    data = reply if isinstance(reply, bytes) else protocol.encode(reply, S)
    return _frame("rx", t_us, data)


def answer(request_frame: TraceRecord, request=None, *, delay_us: int = TURNAROUND, reply=None) -> TraceRecord:
    """The robot's normal answer to `request_frame`, `delay_us` after it ended."""
    if reply is None:
        decoded = request or protocol.decode_request(request_frame.data, S)
        if isinstance(decoded, protocol.ControlRequest):
            reply = protocol.ControlReply.echo(decoded)
        else:
            reply = protocol.StatusReply(1, 0, 0)
    return rx(request_frame.t_end_us + delay_us, reply)


def exchange(t_ms: float, request, **kw) -> list[TraceRecord]:
    request_frame = tx(t_ms, request)
    return [request_frame, answer(request_frame, **kw)]


def healthy(n_reads: int = 5) -> list[TraceRecord]:
    frames = exchange(0, STOP)
    for i in range(1, n_reads + 1):
        frames += exchange(300 * i, READ_TASK)
    frames += exchange(300 * (n_reads + 1), POINT3)
    frames += exchange(300 * (n_reads + 2), READ_TASK)
    return frames


def check(trace, *, end_us: int | None = None, options: RuleOptions | None = None,
          samples: Samples | None = None, settings: protocol.Settings = S):
    end = end_us if end_us is not None else max(f.t_end_us for f in trace) + 100 * MS
    evidence = RunEvidence(settings, trace, end, (), samples or Samples(), options or RuleOptions())
    return check_all(evidence)


def broken(found) -> dict[str, int]:
    return {rule: len(v) for rule, v in found.items() if v}


# --- the rule catalogue ---------------------------------------------------------------------

def test_every_rule_has_a_stable_id_and_cites_its_source():
    ids = [rule.id for rule in RULES]
    assert ids == [
        "UITAMR-CRC", "UITAMR-FORMAT", "UITAMR-PACING", "UITAMR-POWERON-STOP",
        "UITAMR-HALF-DUPLEX", "UITAMR-ONE-AT-A-TIME", "UITAMR-RESPONSE-HANDLING", "UITAMR-CYCLE",
    ]
    for rule in RULES:
        assert "V2.05" in rule.explanation or "V1.02" in rule.explanation, rule.id


def test_a_healthy_trace_breaks_no_rule():
    assert broken(check(healthy())) == {}


# --- UITAMR-CRC -----------------------------------------------------------------------------

def test_crc_flags_a_corrupted_crc_and_names_the_expected_bytes():
    bad = bytearray(protocol.encode(STOP, S))
    bad[-1] ^= 0x01
    trace = [tx(0, bytes(bad))]
    found = check(trace)
    assert broken(found) == {"UITAMR-CRC": 1}
    violation = found["UITAMR-CRC"][0]
    assert "expected 88 14" in violation.message
    assert violation.origin == "Main.st:12:5"
    assert violation.frames[0].hex == protocol.hex_bytes(bytes(bad))


def test_crc_recognises_swapped_crc_bytes():
    good = protocol.encode(STOP, S)
    swapped = good[:-2] + good[-2:][::-1]
    (violation,) = check([tx(0, swapped)])["UITAMR-CRC"]
    assert "swapped" in violation.message


def test_crc_is_only_about_frames_the_plc_sends():
    request = tx(0, STOP)
    corrupted_reply = bytearray(protocol.encode(protocol.ControlReply.echo(STOP), S))
    corrupted_reply[-2] ^= 0xFF
    found = check([request, rx(request.t_end_us + TURNAROUND, bytes(corrupted_reply))])
    assert found["UITAMR-CRC"] == []


# --- UITAMR-FORMAT --------------------------------------------------------------------------

def test_format_flags_another_function_code():
    read_holding = protocol.with_crc(bytes.fromhex("010300000001"))
    (violation,) = check([tx(0, read_holding)])["UITAMR-FORMAT"]
    assert "function" in violation.message and violation.message.startswith("byte 1")


def test_format_flags_a_value_field_that_is_not_zero():
    frame = protocol.with_crc(bytes.fromhex("010601A00001"))
    (violation,) = check([tx(0, frame)])["UITAMR-FORMAT"]
    assert "value field" in violation.message


def test_format_flags_a_wrong_quantity_and_an_unknown_query():
    quantity = protocol.with_crc(bytes.fromhex("010100000008"))
    query = protocol.with_crc(bytes.fromhex("010100070016"))
    found = check([tx(0, quantity), tx(300, query)])
    assert len(found["UITAMR-FORMAT"]) == 2


@pytest.mark.parametrize("fragment", ["01 06 01", "01 01 00"])
def test_a_three_byte_fragment_is_too_short_not_an_invented_function_code(fragment):
    """Taking the last two bytes as a CRC left the address alone and put the made-up CRC's
    low byte where the function code goes ('unknown function code 0x7E')."""
    (violation,) = check([tx(0, bytes.fromhex(fragment))])["UITAMR-FORMAT"]
    assert violation.message.startswith("byte 3: too short for an FC0")
    assert "0x7E" not in violation.message


def test_format_flags_another_slave_address():
    other = protocol.encode(replace(STOP, address=2), S)
    (violation,) = check([tx(0, other)])["UITAMR-FORMAT"]
    assert "slave 2" in violation.message


def test_format_judges_the_layout_even_when_the_crc_is_wrong_but_does_not_double_count():
    bad_crc_only = bytearray(protocol.encode(STOP, S))
    bad_crc_only[-2] ^= 0x55
    assert broken(check([tx(0, bytes(bad_crc_only))])) == {"UITAMR-CRC": 1}
    both = bytearray(protocol.with_crc(bytes.fromhex("010300000001")))
    both[-2] ^= 0x55
    assert broken(check([tx(0, bytes(both))])) == {"UITAMR-CRC": 1, "UITAMR-FORMAT": 1}


def test_format_flags_a_pause_inside_a_frame():
    from verifier.verify.result import LineEvent

    request = tx(0, STOP)
    gap = LineEvent(request.t_start_us + 4 * MS, "gap", "silence of 2.100 ms between bytes of one frame")
    evidence = RunEvidence(S, [request], 1_000_000, [gap])
    (violation,) = check_all(evidence)["UITAMR-FORMAT"]
    assert "continuous stream" in violation.message and "2.100 ms" in violation.message
    outside = LineEvent(request.t_end_us + 10 * MS, "gap", "another frame")
    assert check_all(RunEvidence(S, [request], 1_000_000, [outside]))["UITAMR-FORMAT"] == []


def test_requests_run_together_are_split_where_the_crcs_tell_the_times_apart():
    """Three requests with pauses of 1.6 and 2.7 ms: the times allow 8 + 8 + 8 bytes and
    7 + 9 + 8 (a pause of 1.5 to 3.5 characters leaves one either way); only the first split
    gives whole requests with good CRCs, and it is the one reported."""
    from verifier.verify.result import LineEvent

    first, second = protocol.with_crc(bytes.fromhex("010601A00000")), protocol.with_crc(bytes.fromhex("010601020000"))
    third = protocol.with_crc(bytes.fromhex("010601030000"))
    start = 10 * MS
    pauses = [start + protocol.frame_time_us(8) + 1_600]
    pauses.append(pauses[0] + protocol.frame_time_us(8) + 2_700)
    assert len(protocol.splits_at_pauses(start, pauses[1] + protocol.frame_time_us(8), 24, pauses)) == 2
    frame = TraceRecord(start, pauses[1] + protocol.frame_time_us(8), "tx", first + second + third)
    gaps = [LineEvent(t, "gap", "silence between bytes of one frame") for t in pauses]
    found = check_all(RunEvidence(S, [frame], 1_000_000, gaps))
    assert found["UITAMR-CRC"] == []
    (violation,) = found["UITAMR-FORMAT"]
    assert violation.message.startswith(
        f"three requests ran together: {protocol.hex_bytes(second)} followed {protocol.hex_bytes(first)} after a "
        f"silence of 1.600 ms, {protocol.hex_bytes(third)} followed that after 2.700 ms, each less than t3.5")


def test_format_follows_the_field_order_setting():
    code_low = protocol.Settings(field_order="code-low")
    frame = protocol.encode(STOP, code_low)
    request = _frame("tx", 0, frame)
    reply = rx(request.t_end_us + TURNAROUND, frame)
    assert broken(check([request, reply], settings=code_low)) == {}
    assert "UITAMR-FORMAT" in broken(check([request, reply]))


# --- UITAMR-PACING --------------------------------------------------------------------------

def test_pacing_needs_more_than_250_ms_start_to_start():
    exactly = exchange(0, STOP) + exchange(250, READ_TASK)
    (violation,) = check(exactly)["UITAMR-PACING"]
    assert "250.0 ms" in violation.message and violation.t_us == 250 * MS
    assert check(exchange(0, STOP) + exchange(251, READ_TASK))["UITAMR-PACING"] == []


def test_pacing_counts_reads_and_invalid_frames_too():
    trace = exchange(0, STOP) + [tx(100, b"\x01\x02")]
    assert len(check(trace)["UITAMR-PACING"]) == 1


def test_pacing_minimum_is_configurable():
    trace = exchange(0, STOP) + exchange(300, READ_TASK)
    options = RuleOptions(min_period_us=400 * MS)
    assert len(check(trace, options=options)["UITAMR-PACING"]) == 1


# --- UITAMR-POWERON-STOP --------------------------------------------------------------------

def test_power_on_stop_accepts_reads_before_the_stop():
    trace = exchange(0, READ_TASK) + exchange(300, STOP) + exchange(600, POINT3)
    trace += exchange(900, READ_TASK)
    assert check(trace)["UITAMR-POWERON-STOP"] == []


def test_power_on_stop_flags_a_move_as_first_control_command():
    trace = exchange(0, POINT3) + exchange(300, READ_TASK)
    (violation,) = check(trace)["UITAMR-POWERON-STOP"]
    assert "first control command" in violation.message
    assert "01 06 01 A0 00 00 88 14" in violation.message


def test_power_on_stop_needs_the_stop_acknowledged_before_other_commands():
    trace = [tx(0, STOP)] + exchange(600, POINT3)
    (violation,) = check(trace)["UITAMR-POWERON-STOP"]
    assert "before the robot acknowledged" in violation.message


def test_power_on_stop_accepts_manual_stop_only_when_the_setting_says_so():
    manual_stop = protocol.ControlRequest(1, protocol.ControlCode.MANUAL, protocol.ManualMove.STOP)
    trace = exchange(0, manual_stop) + exchange(300, READ_TASK) + exchange(600, POINT3)
    assert len(check(trace)["UITAMR-POWERON-STOP"]) == 1
    lenient = protocol.Settings(manual_stop_counts_as_stop=True)
    assert check(trace, settings=lenient)["UITAMR-POWERON-STOP"] == []


# --- UITAMR-HALF-DUPLEX and UITAMR-ONE-AT-A-TIME --------------------------------------------

def test_sending_while_the_reply_is_arriving_breaks_half_duplex_and_one_at_a_time():
    request = tx(0, STOP)
    reply = answer(request, delay_us=20 * MS)
    intruder = _frame("tx", reply.t_start_us + 2 * MS, protocol.encode(READ_TASK, S))
    found = check([request, reply, intruder], options=RuleOptions(min_period_us=1))
    assert broken(found) == {"UITAMR-HALF-DUPLEX": 1, "UITAMR-ONE-AT-A-TIME": 1}
    assert "arriving" in found["UITAMR-HALF-DUPLEX"][0].message


def test_sending_while_the_reply_is_due_breaks_half_duplex():
    request = tx(0, STOP)
    reply = answer(request, delay_us=50 * MS)
    early = _frame("tx", request.t_end_us + 10 * MS, protocol.encode(READ_TASK, S))
    found = check([request, reply, early], options=RuleOptions(min_period_us=1))
    assert "was due" in found["UITAMR-HALF-DUPLEX"][0].message


def test_half_duplex_evidence_is_in_time_order_and_reads_the_reply_like_the_trace():
    """The reply that was due is listed after the earlier request, and named as its answer
    (task status: running), exactly as --trace and the HTML name the same frame."""
    from verifier.verify.report_trace import records
    from verifier.verify.result import ScenarioResult

    read = tx(0, READ_TASK)
    reply = answer(read, reply=protocol.StatusReply(1, 0, 1), delay_us=50 * MS)
    early = _frame("tx", read.t_end_us + 10 * MS, protocol.encode(READ_TASK, S))
    trace = [read, reply, early]
    (violation,) = check(trace, options=RuleOptions(min_period_us=1))["UITAMR-HALF-DUPLEX"]
    times = [frame.t_us for frame in violation.frames]
    assert times == sorted(times) and [f.direction for f in violation.frames] == ["tx", "rx"]
    result = ScenarioResult("s", None, "", "Main", "fx3u", "fx3:1", [], 1_000_000, 10_000, 0, S, trace=trace)
    meaning = {r["t"]: r["meaning"] for r in records(result) if r["dir"] == "rx"}
    assert violation.frames[1].meaning == meaning[reply.t_start_us / 1_000_000]
    assert "running" in violation.frames[1].meaning


def test_half_duplex_needs_t3_5_of_silence_after_the_robot():
    request = tx(0, STOP)
    reply = answer(request)
    too_soon = _frame("tx", reply.t_end_us + 2 * MS, protocol.encode(READ_TASK, S))
    (violation,) = check([request, reply, too_soon], options=RuleOptions(min_period_us=1))["UITAMR-HALF-DUPLEX"]
    assert "3.5 characters" in violation.message
    after_t35 = _frame("tx", reply.t_end_us + protocol.T3_5_US, protocol.encode(READ_TASK, S))
    assert check([request, reply, after_t35], options=RuleOptions(min_period_us=1))["UITAMR-HALF-DUPLEX"] == []


def test_replies_are_paired_in_order_when_a_retry_goes_out_too_early():
    """Robot answers each request once, in order: the first echo answers the first stop."""
    first = tx(0, STOP)
    retry = tx(300, STOP)
    replies = [rx(first.t_end_us + 400 * MS, protocol.encode(protocol.ControlReply.echo(STOP), S)),
               rx(retry.t_end_us + 400 * MS, protocol.encode(protocol.ControlReply.echo(STOP), S))]
    found = check([first, retry, *replies], options=RuleOptions(min_period_us=1))
    assert "was due" in found["UITAMR-HALF-DUPLEX"][0].message
    assert len(found["UITAMR-ONE-AT-A-TIME"]) == 1


def test_a_late_reply_colliding_with_a_retry_after_the_time_out_is_the_robots_fault():
    request = tx(0, STOP)
    retry = tx(700, STOP)
    late = rx(retry.t_start_us + 3 * MS, protocol.encode(protocol.ControlReply.echo(STOP), S))
    found = check([request, retry, late, answer(retry, delay_us=20 * MS)])
    assert found["UITAMR-HALF-DUPLEX"] == [] and found["UITAMR-ONE-AT-A-TIME"] == []


def test_a_request_the_robot_talked_over_is_not_answered_and_the_pairing_does_not_slip():
    """A late reply began while the PLC's retry was still going out: the robot could not
    read that retry, so it answers nothing of it. Its next frame answers the PLC's next
    request; pairing it with the talked-over retry (still within its time-out) made every
    later exchange one off - each request "sent while its predecessor's reply was due"
    until the end of the run (UITAMR-HALF-DUPLEX and ONE-AT-A-TIME at every poll)."""
    first = tx(0, READ_TASK)
    retry = tx(700, READ_TASK)
    late = rx(retry.t_start_us + 3 * MS, protocol.encode(protocol.StatusReply(1, 0, 1), S))
    trace = [first, retry, late]
    for start_ms in range(1070, 4000, 370):  # the polls after it, each answered at once
        trace += exchange(start_ms, READ_TASK)
    found = check(trace)
    assert found["UITAMR-HALF-DUPLEX"] == []
    # the PLC took the late frame for its reply and polled again 370 ms after the retry: that
    # one poll is early (the frame began before the retry ended, so it is no reply to it)
    assert [v.t_us for v in found["UITAMR-ONE-AT-A-TIME"]] == [1_070_000]
    # the same retry when the robot began after it had ended: awaited as before
    heard = check([first, retry, rx(retry.t_end_us + 3 * MS, protocol.encode(protocol.StatusReply(1, 0, 1), S)),
                   *exchange(1300, READ_TASK)])
    assert heard["UITAMR-HALF-DUPLEX"] == [] and heard["UITAMR-ONE-AT-A-TIME"] == []


def test_an_overlap_within_the_host_timing_tolerance_does_not_make_a_request_talked_over():
    """Host timestamps (a capture of tx/rx lines, --tolerance 20ms): a request that seems to
    start 5 ms before the robot's previous frame ended may not have overlapped it at all, so
    it still waits for its reply, as UITAMR-HALF-DUPLEX does not blame it either. Exact
    times (verify, --tolerance 0): it did, and the robot cannot have read it."""
    from verifier.verify.traffic import analyse

    first = tx(0, READ_TASK)
    slow = answer(first, delay_us=300 * MS)
    early = _frame("tx", slow.t_end_us - 5 * MS, protocol.encode(READ_TASK, S))
    reply = answer(early)
    trace = [first, slow, early, reply]
    lenient = analyse(trace, S, RuleOptions(timing_tolerance_us=20 * MS))
    assert not lenient.exchanges[1].talked_over and lenient.exchanges[1].reply == reply
    exact = analyse(trace, S, RuleOptions())
    assert exact.exchanges[1].talked_over
    assert check(trace, options=RuleOptions(timing_tolerance_us=20 * MS, min_period_us=1))["UITAMR-HALF-DUPLEX"] == []


def test_one_at_a_time_waits_for_the_time_out_when_no_reply_comes():
    impatient = [tx(0, STOP)] + exchange(300, READ_TASK)
    (violation,) = check(impatient)["UITAMR-ONE-AT-A-TIME"]
    assert "no reply" in violation.message and "500.0 ms" in violation.message
    patient = [tx(0, STOP)] + exchange(520, READ_TASK)
    assert check(patient)["UITAMR-ONE-AT-A-TIME"] == []
    shorter = RuleOptions(reply_timeout_us=250 * MS)
    assert check(impatient, options=shorter)["UITAMR-ONE-AT-A-TIME"] == []


# --- UITAMR-CYCLE ---------------------------------------------------------------------------

def test_cycle_needs_a_status_read_between_control_commands():
    trace = exchange(0, STOP) + exchange(300, POINT3)
    (violation,) = check(trace)["UITAMR-CYCLE"]
    assert "no status read" in violation.message
    assert check(exchange(0, STOP) + exchange(300, READ_TASK) + exchange(600, POINT3))["UITAMR-CYCLE"] == []


def test_cycle_allows_the_retry_of_an_unanswered_command_but_not_a_resend_of_an_answered_one():
    retry = exchange(0, STOP)[:1] + exchange(700, STOP)
    assert check(retry)["UITAMR-CYCLE"] == []
    resend = exchange(0, STOP) + exchange(300, STOP)
    assert len(check(resend)["UITAMR-CYCLE"]) == 1


def test_cycle_lets_the_stop_overtake_a_command_without_a_read_in_between():
    """The library sends the stop at once when the operator presses it, also right after a
    run-point command (answered or not): that was a UITAMR-CYCLE violation. The command
    after the stop still needs its read; a stop after a stop too (a resend)."""
    answered = exchange(0, STOP) + exchange(300, READ_TASK) + exchange(600, POINT3) + exchange(900, STOP)
    assert check(answered)["UITAMR-CYCLE"] == []
    unanswered = exchange(0, STOP) + exchange(300, READ_TASK) + [tx(600, POINT3)] + exchange(1200, STOP)
    assert check(unanswered)["UITAMR-CYCLE"] == []
    (after_the_stop,) = check(answered + exchange(1200, POINT3))["UITAMR-CYCLE"]
    assert "run point/script 3" in after_the_stop.message and "follows stop" in after_the_stop.message


def test_cycle_needs_the_read_answered():
    unanswered_read = exchange(0, STOP) + [tx(300, READ_TASK)] + exchange(900, POINT3)
    assert len(check(unanswered_read)["UITAMR-CYCLE"]) == 1


# --- UITAMR-RESPONSE-HANDLING ---------------------------------------------------------------

def _silent_robot_trace(seconds: int) -> list[TraceRecord]:
    """Stop acknowledged, then the robot never answers again; the PLC keeps polling."""
    trace = exchange(0, STOP)
    trace += [tx(700 * i, READ_TASK) for i in range(1, int(seconds * 1000 / 700))]
    return trace


def _signal(changes: list[tuple[int, bool]]) -> Samples:
    samples = Samples(["o_bErr"])
    for t_us, value in changes:
        samples.record(t_us, {"o_bErr": value})
    return samples


def test_response_handling_passes_when_the_program_signals_within_the_bound():
    options = RuleOptions(response_signal=parse_condition("o_bErr"), response_within_us=5_000_000)
    samples = _signal([(0, False), (2_500_000, True)])
    found = check(_silent_robot_trace(12), end_us=12_000_000, options=options, samples=samples)
    assert found["UITAMR-RESPONSE-HANDLING"] == []


def test_response_handling_flags_a_program_that_never_notices():
    options = RuleOptions(response_signal=parse_condition("o_bErr"), response_within_us=5_000_000)
    samples = _signal([(0, False)])
    (violation,) = check(_silent_robot_trace(12), end_us=12_000_000, options=options, samples=samples)[
        "UITAMR-RESPONSE-HANDLING"
    ]
    assert "'o_bErr' did not become true within 5 s" in violation.message
    assert "no reply" in violation.message


def test_response_handling_flags_a_signal_that_comes_too_late():
    options = RuleOptions(response_signal=parse_condition("o_bErr"), response_within_us=2_000_000)
    samples = _signal([(0, False), (4_000_000, True)])
    assert len(check(_silent_robot_trace(12), end_us=12_000_000, options=options, samples=samples)[
        "UITAMR-RESPONSE-HANDLING"]) == 1


def test_response_handling_lets_a_quick_retry_recover_silently():
    bad = bytearray(protocol.encode(protocol.ControlReply.echo(STOP), S))
    bad[-1] ^= 0xFF
    first = tx(0, STOP)
    trace = [first, rx(first.t_end_us + TURNAROUND, bytes(bad))] + exchange(700, STOP)
    options = RuleOptions(response_signal=parse_condition("o_bErr"), response_within_us=1_000_000)
    found = check(trace, end_us=10_000_000, options=options, samples=_signal([(0, False)]))
    assert found["UITAMR-RESPONSE-HANDLING"] == []


def test_response_handling_counts_exceptions_wrong_addresses_and_garbage_as_failures():
    exception = protocol.encode(protocol.ExceptionReply(1, 6, 4), S)
    wrong_address = protocol.encode(protocol.ControlReply.echo(replace(STOP, address=7)), S)
    options = RuleOptions(response_signal=parse_condition("o_bErr"), response_within_us=1_000_000)
    for reply in (exception, wrong_address, b"\xa5\x5a\xff"):
        trace = exchange(0, STOP, reply=reply)
        for i in range(1, 10):
            trace += exchange(700 * i, STOP, reply=reply)
        found = check(trace, end_us=8_000_000, options=options, samples=_signal([(0, False)]))
        assert len(found["UITAMR-RESPONSE-HANDLING"]) == 1, reply.hex()


def test_response_handling_on_a_capture_says_what_to_check_on_site_for_each_failure():
    """A capture shows no outputs: the message names what to look at on site, per kind of
    failure on the line (no reply: the slave the requests go to; the rest from the table)."""
    options = RuleOptions(outputs_visible=False, response_within_us=1_000_000)
    (silent,) = check(_silent_robot_trace(12), end_us=12_000_000, options=options)["UITAMR-RESPONSE-HANDLING"]
    assert "on site, check why the robot does not answer: its power, its address (the requests go to slave 1)" \
        in silent.message
    exception = protocol.encode(protocol.ExceptionReply(1, 6, 4), S)
    trace = []
    for i in range(10):
        trace += exchange(700 * i, STOP, reply=exception)
    (refused,) = check(trace, end_us=8_000_000, options=options)["UITAMR-RESPONSE-HANDLING"]
    assert refused.message.endswith(
        "on site, check why the robot refused the requests: the exception code in the replies")


def test_response_handling_asks_for_a_signal_when_none_is_known():
    (violation,) = check(_silent_robot_trace(12), end_us=12_000_000)["UITAMR-RESPONSE-HANDLING"]
    assert "[response_handling] signal" in violation.message


# --- properties -----------------------------------------------------------------------------

@hsettings(max_examples=60, deadline=None)
@given(
    gaps=st.lists(st.integers(min_value=251, max_value=2000), min_size=1, max_size=25),
    delays=st.lists(st.integers(min_value=protocol.T3_5_US, max_value=200_000), min_size=25, max_size=25),
)
def test_any_well_paced_polling_with_timely_replies_is_compliant(gaps, delays):
    trace = exchange(0, STOP)
    t = 0
    for gap, delay in zip(gaps, delays):
        t += gap
        trace += exchange(t, READ_TASK, delay_us=delay)
    assert broken(check(trace)) == {}


@hsettings(max_examples=60, deadline=None)
@given(gaps=st.lists(st.integers(min_value=1, max_value=600), min_size=2, max_size=20))
def test_pacing_flags_exactly_the_gaps_of_250_ms_or_less(gaps):
    trace = [tx(0, STOP)]
    t = 0
    for gap in gaps:
        t += gap
        trace.append(tx(t, READ_TASK))
    assert len(check(trace)["UITAMR-PACING"]) == sum(1 for gap in gaps if gap <= 250)


def test_rules_by_id_matches_the_catalogue():
    assert set(RULES_BY_ID) == {rule.id for rule in RULES}


def test_the_cycle_rules_explanation_names_the_stop_that_may_overtake():
    """The explanation `verify --list-rules`, JUnit, HTML and JSON reports print said every
    control command needs a read before the next, while the rule lets a stop overtake the
    command before it (docs/verifier.md): a user reading a passing run's report could not
    tell why point -> stop passed."""
    explanation = RULES_BY_ID["UITAMR-CYCLE"].explanation
    assert "stop" in explanation and "overtake" in explanation, explanation
    assert "a stop after a stop" in explanation, explanation
