"""What the simulator models of the MELSEC CPUs, as plain data: each CPU's family, each
family's serial channels, the buffer memory modelled per module.

The simulator (verifier.sim) and the scenario reader (verifier.verify.scenario) both ask
this module, so that reading a scenario file checks its `channel` and `[initial]` as a run
would without importing the simulator (tests/test_verify_scenario.py reads every bundled
scenario in a fresh interpreter and lists the verifier.sim modules it imported: none).
It imports nothing of the toolkit.
"""
from __future__ import annotations

from types import MappingProxyType

#: CPU profile name (`--platform`, verifier.sim.cpu.PROFILES) -> family (the families of
#: verifier.sim.cpu.PROFILES; kept equal by tests/test_check_reserved.py)
PLATFORM_FAMILY = MappingProxyType({"fx3u": "fx3", "fx3g": "fx3", "fx5u": "fx5", "q": "q"})

#: Every serial channel the simulator drives (verifier.sim.serial.SerialChannel names).
CHANNELS = ("fx3:1", "fx3:2", "fx5:1", "fx5:2", "q:1", "q:2", "adp:1")
#: channels a real CPU can have that the simulator does not drive, and why
NOT_SIMULATED = MappingProxyType(
    {"adp:2": "the simulated ADPRW is the MODBUS master on adp:1 only (docs/instructions.md, ADPRW)"})
#: family -> its serial channels: its own two ports (FX3 RS2 ch1/ch2, FX5 RS2 built-in
#: port/FX5-485-BD, QJ71C24N CH1/CH2) and, on the families that have ADPRW, the MODBUS
#: master's adp:1. The only copy; tests/test_verify_scenario.py holds the adp:1 entries
#: equal to the families the instruction registry (verifier.sim.instructions) runs ADPRW on.
FAMILY_CHANNELS = MappingProxyType({
    "fx3": ("fx3:1", "fx3:2", "adp:1"),
    "fx5": ("fx5:1", "fx5:2", "adp:1"),
    "q": ("q:1", "q:2"),
})

#: Buffer-memory words the simulator models per module (0..5FFFH). ASSUMPTION: enough for
#: the QJ71C24N areas and the QJ71E71 status words (5000H, 5005H) the library uses.
BUFFER_WORDS = 0x6000

#: QJ71C24N, per channel: the buffer-memory words of the receive settings (received data
#: count, receive end code, word/byte units; docs/instructions.md §9 with its sources) and
#: the input signals' offsets from the module's start I/O (reception data read request
#: X(n)3 / X(n)A, reception abnormal detection X(n)4 / X(n)B; C24 (Basic)). The simulator's
#: module (verifier.sim.instructions.c24) and `uitamr check`'s wiring judgement both read them.
C24_BUFFER = MappingProxyType({
    1: MappingProxyType({"recv_count": 0xA4, "end_code": 0xA5, "unit": 0x96}),
    2: MappingProxyType({"recv_count": 0x144, "end_code": 0x145, "unit": 0x136}),
})
C24_READ_REQUEST = MappingProxyType({1: 0x3, 2: 0xA})
C24_ABNORMAL = MappingProxyType({1: 0x4, 2: 0xB})

#: QJ71E71-100 buffer memory, bit n-1 for connection n: the open completion signal and the
#: fixed buffer reception status signal (ASSUMPTION, docs/instructions.md §13). The
#: simulator's module (verifier.sim.instructions.tcp) and `uitamr check` read them.
E71_OPEN_SIGNAL = 0x5000
E71_RECEIVE_SIGNAL = 0x5005


def serial_channels(cpu_name: str) -> list[str]:
    """The serial channels of the CPU profile called `cpu_name` ("fx3u", "fx3g", "fx5u",
    "q"), in the order of CHANNELS."""
    return list(FAMILY_CHANNELS[PLATFORM_FAMILY[cpu_name]])


def channel_problem(channel: str, cpu_name: str) -> str | None:
    """Why `channel` cannot be attached on the CPU `cpu_name`, naming the channels it has;
    None if it can. The simulator's attach and the scenario reader both ask this."""
    have = serial_channels(cpu_name)
    if channel in have:
        return None
    if channel in CHANNELS:
        problem = f"channel {channel} does not exist on the {cpu_name} CPU"
    elif channel in NOT_SIMULATED:
        problem = f"channel {channel} is not simulated: {NOT_SIMULATED[channel]}"
    else:
        problem = f"unknown serial channel {channel!r}"
    return f"{problem}; the {cpu_name} CPU has {', '.join(have)}"
