"""A place in a file: the one shape every message, JUnit test case and annotation that
points into a file is made from (a capture's bad byte, a scenario's key, an ST error of
sources that do not load, the mistakes of a run that cannot start).

Kept free of the toolkit's other modules: the command line's exit-2 paths import it, and
they must stay quick to start.
"""
from __future__ import annotations

from dataclasses import dataclass, replace


@dataclass(frozen=True)
class Place:
    """Line and column (both 1-based) in `file`; `file` None for a place within a file its
    holder knows (a key of the scenario that `Scenario.key_lines` belongs to). Prints as
    `file:line:col` (`line:col` without a file), a name with a line feed or another
    character that is not printable escaped as every line-based message shows it
    (textfile.shown_name). Pickles as it is: places cross `--jobs`'
    worker processes inside the errors that hold them."""

    file: str | None
    line: int
    col: int

    def __str__(self) -> str:
        where = f"{self.line}:{self.col}"
        if self.file is None:
            return where
        if self.file.isprintable():
            return f"{self.file}:{where}"
        from verifier.textfile import shown_name  # a line feed in the name: keep the message on its line

        return f"{shown_name(self.file)}:{where}"

    def in_file(self, file: str) -> "Place":
        """This line and column in `file`."""
        return replace(self, file=file)

    @classmethod
    def of_location(cls, location: str | None) -> "Place | None":
        """An ST location as the simulator names it, "file:line:col" (a frame's origin, where
        the program stopped the CPU; the file's name may hold a ':', as a Windows drive
        does), as a Place; None for anything else."""
        file, _, col = (location or "").rpartition(":")
        file, _, line = file.rpartition(":")
        if not (file and line.isdigit() and col.isdigit()):
            return None
        return cls(file, int(line), int(col))
