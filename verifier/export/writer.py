"""Write the export: per POU `<name>.st` (the body) and `<name>.labels.tsv` (the label
table, tab-separated so a spreadsheet or the label editor takes it by paste), the global
labels of all files in `GlobalLabels.labels.tsv` (when there are any), plus
`IMPORT_ORDER.txt` (functions and function blocks before their users: name, kind and, for
a FUNCTION, its result type as the POU properties dialog asks for it).

Nothing is dropped silently: an initial value the target's label table cannot carry
(GX Works2 has no initial-value column) is listed in `DROPPED_INITIAL_VALUES.txt` and
returned as a `DroppedValue` note naming file, line and column; a file without any POU,
global label or structure type is refused (`NothingToExport`)."""
from __future__ import annotations

import os
import re
from dataclasses import dataclass, field
from pathlib import Path

from verifier import st
from verifier.st import ast
from verifier.export.body import body_text
from verifier.export.needed import needed, only
from verifier.sim import reach
from verifier.sim.cpu import CpuProfile
from verifier.sim.reach import type_names
from verifier.export.labels import LabelRow, initial_text, label_class, label_rows, rows_of
from verifier.export.types import type_name
from verifier.textfile import real_path, shown_name, text_lines, whole_file

COLUMNS = {
    "gxworks2": ("Class", "Label Name", "Data Type", "Constant", "Comment"),
    "gxworks3": ("Label Name", "Data Type", "Class", "Initial Value", "Constant", "Comment"),
}


GLOBAL_COLUMNS = {
    "gxworks2": ("Class", "Label Name", "Data Type", "Constant", "Device", "Comment"),
    "gxworks3": ("Label Name", "Data Type", "Class", "Assign (Device/Label)", "Initial Value", "Constant", "Comment"),
}
GLOBAL_TABLE = "GlobalLabels.labels.tsv"
#: structure members (`TYPE ... STRUCT`), one `<Type>.struct.tsv` per structure
#: (UNCONFIRMED column names of the editors' structure definition tables)
STRUCT_COLUMNS = {
    "gxworks2": ("Label Name", "Data Type", "Comment"),
    "gxworks3": ("Label Name", "Data Type", "Initial Value", "Comment"),
}


DROPPED_TABLE = "DROPPED_INITIAL_VALUES.txt"
IMPORT_ORDER = "IMPORT_ORDER.txt"
#: label classes whose initial value the editor's label table can hold. GX Works2's label
#: editor has no initial-value column at all (only the Constant column of VAR_CONSTANT);
#: GX Works3 has one for every class the checker lets carry a value (it refuses one on
#: VAR_IN_OUT, a reference to the caller's label).
CARRIES_INITIAL = {
    "gxworks2": frozenset(),
    "gxworks3": frozenset({"VAR", "VAR_RETAIN", "VAR_INPUT", "VAR_OUTPUT", "VAR_OUTPUT_RETAIN",
                           "VAR_PUBLIC", "VAR_PUBLIC_RETAIN", "VAR_TEMP", "VAR_GLOBAL",
                           "VAR_GLOBAL_RETAIN"}),
}
EDITOR = {"gxworks2": "GX Works2", "gxworks3": "GX Works3"}


class ExportError(Exception):
    """Sources that cannot be exported; `diagnostics` name file, line and column."""

    def __init__(self, diagnostics: list[ast.Diagnostic]):
        super().__init__("\n".join(str(d) for d in diagnostics))
        self.diagnostics = diagnostics


class NothingToExport(ExportError):
    """A file holds no POU, no global label and no structure type (e.g. an empty file)."""


@dataclass(frozen=True)
class DroppedValue:
    """An initial value written in the source that the target's label table cannot hold."""

    file: str
    line: int
    col: int
    owner: str          # the POU's name, or "global"
    label: str
    label_class: str
    value: str
    target: str

    def __str__(self) -> str:
        where = f"'{self.label}'" if self.owner == "global" else f"'{self.owner}.{self.label}'"
        return (f"{shown_name(self.file)}:{self.line}:{self.col}: note: {self.label_class} {where} := {self.value} "
                f"not exported: the {EDITOR[self.target]} label table has no initial value for it, "
                f"so it starts at 0; assign it in the program (first scan) - listed in {DROPPED_TABLE}")


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


def struct_table(rows: list[LabelRow], target: str) -> str:
    def cells(r: LabelRow) -> list[str]:
        if target == "gxworks2":
            return [r.name, r.data_type, r.comment]
        return [r.name, r.data_type, r.initial, r.comment]
    lines = ["\t".join(STRUCT_COLUMNS[target])]
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

    rank = {"STRUCT": -1, "FUNCTION": 0, "FUNCTION_BLOCK": 1, "PROGRAM": 2}
    for p in sorted(pous, key=lambda p: (rank.get(p.kind, 3), p.name.upper())):
        visit(p.name.upper(), ())
    return done


def dropped_initial_values(files: list[ast.SourceFile], target: str) -> list[DroppedValue]:
    """Every non-constant initial value in `files` that `target`'s label tables cannot carry."""
    carries = CARRIES_INITIAL[target]
    dropped = []
    for f in files:
        lines = text_lines(f.text)
        scopes = [(pou.name, pou.variables) for pou in f.pous]
        scopes += [("global", block.variables) for block in f.globals]
        scopes += [(struct.name, struct.fields) for struct in f.types]
        for owner, decls in scopes:
            for decl in decls:
                cls = label_class(decl)
                if decl.init is None or decl.constant or cls in carries:
                    continue
                dropped.append(DroppedValue(f.filename, decl.init.span.line, decl.init.span.col, owner,
                                            decl.name, cls, initial_text(f.text, lines, decl), target))
    return dropped


def _empty_files(files: list[ast.SourceFile]) -> list[ast.Diagnostic]:
    return [ast.Diagnostic(f.filename, 1, 1, "error",
                           "no POU (PROGRAM, FUNCTION_BLOCK or FUNCTION), global label or structure type "
                           "in this file: nothing to export")
            for f in files if not (f.pous or f.globals or f.types)]


def _pou_files(out: Path, pou) -> tuple[Path, Path]:
    """Where a POU's body and its label table go."""
    return out / f"{pou.name}.st", out / f"{pou.name}.labels.tsv"


def _struct_file(out: Path, struct) -> Path:
    return out / f"{struct.name}.struct.tsv"


def _overwritten_sources(files: list[ast.SourceFile], paths: dict[Path, ast.SourceFile],
                         out: Path) -> list[ast.Diagnostic]:
    """The sources (`paths`: every source file read, by path) the export of `files` would
    write over (`--out` is their own folder and a POU has the file's name): refused before
    anything is written, or the declarations are lost."""
    planned = [(f, pou, target) for f in files for pou in f.pous for target in _pou_files(out, pou)]
    planned += [(f, struct, _struct_file(out, struct)) for f in files for struct in f.types]
    planned += [(None, None, out / name) for name in (GLOBAL_TABLE, DROPPED_TABLE, IMPORT_ORDER)]
    sources = {real_path(path): f for path, f in paths.items()}
    problems = []
    for f, node, target in planned:
        source = sources.get(real_path(target))
        if source is None and target.exists():  # the same file by another name (a hard link)
            source = next((v for k, v in sources.items() if k.exists() and os.path.samefile(k, target)), None)
        if source is None:
            continue
        line, col = (node.span.line, node.span.col) if f is not None and source.filename == f.filename else (1, 1)
        problems.append(ast.Diagnostic(
            source.filename, line, col, "error",
            f"exporting into {out} would write {target.name} over this source file: choose another --out folder"))
    return problems


def _pous_named_like_the_export_files(files: list[ast.SourceFile], out: Path) -> list[ast.Diagnostic]:
    """POUs whose label table would be the global label table (a POU named GlobalLabels):
    one of the two would be written over the other, and the import guides tell to import
    that file as the global labels."""
    return [ast.Diagnostic(f.filename, pou.span.line, pou.span.col, "error",
                           f"a POU named {pou.name} would have its label table written to {GLOBAL_TABLE}, "
                           "the export's global label table: rename the POU")
            for f in files for pou in f.pous for table in _pou_files(out, pou)[1:]
            if table.name.lower() == GLOBAL_TABLE.lower()]


def _on_cpu(files: list[ast.SourceFile], cpu: CpuProfile, problems: list[ast.Diagnostic],
            programs: list[str] | None, warnings: list[ast.Diagnostic] | None) -> list[ast.Diagnostic]:
    """`problems` (the check's errors) as `uitamr check --platform` reports them on `cpu`,
    with the CPU's findings about the POUs to be written (`programs` and what they need,
    else all) in file, line and column order as the check lists them; the CPU's warnings
    go there too when anything refuses the export, else to `warnings`."""
    from verifier.sim.cpucheck import on_cpu  # the instruction tables: only with --platform

    if programs:  # a name no POU has is left out here, and refused below (UnknownProgram)
        keys = reach.needed(files, programs)
        files = [only(f, keys) for f in files]
    standing, found = on_cpu(files, cpu, problems)
    errors = standing + [d for d in found if d.is_error]
    cautions = [d for d in found if not d.is_error]
    if not errors:
        if warnings is not None:
            warnings.extend(cautions)
        return []
    order = {f.filename: i for i, f in enumerate(files)}
    return sorted(errors + cautions, key=lambda d: (order.get(d.file, len(order)), d.line, d.col))


def export_sources(paths: list[Path], target: str, out: Path, texts: dict[Path, str] | None = None,
                   notes: list[DroppedValue] | None = None, programs: list[str] | None = None,
                   cpu: CpuProfile | None = None, warnings: list[ast.Diagnostic] | None = None,
                   removed: list[Path] | None = None) -> list[Path]:
    """Parse and check `paths`, write the export into `out`; returns the files written.
    Raises ExportError (with file:line:col diagnostics) when a source has errors, and
    NothingToExport when a file has nothing in it to export. Initial values the target
    cannot carry are appended to `notes` (and written to DROPPED_INITIAL_VALUES.txt).
    With `programs` (POU names), only those POUs and what they need are written
    (`needed.needed`; UnknownProgram for a name the sources do not define); every file
    is still checked. With `cpu` (a CPU profile), what is written is also checked against
    that CPU as `uitamr check --platform` checks it (`_on_cpu`): its errors refuse the
    export like the check's, its warnings are appended to `warnings`. The files of an
    earlier export into `out` that this one does not write are removed (`_earlier_export`)
    and appended to `removed`."""
    if target not in COLUMNS:
        raise ValueError(f"unknown target {target!r}; expected gxworks2 or gxworks3")
    texts = texts or {}
    files = [st.parse(texts.get(p) or p.read_text(encoding="utf-8-sig"), str(p), target) for p in paths]
    problems = [d for f in files for d in f.diagnostics if d.is_error]
    problems += [d for d in st.check(files, target, cpu.name if cpu is not None else None) if d.is_error]
    if cpu is not None:
        problems = _on_cpu(files, cpu, problems, programs, warnings)
    if problems:
        raise ExportError(problems)
    empty = _empty_files(files)
    if empty:
        raise NothingToExport(empty)
    sources = dict(zip(paths, files))
    if programs:
        keys = needed(files, programs)
        files = [part for part in (only(f, keys) for f in files) if part.pous or part.types or part.globals]
    clashes = _overwritten_sources(files, sources, out) + _pous_named_like_the_export_files(files, out)
    if clashes:
        raise ExportError(clashes)
    known = {p.key for f in files for p in f.pous}
    structs = {t.key for f in files for t in f.types}
    exported: list[ExportedPou] = []
    earlier = _earlier_export(out)
    out.mkdir(parents=True, exist_ok=True)
    written: list[Path] = []
    for f in files:
        for pou in f.pous:
            body = body_text(pou, f.text)
            rows = label_rows(pou, f.text, target)
            body_path, table_path = _pou_files(out, pou)
            _write(body_path, body)
            _write(table_path, label_table(rows, target))
            written += [body_path, table_path]
            result = type_name(pou.return_type, target) if pou.return_type is not None else ""
            exported.append(ExportedPou(pou.name, pou.kind, f.filename, result, _uses(pou, body, known)))
    for f in files:
        for struct in f.types:
            path = _struct_file(out, struct)
            _write(path, struct_table(rows_of(struct.fields, f.text, target), target))
            written.append(path)
            members = {k for v in struct.fields for k in type_names(v.type) if k in structs}
            exported.append(ExportedPou(struct.name, "STRUCT", f.filename, uses=members - {struct.key}))
    global_rows = [row for f in files for block in f.globals for row in rows_of(block.variables, f.text, target)]
    if global_rows:
        path = out / GLOBAL_TABLE
        _write(path, global_table(global_rows, target))
        written.append(path)
    dropped = dropped_initial_values(files, target)
    stale = out / DROPPED_TABLE
    if dropped:
        _write(stale, "".join(str(d) + "\n" for d in dropped))
        written.append(stale)
    elif stale.exists():
        stale.unlink()                     # from an earlier export into the same folder
    if notes is not None:
        notes.extend(dropped)
    order = out / IMPORT_ORDER
    by_name = {p.name: p for p in exported}
    rows = [(name, by_name[name].kind, by_name[name].result) for name in import_order(exported)]
    _write(order, "".join("\t".join(filter(None, row)) + "\n" for row in rows))
    written.append(order)
    kept = {real_path(p) for p in written} | {real_path(p) for p in paths}
    for path in earlier:
        if real_path(path) not in kept:
            path.unlink()
            if removed is not None:
                removed.append(path)
    return written


def _earlier_export(out: Path) -> list[Path]:
    """The files an earlier export wrote into `out`, as its IMPORT_ORDER.txt lists them (and
    its global label table). Left behind by an export of fewer POUs or for the other editor,
    they sat beside the new files unlisted: a stale GlobalLabels.labels.tsv, which the import
    guides say to paste when it is there, or GX Works2 type names among GX Works3 tables."""
    try:
        lines = (out / IMPORT_ORDER).read_text(encoding="utf-8").splitlines()
    except (OSError, UnicodeDecodeError):
        return []
    names = [line.split("\t")[0].strip() for line in lines if line.strip()]
    files = [out / f"{name}{suffix}" for name in names if name and "/" not in name and "\\" not in name
             for suffix in (".st", ".labels.tsv", ".struct.tsv")]
    return [path for path in files + [out / GLOBAL_TABLE] if path.is_file()]


def _write(path: Path, text: str) -> None:
    """One file of the export, whole or not at all (a full disk left half a body behind)."""
    with whole_file(path, encoding="utf-8") as out:
        out.write(text)
