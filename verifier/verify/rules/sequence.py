"""UITAMR-POWERON-STOP and UITAMR-CYCLE: the order of control commands and status reads.

Both look only at requests the robot would accept (valid CRC and format); frames it would
ignore are the business of UITAMR-CRC and UITAMR-FORMAT.
"""
from __future__ import annotations

from verifier import protocol

from ..evidence import RunEvidence, Violation
from ..traffic import Traffic

STOP_HEX = protocol.hex_bytes(protocol.STOP_FRAME)


def check_power_on_stop(evidence: RunEvidence, traffic: Traffic) -> list[Violation]:
    settings = evidence.settings
    stop_sent = False
    for exchange in traffic.exchanges:
        if not exchange.is_control:
            continue
        request = exchange.decoded_request
        if protocol.is_stop_command(request, settings):
            if exchange.answered:
                return []
            stop_sent = True
            continue
        meaning = protocol.describe(request, settings)
        if stop_sent:
            message = (
                f"control command {meaning} sent before the robot acknowledged the stop command; "
                "repeat the stop until it is answered"
            )
        else:
            message = (
                f"the first control command after power-on is {meaning}; it must be the stop "
                f"command 01/A0 ({STOP_HEX} at address 1)"
            )
        return [
            Violation(
                "UITAMR-POWERON-STOP",
                exchange.request.t_start_us,
                message,
                exchange.refs(),
                exchange.request.origin,
            )
        ]
    return []


def check_cycle(evidence: RunEvidence, traffic: Traffic) -> list[Violation]:
    settings = evidence.settings
    violations = []
    last_control = None
    status_read = False
    for exchange in traffic.exchanges:
        if exchange.is_status:
            status_read = status_read or exchange.answered
            continue
        if not exchange.is_control:
            continue
        retry = (
            last_control is not None
            and not last_control.answered
            and bytes(last_control.request.data) == bytes(exchange.request.data)
        )
        if last_control is not None and not status_read and not retry:
            violations.append(
                Violation(
                    "UITAMR-CYCLE",
                    exchange.request.t_start_us,
                    f"control command {protocol.describe(exchange.decoded_request, settings)} "
                    f"follows {protocol.describe(last_control.decoded_request, settings)} "
                    f"with no status read answered in between",
                    last_control.refs() + exchange.refs(),
                    exchange.request.origin,
                )
            )
        last_control = exchange
        status_read = False
    return violations

