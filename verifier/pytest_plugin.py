"""pytest plugin for unit tests of GX Works ST (registered as the `verifier` pytest11
entry point; see docs/testing-st.md).

Fixtures:
- `st_load(*paths, **options)`: `verifier.load` for this test (target, cpu, scan_ms ...).
- `st_project`: a project loaded from the test's `@pytest.mark.st(...)` paths/options.

When a test fails, the report gets an "ST state" section: every FB/PROGRAM instance the
test handed out, with its labels' values and where they are declared (file:line:col),
the simulator's diagnostics (operation errors with their ST location) and the virtual
time — so a failing `assert fb.o_bDone` shows what the ST was doing and where.
"""
from __future__ import annotations

import sys
from pathlib import Path

import pytest


def pytest_configure(config):
    config.addinivalue_line("markers", "st(*paths, **options): ST sources for the st_project fixture")


def pytest_runtest_setup(item):
    # only if a test already loaded the simulator: other test suites do not pay for it
    project_module = sys.modules.get("verifier.sim.project")
    if project_module is not None:
        project_module.forget_projects()  # the failure report shows this test's projects only


@pytest.fixture
def st_load(request):
    import verifier

    loaded = []

    def load(*paths, **options):
        project = verifier.load(*paths, **options)
        loaded.append(project)
        return project

    request.node._st_projects = loaded
    return load


@pytest.fixture
def st_project(request, st_load):
    marker = request.node.get_closest_marker("st")
    if marker is None:
        # the test's mistake, not the plugin's: its place and what to write, no traceback of the plugin
        fspath, lineno, name = request.node.location
        pytest.fail(f"{fspath}:{(lineno or 0) + 1}: {name} uses the st_project fixture but has no "
                    "@pytest.mark.st('file.st', ..., target=...) naming the ST to load; add one, or use "
                    "st_load('file.st') in the test", pytrace=False)
    return st_load(*marker.args, **marker.kwargs)


def describe_project(project) -> str:
    lines = [f"virtual time {project.now_us / 1e6:.6f} s after {project.scan_count} scans "
             f"({project.cpu.name})"]
    for inst in project.touched:
        lines.append(f"{inst._label}:")
        symbols = inst._symbols()
        for sym in symbols.values():
            try:
                value = getattr(inst, sym.name)
            except Exception as e:  # a label the proxy cannot show: say why
                value = f"<{e}>"
            if hasattr(value, "_symbols") and not hasattr(value, "__len__"):
                # a TON's IN/PT/Q/ET and a structure's members in one line; an instance
                # of a user FB (maybe large) by name: the test can create or read it
                if not getattr(sym.type, "standard", True):
                    value = "<instance>"
            elif hasattr(value, "__iter__") and not isinstance(value, str):
                value = list(value)
            where = f"  ({sym.decl.span})" if sym.decl is not None else ""
            lines.append(f"    {sym.name} = {value!r}{where}")
    for d in project.diagnostics[-20:]:
        lines.append(f"diagnostic: {d}")
    return "\n".join(lines)


def _load_error_report(item, excinfo) -> str | None:
    """ST that does not load (a syntax error, a file named wrong) is the test's input, not a
    fault of the toolkit: the report is the user's own lines that led to it (the test's, a
    helper's, a conftest fixture's) and the LoadError's file:line:col message, not the
    frames inside the plugin, the simulator's loader and pytest. None for any other failure,
    and when the run asks for whole tracebacks (--full-trace, --tb=long or native): pytest's
    report as usual."""
    errors = sys.modules.get("verifier.sim.errors")
    if excinfo is None or errors is None or not excinfo.errisinstance(errors.LoadError):
        return None
    config = item.config
    if config.getoption("fulltrace", False) or config.getoption("tbstyle", "auto") in ("long", "native"):
        return None
    import _pytest
    import pluggy

    theirs = [Path(module.__file__).resolve().parent for module in (sys.modules["verifier"], _pytest, pluggy)]
    lines = [f"{entry.path}:{entry.lineno + 1}: {str(entry.statement).strip()}"
             for entry in excinfo.traceback
             if not any(folder in Path(str(entry.path)).resolve().parents for folder in theirs)]
    if not lines and item.get_closest_marker("st") is not None:
        lines = [_st_mark_line(item)]  # the st_project fixture loaded it: the files were named there
    # the error first: pytest's short summary quotes the report's first line
    return "\n".join([f"E   {line}" for line in excinfo.exconly().splitlines()] + lines)


def _st_mark_line(item) -> str:
    """Where the test's `@pytest.mark.st(...)` names the files st_project loaded: the
    decorator's line, else (a mark on the class or module) the test's own."""
    import inspect

    function = getattr(item, "function", None)
    try:
        source, first = inspect.getsourcelines(function)
        path = inspect.getsourcefile(function)
    except (TypeError, OSError):
        source, first, path = [], 0, None
    for number, text in enumerate(source, first):
        if "mark.st(" in text:
            return f"{path}:{number}: {text.strip()}"
        if text.lstrip().startswith("def "):
            break
    fspath, lineno, name = item.location
    return f"{fspath}:{(lineno or 0) + 1}: {name}"


@pytest.hookimpl(hookwrapper=True)
def pytest_runtest_makereport(item, call):
    outcome = yield
    report = outcome.get_result()
    if report.failed:
        load_error = _load_error_report(item, call.excinfo)
        if load_error is not None:
            report.longrepr = load_error
    if report.when != "call" or not report.failed:
        return
    projects = list(getattr(item, "_st_projects", []))
    project_module = sys.modules.get("verifier.sim.project")
    if not projects and project_module is not None:
        projects = [p for p in project_module.live_projects() if p.touched]
    sections = [(f"ST state {i + 1}", describe_project(project)) for i, project in enumerate(projects[-3:])]
    err = getattr(call.excinfo, "value", None) if call.excinfo else None
    location = getattr(err, "location", None)
    if location:
        sections.append(("ST location", f"{location}: {getattr(err, 'message', err)}"))
    add = getattr(report.longrepr, "addsection", None)
    for name, text in sections:
        # in the failure's own text: what --junitxml writes into <failure> (a CI server shows
        # it); report.sections reach only the terminal. The terminal shows them alike.
        if add is not None:
            add(name, text)
        else:
            report.sections.append((name, text))
