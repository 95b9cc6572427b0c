"""What the monitor shows while it runs: every frame as a line (time, direction, hex,
meaning) and every finding in a line of its own with its time and frames; on a terminal a
rich status panel under them counts frames and findings per rule."""
from __future__ import annotations

from collections import Counter

from rich.console import Console
from rich.live import Live
from rich.markup import escape
from rich.table import Table

from verifier import protocol
from verifier.verify.durations import format_seconds
from verifier.verify.evidence import Violation
from verifier.verify.result import TraceRecord
from verifier.verify.traffic import describe_bytes

ARROW = {"tx": "PLC → robot", "rx": "robot → PLC"}


def frame_line(frame: TraceRecord, settings: protocol.Settings, request=None) -> str:
    meaning = describe_bytes(frame.data, settings, frame.direction, request=request)
    return f"{frame.t_start_us / 1_000_000:10.3f} s  {ARROW[frame.direction]}  {protocol.hex_bytes(frame.data):<26} {meaning}"


def finding_lines(violation: Violation) -> list[str]:
    lines = [f"{format_seconds(violation.t_us)}  {violation.rule}: {violation.message}"]
    for ref in violation.frames:
        lines.append(f"        {ref.t_us / 1_000_000:10.3f} s  {ARROW.get(ref.direction, ref.direction)}  "
                     f"{ref.hex}  {ref.meaning}")
    return lines


class MonitorView:
    def __init__(self, console: Console, settings: protocol.Settings, source: str, quiet: bool = False):
        self.console = console
        self.settings = settings
        self.source = source
        self.quiet = quiet
        self.counts = Counter()
        self.rules = Counter()
        self._request = None
        self._live: Live | None = None

    def __enter__(self) -> "MonitorView":
        if self.console.is_terminal:
            self._live = Live(self._panel(), console=self.console, refresh_per_second=4, transient=True)
            self._live.__enter__()
        return self

    def __exit__(self, *exc) -> None:
        if self._live is not None:
            self._live.__exit__(*exc)

    def frames(self, frames: list[TraceRecord]) -> None:
        """New frames, printed in one go (a burst hands over hundreds at a time)."""
        lines = []
        for frame in frames:
            self.counts[frame.direction] += 1
            if frame.direction == "tx":
                try:
                    self._request = protocol.decode_request(frame.data, self.settings)
                except protocol.FrameError:
                    self._request = None
            if not self.quiet:
                request = self._request if frame.direction == "rx" else None
                lines.append(escape(frame_line(frame, self.settings, request)))
        self._show(lines, counted=bool(frames))

    def findings(self, violations: list[Violation]) -> None:
        """New findings, each a red line and its frames, printed in one go."""
        lines = []
        for violation in violations:
            self.rules[violation.rule] += 1
            first, *rest = finding_lines(violation)
            lines += [f"[bold red]{escape(first)}[/]", *(escape(line) for line in rest)]
        self._show(lines, counted=bool(violations))

    def _show(self, lines: list[str], counted: bool) -> None:
        """Print `lines` (markup) at once; refresh the panel when its counts changed."""
        if lines:
            self.console.print("\n".join(lines), highlight=False)
        if counted:
            self._refresh()

    def _refresh(self) -> None:
        if self._live is not None:
            self._live.update(self._panel())
        else:
            self.console.file.flush()  # a pipe or a log file: every line as it happens

    def _panel(self) -> Table:
        table = Table(title=f"uitamr monitor — {escape(self.source)} (Ctrl-C stops and writes the reports)",
                      show_header=True, expand=False)
        table.add_column("requests")
        table.add_column("replies")
        table.add_column("findings")
        found = ", ".join(f"{rule} ×{n}" for rule, n in sorted(self.rules.items())) or "none"
        table.add_row(str(self.counts["tx"]), str(self.counts["rx"]), escape(found))
        return table
