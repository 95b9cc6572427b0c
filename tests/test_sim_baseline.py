"""The tree-walking interpreter bench/simulate.py compares against runs the same program to
the same result as the compiled simulator (so the bench compares like with like)."""
from __future__ import annotations

from pathlib import Path

import verifier
from verifier.amr import Robot
from verifier.link import Line
from verifier.sim.baseline import Interpreter, run_programs
from verifier.sim.cpu import profile_for
from verifier.sim.runtime import Runtime

PLC = Path(__file__).resolve().parents[1] / "plc"
SOURCES = [PLC / "core", PLC / "fx3", PLC / "examples" / "common", PLC / "examples" / "fx3"]
PROGRAM = "UITAMR_ExampleFx3"


def test_baseline_and_compiled_put_the_same_bytes_on_the_line():
    compiled = verifier.load(*SOURCES)
    line_c = Line(Robot())
    compiled.attach_serial("fx3:1", line_c)
    compiled.devices["X0"] = True  # start a point cycle from the first scan
    compiled.run_programs([PROGRAM], ms=4000)

    cpu = profile_for("gxworks2")
    rt = Runtime(cpu, scan_us=10_000)
    interp = Interpreter(compiled.files, rt, cpu)
    line_b = Line(Robot())
    rt.channel("fx3:1").attach(line_b)
    rt.dev["X0"] = True
    run_programs(interp, [PROGRAM], 4_000_000)

    def frames(line):
        return [(f.t_start_us, f.direction, f.data) for f in line.trace]

    assert len(frames(line_c)) >= 10
    assert frames(line_c) == frames(line_b)
    assert compiled.devices["D100"] == rt.dev["D100"]


def test_inlined_and_called_fb_bodies_behave_the_same(monkeypatch):
    from verifier.sim import compiler

    def run(inline: bool):
        monkeypatch.setattr(compiler.compile_files, "__defaults__", (inline,))
        project = verifier.load(*SOURCES)
        line = Line(Robot())
        project.attach_serial("fx3:1", line)
        project.devices["X0"] = True
        project.run_programs([PROGRAM], ms=4000)
        return [(f.t_start_us, f.direction, f.data) for f in line.trace], project.module.source

    inlined, src_inlined = run(True)
    called, src_called = run(False)
    assert src_inlined != src_called and src_inlined.count("._body()") < src_called.count("._body()")
    assert inlined == called and len(inlined) >= 10
