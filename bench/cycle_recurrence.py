"""How often a run's state repeats where it jumps over idle scans: the evidence for or
against replaying whole request cycles (issue 12, docs/performance.md).

    python bench/cycle_recurrence.py [--seconds 1200] [--scenario plc/scenarios/fx3u-healthy.toml]

Runs the scenario stretched to --seconds, in one process, and at every idle jump
(verifier.sim.idle.IdleScans._jump) takes the program's labels as the idle check reads
them. Prints how many different states the jumps see: as they are; with the timers'
start times taken relative to the jump and the labels that count (a different value at
more than a quarter of the jumps, e.g. o_wTxCount) left out; and with a running timer
counted only as "running". Then which fields of the I/O models' state differ between
jumps. A replay keyed on a state needs that state to repeat.
"""
from __future__ import annotations

import argparse
import sys
from collections import Counter
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "bench"))

from verify import stretched  # noqa: E402  (bench/verify.py)

from verifier.sim import idle  # noqa: E402
from verifier.verify.runner import run_scenario  # noqa: E402
from verifier.verify.scenario import load_scenario  # noqa: E402


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--seconds", type=float, default=1200)
    parser.add_argument("--scenario", type=Path, default=ROOT / "plc" / "scenarios" / "fx3u-healthy.toml")
    args = parser.parse_args()
    import tempfile

    jumps = []
    original = idle.IdleScans._jump

    def recording_jump(self, deadline):
        names = [f"{type(obj).__name__}.{slot}" for obj, slots in self._objects for slot in slots]
        names += [f"{type(obj).__name__}.{slot}[]" for obj, slot in self._arrays]
        jumps.append((self.rt.now_us, self._labels(), names, [p.idle_state() for p in self.rt.pollers]))
        return original(self, deadline)

    idle.IdleScans._jump = recording_jump
    with tempfile.TemporaryDirectory() as folder:
        run_scenario(load_scenario(stretched(args.scenario, Path(folder), args.seconds)))
    idle.IdleScans._jump = original

    if not jumps:
        print("no idle jumps: nothing to compare")
        return
    names = jumps[0][2]
    varying = [k for k in range(len(jumps[0][1])) if len({repr(j[1][k]) for j in jumps}) > 1]
    counters = [k for k in varying if not names[k].endswith("._start")
                and len({repr(j[1][k]) for j in jumps}) > len(jumps) // 4]

    def state(jump, relative_timers: bool, drop_counters: bool, abstract_timers: bool) -> tuple:
        now_ms = jump[0] // 1000
        out = []
        for k in varying:
            if drop_counters and k in counters:
                continue
            value = jump[1][k]
            if names[k].endswith("._start") and value is not None:
                value = "running" if abstract_timers else (now_ms - value if relative_timers else value)
            out.append(repr(value))
        return tuple(out)

    print(f"{args.scenario.name} for {args.seconds:g} s: {len(jumps):,} idle jumps, "
          f"{len(varying)} of {len(names)} label slots differ between them")
    print(f"  counters left out: {', '.join(names[k] for k in counters) or 'none'}")
    for title, flags in (("as they are", (False, False, False)),
                         ("timer starts relative to the jump, counters left out", (True, True, False)),
                         ("a running timer only 'running', counters left out", (True, True, True))):
        states = Counter(state(j, *flags) for j in jumps)
        print(f"  different states, {title}: {len(states):,} (the most common at {states.most_common(1)[0][1]:,} jumps)")
    for index in range(len(jumps[0][3])):
        fields = jumps[0][3][index]
        differ = [k for k in range(len(fields)) if len({repr(j[3][index][k]) for j in jumps}) > 1]
        print(f"  I/O model {index}: fields that differ between jumps: "
              + ", ".join(f"#{k} ({len({repr(j[3][index][k]) for j in jumps}):,} values)" for k in differ))


if __name__ == "__main__":
    main()
