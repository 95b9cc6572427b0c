"""The robot's TCP route in the simulator: the virtual converter on a real Line and robot,
the FX5U socket and QJ71E71 fixed-buffer instruction models under the library's port FBs,
and `[converter]` in scenario files. The bundled scenarios (test_plc_scenarios.py) run the
examples through healthy, refused, dropped, split and silent converters; here each piece
is pinned on its own, with controls that show the checks can fail."""
from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import pytest

from sim_helpers import PORT_ERR, RX_DONE, RX_LEN, TX_BASE, TX_LEN, TX_REQ, comparable, load_st
from verifier.amr import Robot
from verifier.link import Line
from verifier.link.converter import Converter, ConverterConfig
from verifier.protocol.codec import STOP_FRAME
from verifier.sim.instructions import tcp
from verifier.verify.runner import run_scenario
from verifier.verify.scenario import ScenarioError, load_scenario, parse_scenario

SCENARIOS = Path(__file__).resolve().parents[1] / "plc" / "scenarios"
STOP = bytes(STOP_FRAME)


def converter(**settings) -> Converter:
    return Converter(Line(Robot()), ConverterConfig(**settings))


def collect(conv: Converter, connection: int, start: int, end: int, step: int = 1_000):
    got = []
    for now in range(start, end, step):
        got += conv.receive_until(now, connection)
    return got


# ---- the converter -----------------------------------------------------------------------

def test_converter_forwards_a_request_after_its_delay_and_the_reply_after_packing_and_delay():
    conv = converter(delay_us=3_000, pack_us=5_000)
    opened = conv.open(0, "192.168.3.50", 4001)
    assert opened.ok and opened.done_us == 1_000
    assert conv.send(10_000, opened.connection, STOP, "st:1:1")
    segments = collect(conv, opened.connection, 10_000, 60_000)
    tx, rx = conv.line.trace
    assert (tx.direction, tx.data, tx.t_start_us, tx.origin) == ("tx", STOP, 13_000, "st:1:1")
    assert rx.direction == "rx" and rx.data == STOP  # the robot echoes the stop command
    assert segments == [(rx.t_end_us + 5_000 + 3_000, STOP)]


def test_converter_splits_a_reply_in_two_segments():
    conv = converter(split_reply=True, split_gap_us=20_000)
    opened = conv.open(0, "192.168.3.50", 4001)
    conv.send(2_000, opened.connection, STOP)
    segments = collect(conv, opened.connection, 2_000, 100_000)
    assert [data for _, data in segments] == [STOP[:4], STOP[4:]]
    assert segments[1][0] - segments[0][0] == 20_000
    assert any(e.kind == "converter.split" for e in conv.events)


@pytest.mark.parametrize("ip, port, reason, done_us", [
    ("192.168.3.50", 502, "refused", 1_000),
    ("192.168.3.51", 4001, "unreachable", 3_000_000),
])
def test_wrong_address_is_refused_or_unanswered(ip, port, reason, done_us):
    conv = converter()
    result = conv.open(0, ip, port)
    assert (result.ok, result.reason, result.done_us) == (False, reason, done_us)
    assert "192.168.3.50:4001" in conv.events[-1].message  # says where the converter is


def test_refuse_until_then_accept_one_client_only():
    conv = converter(refuse_until_us=1_000_000)
    assert conv.open(0, "192.168.3.50", 4001).reason == "refused"
    first = conv.open(1_000_000, "192.168.3.50", 4001)
    assert first.ok
    assert conv.open(1_100_000, "192.168.3.50", 4001).reason == "busy"
    conv.close(1_200_000, first.connection)
    assert conv.open(1_300_000, "192.168.3.50", 4001).ok


def test_drop_forwards_the_request_then_loses_the_reply():
    conv = converter(drops=(0,), delay_us=2_000)
    opened = conv.open(0, "192.168.3.50", 4001)
    conv.send(5_000, opened.connection, STOP)
    assert not conv.peer_closed(6_000, opened.connection)
    assert conv.peer_closed(9_000, opened.connection)  # the close reaches the PLC after the delay
    assert collect(conv, opened.connection, 9_000, 80_000) == []
    assert [f.direction for f in conv.line.trace] == ["tx", "rx"]  # the robot did get it and answer
    assert [e.kind for e in conv.events] == ["converter.accepted", "converter.dropped", "converter.lost"]
    assert not conv.send(90_000, opened.connection, STOP)  # that connection is gone
    assert conv.open(100_000, "192.168.3.50", 4001).ok  # a new one is accepted


def test_time_only_moves_forward():
    conv = converter()
    conv.open(5_000, "192.168.3.50", 4001)
    with pytest.raises(ValueError, match="only moves forward"):
        conv.receive_until(1_000, 1)


# ---- instruction models under small programs ------------------------------------------------

FX5_PROGRAM = """
PROGRAM P
VAR
    bGo : BOOL;
    uCtl : ARRAY[0..9] OF WORD;
    bDone : ARRAY[0..1] OF BOOL;
    bSeen : BOOL;
    bSeenErr : BOOL;
END_VAR
SP_SOCOPEN(bGo, 'U0', 1, uCtl[0], bDone[0]);
IF bDone[0] THEN
    bSeen := TRUE;
    bSeenErr := bDone[1];
END_IF;
END_PROGRAM
"""


def open_fx5(execution_type: int, ip_words=(0x0332, 0xC0A8), port=4001, attach=True):
    project = load_st(FX5_PROGRAM, cpu="fx5u", target="gxworks3")
    if attach:
        project.attach_tcp(converter())
    program = project.program("P")
    program.uCtl[0], program.uCtl[4], program.uCtl[5], program.uCtl[6] = execution_type, *ip_words, port
    program.bGo = True
    project.run_programs(["P"], scans=5)
    return project, program


def test_fx5_open_with_control_data_connects_and_sets_the_open_signal():
    project, program = open_fx5(0x8000)
    assert program.bSeen and not program.bSeenErr and program.uCtl[1] == 0
    assert project.devices["SD10680"] & 1


def test_fx5_open_with_parameter_settings_is_named_as_not_modelled():
    project, program = open_fx5(0x0000)
    assert program.bSeen and program.bSeenErr and program.uCtl[1] == tcp.ERR_PARAMETER_OPEN
    assert any("execution type 0000H" in d.message for d in project.diagnostics)


def test_fx5_open_without_a_converter_fails_as_unreachable():
    project, program = open_fx5(0x8000, attach=False)
    assert program.bSeenErr and program.uCtl[1] == tcp.ERR_UNREACHABLE
    assert not project.devices["SD10680"] & 1


def test_fx5_open_runs_once_per_rising_edge():
    project, program = open_fx5(0x8000)
    project.run_programs(["P"], scans=5)  # EN stays on: no second open (it would fail: already open)
    assert program.uCtl[1] == 0 and not program.bSeenErr


E71_PROGRAM = """
PROGRAM P
VAR
    bGo : BOOL;
    bSend : BOOL;
    wSendConn : INT;
    uCtl : ARRAY[0..9] OF WORD;
    uSendCtl : ARRAY[0..1] OF WORD;
    uData : ARRAY[0..8] OF WORD;
    bDone : ARRAY[0..1] OF BOOL;
    bSendDone : ARRAY[0..1] OF BOOL;
    bSendErr : BOOL;
END_VAR
ZP_OPEN(bGo, 'U0', 1, uCtl[0], bDone[0]);
ZP_BUFSND(bSend, 'U0', wSendConn, uSendCtl[0], uData[0], bSendDone[0]);
IF bSendDone[1] THEN
    bSendErr := TRUE;
END_IF;
END_PROGRAM
"""


@pytest.mark.parametrize("send_on, fails", [(2, False), (1, True)])
def test_e71_pairing_open_sends_on_n_plus_1_only(send_on, fails):
    project = load_st(E71_PROGRAM, cpu="q", target="gxworks2")
    conv = converter()
    project.attach_tcp(conv)
    p = project.program("P")
    p.uCtl[0], p.uCtl[2], p.uCtl[4], p.uCtl[5], p.uCtl[6] = 0x8000, 0x0281, 0x0332, 0xC0A8, 4001
    p.bGo = True
    project.run_programs(["P"], scans=3)
    buffer = project.c24_buffer(0)
    assert buffer[0x5000] & 0b11 == 0b11  # connections 1 and 2 open (pairing)
    for k, word in enumerate([8, 0x0601, 0xA001, 0x0000, 0x1488]):  # byte count, then 01 06 01 A0 00 00 88 14
        p.uData[k] = word
    p.wSendConn, p.bSend = send_on, True
    project.run_programs(["P"], scans=3)
    assert p.bSendErr is fails
    sent = [f.data for f in conv.line.trace if f.direction == "tx"]
    assert sent == ([] if fails else [STOP])


# ---- scenarios ----------------------------------------------------------------------------------

def test_healthy_expectations_fail_when_the_converter_drops():
    """Control: the healthy TCP scenario's expectations do see a dropped connection."""
    scenario = load_scenario(SCENARIOS / "fx5u-tcp-healthy.toml")
    result = run_scenario(replace(scenario, converter=replace(scenario.converter, drops=(20_000_000,))))
    failed = [outcome.expectation.key for outcome in result.failed_expectations]
    assert failed == ["expect[3]", "expect[4]"]  # never an error, no attempt repeated


@pytest.mark.parametrize("ip, port, detail", [("192.168.3.51", 4001, tcp.ERR_UNREACHABLE),
                                              ("192.168.3.50", 502, tcp.ERR_REFUSED)])
def test_a_converter_at_another_address_gives_0310_and_nothing_reaches_the_robot(ip, port, detail):
    scenario = load_scenario(SCENARIOS / "fx5u-tcp-healthy.toml")
    scenario = replace(scenario, duration_us=10_000_000, expectations=(),
                       converter=replace(scenario.converter, ip=ip, port=port))
    result = run_scenario(scenario)
    assert not result.trace  # no byte on the robot's line
    watched = dict(result.watched)
    assert [v for _, v in watched["fbPort.o_uErrId"]][-1] == 0x0310
    assert any(f"{ip}:{port}" in e.message for e in result.events)
    assert "nothing reached the robot's line through the converter" in result.notes[-1]
    assert result.channel == "tcp"


def test_a_split_longer_than_the_reassembly_gap_ends_the_reply_early():
    """UITAMR_TcpLink waits RX_GAP_TIME (50 ms) for the rest of a reply of known length only
    as long as bytes keep coming; a converter that holds the second half for 80 ms makes the
    engine see a short reply and repeat the request - the limit docs/tcp-converter.md names."""
    scenario = load_scenario(SCENARIOS / "fx5u-tcp-split.toml")
    result = run_scenario(replace(scenario, duration_us=5_000_000, expectations=(),
                                  converter=replace(scenario.converter, split_gap_us=80_000)))
    retries = [v for _, v in dict(result.watched)["fbEngine.o_wRetryCount"]]
    assert retries[-1] > 0


def where(text: str) -> str:
    with pytest.raises(ScenarioError) as info:
        parse_scenario(text, Path("s.toml"))
    return str(info.value)


BASE = 'platform = "fx5u"\n'


@pytest.mark.parametrize("text, expected", [
    ('platform = "fx3u"\n[converter]\nport = 4001\n', "s.toml:2:1: converter: the TCP route needs"),
    (BASE + '[converter]\nip = "192.168.3"\n', "s.toml:3:6: converter.ip: expected an IPv4 address"),
    # '²' is a digit to str.isdigit() but not to int(): was a ValueError traceback
    (BASE + '[converter]\nip = "192.168.3.²"\n', "s.toml:3:6: converter.ip: expected an IPv4 address"),
    (BASE + '[converter]\nport = 70000\n', "s.toml:3:8: converter.port: expected a TCP port 1..65535"),
    (BASE + '[converter]\ndrops = "20s"\n', "s.toml:3:9: converter.drops: expected a list of times"),
    (BASE + '[converter]\ndrops = ["20s", "x"]\n', "s.toml:3:17: converter.drops[1]"),
    # a drop after the run was silently never done, while a fault's at_s there is an error
    (BASE + 'duration = "30s"\n[converter]\ndrops = ["20s", "30s"]\n',
     "s.toml:4:17: converter.drops[1]: is at or after the end of the run (30s): the drop would never happen"),
    (BASE + '[converter]\nsplit = true\n', "s.toml:3:1: converter.split: unknown key"),
    (BASE + 'channel = "fx5:1"\n[converter]\n', "s.toml:2:11: channel: a scenario with [converter]"),
])
def test_converter_settings_errors_name_file_line_and_column(text, expected):
    assert expected in where(text)


# ---- any converter: the rules hold on the robot's line ------------------------------------------

from hypothesis import HealthCheck, example, given, settings, strategies as st  # noqa: E402


@settings(max_examples=12, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(platform=st.sampled_from(["fx5u", "q"]),
       delay_ms=st.integers(0, 40), packing_ms=st.integers(1, 20),
       refuse_until_ms=st.sampled_from([0, 0, 700, 2500]),
       drops_s=st.lists(st.integers(4, 18), max_size=3, unique=True),
       split=st.booleans(), split_gap_ms=st.integers(1, 40))
# found by this test: a reply in one-byte segments stalled the receive (EN on two scans in a
# row: no rising edge) and ended early on Q (the gap timer ran from the first byte) ...
@example(platform="fx5u", delay_ms=0, packing_ms=1, refuse_until_ms=0, drops_s=[], split=False, split_gap_ms=1)
@example(platform="q", delay_ms=0, packing_ms=1, refuse_until_ms=0, drops_s=[], split=False, split_gap_ms=1)
# ... and a control command repeated after its reply was lost at the converter was a CYCLE violation
@example(platform="fx5u", delay_ms=0, packing_ms=1, refuse_until_ms=0, drops_s=[4, 9], split=False, split_gap_ms=1)
def test_whatever_the_converter_does_the_line_keeps_every_rule(platform, delay_ms, packing_ms, refuse_until_ms,
                                                              drops_s, split, split_gap_ms):
    """Random converter behaviour (delays, packing, refusals, drops mid-transaction, split
    replies within the reassembly gap): on the robot's line the stop still comes first, the
    pacing and half duplex hold, no rule is broken; the port is connected at the end."""
    name = "fx5u-tcp-healthy" if platform == "fx5u" else "q-tcp-healthy"
    scenario = load_scenario(SCENARIOS / f"{name}.toml")
    config = replace(scenario.converter, delay_us=delay_ms * 1000, pack_us=packing_ms * 1000,
                     refuse_until_us=refuse_until_ms * 1000, drops=tuple(s * 1_000_000 for s in sorted(drops_s)),
                     split_reply=split, split_gap_us=split_gap_ms * 1000)
    result = run_scenario(replace(scenario, duration_us=25_000_000, expectations=(), converter=config))
    assert result.aborted is None
    assert not result.all_violations(), [f"{v.rule}: {v.message}" for v in result.all_violations()[:3]]
    tx = [f for f in result.trace if f.direction == "tx"]
    assert tx and tx[0].data == STOP
    assert dict(result.watched)["fbPort.o_bConnected"][-1][1] is True


# ---- speed without a changed byte (docs/performance.md, session 23) -----------------------------


from verifier.sim import instructions  # noqa: E402
from verifier.sim.instructions.tcp import TcpPort  # noqa: E402
from verifier.sim.refs import operand_key, pulse_keys  # noqa: E402

ETHERNET = sorted(instructions.ETHERNET)
TCP_SCENARIOS = sorted(SCENARIOS.glob("*-tcp-*.toml"))


def _through_the_port(name: str):
    """The InstructionSet entry as it was before the EN shortcut: always into the port."""
    if name.startswith("SP_"):
        return lambda self, *args: getattr(self.socket_port(), name.lower())(*args)
    return lambda self, en, un, *args: getattr(self.e71(un), name.lower())(en, *args)


@pytest.mark.parametrize("path", TCP_SCENARIOS, ids=lambda p: p.stem)
def test_the_en_shortcut_of_the_ethernet_instructions_changes_nothing(path, monkeypatch):
    """The SP_/ZP_ entries return at once on a scan with EN FALSE as on the scan before;
    every bundled TCP scenario gives the same result, field for field, when every call goes
    into the port as before."""
    scenario = load_scenario(path)
    shortcut = run_scenario(scenario)
    for name in ETHERNET:
        monkeypatch.setattr(instructions.InstructionSet, name, _through_the_port(name))
    assert comparable(shortcut) == comparable(run_scenario(scenario))


def test_control_an_entry_that_skips_a_rising_edge_is_seen(monkeypatch):
    """Control for the comparison above: a ZP_BUFSND shortcut that also drops every second
    rising edge changes the result."""
    scenario = load_scenario(SCENARIOS / "q-tcp-healthy.toml")
    scenario = replace(scenario, duration_us=10_000_000)
    before = run_scenario(scenario)
    seen = []

    def lossy(self, en, un, *args):
        if en and not self.e71(un)._last_en.get(args[-1]):
            seen.append(1)
            if len(seen) % 2 == 0:
                return
        self.e71(un).zp_bufsnd(en, *args)

    monkeypatch.setattr(instructions.InstructionSet, "ZP_BUFSND", lossy)
    assert comparable(before) != comparable(run_scenario(scenario))


def _idle_state_before(port: TcpPort) -> tuple:
    """`TcpPort.idle_state` as it was before session 23 (a generator over the connections)."""
    number = lambda c: None if c is None else c.number  # noqa: E731
    conns = tuple(
        (c.state, c.remote, c.open_done_us, c.open_ok, c.open_status,
         None if c.open_refs is None else tuple(map(operand_key, c.open_refs)),
         tuple(c.received), number(c.receiver), number(c.partner), number(c.pair))
        for c in port.connections.values())
    endpoint = port.endpoint
    peer = endpoint.idle_state() if hasattr(endpoint, "idle_state") else None
    return (conns, tuple(port._last_en.items()), pulse_keys(port.pulses), pulse_keys(port.pending),
            port._active, tuple(getattr(port, "direction", {}).items()), peer)


@pytest.mark.parametrize("path", TCP_SCENARIOS, ids=lambda p: p.stem)
def test_idle_state_tells_scans_apart_exactly_as_before(path, monkeypatch):
    """The idle check only compares a port's `idle_state` with the one of the scan before:
    on every scan of every bundled TCP scenario (run scan by scan) the faster one is equal
    to the one before exactly when the old one is."""
    seen = []
    original = TcpPort.poll

    def poll_and_record(self, now):
        seen.append((_idle_state_before(self), self.idle_state()))
        original(self, now)

    monkeypatch.setattr(TcpPort, "poll", poll_and_record)
    run_scenario(load_scenario(path), plain=True)
    assert len(seen) > 1000
    changes = [(old != seen[k - 1][0], new != seen[k - 1][1]) for k, (old, new) in enumerate(seen) if k]
    assert all(a == b for a, b in changes)
    assert any(a for a, _ in changes) and not all(a for a, _ in changes)


def _poll_before(self, now: int) -> None:
    """`TcpPort.poll` as it was before session 23 (the pulse lists swapped on every scan,
    every connection's state compared)."""
    for ref, bit in self.pulses:
        ref.set(bit, False)
    self.pulses, self.pending = self.pending, []
    for ref, bit in self.pulses:
        ref.set(bit, True)
    if not self._active:
        return
    endpoint = self.endpoint
    active = False
    for conn in self.connections.values():
        if conn.state == tcp.OPENING:
            active = True
            if now >= conn.open_done_us:
                control, done = conn.open_refs
                conn.open_refs = None
                conn.state = tcp.OPEN if conn.open_ok else tcp.CLOSED
                control.set(1, conn.open_status)
                done.set(0, True)
                self.pulses.append((done, 0))
                if not conn.open_ok:
                    done.set(1, True)
                    self.pulses.append((done, 1))
                self.opened(conn)
                self.show_status(conn)
        elif conn.state == tcp.OPEN and endpoint is not None:
            active = True
            reader = conn.receiver or conn
            for _, segment in endpoint.receive_until(now, conn.remote):
                reader.received.append(segment)
            if reader.received:
                self.show_status(reader)
            if endpoint.peer_closed(now, conn.remote):
                conn.state = tcp.PEER_CLOSED
                self.show_status(conn)
        elif conn.state == tcp.PEER_CLOSED:
            active = True
    self._active = active


@pytest.mark.parametrize("path", TCP_SCENARIOS, ids=lambda p: p.stem)
def test_the_faster_poll_changes_nothing(path, monkeypatch):
    """Every bundled TCP scenario gives the same result, field for field, with the port's
    poll as it was (tests/test_idle_skip.py compares the skipping run with the scan-by-scan
    one, which share the poll: this compares the poll itself)."""
    scenario = load_scenario(path)
    now = run_scenario(scenario)
    monkeypatch.setattr(TcpPort, "poll", _poll_before)
    assert comparable(now) == comparable(run_scenario(scenario))


@pytest.mark.parametrize("platform", ["fx5u", "q"])
def test_the_port_opens_again_after_the_documented_back_off(platform):
    """docs/tcp-converter.md and the error table: after a failed open the port tries again
    after 0.5 s, 1 s, 2 s, 4 s, then every 8 s; the drop of a connection that was open is a
    first failure again, so the next open follows 0.5 s later. Measured on the converter's events (each open it saw),
    allowing each wait a few scans (close, open, the converter's connect time)."""
    scenario = load_scenario(SCENARIOS / f"{platform}-tcp-refused.toml")
    result = run_scenario(replace(scenario, duration_us=40_000_000, expectations=(),
                                  converter=replace(scenario.converter, refuse_until_us=30_000_000)))
    opens = [(e.t_us, e.kind) for e in result.events if e.kind in ("converter.refused", "converter.accepted")]
    assert [kind for _, kind in opens] == ["converter.refused"] * 7 + ["converter.accepted"]
    waits = [later - earlier for (earlier, _), (later, _) in zip(opens, opens[1:])]
    for wait, back_off in zip(waits, [500_000, 1_000_000, 2_000_000, 4_000_000, 8_000_000, 8_000_000, 8_000_000]):
        assert back_off <= wait <= back_off + 60_000, waits
    scenario = load_scenario(SCENARIOS / f"{platform}-tcp-dropped.toml")
    result = run_scenario(replace(scenario, duration_us=25_000_000, expectations=()))
    events = [(e.t_us, e.kind) for e in result.events if e.kind in ("converter.dropped", "converter.accepted")]
    assert [kind for _, kind in events] == ["converter.accepted", "converter.dropped", "converter.accepted"]
    assert 500_000 <= events[2][0] - events[1][0] <= 600_000


@pytest.mark.parametrize("platform", ["fx5u", "q"])
def test_a_frame_sent_with_no_connection_fails_the_attempt_with_0314(platform):
    """docs/tcp-converter.md: a frame the engine sends while there is no connection is not
    sent (16#0314) and the engine repeats it; after three failed attempts it ends with
    16#0108, detail 16#0314. Here the converter refuses every open: the port holds
    16#0310 (the open), the engine 16#0108/16#0314, and nothing reaches the robot."""
    scenario = load_scenario(SCENARIOS / f"{platform}-tcp-refused.toml")
    result = run_scenario(replace(scenario, duration_us=5_000_000, expectations=(),
                                  watch=scenario.watch + ("fbEngine.o_uErrDetail", "fbEngine.o_wRetryCount"),
                                  converter=replace(scenario.converter, refuse_until_us=30_000_000)))
    watched = dict(result.watched)
    assert not result.trace
    assert watched["fbPort.o_uErrId"][-1][1] == 0x0310
    assert (watched["fbEngine.o_uErrId"][-1][1], watched["fbEngine.o_uErrDetail"][-1][1]) == (0x0108, 0x0314)
    retries = [v for _, v in watched["fbEngine.o_wRetryCount"]]
    assert retries[:4] == [0, 1, 2, 3]  # repeated, not sent


TCP_LINK_HARNESS = """
PROGRAM T_Tcp
VAR
    fbLink : UITAMR_TcpLink;
    uPort : ARRAY[0..39] OF WORD;
    uSockSend : ARRAY[0..8] OF WORD;
    uSockRecv : ARRAY[0..8] OF WORD;
    bEN : BOOL; bConnected : BOOL; bOpenDone : BOOL; bOpenErr : BOOL; uOpenStatus : WORD;
    bSendDone : BOOL; bSendErr : BOOL; uSendStatus : WORD;
    bRecvReady : BOOL; bRecvDone : BOOL; bRecvErr : BOOL; uRecvStatus : WORD; bCloseDone : BOOL;
END_VAR
fbLink(i_bEN := bEN, i_bConnected := bConnected, i_bOpenDone := bOpenDone, i_bOpenErr := bOpenErr,
       i_uOpenStatus := uOpenStatus, i_bSendDone := bSendDone, i_bSendErr := bSendErr,
       i_uSendStatus := uSendStatus, i_bRecvReady := bRecvReady, i_bRecvDone := bRecvDone,
       i_bRecvErr := bRecvErr, i_uRecvStatus := uRecvStatus, i_bCloseDone := bCloseDone,
       io_uPort := uPort, io_uSockSend := uSockSend, io_uSockRecv := uSockRecv);
END_PROGRAM
"""


def test_tcp_link_send_and_receive_errors_are_0312_and_0313_as_the_error_table_says():
    """UITAMR_TcpLink driven by hand (no instruction model can fail a send or a receive on
    an open connection): the engine's frame goes to the send instruction as raw RTU bytes,
    CRC included, low byte first; a failed send is 16#0312 with its completion status and
    fails the engine's attempt at once (port word 4 = 16#0312, as the engine's 16#0108
    detail); a failed receive is 16#0313 and fails nothing (docs/plc-library.md)."""
    import verifier

    guide = (Path(__file__).resolve().parents[1] / "docs" / "plc-library.md").read_text(encoding="utf-8")
    assert "port code (16#0306/0307/0309, 16#0311/0312/0314)" in guide
    assert "| 16#0313 | TCP port: the receive instruction completed with an error | completion status | " \
           "the bytes of that receive are dropped; the attempt is not failed at once" in guide
    h = verifier.load(Path(__file__).resolve().parents[1] / "plc" / "core",
                      sources={"T_Tcp.st": TCP_LINK_HARNESS}).program("T_Tcp")
    h.bEN = True
    h.scan()
    assert h.fbLink.o_bOpen
    h.bOpenDone = h.bConnected = True
    h.scan()
    h.bOpenDone = False
    h.scan()
    assert h.fbLink.o_bConnected and h.fbLink.o_uErrId == 0
    for k, byte in enumerate(STOP):  # the engine's request on the port interface
        h.uPort[TX_BASE + k] = byte
    h.uPort[TX_LEN], h.uPort[TX_REQ] = len(STOP), 1
    h.scan()
    assert h.fbLink.o_bSend
    assert [h.uSockSend[k] for k in range(5)] == [8, 0x0601, 0xA001, 0x0000, 0x1488]
    h.bSendDone, h.bSendErr, h.uSendStatus = True, True, 0xC0A1
    h.scan()
    h.bSendDone = h.bSendErr = False
    assert (h.fbLink.o_bErr, h.fbLink.o_uErrId, h.fbLink.o_uErrDetail) == (True, 0x0312, 0xC0A1)
    h.scan(2)
    assert (h.uPort[RX_DONE], h.uPort[RX_LEN], h.uPort[PORT_ERR]) == (1, 0, 0x0312)  # the attempt failed, no bytes
    h.uPort[RX_DONE] = 0  # the engine took it
    h.bRecvReady = True
    h.scan()
    assert h.fbLink.o_bRecv
    h.bRecvReady, h.bRecvDone, h.bRecvErr, h.uRecvStatus = False, True, True, 0x1234
    h.scan()
    h.bRecvDone = h.bRecvErr = False
    assert (h.fbLink.o_bErr, h.fbLink.o_uErrId, h.fbLink.o_uErrDetail) == (True, 0x0313, 0x1234)
    h.scan(3)
    assert h.uPort[RX_DONE] == 0  # no reply handed to the engine: its reply time-out decides


def test_tcp_link_signals_a_failed_send_also_when_bytes_were_held_meanwhile():
    """A failed send failed the engine's attempt only when no bytes were held
    (IF NOT bHeld): bytes that came while the send was under way (a second device, a
    reply given up on) were held and handed to the engine as the reply to a frame that
    never went out, and the 16#0312 stayed on the port's own o_uErrId. Now the failed
    send replaces them (port word 4 = 16#0312, no bytes), as with nothing held."""
    import verifier

    h = verifier.load(Path(__file__).resolve().parents[1] / "plc" / "core",
                      sources={"T_Tcp.st": TCP_LINK_HARNESS}).program("T_Tcp")
    h.bEN = True
    h.scan()
    h.bOpenDone = h.bConnected = True
    h.scan()
    h.bOpenDone = False
    h.scan()
    for k, byte in enumerate(STOP):
        h.uPort[TX_BASE + k] = byte
    h.uPort[TX_LEN], h.uPort[TX_REQ] = len(STOP), 1
    h.scan()
    assert h.fbLink.o_bSend
    h.bRecvReady = True                     # a well-formed status reply arrives meanwhile
    h.scan()
    assert h.fbLink.o_bRecv
    stray = bytes.fromhex("0101030000003C4E")
    h.uSockRecv[0] = len(stray)
    for k in range(4):
        h.uSockRecv[1 + k] = stray[2 * k] | stray[2 * k + 1] << 8
    h.bRecvReady, h.bRecvDone = False, True
    h.scan()
    h.bRecvDone = False
    h.bSendDone, h.bSendErr, h.uSendStatus = True, True, 0xC0A1
    h.scan()
    h.bSendDone = h.bSendErr = False
    assert (h.fbLink.o_uErrId, h.fbLink.o_uErrDetail) == (0x0312, 0xC0A1)
    h.scan(2)
    assert (h.uPort[RX_DONE], h.uPort[RX_LEN], h.uPort[PORT_ERR]) == (1, 0, 0x0312)
