"""Shared helper of the tests that lay out a small project (sources and scenario files) in a folder."""
from __future__ import annotations

from pathlib import Path


def write_files(folder: Path, files: dict[str, str]) -> None:
    """Each file named in `files` written into `folder` with its text, UTF-8."""
    for name, text in files.items():
        (folder / name).write_text(text, encoding="utf-8")
