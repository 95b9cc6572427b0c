"""UITAMR-POWERON-STOP and UITAMR-CYCLE: the order of control commands and status reads.

Both look only at requests the robot would accept (valid CRC and format); frames it would
ignore are the business of UITAMR-CRC and UITAMR-FORMAT.
"""
from __future__ import annotations

from typing import Iterator

from verifier import protocol

from ..evidence import RunEvidence, Violation
from ..traffic import Traffic
from .judge import Judge

STOP_HEX = protocol.hex_bytes(protocol.STOP_FRAME)


class PowerOnStop(Judge):
    def __init__(self, evidence: RunEvidence, traffic: Traffic):
        super().__init__(evidence, traffic)
        self.stop_sent = False
        self.decided = False  # the stop was answered, or the first violation found: nothing more to judge

    def exchange(self, index: int) -> Iterator[Violation]:
        exchange = self.traffic.exchanges[index]
        if self.decided or not exchange.is_control:
            return
        settings = self.evidence.settings
        request = exchange.decoded_request
        if protocol.is_stop_command(request, settings):
            self.decided = exchange.answered
            self.stop_sent = True
            return
        meaning = protocol.describe(request, settings)
        if self.stop_sent:
            message = (
                f"control command {meaning} sent before the robot acknowledged the stop command; "
                "repeat the stop until it is answered"
            )
        else:
            message = (
                f"the first control command after power-on is {meaning}; it must be the stop "
                f"command 01/A0 ({STOP_HEX} at address 1)"
            )
        self.decided = True
        yield Violation(
            "UITAMR-POWERON-STOP",
            exchange.request.t_start_us,
            message,
            exchange.refs(),
            exchange.request.origin,
        )


class Cycle(Judge):
    def __init__(self, evidence: RunEvidence, traffic: Traffic):
        super().__init__(evidence, traffic)
        self.last_control = None
        self.status_read = False

    def exchange(self, index: int) -> Iterator[Violation]:
        exchange = self.traffic.exchanges[index]
        if exchange.is_status:
            self.status_read = self.status_read or exchange.answered
            return
        if not exchange.is_control:
            return
        settings, last_control = self.evidence.settings, self.last_control
        retry = (
            last_control is not None
            and not last_control.answered
            and bytes(last_control.request.data) == bytes(exchange.request.data)
        )
        # the stop overtakes a command in flight (the library's priority slot): holding the
        # robot's safety command back for a status read would be the worse program; a stop
        # after a stop still needs the read in between, as any resend does
        overtaking_stop = (
            last_control is not None
            and protocol.is_stop_command(exchange.decoded_request, settings)
            and not protocol.is_stop_command(last_control.decoded_request, settings)
        )
        if last_control is not None and not self.status_read and not retry and not overtaking_stop:
            yield Violation(
                "UITAMR-CYCLE",
                exchange.request.t_start_us,
                f"control command {protocol.describe(exchange.decoded_request, settings)} "
                f"follows {protocol.describe(last_control.decoded_request, settings)} "
                f"with no status read answered in between",
                last_control.refs() + exchange.refs(),
                exchange.request.origin,
            )
        self.last_control = exchange
        self.status_read = False
