"""Conditions over PLC variables, written the way an ST programmer would write them.

    o_bOK
    o_bErr AND o_uErrId = 16#0101
    NOT fbRobot.o_bBusy OR (o_uState >= 3 AND o_uState <> 7)

Names are label paths into the program instance (`fbRobot.o_bBusy`, `wBuf[2]`); literals
are TRUE/FALSE, decimal and 2#/8#/16# integers (with `_` separators), decimals and
TIME literals (`T#1s`, `TIME#500ms`: their value in ms, as a TIME label reads).
Comparison operators: = <> < <= > >=; logic: NOT, AND (or &), OR, XOR; parentheses.
Parsing is strict and errors carry the column, so a scenario file's message can point at
the character that is wrong.
"""
from __future__ import annotations

import re
from dataclasses import dataclass
from typing import Callable, Mapping

from verifier.digits import describe, foreign_digit
from verifier.st.errors import TIME_LITERAL, TIME_LITERAL_HINT, bare_time, spaced_time_literal
from verifier.st.parser import time_literal_ms

Value = bool | int | float


class ConditionError(ValueError):
    def __init__(self, message: str, column: int):
        super().__init__(message)
        self.message = message
        self.column = column  # 1-based


_TOKEN = re.compile(
    r"""
    (?P<space>\s+)
  | (?P<time>(?i:""" + TIME_LITERAL + r""")(?![A-Za-z0-9_.\#]))
  | (?P<number>(?:2|8|16)\#[0-9A-Fa-f_]+|[0-9][0-9_]*(?:\.[0-9]+)?)
  | (?P<name>[A-Za-z_][A-Za-z0-9_]*(?:\[[0-9]+\])*(?:\.[A-Za-z_][A-Za-z0-9_]*(?:\[[0-9]+\])*)*)
  | (?P<op><>|<=|>=|=|<|>|&|\(|\)|-)
    """,
    re.VERBOSE,
)

_KEYWORDS = {"AND", "OR", "XOR", "NOT", "TRUE", "FALSE"}
#: the start of a TIME literal, with whatever follows it in the word (for its error)
_TIME_PREFIX = re.compile(r"(?:TIME|T)#[-0-9A-Za-z_.]*", re.IGNORECASE)


@dataclass(frozen=True)
class _Token:
    kind: str  # number, name, op, keyword, end
    text: str
    column: int


_C_NUMBER = re.compile(r"0([xXbB])([0-9A-Fa-f_]+)")
_C_OPERATORS = {"==": "=", "!=": "<>", "&&": "AND", "||": "OR", "!": "NOT"}


def _c_notation(text: str, position: int) -> None:
    """C's spelling of a number or an operator at `position`: said with the ST one."""
    number = _C_NUMBER.match(text, position)
    if number and (position == 0 or not (text[position - 1].isalnum() or text[position - 1] in "_#")):
        base = "16" if number.group(1) in "xX" else "2"
        raise ConditionError(f"{number.group()!r} is C notation: write {base}#{number.group(2)}", position + 1)
    for c_op, st_op in _C_OPERATORS.items():
        if text.startswith(c_op, position):
            raise ConditionError(f"{c_op!r} is C notation: write {st_op!r}", position + 1)


def _tokenize(text: str) -> list[_Token]:
    tokens: list[_Token] = []
    foreign = foreign_digit(text)  # '٣' in a number or an index: the message says what it is
    if foreign is not None:
        raise ConditionError(describe(text[foreign]), foreign + 1)
    for index in range(len(text)):
        _c_notation(text, index)
    spaced = spaced_time_literal(text)  # T#1h 30m: "unexpected '30'"
    if spaced is not None:
        raise ConditionError(spaced[1], spaced[0] + 1)
    position = 0
    while position < len(text):
        match = _TOKEN.match(text, position)
        if not match or match.lastgroup == "name" and text.startswith("#", match.end()):
            literal = _TIME_PREFIX.match(text, position)
            if literal:  # T#2sec, T#500: the whole word, as the ST checker names it
                raise ConditionError(f"{literal.group()!r} is not a TIME literal: {TIME_LITERAL_HINT}", position + 1)
        if not match:
            raise ConditionError(f"unexpected character {text[position]!r}", position + 1)
        kind = match.lastgroup
        unit_at = len(text) - len(text[match.end():].lstrip(" \t"))  # 500ms, and 2 s
        if kind == "number" and text[unit_at:unit_at + 1].isalpha():
            bare = bare_time(text, unit_at)  # a scenario's duration, not a TIME literal
            if bare is not None:
                raise ConditionError(bare[1], bare[0] + 1)
        if kind != "space":
            word = match.group()
            if kind == "name" and word.upper() in _KEYWORDS:
                tokens.append(_Token("keyword", word.upper(), position + 1))
            else:
                tokens.append(_Token(kind, word, position + 1))
        position = match.end()
    tokens.append(_Token("end", "", len(text) + 1))
    return tokens


def _number(token: _Token) -> Value:
    digits = token.text.replace("_", "")
    # int() reads no more than 4300 digits, a float of 310 is infinite (a TIME literal's value
    # would be an OverflowError); no label holds even 100
    size = sum(c.isdigit() for c in digits) if token.kind == "time" else len(digits)
    if size > 100:
        raise ConditionError(f"a number of {size} digits: no PLC label holds one this long", token.column)
    if token.kind == "time":  # T#1s: a TIME label's value, in ms
        return time_literal_ms(token.text)
    try:
        if "#" in digits:
            base, body = digits.split("#", 1)
            return int(body, int(base))
        if "." in digits:
            return float(digits)
        return int(digits)
    except ValueError:
        raise ConditionError(f"{token.text!r} is not a number", token.column) from None


# The parsed form: nested tuples, evaluated by `_evaluate`.
#   ("lit", value) | ("var", name) | ("not", node) | ("neg", node)
#   ("and"|"or"|"xor", left, right) | ("cmp", op, left, right)


MAX_NESTING = 50  # parentheses, NOT and unary minus inside one another
MAX_DEPTH = 200  # the tree: nesting plus chained AND/OR/XOR (evaluated recursively)


class _Parser:
    def __init__(self, text: str):
        self.tokens = _tokenize(text)
        self.index = 0
        self.nesting = 0

    def nest(self, token: _Token) -> None:
        self.nesting += 1
        if self.nesting > MAX_NESTING:
            raise ConditionError(f"nested too deeply (more than {MAX_NESTING} levels of parentheses, NOT or "
                                 "minus signs inside one another)", token.column)

    @property
    def current(self) -> _Token:
        return self.tokens[self.index]

    def take(self) -> _Token:
        token = self.tokens[self.index]
        self.index += 1
        return token

    def parse(self):
        if self.current.kind == "end":
            raise ConditionError("the condition is empty", 1)
        node = self.logic()
        if self.current.kind != "end":
            raise ConditionError(f"unexpected {self.current.text!r}", self.current.column)
        if _depth(node) > MAX_DEPTH:
            raise ConditionError(f"too long: more than {MAX_DEPTH} operators one inside the other; "
                                 "split it into several expectations", 1)
        return node

    def logic(self, level: int = 0):
        operators = (("OR",), ("XOR",), ("AND", "&"))
        if level == len(operators):
            return self.negation()
        node = self.logic(level + 1)
        while self.current.text.upper() in operators[level] and self.current.kind in ("keyword", "op"):
            name = self.take().text.upper()
            node = ({"&": "and"}.get(name, name.lower()), node, self.logic(level + 1))
        return node

    def negation(self):
        if self.current.kind == "keyword" and self.current.text == "NOT":
            self.nest(self.take())
            node = ("not", self.negation())
            self.nesting -= 1
            return node
        return self.comparison()

    def comparison(self):
        left = self.operand()
        if self.current.kind == "op" and self.current.text in ("=", "<>", "<", "<=", ">", ">="):
            op = self.take().text
            right = self.operand()
            if self.current.kind == "op" and self.current.text in ("=", "<>", "<", "<=", ">", ">="):
                raise ConditionError(
                    "comparisons do not chain; join them with AND", self.current.column
                )
            return ("cmp", op, left, right)
        return left

    def operand(self):
        token = self.take()
        if token.kind in ("number", "time"):
            return ("lit", _number(token))
        if token.kind == "keyword" and token.text in ("TRUE", "FALSE"):
            return ("lit", token.text == "TRUE")
        if token.kind == "name":
            return ("var", token.text)
        if token.kind == "op" and token.text == "-":
            self.nest(token)
            node = ("neg", self.operand())
            self.nesting -= 1
            return node
        if token.kind == "op" and token.text == "(":
            self.nest(token)
            node = self.logic()
            closing = self.take()
            if closing.text != ")":
                raise ConditionError("missing ')'", closing.column)
            self.nesting -= 1
            return node
        found = "the end of the condition" if token.kind == "end" else repr(token.text)
        raise ConditionError(f"expected a label, a value or '(', found {found}", token.column)


def _depth(node) -> int:
    """How deep the tree goes (worked out without recursion: it may be very deep)."""
    deepest, stack = 0, [(node, 1)]
    while stack:
        item, level = stack.pop()
        deepest = max(deepest, level)
        stack += [(child, level + 1) for child in item[1:] if isinstance(child, tuple)]
    return deepest


def _names(node) -> set[str]:
    kind = node[0]
    if kind == "var":
        return {node[1]}
    if kind == "lit":
        return set()
    return set().union(*(_names(child) for child in node[1:] if isinstance(child, tuple)))


_COMPARE: dict[str, Callable[[Value, Value], bool]] = {
    "=": lambda a, b: a == b,
    "<>": lambda a, b: a != b,
    "<": lambda a, b: a < b,
    "<=": lambda a, b: a <= b,
    ">": lambda a, b: a > b,
    ">=": lambda a, b: a >= b,
}


def _evaluate(node, values: Mapping[str, Value]) -> Value:
    kind = node[0]
    if kind == "lit":
        return node[1]
    if kind == "var":
        return values[node[1]]
    if kind == "not":
        return not _evaluate(node[1], values)
    if kind == "neg":
        return -_evaluate(node[1], values)
    if kind == "cmp":
        return _COMPARE[node[1]](_evaluate(node[2], values), _evaluate(node[3], values))
    left = bool(_evaluate(node[1], values))
    right = bool(_evaluate(node[2], values))
    return {"and": left and right, "or": left or right, "xor": left != right}[kind]


#: A condition of BOOLs over at most this many labels is tried on every combination of their
#: values (2**10 = 1024 evaluations); over more, whether it can change is not decided.
MAX_LABELS_DECIDED = 10


def _bools_only(node) -> bool:
    """Whether `node` is BOOL-valued by its shape alone, each label in it a BOOL: a label,
    TRUE/FALSE, NOT/AND/OR/XOR of such, or = / <> of two such of which one at least is not
    a bare label (`a = b` may compare two numbers; `a = TRUE`, `(a AND b) <> c` cannot)."""
    tag = node[0]
    if tag == "lit":
        return isinstance(node[1], bool)
    if tag == "var":
        return True
    if tag in ("not", "and", "or", "xor"):
        return all(_bools_only(child) for child in node[1:])
    if tag == "cmp":
        op, left, right = node[1:]
        return (op in ("=", "<>") and _bools_only(left) and _bools_only(right)
                and not (left[0] == "var" and right[0] == "var"))
    return False  # a number or a minus sign: the labels may be numbers


class _TypeProblem(Exception):
    pass


def _shown(node) -> str:
    if node[0] == "var":
        return node[1]
    if node[0] == "lit":
        return ("TRUE" if node[1] else "FALSE") if isinstance(node[1], bool) else str(node[1])
    return "the expression"


def _kind(node, kinds: Mapping[str, str]) -> str:
    """"bool" or "number" for a node; _TypeProblem when its parts do not fit together."""
    tag = node[0]
    if tag == "lit":
        return "bool" if isinstance(node[1], bool) else "number"
    if tag == "var":
        kind = kinds[node[1]]
        if kind not in ("bool", "number"):  # a STRING: compared with a number it stopped the run
            raise _TypeProblem(f"{node[1]} is a {kind}: a condition reads BOOL and number labels only")
        return kind
    if tag == "not":
        if _kind(node[1], kinds) != "bool":
            raise _TypeProblem(f"NOT needs a BOOL, but {_shown(node[1])} is a number")
        return "bool"
    if tag == "neg":
        if _kind(node[1], kinds) != "number":
            raise _TypeProblem(f"'-' needs a number, but {_shown(node[1])} is a BOOL")
        return "number"
    if tag == "cmp":
        op, left, right = node[1:]
        sides = _kind(left, kinds), _kind(right, kinds)
        if sides[0] != sides[1]:
            which = left if sides[0] == "bool" else right
            other = right if which is left else left
            raise _TypeProblem(
                f"{_shown(which)} is a BOOL and {_shown(other)} a number: compare a BOOL with TRUE or FALSE"
            )
        if sides[0] == "bool" and op not in ("=", "<>"):
            raise _TypeProblem(f"BOOLs are compared with = or <> only, not {op}")
        return "bool"
    word = tag.upper()
    for side in node[1:]:
        if _kind(side, kinds) != "bool":
            raise _TypeProblem(
                f"{word} joins BOOLs, but {_shown(side)} is a number: compare it, e.g. {_shown(side)} <> 0"
            )
    return "bool"


@dataclass(frozen=True)
class Condition:
    """A parsed condition: `names` are the labels it reads, `holds(values)` evaluates it."""

    text: str
    tree: tuple

    @property
    def names(self) -> frozenset[str]:
        return frozenset(_names(self.tree))

    def name_columns(self) -> dict[str, int]:
        """The 1-based column in `text` where each label first stands, as the tokenizer
        read it (for pointing at a label in the scenario file)."""
        columns: dict[str, int] = {}
        for token in _tokenize(self.text):
            if token.kind == "name":
                columns.setdefault(token.text, token.column)
        return columns

    def holds(self, values: Mapping[str, Value]) -> bool:
        return bool(_evaluate(self.tree, values))

    def constant_value(self) -> bool | None:
        """TRUE or FALSE when the condition has that value whatever the values of the labels
        it reads (`Y7 AND NOT Y7`, `X0 OR NOT X0`), else None. Decided exactly, by trying
        every combination, for a condition of BOOLs only over at most MAX_LABELS_DECIDED
        labels; for any other (numbers, or more labels) None: not decided, not guessed."""
        labels = sorted({name.upper() for name in self.names})  # ST: y7 is Y7
        if not labels or len(labels) > MAX_LABELS_DECIDED or not _bools_only(self.tree):
            return None
        seen: set[bool] = set()
        for k in range(2 ** len(labels)):
            value = {label: bool(k >> i & 1) for i, label in enumerate(labels)}
            seen.add(bool(_evaluate(self.tree, {name: value[name.upper()] for name in self.names})))
            if len(seen) == 2:
                return None
        return seen.pop()

    def type_error(self, kinds: Mapping[str, str]) -> str | None:
        """Why the condition does not type-check, given each label's kind ("bool",
        "number", or the name of a type a condition cannot read, e.g. "STRING"), or None.
        A condition must be BOOL; AND/OR/XOR/NOT join BOOLs; a comparison compares two
        numbers, or two BOOLs with = and <>."""
        try:
            kind = _kind(self.tree, kinds)
        except _TypeProblem as problem:
            return str(problem)
        if kind != "bool":
            return f"{_shown(self.tree)} is a number, not a condition: compare it, e.g. {_shown(self.tree)} <> 0"
        return None

    def __str__(self) -> str:
        return self.text


def unchanging(condition: Condition, name_labels: str) -> str | None:
    """Why `condition` is refused: it reads no label (`that = "TRUE"`; `name_labels` says
    what to name instead), or it has one value whatever theirs (Condition.constant_value).
    Either way it is the same at every moment, so it always passes or can never pass. None
    when it can change (or when that is not decided)."""
    if not condition.names:
        return (f"'{condition}' reads no label: it is the same at every moment and says nothing about the "
                f"program; {name_labels}")
    value = condition.constant_value()
    if value is None:
        return None
    names = sorted({name.upper(): name for name in sorted(condition.names)}.values())
    which = (f"whichever value {names[0]} takes" if len(names) == 1
             else f"whichever values {', '.join(names)} take")
    return (f"'{condition}' is {'TRUE' if value else 'FALSE'} {which}: it is the same at every moment and says "
            "nothing about the program; write what the program's labels must show")


def parse_condition(text: str) -> Condition:
    if not isinstance(text, str):
        raise ConditionError(f"expected a condition as a string, got {text!r}", 1)
    return Condition(text, _Parser(text).parse())
