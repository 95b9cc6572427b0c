"""The special devices of the RS2 channels, per CPU family (docs/instructions.md §7, §8),
and of the FX3U-485ADP-MB MODBUS master (§10): data the RS2 and ADPRW models drive
(`instructions.rs2`, `instructions.adprw`) and the CPU check names when a program moved
to another family uses the FX3's (`cpu.FX3_SERIAL`)."""
from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class Rs2Devices:
    """The special devices of one RS2 channel."""

    send_request: str
    receive_complete: str
    timeout_flag: str
    send_remaining: str
    receive_count: str
    timeout_setting: str
    timeout_unit_ms: int  # FX3: 10 ms per count (0 = 100 ms); FX5: 1 ms (out of range = 10 ms)
    format_register: str | None = None  # FX3 only; FX5 takes the format from parameters
    eight_bit_mode: str | None = None  # FX5 SD8622/SD8632


FX3_CHANNELS = {
    1: Rs2Devices("M8402", "M8403", "M8409", "D8402", "D8403", "D8409", 10, "D8400"),
    2: Rs2Devices("M8422", "M8423", "M8429", "D8422", "D8423", "D8429", 10, "D8420"),
}
FX5_CHANNELS = {
    1: Rs2Devices("SM8561", "SM8562", "SM8565", "SD8560", "SD8561", "SD8621", 1, None, "SD8622"),
    2: Rs2Devices("SM8571", "SM8572", "SM8575", "SD8570", "SD8571", "SD8631", 1, None, "SD8632"),
}


@dataclass(frozen=True)
class Fx3ModbusDevices:
    """The special devices of one FX3U-485ADP-MB MODBUS master channel (FX3U MODBUS Serial
    Communication Edition 6.1 and 12.6, docs/instructions.md §10). Some share their number
    with an RS2 device of the same channel: the two modes do not run on one channel."""

    response_timeout: str  # slave response time-out, ms (0 = 3 s)
    retries: str
    error_code: str
    error_details: str
    error_flag: str
    serial_error: str  # serial communication error code register
    serial_error_code: int  # the code ADPRW stores there: "MODBUS error on ch1 / ch2"
    # turned ON with the error code and with its details (§12.6 "Related Devices": "M8402
    # set to ON, D8402 set to MODBUS Error Code, M8403 set to ON, D8403 set to Error Details")
    code_flag: str
    details_flag: str


FX3_MODBUS_CHANNELS = {
    1: Fx3ModbusDevices("D8409", "D8412", "D8402", "D8403", "M8063", "D8063", 6321, "M8402", "M8403"),
    2: Fx3ModbusDevices("D8429", "D8432", "D8422", "D8423", "M8438", "D8438", 3821, "M8422", "M8423"),
}
