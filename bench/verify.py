"""`uitamr verify` as users run it: whole processes, long scenarios, side by side.

    python bench/verify.py [--hours 1] [--stretch 5] [--jobs 1,2] [--skip-rss] [--parts 1,2,3,4,5]

Prints, measured in one run on this machine:
  1. fx3u-healthy at 60 s and stretched to --hours: the wall time of each whole
     `uitamr verify --scenario` process and the simulated time per extra wall second
     (x real time = (long - short virtual) / (long - short wall); start-up, loading and
     compiling cancel out); and the long run again with --every-scan (the reference path,
     no idle scans jumped over), as a ratio to the default;
  2. the same x-real-time figure for every bundled scenario, stretched --stretch times
     (at least to 600 s, so that the extra time is well above the noise);
  3. side by side in one process: the fast path (watched labels read through accessors
     resolved once and recorded on change, idle scans jumped over) against the plain
     path (every label by name, every scan run) - the ratio of the two, the number of
     scans jumped over, and whether the results are equal;
  4. `uitamr verify --matrix --jobs N` for each N, three rounds of one after the other:
     the median speed-up against N=1, for the bundled matrix as it is and with every
     scenario run for 300 s, next to the machine's ceiling: N copies of a CPU-bound Python loop at once against
     one after the other (median of 5);
  5. peak RSS of a 1 h and a 10 h run of fx3u-healthy (whole processes, os.wait4), without
     reports, with --trace and with --html; and of the bundled matrix at 1 h with --html.
Wall-clock figures move with the machine's load; ratios measured side by side much less.
"""
from __future__ import annotations

import argparse
import os
import re
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from verifier.sim.project import Project  # noqa: E402
from verifier.verify import report_html  # noqa: E402
from verifier.verify.runner import run_scenario  # noqa: E402
from verifier.verify.scenario import load_scenario  # noqa: E402

SCENARIOS = ROOT / "plc" / "scenarios"
UITAMR = [sys.executable, "-m", "verifier.cli"]


def stretched(source: Path, folder: Path, seconds: float) -> Path:
    """A copy of a bundled scenario with its duration set, its sources made absolute."""
    text = source.read_text(encoding="utf-8").replace('"../', f'"{SCENARIOS.parent.as_posix()}/')
    line = f'duration = "{seconds:g}s"'
    text, count = re.subn(r'^duration = "[^"]*"', line, text, count=1, flags=re.M)
    if count == 0:
        text = line + "\n" + text
    path = folder / f"{source.stem}-{seconds:g}s.toml"
    path.write_text(text, encoding="utf-8")
    return path


def duration_of(path: Path) -> float:
    return load_scenario(path).duration_us / 1_000_000


def run_process(*args) -> tuple[float, int]:
    """Wall seconds and peak RSS (KiB) of one whole `uitamr` process."""
    start = time.perf_counter()
    proc = subprocess.Popen([*UITAMR, *map(str, args)], stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    _, status, usage = os.wait4(proc.pid, 0)
    wall = time.perf_counter() - start
    code = os.waitstatus_to_exitcode(status)
    if code not in (0, 1):
        raise SystemExit(f"uitamr {' '.join(map(str, args))} exited {code}: {proc.stderr.read().decode()}")
    proc.stderr.close()
    return wall, usage.ru_maxrss


# a pure-Python CPU-bound loop of about a second: what N cores give N processes of it
_SPIN = "x = 0\nfor i in range(12_000_000):\n    x += i * i % 7\n"


def machine_ceiling(n: int, repeat: int = 5) -> tuple[float, float, float]:
    """How much faster N copies of a CPU-bound Python process finish at once than one
    after the other, on this machine now: the most `--jobs N` can give (vCPUs may share
    a physical core, and other tenants share the host). Lowest, median, highest."""
    ratios = []
    for _ in range(repeat):
        start = time.perf_counter()
        subprocess.run([sys.executable, "-c", _SPIN], check=True)
        alone = time.perf_counter() - start
        start = time.perf_counter()
        procs = [subprocess.Popen([sys.executable, "-c", _SPIN]) for _ in range(n)]
        for proc in procs:
            proc.wait()
        ratios.append(n * alone / (time.perf_counter() - start))
    ratios.sort()
    return ratios[0], ratios[len(ratios) // 2], ratios[-1]


def best_wall(*args, repeat: int = 3) -> float:
    return min(run_process(*args)[0] for _ in range(repeat))


# below this, a difference of best-of-3 process times is start-up noise, not simulation
NOISE_S = 0.05


def x_real_time(short: Path, long: Path, repeat: int = 3) -> tuple[float, float, float, bool]:
    """Wall times of the two runs and the x real time of the difference; the flag is True
    when the difference is within the noise and the figure only a lower bound."""
    short_wall = best_wall("verify", "--scenario", short, repeat=repeat)
    long_wall = best_wall("verify", "--scenario", long, repeat=repeat)
    extra = long_wall - short_wall
    virtual = duration_of(long) - duration_of(short)
    if extra < NOISE_S:
        return short_wall, long_wall, virtual / NOISE_S, True
    return short_wall, long_wall, virtual / extra, False


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--hours", type=float, default=1.0)
    parser.add_argument("--stretch", type=float, default=5.0)
    parser.add_argument("--jobs", default=f"1,{os.cpu_count() or 1}")
    parser.add_argument("--skip-rss", action="store_true")
    parser.add_argument("--parts", default="1,2,3,4,5", help="which of the figures above to measure, e.g. 4")
    options = parser.parse_args()
    parts = {int(p) for p in options.parts.split(",")}
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        healthy = SCENARIOS / "fx3u-healthy.toml"
        short, long = stretched(healthy, folder, 60), stretched(healthy, folder, options.hours * 3600)
        if 1 in parts:
            part_1(short, long, options.hours)
        if 2 in parts:
            part_2(folder, options.stretch)
        if 3 in parts:
            part_3(healthy, folder)
        if 4 in parts:
            part_4([int(j) for j in options.jobs.split(",")])
        if 5 in parts and not options.skip_rss:
            part_5(healthy, folder)


def part_1(short: Path, long: Path, hours: float) -> None:
    s, l, x, bound = x_real_time(short, long)
    print(f"1. uitamr verify fx3u-healthy: 60 s in {s:.2f} s wall, {hours:g} h in {l:.2f} s wall "
          f"-> {'at least ' if bound else ''}{x:,.0f}x real time "
          f"(the {hours:g} h costs {l - s:.2f} s more than 60 s)")
    every = best_wall("verify", "--scenario", long, "--every-scan", repeat=1)
    print(f"   the same {hours:g} h with --every-scan (every scan run, every label read by name): "
          f"{every:.2f} s wall -> the default is {every / l:.1f}x faster as a whole process")


def part_2(folder: Path, stretch: float) -> None:
    print(f"2. every bundled scenario at its duration and stretched to max({stretch:g}x, 600 s) "
          "(whole processes, best of 3):")
    worst = None
    for source in sorted(SCENARIOS.glob("*.toml")):
        base = duration_of(source)
        a = stretched(source, folder, base)
        b = stretched(source, folder, max(base * stretch, 600))
        _, _, x, bound = x_real_time(a, b, repeat=3)
        worst = x if worst is None else min(worst, x)
        print(f"   {source.stem:32} {'>=' if bound else '  '}{x:10,.0f}x"
              + (f"  (the longer run costs less than {NOISE_S} s more: within the start-up noise)"
                 if bound else ""))
    print(f"   lowest: {worst:,.0f}x")


def part_3(healthy: Path, folder: Path) -> None:
    scenario = load_scenario(stretched(healthy, folder, 600))
    skippers = []
    original = Project.skip_idle_scans

    def recording(self, *args, **kwargs):
        skippers.append(original(self, *args, **kwargs))
        return skippers[-1]

    Project.skip_idle_scans = recording
    fast_start = time.perf_counter()
    fast = run_scenario(scenario)
    fast_wall = time.perf_counter() - fast_start
    Project.skip_idle_scans = original
    plain_start = time.perf_counter()
    plain = run_scenario(scenario, plain=True)
    plain_wall = time.perf_counter() - plain_start
    fast.wall_s = plain.wall_s = 0.0
    same = fast == plain
    idle = skippers[-1]
    print(f"3. 600 s of fx3u-healthy in one process: fast path {fast_wall:.2f} s (accessors, record on "
          f"change, {idle.skipped_scans:,} of {idle.rt.scan_count:,} scans idle and jumped over), plain "
          f"path {plain_wall:.2f} s (every label by name, every scan run) -> {plain_wall / fast_wall:.1f}x; "
          f"same result: {same}")


def part_4(jobs: list[int]) -> None:
    print("4. uitamr verify --matrix, three rounds of " + ", ".join(f"--jobs {n}" for n in jobs) + ":")
    # the bundled matrix as it is (about 3 s of work: start-up weighs), and with every
    # scenario run for 300 s, as a fault sweep of a soak test runs it
    for extra in ((), ("--duration", "300s")):
        rounds: list[dict[int, float]] = []
        for _ in range(3):  # the job counts one after the other, three times: side by side
            rounds.append({n: run_process("verify", "--matrix", *extra, "--jobs", n)[0] for n in jobs})
        for n in jobs[1:]:
            speedups = sorted(r[jobs[0]] / r[n] for r in rounds)
            print(f"   {' '.join(extra) or 'as bundled'}: --jobs {n} against --jobs {jobs[0]}: x{speedups[1]:.2f} "
                  "(median; rounds " + ", ".join(f"{r[jobs[0]]:.2f} s / {r[n]:.2f} s" for r in rounds) + ")")
    for n in (n for n in jobs if n > 1):
        low, median, high = machine_ceiling(n)
        print(f"   the machine's own ceiling for N={n}: {n} CPU-bound Python processes at once against "
              f"one after the other: x{median:.2f} (x{low:.2f} to x{high:.2f} in 5 tries)")


def part_5(healthy: Path, folder: Path) -> None:
    one = stretched(healthy, folder, 3600)
    ten = stretched(healthy, folder, 36000)
    _, rss_one = run_process("verify", "--scenario", one)
    _, rss_ten = run_process("verify", "--scenario", ten)
    print(f"5. peak RSS: 1 h {rss_one / 1024:.0f} MiB, 10 h {rss_ten / 1024:.0f} MiB "
          f"(ratio {rss_ten / rss_one:.2f})")
    trace = folder / "trace.jsonl"
    _, rss_one = run_process("verify", "--scenario", one, "--trace", trace)
    _, rss_ten = run_process("verify", "--scenario", ten, "--trace", trace)
    print(f"   with --trace (every frame listed): 1 h {rss_one / 1024:.0f} MiB, 10 h {rss_ten / 1024:.0f} MiB "
          f"(ratio {rss_ten / rss_one:.2f}; the trace file: {trace.stat().st_size / 2**20:.0f} MiB)")
    page = folder / "report.html"
    _, rss_one = run_process("verify", "--scenario", one, "--html", page)
    size_one = page.stat().st_size
    _, rss_ten = run_process("verify", "--scenario", ten, "--html", page)
    print(f"   with --html (the page draws at most {report_html.FRAMES_AT_MOST:,} frames a run, read "
          f"from a file the run writes them to): 1 h {rss_one / 1024:.0f} MiB, 10 h {rss_ten / 1024:.0f} MiB "
          f"(ratio {rss_ten / rss_one:.2f}; the page: {size_one / 2**20:.1f} / "
          f"{page.stat().st_size / 2**20:.1f} MiB)")
    _, rss = run_process("verify", "--matrix", "--duration", "1h", "--jobs", "2", "--html", page)
    print(f"   --matrix --duration 1h --jobs 2 --html ({len(list(SCENARIOS.glob('*.toml')))} runs): "
          f"{rss / 1024:.0f} MiB (the largest process; the page: {page.stat().st_size / 2**20:.1f} MiB)")


if __name__ == "__main__":
    main()
