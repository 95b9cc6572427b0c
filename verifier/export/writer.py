"""Write the export: per POU `<name>.st` (the body) and `<name>.labels.tsv` (the label
table, tab-separated so a spreadsheet or the label editor takes it by paste), the global
labels of all files in `GlobalLabels.labels.tsv` (when there are any), plus
`IMPORT_ORDER.txt` (functions and function blocks before their users: name, kind and, for
a FUNCTION, its result type as the POU properties dialog asks for it)."""
from __future__ import annotations

import re
from dataclasses import dataclass, field
from pathlib import Path

from verifier import st
from verifier.st import ast
from verifier.export.body import body_text
from verifier.export.labels import LabelRow, label_rows, rows_of
from verifier.export.types import type_name

COLUMNS = {
    "gxworks2": ("Class", "Label Name", "Data Type", "Constant", "Comment"),
    "gxworks3": ("Label Name", "Data Type", "Class", "Initial Value", "Constant", "Comment"),
}


GLOBAL_COLUMNS = {
    "gxworks2": ("Class", "Label Name", "Data Type", "Constant", "Device", "Comment"),
    "gxworks3": ("Label Name", "Data Type", "Class", "Assign (Device/Label)", "Initial Value", "Constant", "Comment"),
}
GLOBAL_TABLE = "GlobalLabels.labels.tsv"


class ExportError(Exception):
    """Sources that cannot be exported; `diagnostics` name file, line and column."""

    def __init__(self, diagnostics: list[ast.Diagnostic]):
        super().__init__("\n".join(str(d) for d in diagnostics))
        self.diagnostics = diagnostics


@dataclass
class ExportedPou:
    name: str
    kind: str
    source: str
    result: str = ""
    uses: set[str] = field(default_factory=set)


def _row_cells(row: LabelRow, target: str) -> list[str]:
    if target == "gxworks2":
        return [row.label_class, row.name, row.data_type, row.constant, row.comment]
    return [row.name, row.data_type, row.label_class, row.initial, row.constant, row.comment]


def label_table(rows: list[LabelRow], target: str) -> str:
    lines = ["\t".join(COLUMNS[target])]
    lines += ["\t".join(cell.replace("\t", " ") for cell in _row_cells(r, target)) for r in rows]
    return "\n".join(lines) + "\n"


def global_table(rows: list[LabelRow], target: str) -> str:
    def cells(r: LabelRow) -> list[str]:
        if target == "gxworks2":
            return [r.label_class, r.name, r.data_type, r.constant, r.device, r.comment]
        return [r.name, r.data_type, r.label_class, r.device, r.initial, r.constant, r.comment]
    lines = ["\t".join(GLOBAL_COLUMNS[target])]
    lines += ["\t".join(c.replace("\t", " ") for c in cells(r)) for r in rows]
    return "\n".join(lines) + "\n"


def _uses(pou: ast.Pou, body: str, known: set[str]) -> set[str]:
    used = {d.type.key for d in pou.variables if isinstance(d.type, ast.NamedType) and d.type.key in known}
    used |= {w.upper() for w in re.findall(r"\b([A-Za-z][A-Za-z0-9_]*)\s*\(", body) if w.upper() in known}
    used.discard(pou.key)
    return used


def import_order(pous: list[ExportedPou]) -> list[str]:
    """Names in an order where every POU comes after the POUs it uses."""
    by_key = {p.name.upper(): p for p in pous}
    done: list[str] = []
    seen: set[str] = set()

    def visit(key: str, path: tuple[str, ...]) -> None:
        if key in seen or key in path:
            return
        for dep in sorted(by_key[key].uses):
            visit(dep, path + (key,))
        seen.add(key)
        done.append(by_key[key].name)

    rank = {"FUNCTION": 0, "FUNCTION_BLOCK": 1, "PROGRAM": 2}
    for p in sorted(pous, key=lambda p: (rank.get(p.kind, 3), p.name.upper())):
        visit(p.name.upper(), ())
    return done


def export_sources(paths: list[Path], target: str, out: Path, texts: dict[Path, str] | None = None) -> list[Path]:
    """Parse and check `paths`, write the export into `out`; returns the files written.
    Raises ExportError (with file:line:col diagnostics) when a source has errors."""
    if target not in COLUMNS:
        raise ValueError(f"unknown target {target!r}; expected gxworks2 or gxworks3")
    texts = texts or {}
    files = [st.parse(texts.get(p) or p.read_text(encoding="utf-8-sig"), str(p), target) for p in paths]
    problems = [d for f in files for d in f.diagnostics if d.is_error]
    problems += [d for d in st.check(files, target) if d.is_error]
    if problems:
        raise ExportError(problems)
    known = {p.key for f in files for p in f.pous}
    exported: list[ExportedPou] = []
    out.mkdir(parents=True, exist_ok=True)
    written: list[Path] = []
    for f in files:
        for pou in f.pous:
            body = body_text(pou, f.text)
            rows = label_rows(pou, f.text, target)
            body_path = out / f"{pou.name}.st"
            table_path = out / f"{pou.name}.labels.tsv"
            body_path.write_text(body, encoding="utf-8")
            table_path.write_text(label_table(rows, target), encoding="utf-8")
            written += [body_path, table_path]
            result = type_name(pou.return_type, target) if pou.return_type is not None else ""
            exported.append(ExportedPou(pou.name, pou.kind, f.filename, result, _uses(pou, body, known)))
    global_rows = [row for f in files for block in f.globals for row in rows_of(block.variables, f.text, target)]
    if global_rows:
        path = out / GLOBAL_TABLE
        path.write_text(global_table(global_rows, target), encoding="utf-8")
        written.append(path)
    order = out / "IMPORT_ORDER.txt"
    by_name = {p.name: p for p in exported}
    rows = [(name, by_name[name].kind, by_name[name].result) for name in import_order(exported)]
    order.write_text("".join("\t".join(filter(None, row)) + "\n" for row in rows), encoding="utf-8")
    written.append(order)
    return written
