"""What the simulator reports: user-facing errors that point at ST source locations."""
from __future__ import annotations

from dataclasses import dataclass

from verifier.place import Place


class LoadError(Exception):
    """The ST sources could not be loaded: parse or check diagnostics (file:line:col)."""

    def __init__(self, diagnostics):
        self.diagnostics = list(diagnostics)
        options = all(getattr(d, "file", "").startswith(OPTION_PLACE) for d in self.diagnostics)
        heading = "verifier.load was given an option it cannot use" if options else "ST sources have errors"
        super().__init__(f"{heading}:\n" + "\n".join("  " + s for s in self.lines()))

    def __reduce__(self):  # pickled as its diagnostics: the message is made from them
        return type(self), (self.diagnostics,)

    def lines(self) -> list[str]:
        """Each diagnostic, errors and warnings alike, in order, as its line of the message
        shows it (`file:line:col: severity: message`)."""
        return [_format_diag(d) for d in self.diagnostics]

    def shown_from(self, cwd: str) -> "LoadError":
        """The same diagnostics, each source's path as reports show it from the working
        folder `cwd` (relative when inside it, by the path the sources reach it:
        textfile.shown_path): `uitamr verify` names ST errors as `uitamr check` and the
        frames' ST places do (`plc/MAIN.st:7:1`), not by the absolute path it loaded."""
        from dataclasses import replace

        from verifier.textfile import shown_path

        return type(self)([d if d.file.startswith(OPTION_PLACE) else replace(d, file=shown_path(d.file, cwd))
                           for d in self.diagnostics])

    def place(self) -> Place | None:
        """The place of the first error that names a source's line (not an option of
        verifier.load), as its line of the message shows it; None if none does."""
        located = self.located()
        return located[0][0] if located else None

    def located(self) -> list[tuple[Place, str]]:
        """The place and the line of the message of each error that names a source's line,
        in the message's order: the mistakes a report can place one by one."""
        return [(d.place, _format_diag(d)) for d in self.diagnostics
                if not d.file.startswith(OPTION_PLACE) and d.is_error]


#: the "file" of a diagnostic about an argument of verifier.load, not about a source:
#: `verifier.load(scan_ms=0)`
OPTION_PLACE = "verifier.load("


def option_error(message: str, **given) -> "LoadError":
    """A LoadError about arguments of verifier.load, placed by their names and values:
    `verifier.load(scan_ms=0): error: ...`."""
    from verifier.st import ast

    args = ", ".join(f"{name}={value!r:.60}" for name, value in given.items())
    return LoadError([ast.Diagnostic(f"{OPTION_PLACE}{args})", 0, 0, "error", message)])


def _format_diag(d) -> str:
    if d.file.startswith(OPTION_PLACE):  # a call's argument has no line and column
        return f"{d.file}: {d.severity}: {d.message}"
    return str(d)


class SimulationError(Exception):
    """The simulated program did something the simulator must stop on (an array index out
    of bounds, a CPU that stops on an operation error, ...). `location` is the ST source
    location "file:line:col"; `t_us` the virtual time."""

    def __init__(self, message: str, location: str | None = None, t_us: int | None = None):
        self.message = message
        self.location = location
        self.t_us = t_us
        self.source_line: str | None = None  # the ST line, filled in by the project
        super().__init__(message)

    def __str__(self) -> str:
        where = f"{self.location}: " if self.location else ""
        when = f" (at t={self.t_us / 1e6:.6f} s)" if self.t_us is not None else ""
        text = f"{where}{self.message}{when}"
        if self.source_line is not None and self.location:
            col = int(self.location.rsplit(":", 1)[1])
            text += f"\n    {self.source_line}\n    {' ' * max(col - 1, 0)}^"
        return text


@dataclass(frozen=True)
class SimDiagnostic:
    """Something the simulator noticed and let pass, as the CPU would (operation errors
    flagged in SM0/M8067, ...), kept for the report."""

    t_us: int
    location: str | None
    code: int
    message: str

    def __str__(self) -> str:
        where = f"{self.location}: " if self.location else ""
        return f"{where}t={self.t_us / 1e6:.6f} s: {self.message} (error code {self.code})"
