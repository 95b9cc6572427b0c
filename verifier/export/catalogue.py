"""The "Catalogue of POUs" section of docs/plc-library.md, generated from the library's
declarations so the documentation cannot drift from the code.

    python -m verifier.export.catalogue            # print the section
    python -m verifier.export.catalogue --write    # replace it in docs/plc-library.md
"""
from __future__ import annotations

import sys
from pathlib import Path

from verifier import st
from verifier.export.labels import label_rows
from verifier.textfile import text_lines

ROOT = Path(__file__).resolve().parents[2]
DOC = ROOT / "docs" / "plc-library.md"
MARKER = "## Catalogue of POUs"
FOLDERS = ("core", "fx3", "fx5", "q", "examples/common", "examples/fx3", "examples/fx5", "examples/q")
INTERFACE = ("VAR_INPUT", "VAR_OUTPUT", "VAR_IN_OUT")


def _title(text: str, name: str) -> str:
    """The summary of the header comment: `NAME : summary`, with the lines that carry it on
    (up to a blank line or the header's ---- rule)."""
    lines = text_lines(text)
    for k, line in enumerate(lines):
        head, sep, rest = line.strip().partition(":")
        if sep and head.strip() == name:
            summary = [rest.strip()]
            for more in lines[k + 1:]:
                more = more.strip()
                if not more or more.startswith(("---", "===", "*)")):
                    break
                summary.append(more)
            return " ".join(summary)
    return ""


def catalogue(plc: Path = ROOT / "plc") -> str:
    out: list[str] = []
    for folder in FOLDERS:
        for path in sorted((plc / folder).glob("*.st")):
            text = path.read_text(encoding="utf-8")
            source = st.parse(text, str(path.relative_to(plc.parent)))
            for pou in source.pous:
                kind = pou.kind.replace("_", " ").lower()
                out.append(f"### {pou.name} ({kind}) — `{path.relative_to(plc.parent)}`\n")
                out.append(f"{_title(text, pou.name)}.\n")
                if pou.return_type is not None:
                    out.append(f"Result: `{pou.return_type.name}`.\n")
                rows = [r for r in label_rows(pou, text, "gxworks2") if r.label_class in INTERFACE]
                if rows:
                    out.append("| class | label | type | meaning |\n|---|---|---|---|")
                    out += [f"| {r.label_class} | `{r.name}` | {r.data_type} | {r.comment} |" for r in rows]
                    out.append("")
    return "\n".join(out) + "\n"


def documented_catalogue(doc: Path = DOC) -> str:
    text = doc.read_text(encoding="utf-8")
    _, _, rest = text.partition(MARKER)
    _, _, body = rest.partition("\n\n")          # skip the section's introduction
    _, _, body = body.partition("\n\n")
    return body


def write(doc: Path = DOC) -> None:
    text = doc.read_text(encoding="utf-8")
    head, _, rest = text.partition(MARKER)
    intro, _, _ = rest.partition("### ")
    doc.write_text(head + MARKER + intro + catalogue(), encoding="utf-8")


if __name__ == "__main__":  # pragma: no cover
    if "--write" in sys.argv:
        write()
    else:
        sys.stdout.write(catalogue())
