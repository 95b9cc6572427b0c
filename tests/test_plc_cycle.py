"""UITAMR_PointCycle as the example programs use it: UITAMR_ExampleFx3 on RS2 channel 1
against the emulated robot, driven through X0 (start), X1 (stop) and X2 (acknowledge)."""
from __future__ import annotations

from pathlib import Path

import verifier
from verifier.amr import Robot
from verifier.amr.config import RobotConfig
from verifier.amr.faults import Fault
from verifier.link import Line

PLC = Path(__file__).resolve().parents[1] / "plc"
PROGRAM = "UITAMR_ExampleFx3"


def example(faults=()):
    project = verifier.load(PLC / "core", PLC / "fx3", PLC / "examples" / "common", PLC / "examples" / "fx3",
                            programs=[PROGRAM])
    project.attach_serial("fx3:1", Line(Robot(config=RobotConfig(point_duration_s=3.0), faults=list(faults))))
    return project


def press(project, device, then_ms=2000):
    project.devices[device] = True
    project.run_programs([PROGRAM], ms=200)
    project.devices[device] = False
    project.run_programs([PROGRAM], ms=then_ms)


def test_stop_in_the_fault_state_does_not_clear_the_fault_only_acknowledge_does():
    """A stop (X1) pressed in the fault state used to leave the fault step without an
    acknowledgement: Y3 and D101 stayed on for good, the cycle could be started again
    with the fault shown, and X2 no longer cleared it."""
    project = example([Fault(kind="anti_collision", at_s=2.5)])
    project.run_programs([PROGRAM], ms=1000)
    press(project, "X0", then_ms=2500)                # the cycle runs into the obstacle
    assert project.devices["Y3"] and project.devices["D101"] == 0x0201
    press(project, "X1")                              # stop: sent, the fault stays
    assert project.devices["Y3"] and project.devices["D101"] == 0x0201
    press(project, "X0")                              # no restart before the acknowledgement
    assert not project.devices["Y1"]
    press(project, "X2")                              # acknowledge: fault cleared
    assert not project.devices["Y3"] and project.devices["D101"] == 0
    press(project, "X0")
    assert project.devices["Y1"] and not project.devices["Y3"]


def test_acknowledge_while_the_stop_of_the_fault_state_runs_clears_the_fault():
    project = example([Fault(kind="anti_collision", at_s=2.5)])
    project.run_programs([PROGRAM], ms=1000)
    press(project, "X0", then_ms=2500)
    assert project.devices["Y3"]
    project.devices["X1"] = True                      # stop, and acknowledge in the next scan
    project.run_programs([PROGRAM], scans=1)
    project.devices["X2"] = True
    project.run_programs([PROGRAM], ms=200)
    project.devices["X1"] = project.devices["X2"] = False
    project.run_programs([PROGRAM], ms=2000)
    assert not project.devices["Y3"] and project.devices["D101"] == 0
    press(project, "X0")
    assert project.devices["Y1"]
