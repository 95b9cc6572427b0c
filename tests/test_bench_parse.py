"""bench/parse.py times ours as `uitamr check` works: the function the command runs, on
files, with the same findings the command reports (blark's side is not run here: its
grammar and the corpus filter take most of a minute)."""
import importlib.util
from pathlib import Path

from verifier.commands.check import check_findings

ROOT = Path(__file__).resolve().parent.parent
BENCH = ROOT / "bench" / "parse.py"


def _bench_module():
    spec = importlib.util.spec_from_file_location("bench_parse", BENCH)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_the_bench_times_what_uitamr_check_reports(tmp_path):
    bench = _bench_module()
    chunks = bench._candidate_sources()[:6]
    paths = bench.write_corpus(chunks, tmp_path)
    assert [p.read_text(encoding="utf-8") for p in paths] == chunks
    seconds, count = bench.time_check(paths, repeat=1)
    assert seconds > 0
    _files, findings = check_findings(sorted(tmp_path.glob("*.st")), "gxworks3")
    assert count == len(findings)
    assert not [f for f in findings if f.rule == "UITAMR-ST-SYNTAX"]
    assert bench.time_command(tmp_path, repeat=1) > 0  # the whole command ran (exit 0 or 1)

