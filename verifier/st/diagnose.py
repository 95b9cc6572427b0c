"""Explain a syntax error by what is still open where it happens.

The LALR parser stops at the first token it cannot take, and all it knows then is the set
of tokens it would have taken. For a block left open that set is misleading: an `IF`
never closed before `END_FUNCTION_BLOCK`, a `VAR` section never closed before the first
statement (GX Works' keywords turn into names there, so the parser complains about a
missing ':'). This module walks the tokens before the error, keeps the stack of open
constructs with the place each one opened (POUs, TYPE/STRUCT, VAR sections, IF, CASE,
FOR, WHILE, REPEAT, parentheses and brackets), and words the error after the innermost
one: "IF opened at 6:1 is not closed: expected END_IF before END_FUNCTION_BLOCK".

It runs only after a failed parse (the success path never comes here) and reads the
text with the full keyword lexer, so a keyword is a keyword wherever it stands.
`explain` returns None when the open constructs say nothing about the error; the caller
then describes it from the parser's expected tokens (verifier/st/errors.py).
"""
from __future__ import annotations

from dataclasses import dataclass

from lark import Lark, Token
from lark.exceptions import UnexpectedInput, UnexpectedToken

from verifier.textfile import place_of_char

#: block keyword -> the keyword that closes it
BLOCK_CLOSER = {
    "IF": "END_IF", "CASE": "END_CASE", "FOR": "END_FOR", "WHILE": "END_WHILE",
    "REPEAT": "END_REPEAT",
}
POU_CLOSER = {
    "FUNCTION_BLOCK": "END_FUNCTION_BLOCK", "FUNCTION": "END_FUNCTION", "PROGRAM": "END_PROGRAM",
}
TYPE_CLOSER = {"TYPE": "END_TYPE", "STRUCT": "END_STRUCT"}
VAR_SECTIONS = ("VAR", "VAR_INPUT", "VAR_OUTPUT", "VAR_IN_OUT", "VAR_TEMP", "VAR_GLOBAL",
                "VAR_EXTERNAL", "VAR_CONSTANT", "VAR_RETAIN", "VAR_GLOBAL_CONSTANT",
                "VAR_GLOBAL_RETAIN", "VAR_OUTPUT_RETAIN", "VAR_PUBLIC", "VAR_PUBLIC_RETAIN")
BRACKET_CLOSER = {"LPAR": "RPAR", "LSQB": "RSQB"}
BRACKET_TEXT = {"LPAR": "'('", "RPAR": "')'", "LSQB": "'['", "RSQB": "']'"}

CLOSER = {**BLOCK_CLOSER, **POU_CLOSER, **TYPE_CLOSER, **{v: "END_VAR" for v in VAR_SECTIONS},
          **BRACKET_CLOSER}
OPENER_OF = {}
for _opener, _closer in CLOSER.items():
    OPENER_OF.setdefault(_closer, _opener)
OPENER_OF["END_VAR"] = "VAR"

#: the keyword that must follow the head of a block (IF cond THEN, WHILE cond DO, ...)
HEAD_END = {"IF": "THEN", "ELSIF": "THEN", "WHILE": "DO", "CASE": "OF"}

#: tokens that start or end statements: inside a VAR section they show the section was
#: never closed; inside parentheses they show a ')' is missing
STATEMENT_WORDS = frozenset({
    "IF", "THEN", "ELSIF", "ELSE", "CASE", "OF", "FOR", "TO", "BY", "DO", "WHILE", "REPEAT",
    "UNTIL", "EXIT", "RETURN", *BLOCK_CLOSER.values(), *POU_CLOSER, *POU_CLOSER.values(),
    "TYPE", "END_TYPE", *VAR_SECTIONS,
})
KEYWORD_TOKENS = STATEMENT_WORDS | {"END_VAR", "END_STRUCT", "STRUCT"}
NOT_IN_BRACKETS = STATEMENT_WORDS | {"SEMI", "END_VAR", "END_STRUCT"}


@dataclass
class Open:
    """A construct that is open at the error: its keyword token and, for a block, the
    token of its current head (the IF or the latest ELSIF)."""

    token: Token
    name: str = ""  # the POU's name
    head: Token | None = None
    has_until: bool = False
    else_token: Token | None = None  # the ELSE of an IF or CASE, once read
    body_started: bool = False  # a POU: its first statement has been read
    late_section: Token | None = None  # a POU: a VAR section that came after its first statement

    @property
    def kind(self) -> str:
        return self.token.type

    @property
    def closer(self) -> str:
        return CLOSER[self.kind]

    def describe(self) -> str:
        what = BRACKET_TEXT.get(self.kind, self.kind)
        if self.name:
            what += f" {self.name}"
        return f"{what} opened at {self.token.line}:{self.token.column}"


_keyword_parsers: dict[int, Lark] = {}


def keyword_parser(parser: Lark) -> Lark:
    """The same grammar read with the plain lexer, where a keyword is always a keyword.
    The toolkit's parser uses lark's contextual lexer, which reads a keyword as a name
    where no keyword fits (`END_REPEAT` with no UNTIL before it becomes a statement's
    first name); the plain one stops at the keyword itself. Built on the first error."""
    found = _keyword_parsers.get(id(parser))
    if found is None:
        found = Lark(parser.source_grammar, parser="lalr", lexer="basic", keep_all_tokens=True,
                     maybe_placeholders=False, cache=True)
        _keyword_parsers[id(parser)] = found
    return found


def earlier_keyword_error(parser: Lark, text: str, pos: int) -> UnexpectedToken | None:
    """The plain lexer's error when it stops at a keyword of the statement that failed at
    `pos` (the contextual lexer took that keyword for a name), else None."""
    try:
        keyword_parser(parser).parse(text)
    except UnexpectedToken as exc:
        tok = exc.token
        if tok.type == "$END" or tok.start_pos is None or tok.start_pos >= pos:
            return None
        if tok.type not in STATEMENT_WORDS and tok.type not in ("END_VAR", "END_STRUCT", "END_TYPE"):
            return None
        if ";" in text[tok.end_pos:pos]:
            return None
        return exc
    except UnexpectedInput:
        return None
    return None


def lex_all(parser: Lark, text: str) -> list[Token]:
    """Every significant token the full lexer finds, up to the first character it cannot
    read (the caller reports that one on its own)."""
    tokens: list[Token] = []
    try:
        for tok in parser.lex(text):
            tokens.append(tok)
    except UnexpectedInput:
        pass
    return tokens


def open_constructs(tokens: list[Token]) -> list[Open]:
    """The stack of constructs open after `tokens` (which the parser accepted)."""
    stack: list[Open] = []
    previous: Token | None = None
    for tok in tokens:
        kind = tok.type
        top = stack[-1] if stack else None
        if kind in BRACKET_CLOSER:
            stack.append(Open(tok))
        elif kind in ("RPAR", "RSQB"):
            if top is not None and top.closer == kind:
                stack.pop()
        elif top is not None and top.kind in VAR_SECTIONS:
            if kind == "END_VAR":
                stack.pop()
        elif kind in POU_CLOSER:
            while stack and stack[-1].kind in POU_CLOSER:  # a POU left without its END_
                stack.pop()
            stack.append(Open(tok))
        elif kind in VAR_SECTIONS or kind in TYPE_CLOSER:
            if top is not None and top.kind in POU_CLOSER and top.body_started and kind in VAR_SECTIONS:
                top.late_section = top.late_section or tok
            stack.append(Open(tok))
        elif kind in BLOCK_CLOSER:
            stack.append(Open(tok, head=tok))
        elif kind == "ELSIF" and top is not None and top.kind == "IF":
            top.head = tok
        elif kind == "ELSE" and top is not None and top.kind in ("IF", "CASE"):
            top.else_token = tok
        elif kind == "UNTIL" and top is not None and top.kind == "REPEAT":
            top.has_until = True
        elif kind in OPENER_OF and top is not None and top.closer == kind:
            stack.pop()
        elif kind == "IDENT" and previous is not None and previous.type in POU_CLOSER \
                and top is not None and top.token is previous:
            top.name = str(tok.value)
        elif top is not None and top.kind in POU_CLOSER and previous is not None \
                and previous.type in ("END_VAR", "IDENT", "SEMI") and kind not in ("COLON",):
            if not (previous.type == "IDENT" and top.kind == "FUNCTION"):
                top.body_started = True
        previous = tok
    return stack


def word(tok: Token | None) -> str:
    """How the token is named in a message: a keyword by itself, anything else quoted."""
    if tok is None:
        return "the end of the file"
    kind = tok.type
    if kind in BRACKET_TEXT:
        return BRACKET_TEXT[kind]
    value = str(tok.value)
    if value.upper() == kind or value.upper() in KEYWORD_TOKENS:
        return value.upper()  # a keyword, also where the contextual lexer took it for a name
    if len(value) > 30:
        value = value[:27] + "..."
    return f"'{value}'"


def _declaration_start(tokens: list[Token], section: Open) -> int:
    """Index of the first token of the declaration being read in `section`."""
    start = next(i for i, t in enumerate(tokens) if t is section.token) + 1
    for i in range(len(tokens) - 1, start - 1, -1):
        if tokens[i].type in ("SEMI", "CONSTANT", "RETAIN", "NON_RETAIN", "PERSISTENT"):
            return i + 1
    return start


def _statement_in_section(declaration: list[Token]) -> tuple[Token, str] | None:
    """(first token, how to name it) when `declaration` (the tokens since the last ';' of
    a VAR section, up to and including the one the parser refused) is a statement or the
    end of the POU rather than a declaration."""
    if not declaration:
        return None
    first = declaration[0]
    for tok in declaration:
        if tok.type in STATEMENT_WORDS:
            return first, word(tok) if tok is first else f"the statement at {first.line}:{first.column}"
    if first.type == "IDENT" and len(declaration) > 1:
        second = declaration[1]
        if second.type == "ASSIGN":
            return first, f"the assignment to '{first.value}'"
        if second.type == "LPAR":
            return first, f"the call of '{first.value}'"
        if second.type in ("DOT", "LSQB"):
            return first, f"the statement at {first.line}:{first.column}"
    return None


def explain(parser: Lark, text: str, pos: int, accepted: set[str]) -> tuple[int, int, str] | None:
    """(line, column, message) for a parse that failed at character `pos` (len(text) at the
    end of the file), or None when no open construct explains it. `accepted` holds the
    terminals the parser would have taken there."""
    tokens = lex_all(parser, text)
    index = next((i for i, t in enumerate(tokens) if t.end_pos > pos), len(tokens))
    before = tokens[:index]
    here = tokens[index] if index < len(tokens) else None
    for candidate in (before[-1] if before else None, here):
        typo = _misspelt_keyword(candidate)
        if typo is not None:
            return _misspelt(candidate, typo, open_constructs([t for t in before if t is not candidate]))
    stack = open_constructs(before)
    if not stack:
        after = tokens[index + 1] if index + 1 < len(tokens) else None
        return _stray(here, after)
    top = stack[-1]

    late = next((o for o in stack if o.late_section is not None), None)
    if late is not None:
        section = late.late_section
        return (section.line, section.column,
                f"{section.type} after the body of {late.describe()}: declaration sections come "
                "before the first statement; move this one up")

    if top.kind in VAR_SECTIONS:
        start = _declaration_start(before, top)
        found = _statement_in_section(before[start:] + ([here] if here is not None else []))
        if found is not None:
            first, what = found
            return (first.line, first.column,
                    f"{top.describe()} is not closed: expected END_VAR before {what}")
        declaration = before[start:]
        if here is not None and here.type == "COLON" and not declaration:
            return here.line, here.column, "a declaration needs a label name before ':'"
        if declaration and declaration[-1].type == "COLON" and (here is None or here.type != "IDENT"):
            name = declaration[0].value if declaration[0].type == "IDENT" else "the label"
            return _at(here, text, f"expected a data type after ':' in the declaration of '{name}' "
                                   f"(before {word(here)})", before)
        if len(declaration) == 1 and declaration[0].type == "IDENT" and here is not None \
                and here.type == "IDENT" and "COLON" in accepted:
            return (here.line, here.column,
                    f"expected ':' between the label '{declaration[0].value}' and its data type "
                    f"(write '{declaration[0].value} : {here.value}')")
        if here is None:
            return _at(None, text, f"{top.describe()} is not closed: expected END_VAR before the end of the file",
                       before)
        return None

    if top.kind in BRACKET_CLOSER:
        if here is None or here.type in NOT_IN_BRACKETS:
            return _at(here, text, f"{top.describe()} is not closed: expected {BRACKET_TEXT[top.closer]} "
                                   f"before {word(here)}", before)
        if here.type in ("RPAR", "RSQB") and here.type != top.closer:
            return _at(here, text, f"{top.describe()} is not closed: expected {BRACKET_TEXT[top.closer]} "
                                   f"before {word(here)}", before)
        return None

    if here is not None and here.type in ("RPAR", "RSQB"):
        return _at(here, text, f"{word(here)} has no matching {BRACKET_TEXT[OPENER_OF[here.type]]}")

    closes = here is None or here.type in OPENER_OF or here.type in POU_CLOSER \
        or here.type in ("TYPE", *VAR_SECTIONS)
    if closes:
        if here is not None and here.type == top.closer:
            if top.kind == "REPEAT" and not top.has_until:
                return _at(here, text, f"{top.describe()} has no UNTIL: write 'UNTIL condition' "
                                       f"before {here.type}")
            return None
        if here is None and top.kind in POU_CLOSER:
            return None
        if top.kind in POU_CLOSER and here is not None and here.type in OPENER_OF \
                and not any(o.closer == here.type for o in stack):
            opener = OPENER_OF[here.type]
            return _at(here, text, f"{here.type} has no matching {opener}: no {opener} is open here")
        if top.kind == "FUNCTION" and before and before[-1].type == "COLON" and len(before) >= 3 \
                and before[-3] is top.token:
            return _at(here, text, f"expected the return type of FUNCTION {top.name} after ':' "
                                   f"(before {word(here)})", before)
        if top.kind == "FUNCTION" and here is not None and "COLON" in accepted and before \
                and before[-1].type == "IDENT" and before[-2] is top.token:
            return _at(here, text, f"FUNCTION {top.name} has no return type: write "
                                   f"'FUNCTION {top.name} : INT' (or the type it returns) before {here.type}")
        if top.kind in POU_CLOSER and here is not None and here.type in VAR_SECTIONS:
            return _at(here, text, f"{here.type} after the body of {top.describe()}: declaration sections "
                                   "come before the first statement; move this one up")
        return _at(here, text, f"{top.describe()} is not closed: expected {top.closer} before {word(here)}",
                   before)

    if here is not None and here.type in ("ELSE", "ELSIF") and top.else_token is not None:
        other = top.else_token
        return _at(here, text, f"{here.type} after the ELSE at {other.line}:{other.column}: the ELSE branch "
                               f"comes last in the {top.describe()}")

    if here is not None and here.type in ("ELSE", "ELSIF", "UNTIL"):
        owners = {"ELSE": ("IF", "CASE"), "ELSIF": ("IF",), "UNTIL": ("REPEAT",)}[here.type]
        if top.kind not in owners:
            if any(o.kind in owners for o in stack):
                return _at(here, text, f"{top.describe()} is not closed: expected {top.closer} before {here.type}")
            return _at(here, text, f"{here.type} without an open {' or '.join(owners)}")

    if here is not None and here.type == "COLON" and top.kind in POU_CLOSER and len(before) >= 2 \
            and before[-1].type == "IDENT" and before[-2].type in ("SEMI", "END_VAR", "IDENT"):
        name = before[-1]
        return (name.line, name.column,
                f"'{name.value} : ...' is a declaration outside every declaration section: "
                f"write VAR (or VAR_INPUT, VAR_OUTPUT ...) before it")

    if here is not None and top.kind in BLOCK_CLOSER and top.closer in accepted:
        return _at(here, text, f"{top.describe()} is not closed: expected {top.closer} before {word(here)}")

    head = top.head
    if head is not None and (here is None or here.type != "ASSIGN"):
        needed = HEAD_END.get(head.type)
        if head.type == "FOR":
            needed = "TO" if "TO" in accepted else "DO"
        if needed is not None and needed in accepted and (here is None or here.type != needed):
            # reported at the token that shows the keyword is missing, naming where it goes
            prev = before[-1] if before else head
            what = "condition" if head.type in ("IF", "ELSIF", "WHILE") else \
                "selector" if head.type == "CASE" else ("start value" if needed == "TO" else "end value")
            return _at(here, text, f"expected {needed} at {prev.end_line}:{prev.end_column}, after the {what} "
                                   f"of the {head.type} at {head.line}:{head.column}, before {word(here)}", before)
    return None


#: keywords as people mistype them, without the underscore (ENDIF) or with one too many
_KEYWORDS = (*BLOCK_CLOSER.values(), *POU_CLOSER, *POU_CLOSER.values(), "END_VAR", "END_TYPE",
             "END_STRUCT", "ELSIF", *VAR_SECTIONS)
_BY_LETTERS = {k.replace("_", ""): k for k in _KEYWORDS}
_BY_LETTERS["ELSEIF"] = "ELSIF"


def _misspelt_keyword(tok: Token | None) -> str | None:
    """The keyword an identifier was meant to be (ENDIF -> END_IF, ELSEIF -> ELSIF)."""
    if tok is None or tok.type != "IDENT":
        return None
    value = str(tok.value).upper()
    meant = _BY_LETTERS.get(value.replace("_", ""))
    return meant if meant is not None and meant != value else None


def _misspelt(tok: Token, meant: str, stack: list[Open]) -> tuple[int, int, str]:
    """A misspelt keyword; a closer is suggested only when it closes what is open."""
    where = tok.line, tok.column
    if meant not in OPENER_OF:
        return (*where, f"'{tok.value}' is not a keyword: write {meant}")
    block = next((o for o in reversed(stack) if o.kind not in BRACKET_CLOSER), None)
    if block is not None and block.closer == meant:
        return (*where, f"'{tok.value}' is not a keyword: write {meant} to close the {block.describe()}")
    if block is not None:
        return (*where, f"'{tok.value}' is not a keyword, and the innermost open construct is the "
                        f"{block.describe()}, closed by {block.closer}")
    return (*where, f"'{tok.value}' is not a keyword, and nothing is open here to close")


def _stray(here: Token | None, after: Token | None) -> tuple[int, int, str] | None:
    """An error outside every construct: a closer with nothing to close, or a statement
    outside a POU."""
    statement = here is not None and (
        here.type in BLOCK_CLOSER or here.type in ("EXIT", "RETURN")
        or (here.type == "IDENT" and after is not None and after.type in ("ASSIGN", "LPAR")))
    if statement:
        return (here.line, here.column, f"a statement ({word(here)}) outside a POU: statements go in the body "
                                        "of a PROGRAM, FUNCTION_BLOCK or FUNCTION (after its declarations)")
    if here is not None and here.type in OPENER_OF:
        opener = OPENER_OF[here.type]
        name = BRACKET_TEXT.get(opener, opener)
        return here.line, here.column, f"{word(here)} has no matching {name}: nothing is open here"
    return None


def _at(tok: Token | None, text: str, message: str,
        before: list[Token] | None = None) -> tuple[int, int, str]:
    """The place of `tok`; for the end of the file, right after the last token read."""
    if tok is not None:
        return tok.line, tok.column, message
    if before:
        return before[-1].end_line, before[-1].end_column, message
    return *place_of_char(text, len(text)), message
