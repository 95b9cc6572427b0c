"""The emulated robot on real ports (serial or TCP), on the wall clock: ``uitamr emulate``."""
from verifier.emulate.assembler import Dropped, ReceivedFrame, RequestAssembler
from verifier.emulate.core import Emulator, Outgoing
from verifier.emulate.faultfile import FaultFile, FaultFileError, load_fault_file
from verifier.emulate.ports import PortError, serve_serial, serve_tcp

__all__ = [
    "Dropped", "Emulator", "FaultFile", "FaultFileError", "Outgoing", "PortError",
    "ReceivedFrame", "RequestAssembler", "load_fault_file", "serve_serial", "serve_tcp",
]
