"""Where the bundled PLC library, examples and scenarios are.

`plc/` sits beside the `verifier` package both in a checkout (editable install) and in a
non-editable install, where pyproject.toml ships it as data next to `verifier/`.
"""
from __future__ import annotations

import functools
from pathlib import Path

PLC_DIR = Path(__file__).resolve().parents[1] / "plc"


def plc_dir() -> Path:
    """The bundled `plc/` folder."""
    return PLC_DIR


@functools.cache
def _library_files() -> dict[str, Path]:
    # one POU per file, the file named after the POU (docs/plc-library.md)
    return {path.stem.upper(): path for path in sorted(PLC_DIR.glob("**/*.st"))}


def library_file(pou: str) -> Path | None:
    """The bundled file that declares the POU `pou` (any case), or None."""
    return _library_files().get(pou.upper())
