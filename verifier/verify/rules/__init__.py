"""The compliance rules: what the robot's manual demands of the PLC's traffic.

Each rule has a stable id (used in reports, JUnit failures and docs/verifier.md), a one-line
explanation that cites its source, and a pure check over the run's evidence. The rules
judge only what the PLC did; a misbehaving robot (a scripted fault) is never a violation by
itself — how the program copes with it is.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

from ..evidence import RunEvidence, Violation
from ..traffic import Traffic, analyse, converter_drops
from . import framing, response, sequence, timing

MANUAL = "UITAMR Modbus 通訊手冊 V2.05"
MODBUS_SERIAL = "MODBUS over Serial Line V1.02 (modbus.org)"


@dataclass(frozen=True)
class Rule:
    id: str
    title: str
    explanation: str
    check: Callable[[RunEvidence, Traffic], list[Violation]]


RULES: tuple[Rule, ...] = (
    Rule(
        "UITAMR-CRC",
        "CRC on every frame",
        f"Every frame the PLC sends ends with its CRC-16/MODBUS (init FFFF, polynomial A001 "
        f"reflected), low byte first; the robot ignores frames with a bad CRC "
        f"({MODBUS_SERIAL} §2.5.1.2; {MANUAL}, 'CRC 校驗碼').",
        framing.check_crc,
    ),
    Rule(
        "UITAMR-FORMAT",
        "Frame format",
        f"Requests go to the robot's slave address, use only function 06 (control) or 01 "
        f"(status), a control code of table 1 with a command of table 2 / note 2, value field "
        f"0000, query 0-3 and quantity 0016, sent as one continuous stream ({MANUAL}, 功能碼 0x06 / "
        f"0x01 tables; {MODBUS_SERIAL} §2.5.1.1).",
        framing.check_format,
    ),
    Rule(
        "UITAMR-PACING",
        "More than 250 ms between requests",
        f"Fewer than four commands per second: each request starts more than 250 ms after the "
        f"start of the previous one, reads included ({MANUAL}, 通訊說明: "
        f"'收送命令的頻率要低於每秒四次').",
        timing.check_pacing,
    ),
    Rule(
        "UITAMR-POWERON-STOP",
        "Stop first after power-on",
        f"The first control command after power-on is the stop command 01/A0 "
        f"(01 06 01 A0 00 00 88 14), and no other control command goes out before the robot "
        f"has acknowledged it ({MANUAL}, 指令週期說明 [重要]: '開機後第一個控制命令請先下達停車命令').",
        sequence.check_power_on_stop,
    ),
    Rule(
        "UITAMR-HALF-DUPLEX",
        "Half duplex",
        f"The PLC never transmits while the robot's reply is due or arriving, and leaves 3.5 "
        f"character times of silence after it (RS-485 two-wire is half duplex; "
        f"{MODBUS_SERIAL} §2.5.1.1).",
        timing.check_half_duplex,
    ),
    Rule(
        "UITAMR-ONE-AT-A-TIME",
        "One request at a time",
        f"After a request the PLC waits for the reply, or for its reply time-out, before the "
        f"next request ({MODBUS_SERIAL} §2.4.1: the master is in 'waiting for reply' until "
        f"the reply or the response time-out).",
        timing.check_one_at_a_time,
    ),
    Rule(
        "UITAMR-RESPONSE-HANDLING",
        "Failed replies are noticed",
        f"A reply with a bad CRC, an exception, another address, or no reply at all is "
        f"noticed: when the failure persists, the program shows it in its outputs within the "
        f"scenario's bound ({MODBUS_SERIAL} §2.4.1; {MANUAL} gives no time-out — see "
        f"docs/protocol.md).",
        response.check_response_handling,
    ),
    Rule(
        "UITAMR-CYCLE",
        "Control, then read status",
        f"After a control command the program reads the robot's status (function 01) before "
        f"the next control command; resending the same command after a failed exchange is a "
        f"retry ({MANUAL}, 指令週期說明: 控制命令 -> 讀取 -> 讀取 -> ... -> 下一輪).",
        sequence.check_cycle,
    ),
)

RULES_BY_ID = {rule.id: rule for rule in RULES}


def check_all(evidence: RunEvidence, traffic: Traffic | None = None) -> dict[str, list[Violation]]:
    """Every rule's violations (an empty list for a rule that holds), in rule order."""
    if traffic is None:
        traffic = analyse(evidence.trace, evidence.settings, evidence.options, converter_drops(evidence.events))
    return {rule.id: sorted(rule.check(evidence, traffic), key=lambda v: v.t_us) for rule in RULES}
