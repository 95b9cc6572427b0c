"""What `uitamr verify` tells an integrator about their own program's sequence (journey32b:
a station program written from the docs, not copied from an example)."""
from __future__ import annotations

from pathlib import Path

from verifier.verify.runner import run_scenario
from verifier.verify.scenario import load_scenario

ROOT = Path(__file__).resolve().parents[1]

#: a station that runs point 2 on every rising edge of X0 and never sends the stop
NO_ACK = """\
PROGRAM StationNoAck
VAR
    fbPort : UITAMR_PortFx5;
    fbEngine : UITAMR_Engine;
    fbGo : UITAMR_RunPoint;
    uMbx : ARRAY[0..15] OF WORD;
    uPort : ARRAY[0..39] OF WORD;
END_VAR
fbPort(i_bEN := TRUE, i_wChannel := 1, io_uPort := uPort);
fbEngine(i_bEN := NOT SM402, i_wAddress := 1, i_bMonitor := TRUE, io_uMbx := uMbx, io_uPort := uPort);
fbGo(i_bEN := TRUE, i_bExecute := X0, i_wPoint := 2, io_uMbx := uMbx);
Y3 := fbGo.o_bErr;
END_PROGRAM
"""


def test_a_point_sent_again_after_anti_collision_without_the_stop_is_told_why_it_never_ran(tmp_path):
    """A station that went on after an anti-collision without sending the stop (no
    acknowledge) failed `reached_point` with "accepted, but the robot never reported the
    task running": true, and no word of the robot's answer, error 01 in every status reply,
    which it keeps until the stop command."""
    (tmp_path / "StationNoAck.st").write_text(NO_ACK, encoding="utf-8")
    (tmp_path / "s.toml").write_text(f"""\
name = "no acknowledge"
sources = ["{(ROOT / 'plc' / 'core').as_posix()}", "{(ROOT / 'plc' / 'fx5' / 'UITAMR_PortFx5.st').as_posix()}", "StationNoAck.st"]
program = "StationNoAck"
platform = "fx5u"
duration = "25s"

[robot]
point_duration_s = 6.0

[[faults]]
kind = "anti_collision"
at_s = 4.0

[[inputs]]
at = "2s"
set = {{ X0 = true }}
pulse = "300ms"

[[inputs]]
at = "12s"
set = {{ X0 = true }}
pulse = "300ms"

[[expect]]
reached_point = 2
after = "12s"
within = "8s"

[response_handling]
signal = "Y3"
""", encoding="utf-8")
    result = run_scenario(load_scenario(tmp_path / "s.toml"))
    (outcome,) = result.expectations
    assert not outcome.passed
    assert "but the robot never reported the task running: its task status at " in outcome.detail
    assert ("carried error 01 (anti-collision triggered), which the robot keeps until the stop command (01/A0): "
            "send the stop (acknowledge the fault) before the next point") in outcome.detail, outcome.detail


def test_the_fault_trigger_scenarios_md_quotes_is_the_bundled_files():
    """scenarios.md tells how to strike a command rather than the N-th request (the
    engine's polls count too) by quoting fx5u-exception.toml's trigger: it must be the file's."""
    import re
    import tomllib

    text = " ".join((ROOT / "docs" / "scenarios.md").read_text(encoding="utf-8").split())
    quoted = re.search(r"as the bundled `fx5u-exception.toml` does \(`at_s = (\S+)`, `duration_s = (\S+)`, "
                       r"`requests = \"(\w+)\"`\)", text).groups()
    (fault,) = tomllib.loads((ROOT / "plc" / "scenarios" / "fx5u-exception.toml").read_text(encoding="utf-8"))["faults"]
    assert (float(quoted[0]), float(quoted[1]), quoted[2]) == (fault["at_s"], fault["duration_s"], fault["requests"])


def test_a_q_run_without_timer_0_whose_replies_go_out_of_step_is_told_to_set_it():
    """The Q station's scenario, written without `[[c24]] no_reception` (the program sets
    byte units, count and end code, the scenario has nothing to say about timer 0): a 5-byte
    exception waited in the module for 3 bytes of the next reply, every reply after it was
    read out of step, and the report showed a second stop without a status read and an
    error 16#0101 where 16#0103 was expected, with no word of the module setting that makes
    the difference. It now says so in a note; with timer 0 set there is none, nor on any
    bundled Q scenario (they set it)."""
    from dataclasses import replace

    scenario = load_scenario(ROOT / "plc" / "scenarios" / "q-exception.toml")
    note = "no no-reception monitoring time (timer 0) is set, so a short reply (an exception, 5 bytes; noise) " \
           "puts every later reply out of step. Set timer 0 with format 1 in GX Works"
    assert not [n for n in run_scenario(scenario).notes if "timer 0" in n]
    without = replace(scenario, c24=tuple(replace(c, no_reception_us=None) for c in scenario.c24))
    notes = [n for n in run_scenario(without).notes if "timer 0" in n]
    assert len(notes) == 1 and note in notes[0] and notes[0].startswith("QJ71C24N U0 CH1: 5 received byte(s) from "), \
        notes
    assert notes[0].endswith('in a scenario, [[c24]] no_reception = "5ms"')


def test_a_button_on_the_c24s_read_request_signal_is_told(tmp_path):
    """A Q station with its jog button wired to X3, the QJ71C24N's CH1 reception data read
    request that the program also gives the port (i_bReadReq := X3): the jog was never
    sent, and nothing said why (journey32b). A scenario input on one of the module's
    reception signals now gets a note at its place; one on a free input (X20) none."""
    text = (ROOT / "plc" / "scenarios" / "q-healthy.toml").read_text(encoding="utf-8")
    text = text.replace('"../', f'"{(ROOT / "plc").as_posix()}/').replace('duration = "60s"', 'duration = "5s"')
    free = tmp_path / "free.toml"
    free.write_text(text, encoding="utf-8")
    assert not [n for n in run_scenario(load_scenario(free)).notes if "QJ71C24N" in n]
    on_signal = tmp_path / "x3.toml"
    on_signal.write_text(text.replace("set = { X20 = true }", "set = { X20 = true, X3 = true }"), encoding="utf-8")
    notes = [n for n in run_scenario(load_scenario(on_signal)).notes if "QJ71C24N" in n]
    assert notes[0] == (f"{on_signal}:23:21: inputs[0].set: X3 is the CH1 reception data read request of the "
                        "QJ71C24N at U0 that the program drives: the module turns it on and off itself, so a button "
                        "or sensor wired there fights the module (and the program reads the module's signal); wire "
                        "it to an X input that is not one of the module's signals"), notes
