"""The virtual RS-485 line between the simulated PLC and the robot model (virtual time)."""
from verifier.link.line import Line, LineConfig
from verifier.link.trace import RX, TX, LineEvent, TraceFrame

__all__ = ["Line", "LineConfig", "LineEvent", "RX", "TX", "TraceFrame"]
