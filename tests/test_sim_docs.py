"""The examples of docs/testing-st.md run as written (ST blocks become files, Python
blocks run in order, from a folder that also holds the repository's plc/)."""
from __future__ import annotations

import os
import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
DOC = ROOT / "docs" / "testing-st.md"


def blocks(kind: str) -> list[str]:
    return re.findall(rf"```{kind}\n(.*?)```", DOC.read_text(encoding="utf-8"), re.S)


def test_quick_start_runs(tmp_path, monkeypatch):
    st_block = blocks("iecst")[0]
    name = re.search(r"FUNCTION_BLOCK (\w+)", st_block).group(1)
    (tmp_path / f"{name}.st").write_text(st_block, encoding="utf-8")
    os.symlink(ROOT / "plc", tmp_path / "plc")
    monkeypatch.chdir(tmp_path)
    exec(compile(blocks("python")[0], str(DOC), "exec"), {})


def test_serial_example_runs(tmp_path, monkeypatch):
    monkeypatch.chdir(ROOT)
    code = blocks("python")[1].replace("ms=60_000", "ms=3_000")
    code = code.replace("for frame in line.trace:\n    print(", "for frame in line.trace[:2]:\n    (")
    namespace: dict = {}
    exec(compile(code, str(DOC), "exec"), namespace)
    assert namespace["project"].get("UITAMR_ExampleFx3.fbEngine.o_bInitDone") is True


pytest_plugins = ["pytester"]


def test_pytest_example_passes(pytester):
    st_block = blocks("iecst")[0]
    pytester.makefile(".st", FB_Delay=st_block)
    os.symlink(ROOT / "plc", pytester.path / "plc")
    pytester.makepyfile(test_doc_example=blocks("python")[2])
    result = pytester.runpytest("-p", "no:cacheprovider")
    result.assert_outcomes(passed=2)
