"""Every valid file of the ST corpus (tests/corpus/valid) loads into the simulator for at
least one CPU and runs, or is refused with a LoadError naming file:line:col — never a
crash of the simulator."""
from __future__ import annotations

import re
from pathlib import Path

import pytest

import verifier
from verifier.sim import LoadError, SimulationError

CORPUS = Path(__file__).resolve().parent / "corpus" / "valid"
FILES = sorted(CORPUS.glob("*.st"))
LOCATION = re.compile(r"\.st:\d+:\d+: error: ")


def sources_for(path: Path) -> list[Path]:
    """multi_file_a.st needs its partner multi_file_b.st, and the other way round."""
    m = re.match(r"(.*_)([a-z])\.st$", path.name)
    if m and m.group(1).startswith("multi_file"):
        return sorted(CORPUS.glob(m.group(1) + "*.st"))
    return [path]


def target_of(path: Path) -> str:
    return "gxworks3" if path.name.startswith("gx3_") else "gxworks2"


@pytest.mark.parametrize("path", FILES, ids=[p.name for p in FILES])
def test_valid_corpus_file_runs_or_is_refused_with_a_location(path):
    target = target_of(path)
    cpus = ["fx5u"] if target == "gxworks3" else ["fx3u", "q"]
    refusals = []
    for cpu in cpus:
        try:
            project = verifier.load(*sources_for(path), target=target, cpu=cpu)
        except LoadError as err:
            assert LOCATION.search(str(err)), str(err)
            refusals.append(str(err))
            continue
        for info in project.module.pous.values():
            try:
                if info.kind == "PROGRAM":
                    project.run_programs([info.pou.name], scans=3)
                elif info.kind == "FUNCTION_BLOCK":
                    project.instance(info.pou.name).scan(3)
            except SimulationError as err:
                assert err.location and LOCATION.sub("", err.location + ": error: ") is not None
                assert "simulator fault" not in str(err), str(err)
        return
    # no CPU runs this file: only acceptable when it mixes instructions or devices of
    # different CPUs (X1F is hexadecimal on Q, SD8400 exists on FX5 only...)
    assert all(any(why in r for why in ("does not exist on the", "has no", "are base"))
               for r in refusals), refusals
