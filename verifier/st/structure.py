"""Whole-project rules the statement checker cannot see one POU at a time: recursion
(a function block holding an instance of itself, POUs calling each other in a circle)
and storage sizes the target cannot hold. Rules and sources: docs/st-dialect.md §6.

Everything here works on the `SymbolTable` after the declarations are resolved; calls
come as (caller key, callee key, Call node) edges collected while checking bodies.
"""
from __future__ import annotations

from dataclasses import dataclass

from verifier.st import ast
from verifier.st import types as T

#: Array bounds GX Works accepts: an index is -32768..32767 (MELSEC-Q/L/F Structured
#: Programming Manual (Fundamentals) §4.4.7, p.4-35).
INDEX_MIN, INDEX_MAX = -32768, 32767
#: The most storage one label, or one POU instance with everything it holds, may take.
#: ASSUMPTION (docs/st-dialect.md §6): 32768 words (64 KiB).
MAX_WORDS = 32768
_BITS_PER_WORD = 16
#: bits an instance of a standard FB (TON, CTU ...) takes: ASSUMPTION, a small fixed size
_STANDARD_FB_BITS = 4 * 32
#: GX Works' default STRING length when none is written: ASSUMPTION (32 characters)
DEFAULT_STRING_LENGTH = 32
#: label sections that refer to storage held elsewhere (not part of the instance)
_REFERENCES = ("VAR_IN_OUT", "VAR_EXTERNAL")


@dataclass
class Finding:
    node: ast.Node
    message: str


# ----------------------------------------------------------------------------- recursion
def _cycles(nodes: list[str], edges: dict[str, list[tuple[str, object]]]) -> list[list[str]]:
    """Strongly connected components that hold a cycle (more than one node, or a node
    with an edge to itself), each in `nodes` order; iterative Tarjan, no deep recursion."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    on_stack: set[str] = set()
    stack: list[str] = []
    found: list[list[str]] = []
    counter = 0
    for root in nodes:
        if root in index:
            continue
        work = [(root, 0)]
        while work:
            node, i = work.pop()
            if i == 0:
                index[node] = low[node] = counter
                counter += 1
                stack.append(node)
                on_stack.add(node)
            targets = [t for t, _ in edges.get(node, ())]
            if i < len(targets):
                work.append((node, i + 1))
                nxt = targets[i]
                if nxt not in index:
                    work.append((nxt, 0))
                elif nxt in on_stack:
                    low[node] = min(low[node], index[nxt])
                continue
            if low[node] == index[node]:
                component = []
                while True:
                    top = stack.pop()
                    on_stack.discard(top)
                    component.append(top)
                    if top == node:
                        break
                if len(component) > 1 or any(t == node for t, _ in edges.get(node, ())):
                    order = {n: k for k, n in enumerate(nodes)}
                    found.append(sorted(component, key=lambda n: order.get(n, len(order))))
            if work:
                parent = work[-1][0]
                low[parent] = min(low[parent], low[node])
    order = {n: k for k, n in enumerate(nodes)}
    return sorted(found, key=lambda c: order.get(c[0], len(order)))


def _path(component: list[str], edges: dict[str, list[tuple[str, object]]]) -> list[tuple[str, object]]:
    """A circle through the component's first node: [(node, edge taken from it), ...]."""
    members = set(component)
    start = component[0]
    # breadth-first from start's successors back to start, inside the component
    previous: dict[str, tuple[str, object]] = {}
    frontier = [start]
    seen = {start}
    while frontier:
        nxt_frontier = []
        for node in frontier:
            for target, label in edges.get(node, ()):
                if target not in members:
                    continue
                if target == start:
                    steps = [(node, label)]
                    while node != start:
                        node, label = previous[node]
                        steps.append((node, label))
                    return list(reversed(steps))
                if target not in seen:
                    seen.add(target)
                    previous[target] = (node, label)
                    nxt_frontier.append(target)
        frontier = nxt_frontier
    return [(start, None)]


def _contained(t: T.Type) -> T.Type:
    while isinstance(t, T.ArrayOf):
        t = t.element
    return t


def containment_edges(table) -> tuple[list[str], dict[str, list[tuple[str, object]]], dict[str, str]]:
    """Nodes (user FBs and structures), edges "holds an instance/member of" labelled by
    the declaring VarDecl, and each node's display name."""
    nodes: list[str] = []
    edges: dict[str, list[tuple[str, object]]] = {}
    names: dict[str, str] = {}
    for key, info in table.pous.items():
        if info.pou.kind != "FUNCTION_BLOCK":
            continue
        nodes.append(key)
        names[key] = info.pou.name
        for decl, t in info.labels.values():
            if decl.section in _REFERENCES:
                continue
            inner = _contained(t)
            if isinstance(inner, T.FbType) and not inner.standard and inner.name.upper() in table.pous:
                edges.setdefault(key, []).append((inner.name.upper(), decl))
            elif isinstance(inner, T.StructOf):
                edges.setdefault(key, []).append((inner.name.upper(), decl))
    for key, decl in table.struct_decls.items():
        nodes.append(key)
        names[key] = decl.name
        struct = table.structs.get(key)
        if struct is None:
            continue
        for field_decl, (_, t) in zip(decl.fields, struct.fields):
            inner = _contained(t)
            if isinstance(inner, T.StructOf):
                edges.setdefault(key, []).append((inner.name.upper(), field_decl))
            elif isinstance(inner, T.FbType) and not inner.standard:
                edges.setdefault(key, []).append((inner.name.upper(), field_decl))
    return nodes, edges, names


def recursive_types(table, graph=None) -> tuple[list[Finding], set[str]]:
    """A function block or structure that holds an instance of itself (directly or
    through others) has no finite size: one error per circle, at the label that starts
    it. Also returns the keys of every type on such a circle. `graph`: the table's
    `containment_edges`, when the caller has them."""
    nodes, edges, names = graph or containment_edges(table)
    findings: list[Finding] = []
    bad: set[str] = set()
    for component in _cycles(nodes, edges):
        bad.update(component)
        steps = _path(component, edges)
        first_decl = steps[0][1]
        chain = " -> ".join(f"{names[n]}.{d.name}" for n, d in steps) + f" -> {names[steps[0][0]]}"
        if steps[0][0] in table.pous:
            what = f"function block {names[steps[0][0]]} holds an instance of itself"
        else:
            what = f"structure {names[steps[0][0]]} contains itself"
        findings.append(Finding(first_decl, f"{what} ({chain}); GX Works does not allow recursion: "
                                            "a type cannot contain itself, directly or through others"))
    return findings, bad


def recursive_calls(table, calls: list[tuple[str, str, ast.Call]], skip: set[str]) -> list[Finding]:
    """POUs that call themselves, directly or through others: one error per circle, at
    the call that starts it. Circles through a type already reported by
    `recursive_types` are not reported twice."""
    edges: dict[str, list[tuple[str, object]]] = {}
    for caller, callee, call in calls:
        edges.setdefault(caller, []).append((callee, call))
    nodes = list(table.pous)
    findings = []
    for component in _cycles(nodes, edges):
        if skip.intersection(component):
            continue
        steps = _path(component, edges)
        names = {k: table.pous[k].pou.name for k in component}
        chain = " -> ".join(names[n] for n, _ in steps) + f" -> {names[steps[0][0]]}"
        start = names[steps[0][0]]
        findings.append(Finding(steps[0][1],
                                f"{start} calls itself ({chain}); GX Works does not allow recursive "
                                "calls: rewrite it with a FOR or WHILE loop"))
    return findings


# ----------------------------------------------------------------------------- storage
class Storage:
    """Bits each declared type takes, with user FBs and structures summed over their
    labels (memoised; types on a recursion circle count as 0, they are reported
    separately)."""

    def __init__(self, table, target: str, recursive: set[str]):
        self.table = table
        self.target = target
        self.recursive = recursive
        self._memo: dict[str, int] = {}

    def of_ref(self, ref: ast.TypeRef) -> int:
        if isinstance(ref, ast.StringType):
            length = ref.length if ref.length is not None else DEFAULT_STRING_LENGTH
            chars = (length + 1) * (2 if ref.wide else 1)
            return ((chars + 1) // 2) * _BITS_PER_WORD
        if isinstance(ref, ast.ArrayType):
            if not bounds_ok(ref):
                return 0  # the bound is reported where it is written
            count = 1
            for d in ref.dims:
                count *= max(d.high - d.low + 1, 0)
            return count * self.of_ref(ref.element)
        return self.of_named(ref.key)

    def of_named(self, key: str) -> int:
        if key in self.recursive:
            return 0
        if key in self._memo:
            return self._memo[key]
        elementary = T.ELEMENTARY_BY_TARGET[self.target].get(key)
        if elementary is not None:
            bits = 1 if elementary == T.BOOL else max(T.width(elementary), 16)
            self._memo[key] = bits
            return bits
        from verifier.st import library

        if key in library.STANDARD_FBS:
            return _STANDARD_FB_BITS
        self._memo[key] = 0  # guards against circles not yet reported
        decl = self.table.struct_decls.get(key)
        if decl is not None:
            bits = sum(self.of_ref(f.type) for f in decl.fields)
        elif key in self.table.pous:
            bits = self.of_pou(key)
        else:
            bits = 0
        self._memo[key] = bits
        return bits

    def of_pou(self, key: str) -> int:
        info = self.table.pous[key]
        total = 0
        for decl in info.pou.variables:
            total += 32 if decl.section in _REFERENCES else self.of_ref(decl.type)
        return total


def words(bits: int) -> int:
    return -(-bits // _BITS_PER_WORD)


def _post_order(nodes: list[str], edges: dict[str, list[tuple[str, object]]]) -> list[str]:
    """Every node after the nodes it holds (iterative depth-first walk)."""
    done: set[str] = set()
    order: list[str] = []
    for root in nodes:
        if root in done:
            continue
        done.add(root)
        work = [(root, iter(edges.get(root, ())))]
        while work:
            node, children = work[-1]
            for child, _ in children:
                if child not in done:
                    done.add(child)
                    work.append((child, iter(edges.get(child, ()))))
                    break
            else:
                work.pop()
                order.append(node)
    return order


def oversized(table, target: str, recursive: set[str], graph=None) -> list[Finding]:
    """Labels, and POU instances, that need more than MAX_WORDS words. `graph`: the
    table's `containment_edges`, when the caller has them."""
    storage = Storage(table, target, recursive)
    nodes, edges, _ = graph or containment_edges(table)
    for key in _post_order(nodes, edges):  # innermost types first: no deep recursion below
        storage.of_named(key)
    findings: list[Finding] = []
    for decl, _t in table.globals.values():
        _check_label(storage, decl, findings)
    for key, info in table.pous.items():
        for decl in info.pou.variables:
            if decl.section not in _REFERENCES:
                _check_label(storage, decl, findings)
        if key in recursive:
            continue
        size = words(storage.of_pou(key))
        if size > MAX_WORDS:
            findings.append(Finding(info.pou,
                                    f"{info.pou.kind} {info.pou.name} needs {size} words of labels; at most "
                                    f"{MAX_WORDS} words per POU instance (docs/st-dialect.md §6): "
                                    "split the data or use file registers (R/ZR devices)"))
    return findings


def bounds_ok(ref: ast.TypeRef) -> bool:
    """False when an array dimension lies outside the index range (reported on its own)."""
    while isinstance(ref, ast.ArrayType):
        if any(not (INDEX_MIN <= d.low <= INDEX_MAX and INDEX_MIN <= d.high <= INDEX_MAX) for d in ref.dims):
            return False
        ref = ref.element
    return True


def _check_label(storage: Storage, decl: ast.VarDecl, findings: list[Finding]) -> None:
    if not bounds_ok(decl.type):
        return
    size = words(storage.of_ref(decl.type))
    if size > MAX_WORDS:
        findings.append(Finding(decl,
                                f"label '{decl.name}' needs {size} words; at most {MAX_WORDS} words per label "
                                "(docs/st-dialect.md §6): make the array smaller"))
