"""The emulated UITAMR robot: a deterministic state machine on a virtual clock.

``Robot(settings, config, faults)`` answers request frames with ``on_request(frame, t_us)``
(a :class:`Reply` with bytes and delay, or None for silence) and runs its tasks with
``advance(t_us)``. ``RobotConfig.from_dict`` and ``Fault.from_dict`` / ``faults_from_list``
read scenario tables and name the bad key on error (:class:`ConfigError`).
"""
from verifier.amr.config import BEFORE_STOP_POLICIES, PACING_POLICIES, RobotConfig
from verifier.amr.faults import FAULT_KINDS, Fault, check_fault_addresses, faults_from_list
from verifier.amr.robot import Reply, Robot, RobotEvent
from verifier.amr.schema import ConfigError

__all__ = [
    "BEFORE_STOP_POLICIES", "ConfigError", "FAULT_KINDS", "Fault", "PACING_POLICIES",
    "Reply", "Robot", "RobotConfig", "RobotEvent", "check_fault_addresses", "faults_from_list",
]
