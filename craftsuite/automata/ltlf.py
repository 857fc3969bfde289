"""LTLf syntax: a small parser producing a plain tuple AST.

Grammar (lowest precedence first, the same layering as flloat's):

    formula := iff
    iff     := implies ('<->' implies)*
    implies := or ('->' implies)?            (right associative)
    or      := and ('|' and)*
    and     := until ('&' until)*
    until   := release ('U' until)?          (right associative)
    release := unary ('R' release)?          (right associative)
    unary   := ('!' | 'X' | 'WX' | 'F' | 'G') unary | atom | '(' formula ')'
    atom    := proposition | 'true' | 'false' | 'last'

Propositions are lower-case identifiers (``wood``, ``tools3``, ``gold_1``); the operator
letters are upper-case, so the two never clash. ``&&``, ``||``, ``~``, ``=>`` and ``<=>``
are accepted as spellings of ``&``, ``|``, ``!``, ``->`` and ``<->``.

AST nodes are tuples: ``("ap", name)``, ``("true",)``, ``("false",)``, ``("last",)``,
``(op, child)`` for the unary ops ``not X WX F G`` and ``(op, left, right)`` for
``and or implies iff U R``.
"""

from __future__ import annotations

import re

__all__ = ["LTLfSyntaxError", "parse", "to_string", "atoms"]


class LTLfSyntaxError(ValueError):
    """A formula that does not parse; the message names the position and the problem."""


_TOKEN = re.compile(
    r"\s*(?:(?P<op><->|<=>|->|=>|&&|\|\||[!~&|()])|(?P<word>[A-Za-z_][A-Za-z0-9_]*)|(?P<bad>\S))"
)
_SPELLING = {"<=>": "<->", "=>": "->", "&&": "&", "||": "|", "~": "!"}
_UNARY = {"!": "not", "X": "X", "WX": "WX", "F": "F", "G": "G"}
_CONSTANTS = {"true": ("true",), "false": ("false",), "tt": ("true",), "ff": ("false",), "last": ("last",)}
_PROPOSITION = re.compile(r"[a-z_][a-z0-9_]*\Z")


def _tokenize(text: str) -> list[tuple[str, int]]:
    tokens = []
    pos = 0
    while pos < len(text):
        m = _TOKEN.match(text, pos)
        if m is None:  # only trailing whitespace is left
            break
        if m.group("bad") is not None:
            raise LTLfSyntaxError(
                f"unexpected character {m.group('bad')!r} at column {m.start('bad') + 1} in {text!r}"
            )
        tok = m.group("op") or m.group("word")
        tokens.append((_SPELLING.get(tok, tok), m.start(m.lastgroup) + 1))
        pos = m.end()
    return tokens


class _Parser:
    def __init__(self, text: str):
        self.text = text
        self.tokens = _tokenize(text)
        self.i = 0

    def peek(self) -> str | None:
        return self.tokens[self.i][0] if self.i < len(self.tokens) else None

    def take(self) -> str:
        tok = self.tokens[self.i][0]
        self.i += 1
        return tok

    def fail(self, expected: str):
        if self.i < len(self.tokens):
            tok, col = self.tokens[self.i]
            where = f"found {tok!r} at column {col}"
        else:
            where = "found the end of the formula"
        raise LTLfSyntaxError(f"expected {expected}, {where} in {self.text!r}")

    def parse(self):
        if not self.tokens:
            raise LTLfSyntaxError("the formula is empty")
        node = self.iff()
        if self.peek() is not None:
            self.fail("an operator or the end of the formula")
        return node

    def _left(self, sub, op: str, name: str):
        node = sub()
        while self.peek() == op:
            self.take()
            node = (name, node, sub())
        return node

    def iff(self):
        return self._left(self.implies, "<->", "iff")

    def implies(self):
        left = self.or_()
        if self.peek() == "->":
            self.take()
            return ("implies", left, self.implies())
        return left

    def or_(self):
        return self._left(self.and_, "|", "or")

    def and_(self):
        return self._left(self.until, "&", "and")

    def until(self):
        left = self.release()
        if self.peek() == "U":
            self.take()
            return ("U", left, self.until())
        return left

    def release(self):
        left = self.unary()
        if self.peek() == "R":
            self.take()
            return ("R", left, self.release())
        return left

    def unary(self):
        tok = self.peek()
        if tok in _UNARY:
            self.take()
            return (_UNARY[tok], self.unary())
        if tok == "(":
            self.take()
            node = self.iff()
            if self.peek() != ")":
                self.fail("')'")
            self.take()
            return node
        if tok is None or not re.match(r"[A-Za-z_]", tok):
            self.fail("a proposition, a constant, '!', 'X', 'WX', 'F', 'G' or '('")
        if tok in _CONSTANTS:
            self.take()
            return _CONSTANTS[tok]
        if tok in ("U", "R"):
            self.fail("a left operand before the binary operator")
        if not _PROPOSITION.match(tok):
            self.fail("a proposition (lower-case identifier)")
        self.take()
        return ("ap", tok)


def parse(text: str):
    """Parse an LTLf formula into a tuple AST. Raises LTLfSyntaxError on bad input."""
    if not isinstance(text, str):
        raise LTLfSyntaxError(f"an LTLf formula must be a string, got {type(text).__name__}")
    return _Parser(text).parse()


def atoms(node) -> set[str]:
    """The proposition names that occur in an AST."""
    if node[0] == "ap":
        return {node[1]}
    return set().union(*(atoms(c) for c in node[1:] if isinstance(c, tuple)))


_INFIX = {"and": "&", "or": "|", "implies": "->", "iff": "<->", "U": "U", "R": "R"}
_PREFIX = {"not": "!", "X": "X", "WX": "WX", "F": "F", "G": "G"}


def to_string(node) -> str:
    """Fully parenthesised text of an AST (parses back to the same AST)."""
    op = node[0]
    if op == "ap":
        return node[1]
    if op in ("true", "false", "last"):
        return op
    if op in _PREFIX:
        sep = "" if op == "not" else " "
        return f"{_PREFIX[op]}{sep}({to_string(node[1])})"
    return f"({to_string(node[1])}) {_INFIX[op]} ({to_string(node[2])})"
