"""The compliance rules: what the robot's manual demands of the PLC's traffic.

Each rule has a stable id (used in reports, JUnit failures and docs/verifier.md), a one-line
explanation that cites its source, and a pure check over the run's evidence (a `Judge`,
reading the traffic in order). The rules judge only what the PLC did; a misbehaving robot
(a scripted fault) is never a violation by itself — how the program copes with it is.
"""
from __future__ import annotations

from dataclasses import dataclass

from ..evidence import RunEvidence, Violation
from ..traffic import Exchange, Traffic, analyse, converter_drops
from . import framing, response, sequence, timing
from .judge import Judge

MANUAL = "UITAMR Modbus 通訊手冊 V2.05"
MODBUS_SERIAL = "MODBUS over Serial Line V1.02 (modbus.org)"


@dataclass(frozen=True)
class Rule:
    id: str
    title: str
    explanation: str
    judge: type[Judge]


RULES: tuple[Rule, ...] = (
    Rule(
        "UITAMR-CRC",
        "CRC on every frame",
        f"Every frame the PLC sends ends with its CRC-16/MODBUS (init FFFF, polynomial A001 "
        f"reflected), low byte first; the robot ignores frames with a bad CRC "
        f"({MODBUS_SERIAL} §2.5.1.2; {MANUAL}, 'CRC 校驗碼').",
        framing.Crc,
    ),
    Rule(
        "UITAMR-FORMAT",
        "Frame format",
        f"Requests go to the robot's slave address, use only function 06 (control) or 01 "
        f"(status), a control code of table 1 with a command of table 2 / note 2, value field "
        f"0000, query 0-3 and quantity 0016, sent as one continuous stream ({MANUAL}, 功能碼 0x06 / "
        f"0x01 tables; {MODBUS_SERIAL} §2.5.1.1).",
        framing.Format,
    ),
    Rule(
        "UITAMR-PACING",
        "More than 250 ms between requests",
        f"Fewer than four commands per second: each request starts more than 250 ms after the "
        f"start of the previous one, reads included ({MANUAL}, 通訊說明: "
        f"'收送命令的頻率要低於每秒四次').",
        timing.Pacing,
    ),
    Rule(
        "UITAMR-POWERON-STOP",
        "Stop first after power-on",
        f"The first control command after power-on is the stop command 01/A0 "
        f"(01 06 01 A0 00 00 88 14), and no other control command goes out before the robot "
        f"has acknowledged it ({MANUAL}, 指令週期說明 [重要]: '開機後第一個控制命令請先下達停車命令').",
        sequence.PowerOnStop,
    ),
    Rule(
        "UITAMR-HALF-DUPLEX",
        "Half duplex",
        f"The PLC never transmits while the robot's reply is due or arriving, and leaves 3.5 "
        f"character times of silence after it (RS-485 two-wire is half duplex; "
        f"{MODBUS_SERIAL} §2.5.1.1).",
        timing.HalfDuplex,
    ),
    Rule(
        "UITAMR-ONE-AT-A-TIME",
        "One request at a time",
        f"After a request the PLC waits for the reply, or for its reply time-out, before the "
        f"next request ({MODBUS_SERIAL} §2.4.1: the master is in 'waiting for reply' until "
        f"the reply or the response time-out).",
        timing.OneAtATime,
    ),
    Rule(
        "UITAMR-RESPONSE-HANDLING",
        "Failed replies are noticed",
        f"A reply with a bad CRC, an exception, another address, or no reply at all is "
        f"noticed: when the failure persists, the program shows it in its outputs within the "
        f"scenario's bound ({MODBUS_SERIAL} §2.4.1; {MANUAL} gives no time-out — see "
        f"docs/protocol.md).",
        response.ResponseHandling,
    ),
    Rule(
        "UITAMR-CYCLE",
        "Control, then read status",
        f"After a control command the program reads the robot's status (function 01) before "
        f"the next control command; resending the same command after a failed exchange is a "
        f"retry, and the stop command may overtake the command before it without the read "
        f"(a stop after a stop, and the command after the stop, still need it) "
        f"({MANUAL}, 指令週期說明: 控制命令 -> 讀取 -> 讀取 -> ... -> 下一輪).",
        sequence.Cycle,
    ),
)

RULES_BY_ID = {rule.id: rule for rule in RULES}


class Judgement:
    """Every rule over one run's traffic, as far as the traffic is settled.

    `advance` judges the requests given so far and the exchanges that are settled, each
    once; `finish` judges the rest when the run has ended. `check_all` does both at once
    over a whole run; `uitamr monitor` advances as the line goes (`Pairing.settled`), so a
    periodic check costs what the new frames cost, and finds the same violations.
    """

    def __init__(self, evidence: RunEvidence, traffic: Traffic):
        self.evidence = evidence
        self.traffic = traffic
        self._judges = [(rule.id, rule.judge(evidence, traffic)) for rule in RULES]
        self._on_request = [(rule_id, judge.request) for rule_id, judge in self._judges
                            if type(judge).request is not Judge.request]
        self._on_exchange = [(rule_id, judge.exchange) for rule_id, judge in self._judges
                             if type(judge).exchange is not Judge.exchange]
        self.found: dict[str, list[Violation]] = {rule.id: [] for rule in RULES}
        self.requests = 0  # requests judged
        self.exchanges = 0  # exchanges judged
        self.finished = False

    def advance(self, settled: int) -> list[Violation]:
        """Judge the requests not judged yet and exchanges up to `settled`; the violations found."""
        new: list[Violation] = []
        for steps, upto, done in ((self._on_request, len(self.traffic.tx), self.requests),
                                  (self._on_exchange, settled, self.exchanges)):
            for index in range(done, upto):
                for rule_id, step in steps:
                    for violation in step(index):
                        self.found[rule_id].append(violation)
                        new.append(violation)
        self.requests, self.exchanges = len(self.traffic.tx), max(self.exchanges, settled)
        return new

    def forget(self, requests: int, robot_frames: int) -> None:
        """The traffic let go of its first `requests` exchanges and `robot_frames` robot
        frames (`Pairing.forget`), all of them judged."""
        self.requests -= requests
        self.exchanges -= requests
        for _, judge in self._judges:
            judge.forget(requests, robot_frames)

    def provisional(self, end_us: int, overdue: Exchange | None = None) -> list[Violation]:
        """What the rules would still find if the run ended at `end_us` and nothing came;
        `overdue` (Judge.provisional): the first exchange not settled, its reply overdue."""
        return [v for _, judge in self._judges for v in judge.provisional(end_us, overdue)]

    def finish(self) -> list[Violation]:
        """The run has ended (at evidence.end_us): judge the rest; the violations found."""
        if self.finished:
            return []
        new = self.advance(len(self.traffic.exchanges))
        for rule_id, judge in self._judges:
            for violation in judge.finish():
                self.found[rule_id].append(violation)
                new.append(violation)
        self.finished = True
        return new

    def violations(self) -> dict[str, list[Violation]]:
        """Every rule's violations so far, in rule order, each rule's in time order."""
        return {rule_id: sorted(found, key=lambda v: v.t_us) for rule_id, found in self.found.items()}


def check_all(evidence: RunEvidence, traffic: Traffic | None = None) -> dict[str, list[Violation]]:
    """Every rule's violations (an empty list for a rule that holds), in rule order."""
    if traffic is None:
        traffic = analyse(evidence.trace, evidence.settings, evidence.options, converter_drops(evidence.events))
    judgement = Judgement(evidence, traffic)
    judgement.finish()
    return judgement.violations()
