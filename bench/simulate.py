"""How much faster than real time the simulator runs the FX3 example program.

    python bench/simulate.py [--hours 1] [--baseline-s 120] [--scan-ms 10]

Runs plc/examples/fx3/UITAMR_ExampleFx3 (with the core library and the FX3 RS2 port) with
a 10 ms scan, in one process, side by side:
  1. compiled simulator, RS2 attached to the virtual line + emulated robot, for --hours;
  2. compiled simulator, the robot's replies of run 1 replayed at the same calls without
     a line (the PLC doing the same work; the difference to run 1 is the line + robot);
  3. compiled simulator, nothing attached (the PLC alone: no replies, so the engine
     times out and sends less), for --hours;
  4. the plain tree-walking interpreter (verifier/sim/baseline.py) with the line + robot,
     for --baseline-s of virtual time (it is too slow for an hour);
and prints simulated time / wall time for each, the compiled-vs-baseline ratio, and
whether compiled and baseline produced the same bytes on the line.  Goal: >= 1000x real
time on one core for the simulator.  Wall-clock numbers depend on the machine's load; the
side-by-side ratio does much less.
"""
from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

import verifier  # noqa: E402
from verifier.amr import Robot  # noqa: E402
from verifier.link import Line  # noqa: E402
from verifier.sim.baseline import Interpreter, run_programs  # noqa: E402
from verifier.sim.cpu import profile_for  # noqa: E402
from verifier.sim.runtime import Runtime  # noqa: E402

PROGRAM = "UITAMR_ExampleFx3"
GOAL = 1000


def sources() -> list[Path]:
    """The core library plus the files (one POU each, named after it) the example needs."""
    plc = ROOT / "plc"
    extra = [next(plc.rglob(f"{pou}.st")) for pou in ("UITAMR_PortFx3", "UITAMR_PointCycle", PROGRAM)]
    return sorted((plc / "core").glob("*.st")) + extra


class Recorder(Line):
    """The line, with every non-empty receive_until answer noted (for Replay)."""

    def __init__(self, robot: Robot):
        super().__init__(robot)
        self.received = {}

    def receive_until(self, t_us):
        got = super().receive_until(t_us)
        if got:
            self.received[t_us] = got
        return got


class Replay:
    """The replies a Recorder saw, handed over at the same calls; sends go nowhere."""

    def __init__(self, received: dict):
        self.received = received

    def send(self, data, t_us, origin=None):
        return t_us

    def receive_until(self, t_us):
        return self.received.get(t_us, ())


def run_compiled(seconds: float, scan_ms: float, endpoint=None):
    project = verifier.load(*sources(), target="gxworks2", scan_ms=scan_ms)
    line = endpoint
    if endpoint is not None:
        project.attach_serial("fx3:1", endpoint)
    wall0, cpu0 = time.perf_counter(), time.process_time()
    project.run_programs([PROGRAM], ms=seconds * 1000)
    wall, cpu = time.perf_counter() - wall0, time.process_time() - cpu0
    return wall, cpu, project.scan_count, line


def run_baseline(seconds: float, scan_ms: float):
    project = verifier.load(*sources(), target="gxworks2", scan_ms=scan_ms)  # parse + check
    cpu_profile = profile_for("gxworks2")
    rt = Runtime(cpu_profile, scan_us=round(scan_ms * 1000))
    interp = Interpreter(project.files, rt, cpu_profile)
    line = Line(Robot())
    rt.channel("fx3:1").attach(line)
    wall0, cpu0 = time.perf_counter(), time.process_time()
    run_programs(interp, [PROGRAM], round(seconds * 1_000_000))
    return time.perf_counter() - wall0, time.process_time() - cpu0, rt.scan_count, line


def traffic(line, until_us: int):
    return [(f.t_start_us, f.direction, f.data) for f in line.trace if f.t_start_us < until_us]


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--hours", type=float, default=1.0, help="virtual time for the compiled runs")
    ap.add_argument("--baseline-s", type=float, default=120.0, help="virtual time for the interpreter")
    ap.add_argument("--scan-ms", type=float, default=10.0)
    args = ap.parse_args(argv)
    seconds = args.hours * 3600

    print(f"{PROGRAM}, scan {args.scan_ms:g} ms")
    rows = []
    wall, cpu, scans, line_c = run_compiled(seconds, args.scan_ms, Recorder(Robot()))
    rows.append(("compiled, line + robot", seconds, wall, cpu, scans))
    wall, cpu, scans, _ = run_compiled(seconds, args.scan_ms, Replay(line_c.received))
    rows.append(("compiled, same replies replayed, no line", seconds, wall, cpu, scans))
    wall, cpu, scans, _ = run_compiled(seconds, args.scan_ms)
    rows.append(("compiled, PLC alone", seconds, wall, cpu, scans))
    wall, cpu, scans, line_b = run_baseline(args.baseline_s, args.scan_ms)
    rows.append(("tree-walking baseline, line + robot", args.baseline_s, wall, cpu, scans))

    print(f"{'run':42} {'virtual s':>10} {'wall s':>8} {'scans':>9} {'x real time':>12} {'x (cpu time)':>13}")
    for name, virt, wall, cpu, scans in rows:
        print(f"{name:42} {virt:10.0f} {wall:8.2f} {scans:9d} {virt / wall:12.0f} {virt / cpu:13.0f}")
    compiled = rows[0][1] / rows[0][2]
    compiled_cpu = rows[0][1] / rows[0][3]
    alone = rows[2][1] / rows[2][2]
    alone_cpu = rows[2][1] / rows[2][3]
    baseline = rows[3][1] / rows[3][2]
    per_scan = [cpu / scans * 1e6 for _, _, _, cpu, scans in rows[:3]]
    print(f"CPU time per scan: line + robot {per_scan[0]:.1f} us = the PLC's own work {per_scan[1]:.1f} us "
          f"+ line and robot {per_scan[0] - per_scan[1]:.1f} us (PLC alone, no replies: {per_scan[2]:.1f} us)")
    print(f"compiled / baseline (line + robot): {compiled / baseline:.1f}x")
    same = traffic(line_c, round(args.baseline_s * 1e6)) == traffic(line_b, round(args.baseline_s * 1e6))
    print(f"same bytes at the same times on the line over the first {args.baseline_s:g} s: {'yes' if same else 'NO'}")
    print(f"goal {GOAL}x real time: PLC alone {'met' if alone >= GOAL else 'NOT met'} ({alone:.0f}x wall, "
          f"{alone_cpu:.0f}x on CPU time), with line + robot {'met' if compiled >= GOAL else 'NOT met'} "
          f"({compiled:.0f}x wall, {compiled_cpu:.0f}x on CPU time)")
    if alone < GOAL <= alone_cpu or compiled < GOAL <= compiled_cpu:
        print("note: wall time includes waiting for a core on a loaded machine; CPU time does not")
    return 0 if same else 1


if __name__ == "__main__":
    raise SystemExit(main())
