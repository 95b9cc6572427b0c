"""Where the bundled PLC library, examples and scenarios are.

`plc/` sits beside the `verifier` package both in a checkout (editable install) and in a
non-editable install, where pyproject.toml ships it as data next to `verifier/`.
"""
from __future__ import annotations

from pathlib import Path

PLC_DIR = Path(__file__).resolve().parents[1] / "plc"


def plc_dir() -> Path:
    """The bundled `plc/` folder."""
    return PLC_DIR
