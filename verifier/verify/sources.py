"""Which ST files a name stands for: a file, a folder (its .st files, recursively — as
`uitamr check` and `uitamr export` read folders) or a glob pattern, relative or absolute."""
from __future__ import annotations

import glob
import os
from functools import lru_cache
from pathlib import Path

from verifier.textfile import file_kind, reached_path, real_path, shown_name

GLOB_CHARACTERS = "*?["
#: what a symbolic link whose target is missing is, in every command's message naming it
DANGLING_LINK = "is a symbolic link to nothing (its target is missing, or a loop of links)"


class SourceError(ValueError):
    """A name that stands for no ST file; the message says why."""


def expand(name: str, base: Path) -> list[Path]:
    """The .st files `name` stands for, relative to `base` unless absolute, sorted. A name
    with glob characters that is also an existing path ("[A]/x.st") is that path."""
    try:
        return _expand(name, base)
    except OSError as exc:  # a name too long for the file system, a folder that cannot be read ...
        raise SourceError(f"{shown_name(str(exc.filename or name))}: {exc.strerror or exc}") from None


def is_pattern(name: str, literal: Path | None = None) -> bool:
    """`name` has glob characters and is no existing path (`literal`, the path it names
    where that is not `name` itself): "[A]/x.st" that exists is that file, not a pattern."""
    return any(ch in name for ch in GLOB_CHARACTERS) and not (Path(name) if literal is None else literal).exists()


def pattern_matches(pattern: str) -> list[Path]:
    """The files and folders a glob pattern matches, sorted (`**` at any depth)."""
    return sorted(Path(p) for p in glob.glob(pattern, recursive=True))


def pattern_files(pattern: str) -> list[Path]:
    """The files a glob pattern stands for: the files it matches, and the .st files of
    the folders it matches (`st_files_in`)."""
    return [f for match in pattern_matches(pattern) for f in (st_files_in(match) if match.is_dir() else [match])]


def _expand(name: str, base: Path) -> list[Path]:
    literal = Path(name) if Path(name).is_absolute() else base / name
    if is_pattern(name, literal):
        files = pattern_files(name if Path(name).is_absolute() else str(base / name))
        if not files:
            where = "" if Path(name).is_absolute() else f" (relative to {base})"
            raise SourceError(f"{name!r} matches no file{where}")
        return files
    path = literal
    if path.is_dir():
        files = st_files_in(path)
        if not files:
            raise SourceError(f"the folder {shown_name(str(path))} holds no .st file")
        return files
    if not path.is_file():
        if path.exists():
            raise SourceError(f"{shown_name(str(path))} is not a regular file ({file_kind(path.stat().st_mode)}); give .st files")
        if path.is_symlink():
            raise SourceError(f"{shown_name(str(path))} {DANGLING_LINK}")
        raise SourceError(f"no such file or folder: {shown_name(str(path))}")
    return [path]


def st_files_in(path: Path) -> list[Path]:
    """The .st files below the folder `path`, recursively: `.ST` too (as Windows tools may
    name them), and never a folder whose name ends in .st."""
    return sorted(p for p in files_below(path) if p.suffix.lower() == ".st")


def files_below(folder: Path) -> list[Path]:
    """The regular files below `folder`, recursively, as `folder.rglob("*")` finds them
    (symlinked folders not entered, a folder that cannot be read passed over), and also
    passing over a folder that vanishes between being listed and being read: `rglob` stopped
    the walk there ("/proc/10441: No such file or directory" ended `uitamr check /`, exit 2),
    though what vanished was no file of the user's."""
    def skipped(exc: OSError) -> None:
        if not isinstance(exc, (FileNotFoundError, NotADirectoryError, PermissionError)):
            raise exc

    found = []
    for top, _, names in os.walk(folder, onerror=skipped):
        found += [p for name in names if _is_file(p := Path(top, name))]
    return found


def _is_file(path: Path) -> bool:
    """`path.is_file()`, False where even asking is refused (/proc/1/cwd: permission denied)."""
    try:
        return path.is_file()
    except OSError:
        return False


def unique(paths: list[Path]) -> tuple[Path, ...]:
    """Each file once (named twice, through a folder, a symlink or `..`, it is one: the same
    real path), in first-seen order, by the path it was first named by, made absolute but
    not resolved: an ST file's path is where its diagnostics and the frames it sends say
    they come from, and reports show it as the user reached it (a toolkit vendored by a
    symlink as vendor/uitamr/plc/..., textfile.shown_path), not where the link leads."""
    first: dict[Path, Path] = {}
    cwd = os.getcwd()
    for p in paths:
        reached = _reached(p, cwd)
        first.setdefault(_resolved(reached), reached)
    return tuple(first.values())


@lru_cache(maxsize=4096)
def _reached(path: Path, cwd: str) -> Path:
    """`textfile.reached_path`, remembered as `_resolved` is."""
    return reached_path(path, cwd)


@lru_cache(maxsize=4096)
def _resolved(path: Path) -> Path:
    """`path.resolve()`, remembered: the bundled scenarios name the same 30-odd files
    again and again, and resolving one walks every folder above it."""
    return real_path(path)
