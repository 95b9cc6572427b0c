"""Paste-ready GX Works material from ST files: per POU, the ST body for the editor and a
label table (class, name, data type in the editor's own words, constant, comment).

    from verifier.export import export_sources
    written = export_sources([Path("plc/core/UITAMR_Engine.st")], "gxworks2", Path("out"))

`labels` turns declarations into label rows, `types` names data types the way each
editor does, `body` cuts the body text out of a file, `writer` writes the files.
docs/import-gxworks2.md and docs/import-gxworks3.md say what to do with them.
"""
from verifier.export.writer import (
    DroppedValue, ExportError, NothingToExport, dropped_initial_values, export_sources,
)

__all__ = ["DroppedValue", "ExportError", "NothingToExport", "dropped_initial_values", "export_sources"]
