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
    seconds, count = bench.time_check(chunks, repeat=1)
    assert seconds > 0
    for i, chunk in enumerate(chunks):
        (tmp_path / f"bench{i:04}.st").write_text(chunk, encoding="utf-8")
    _files, findings = check_findings(sorted(tmp_path.glob("*.st")), "gxworks3")
    assert count == len(findings)
    assert not [f for f in findings if f.rule == "UITAMR-ST-SYNTAX"]

