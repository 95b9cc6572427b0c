"""Bytes that arrive while no request is outstanding - here the late reply to a request the
engine has already given up on (its third attempt) - must never be taken as the reply to
the next request, on any route. The scenarios time that late reply to land just before the
next request (a run-point command) goes out: a port that takes it for the command's reply
rejects it (another function code), repeats the command and the robot runs the point twice
(UITAMR-CYCLE); one whose stale reply had the right function code would accept stale data.

The QJ71C24N shows a message only once it has ended (read request X3) and read it after
its send had started; the TCP ports read data the connection already held after the send
had started: both handed it to the engine as the reply. Now data that wait in the module,
or are being read, as the frame goes out are read and dropped (docs/plc-library.md,
"Bytes that come when no request is outstanding"). The RS2 and ADPRW routes pass before
and after."""
from __future__ import annotations

from pathlib import Path

import pytest

from verifier.verify.runner import run_scenario
from verifier.verify.scenario import load_scenario

ROOT = Path(__file__).resolve().parents[1]
PLC = ROOT / "plc"

C24 = """
[[c24]]
unit = 0
channel = 1
no_reception = "5ms"
byte_units = true
receive_count = 8
end_code = "none"
"""
CONVERTER = """
[converter]
ip = "192.168.3.50"
port = 4001
delay = "3ms"
"""
ADPRW_RULES = """
[rules]
reply_timeout = "400ms"   # the adapter's slave response time-out (docs/plc-library.md)
"""
# route: (sources under plc/, program, platform, start input, top-level keys, tables)
ROUTES = {
    "fx3u": (["core/*.st", "fx3/*.st", "examples/common/*.st", "examples/fx3/UITAMR_ExampleFx3.st"],
             "UITAMR_ExampleFx3", "fx3u", "X0", "", ""),
    "fx3u-adprw": (["core/*.st", "fx3/UITAMR_PortAdpFx3.st", "examples/common/*.st",
                    "examples/fx3/UITAMR_ExampleAdpFx3.st"],
                   "UITAMR_ExampleAdpFx3", "fx3u", "X0", 'channel = "adp:1"\n', ADPRW_RULES),
    "fx5u": (["core/*.st", "fx5/*.st", "examples/common/*.st", "examples/fx5/UITAMR_ExampleFx5.st"],
             "UITAMR_ExampleFx5", "fx5u", "X0", "", ""),
    "fx5u-adprw": (["core/*.st", "fx5/UITAMR_PortAdpFx5.st", "examples/common/*.st",
                    "examples/fx5/UITAMR_ExampleAdpFx5.st"],
                   "UITAMR_ExampleAdpFx5", "fx5u", "X0", 'channel = "adp:1"\n', ADPRW_RULES),
    "q": (["core/*.st", "q/*.st", "examples/common/*.st", "examples/q/UITAMR_ExampleQ.st"],
          "UITAMR_ExampleQ", "q", "X20", "", C24),
    "fx5u-tcp": (["core/*.st", "fx5/*.st", "examples/common/*.st", "examples/fx5/UITAMR_ExampleTcpFx5.st"],
                 "UITAMR_ExampleTcpFx5", "fx5u", "X0", "", CONVERTER),
    "q-tcp": (["core/*.st", "q/*.st", "examples/common/*.st", "examples/q/UITAMR_ExampleTcpQ.st"],
              "UITAMR_ExampleTcpQ", "q", "X20", "", CONVERTER),
}


NOISE = """
[[faults]]          # ... and it is line noise instead of the reply
kind = "garbage"
on_request = 8
data = "A5 5A FF"
"""


def stray_scenario(route: str, delay_ms: int, noise: bool = False) -> str:
    """The scenario TOML for `route`: request 6 (the monitor's battery read at 1.78 s) gets
    no reply twice, its third attempt a reply `delay_ms` late - after the engine's time-out
    and guard time, as the run-point command of the cycle started at 2 s falls due. With
    `noise`, three bytes of garbage come instead of that late reply."""
    sources, program, platform, start, top, tables = ROUTES[route]
    paths = ", ".join(f'"{(PLC / s).as_posix()}"' for s in sources)
    what = "line noise" if noise else "a late reply"
    return f'''name = "{route}: {what} arrives as the next request is due ({delay_ms} ms)"
description = "The third attempt of a status read is answered {delay_ms} ms late ({what}), after the engine gave up on it; the run-point command that follows must get its own reply, not that."
sources = [{paths}]
program = "{program}"
platform = "{platform}"
{top}duration = "12s"
scan = "10ms"
watch = ["fbEngine.o_wTxCount", "fbEngine.o_wRetryCount", "fbEngine.o_wCommErrCount", "fbEngine.o_uErrId"]
{tables}
[robot]
point_duration_s = 6.0

[[inputs]]
at = "2s"
set = {{ {start} = true }}
pulse = "500ms"

[[faults]]
kind = "no_reply"
on_request = 6
count = 2

[[faults]]
kind = "late_reply"
on_request = 8
delay_ms = {delay_ms}
{NOISE if noise else ""}
[[expect]]
name = "the stop command goes first"
sent = "stop"
within = "1s"

[[expect]]
name = "the run-point command goes out once and its point is reached"
reached_point = 1
within = "11s"

[[expect]]
name = "the cycle never fails"
never = "fbCycle.o_bErr"
'''


@pytest.mark.parametrize("delay_ms", [672, 680, 686])
@pytest.mark.parametrize("route", list(ROUTES))
@pytest.mark.parametrize("noise", [False, True], ids=["late-reply", "noise"])
def test_bytes_due_as_the_next_request_goes_out_are_not_taken_as_its_reply(route, delay_ms, noise, tmp_path):
    path = tmp_path / f"{route}-stray-{delay_ms}.toml"
    path.write_text(stray_scenario(route, delay_ms, noise), encoding="utf-8")
    result = run_scenario(load_scenario(path))
    found = {rule: [v.message for v in found] for rule, found in result.violations.items() if found}
    assert result.passed, (found, [o for o in result.expectations if not o.passed])
