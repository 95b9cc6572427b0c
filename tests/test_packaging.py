"""A non-editable install (a wheel, `pip install ./uitamr`) carries the PLC library and the
bundled scenarios, and the commands find them there exactly as in a checkout."""
from __future__ import annotations

import os
import sys
import zipfile
from pathlib import Path

import pytest
import procs

ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="module")
def wheel(tmp_path_factory) -> Path:
    out = tmp_path_factory.mktemp("wheel")
    procs.run(
        [sys.executable, "-m", "pip", "wheel", "-q", "--no-deps", "--no-build-isolation", str(ROOT), "-w", str(out)],
        check=True, capture_output=True, text=True, timeout=300,
    )
    (found,) = out.glob("*.whl")
    return found


def _files_under(folder: Path) -> set[str]:
    return {p.relative_to(ROOT).as_posix() for p in folder.rglob("*") if p.is_file() and "__pycache__" not in p.parts}


def test_the_wheel_carries_every_file_of_plc(wheel):
    names = set(zipfile.ZipFile(wheel).namelist())
    missing = _files_under(ROOT / "plc") - names
    assert not missing, f"plc/ files missing from the wheel: {sorted(missing)}"
    assert "verifier/st/st.lark" in names
    assert any(n.startswith("verifier/verify/templates/") for n in names)


def test_an_installed_wheel_finds_the_bundled_library(wheel, tmp_path):
    site = tmp_path / "site"
    procs.run(
        [sys.executable, "-m", "pip", "install", "-q", "--no-deps", "--target", str(site), str(wheel)],
        check=True, capture_output=True, text=True, timeout=300,
    )
    env = {**os.environ, "PYTHONPATH": str(site)}
    probe = (
        "import verifier, verifier.commands.verify as v;"
        "print(verifier.__file__); print(len(v.bundled_scenarios()))"
    )
    shown = procs.run([sys.executable, "-c", probe], env=env, cwd=tmp_path,
                      capture_output=True, text=True, timeout=120, check=True).stdout.split()
    assert shown[0].startswith(str(site)), "the probe imported the checkout, not the installed wheel"
    assert int(shown[1]) == len(list((ROOT / "plc" / "scenarios").glob("*.toml"))) > 0

    exported = procs.run(
        [sys.executable, "-m", "verifier.cli", "export", "--target", "gxworks2", "--out", str(tmp_path / "out")],
        env=env, cwd=tmp_path, capture_output=True, text=True, timeout=120,
    )
    assert exported.returncode == 0, exported.stderr
    assert any((tmp_path / "out").rglob("UITAMR_Engine*")), exported.stdout
