"""OpenSCENARIO 1.1/1.2 expressions (`${...}`): a tokenizer and a recursive-descent
evaluator. Nothing is handed to Python's `eval`.

Grammar (lowest precedence first)::

    expr    := or
    or      := and ("or" and)*
    and     := not ("and" not)*
    not     := "not" not | compare
    compare := sum (("==" | "!=" | "<" | "<=" | ">" | ">=") sum)?
    sum     := product (("+" | "-") product)*
    product := unary (("*" | "/" | "%") unary)*
    unary   := "-" unary | primary
    primary := NUMBER | "true" | "false" | CONST | "$"NAME | FUNC "(" expr ("," expr)* ")"
             | "(" expr ")"

FUNC is one of `FUNCTIONS`: the standard's round, floor, ceil, sqrt, pow, and esmini's
additions sin, cos, tan, asin, acos, atan, sign, abs, max, min. CONST is `pi` or `e`
(`CONSTANTS`): not in the standard, but esmini defines them and published files use them
(Euro NCAP's `${$Trajectory_alpha_deg * pi / 180}`, `${-pi/2}`).

Numbers are doubles; `and`/`or`/`not` take and give booleans; `%` is the remainder with
the sign of the dividend (C's fmod), as the standard's reference implementations do.

Every number, written or computed, must be finite: a literal like `1e999`, a product that
overflows, a function whose argument is out of its domain is an `ExpressionError`. The
work is linear in the text: its length is bounded (`MAX_LENGTH`) and its nesting checked
on the tokens (`MAX_DEPTH`) before anything is evaluated; tokenizing scans each character
once, and evaluating takes each token once.
"""

from __future__ import annotations

import math
import re
from collections.abc import Callable, Mapping
from dataclasses import dataclass

Value = float | bool  # what an expression gives
CONSTANTS: dict[str, float] = {"pi": math.pi, "e": math.e}  # names an expression may use
Lookup = Callable[[str], Value]  # a parameter's value by name; raises ExpressionError


MAX_DEPTH = 100  # deepest nesting of parentheses, unary minus and `not`
MAX_LENGTH = 10_000  # [characters] the longest expression text (inside `${...}`)


class ExpressionError(ValueError):
    """An expression cannot be evaluated: the message says why (one line)."""


_TOKEN = re.compile(
    r"\s*(?:(?P<num>(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?)"
    r"|(?P<param>\$[A-Za-z_][A-Za-z0-9_]*)"
    r"|(?P<word>[A-Za-z_][A-Za-z0-9_]*)"
    r"|(?P<op>==|!=|<=|>=|[-+*/%(),<>]))"
)


@dataclass(frozen=True, slots=True)
class Token:
    kind: str  # num, param, word, op, end
    text: str
    pos: int  # offset in the expression text


_SPACE = re.compile(r"\s*")


def tokenize(text: str) -> list[Token]:
    """The tokens of an expression; `ExpressionError` at an unknown character or for a text
    over `MAX_LENGTH`. Each character is looked at a bounded number of times."""
    if len(text) > MAX_LENGTH:
        raise ExpressionError(f"{len(text)} characters long: at most {MAX_LENGTH}")
    tokens: list[Token] = []
    pos = _space_end(text, 0)
    while pos < len(text):
        m = _TOKEN.match(text, pos)
        if m is None or m.lastgroup is None:
            raise ExpressionError(f"unexpected character {text[pos]!r} at {pos}")
        tokens.append(Token(m.lastgroup, m.group(m.lastgroup), m.start(m.lastgroup)))
        pos = _space_end(text, m.end())
    tokens.append(Token("end", "", len(text)))
    return tokens


def _space_end(text: str, pos: int) -> int:
    """The offset of the first non-space character at or after `pos`."""
    found = _SPACE.match(text, pos)
    assert found is not None  # `\s*` matches the empty string
    return found.end()


_WORD_VALUES = ("true", "false", *CONSTANTS)  # words that are a value by themselves


def check_nesting(tokens: list[Token]) -> None:
    """`ExpressionError` when parentheses, unary minus or `not` nest over MAX_DEPTH, counted
    on the tokens before evaluating, as the evaluator counts them: the expression itself
    is one level, each open parenthesis one until it closes, and each unary operator one
    until the value it applies to ends (with that value's parentheses)."""
    depth = 1  # levels open now
    pending = 0  # unary operators in a row, not yet applied to a value
    opened: list[int] = []  # for each open parenthesis: the unary operators before it
    previous_is_value = False  # a `-` after a value is binary
    for tok in tokens:
        if (tok.kind == "op" and tok.text == "-" and not previous_is_value) or (
                tok.kind == "word" and tok.text == "not"):
            pending += 1
            depth += 1
        elif tok.kind == "op" and tok.text == "(":
            opened.append(pending)
            depth += 1
            pending = 0
        elif tok.kind == "op" and tok.text == ")" and opened:
            depth -= 1 + opened.pop()
        elif tok.kind in ("num", "param") or tok.text in _WORD_VALUES:
            depth -= pending
            pending = 0
        if depth > MAX_DEPTH:
            raise ExpressionError(f"nested more than {MAX_DEPTH} deep")
        previous_is_value = tok.kind in ("num", "param") or tok.text in (")", *_WORD_VALUES)


def _cut(text: str) -> str:
    """A token's text as a message quotes it: at most 20 characters."""
    return text if len(text) <= 20 else text[:17] + "..."


def finite(value: float, what: str) -> float:
    """`value` if finite, else `ExpressionError` ("<what>: result out of range")."""
    if not math.isfinite(value):
        raise ExpressionError(f"{what}: result out of range")
    return value


def _check_domain(name: str, ok: bool) -> None:
    if not ok:
        raise ExpressionError(f"{name}: argument out of range")


def _sqrt(x: float) -> float:
    _check_domain("sqrt", x >= 0)
    return math.sqrt(x)


def _asin(x: float) -> float:
    _check_domain("asin", -1 <= x <= 1)
    return math.asin(x)


def _acos(x: float) -> float:
    _check_domain("acos", -1 <= x <= 1)
    return math.acos(x)


def _pow(x: float, y: float) -> float:
    try:
        result = math.pow(x, y)
    except (ValueError, OverflowError):
        raise ExpressionError("pow: argument out of range") from None
    return result


def _round(x: float) -> float:
    """Half away from zero, as C's round."""
    return float(math.floor(abs(x) + 0.5) * (1 if x >= 0 else -1))


def _sign(x: float) -> float:
    return 1.0 if x > 0 else -1.0 if x < 0 else 0.0


FUNCTIONS: Mapping[str, tuple[int, Callable[..., float]]] = {
    "round": (1, _round),
    "floor": (1, lambda x: float(math.floor(x))),
    "ceil": (1, lambda x: float(math.ceil(x))),
    "sqrt": (1, _sqrt),
    "pow": (2, _pow),
    "sin": (1, math.sin),
    "cos": (1, math.cos),
    "tan": (1, math.tan),
    "asin": (1, _asin),
    "acos": (1, _acos),
    "atan": (1, math.atan),
    "sign": (1, _sign),
    "abs": (1, abs),
    "max": (2, max),
    "min": (2, min),
}  # name -> (number of arguments, implementation)

_COMPARE: Mapping[str, Callable[[float, float], bool]] = {
    "==": lambda a, b: a == b,
    "!=": lambda a, b: a != b,
    "<": lambda a, b: a < b,
    "<=": lambda a, b: a <= b,
    ">": lambda a, b: a > b,
    ">=": lambda a, b: a >= b,
}


def _number(value: Value, what: str) -> float:
    if isinstance(value, bool):
        raise ExpressionError(f"{what} needs a number, got a boolean")
    return value


def _boolean(value: Value, what: str) -> bool:
    if not isinstance(value, bool):
        raise ExpressionError(f"{what} needs a boolean, got a number")
    return value


class _Evaluator:
    """Evaluates while parsing (the grammar has no short-circuit side effects)."""

    def __init__(self, text: str, lookup: Lookup) -> None:
        self.tokens = tokenize(text)
        check_nesting(self.tokens)
        self.i = 0
        self.lookup = lookup
        self.depth = 0

    def enter(self) -> None:
        """Counts one more level of nesting; refuses more than MAX_DEPTH."""
        self.depth += 1
        if self.depth > MAX_DEPTH:
            raise ExpressionError(f"nested more than {MAX_DEPTH} deep")

    def peek(self) -> Token:
        return self.tokens[self.i]

    def take(self) -> Token:
        tok = self.tokens[self.i]
        self.i += 1
        return tok

    def expect(self, text: str) -> None:
        tok = self.take()
        if tok.text != text:
            found = repr(_cut(tok.text)) if tok.kind != "end" else "the end"
            raise ExpressionError(f"expected {text!r} at {tok.pos}, found {found}")

    def is_word(self, word: str) -> bool:
        tok = self.peek()
        return tok.kind == "word" and tok.text == word

    def run(self) -> Value:
        value = self.or_()
        tok = self.peek()
        if tok.kind != "end":
            raise ExpressionError(f"unexpected {_cut(tok.text)!r} at {tok.pos}")
        return value

    def or_(self) -> Value:
        self.enter()
        value = self.and_()
        while self.is_word("or"):
            self.take()
            right = self.and_()
            value = _boolean(value, "or") | _boolean(right, "or")
        self.depth -= 1
        return value

    def and_(self) -> Value:
        value = self.not_()
        while self.is_word("and"):
            self.take()
            right = self.not_()
            value = _boolean(value, "and") & _boolean(right, "and")
        return value

    def not_(self) -> Value:
        if self.is_word("not"):
            self.take()
            self.enter()
            value = not _boolean(self.not_(), "not")
            self.depth -= 1
            return value
        return self.compare()

    def compare(self) -> Value:
        left = self.sum_()
        tok = self.peek()
        if tok.kind == "op" and tok.text in _COMPARE:
            self.take()
            right = self.sum_()
            return _COMPARE[tok.text](_number(left, tok.text), _number(right, tok.text))
        return left

    def sum_(self) -> Value:
        value = self.product()
        while self.peek().text in ("+", "-") and self.peek().kind == "op":
            op = self.take().text
            right = _number(self.product(), op)
            left = _number(value, op)
            value = finite(left + right if op == "+" else left - right, op)
        return value

    def product(self) -> Value:
        value = self.unary()
        while self.peek().text in ("*", "/", "%") and self.peek().kind == "op":
            op = self.take().text
            right = _number(self.unary(), op)
            left = _number(value, op)
            if op == "*":
                value = finite(left * right, op)
            elif right == 0:
                raise ExpressionError("division by zero" if op == "/" else "modulo by zero")
            else:
                value = finite(left / right if op == "/" else math.fmod(left, right), op)
        return value

    def unary(self) -> Value:
        tok = self.peek()
        if tok.kind == "op" and tok.text == "-":
            self.take()
            self.enter()
            value = -_number(self.unary(), "unary minus")
            self.depth -= 1
            return value
        return self.primary()

    def primary(self) -> Value:
        tok = self.take()
        if tok.kind == "num":
            return finite(float(tok.text), f"number {_cut(tok.text)} at {tok.pos}")
        if tok.kind == "param":
            value = self.lookup(tok.text[1:])
            return value if isinstance(value, bool) else finite(value, tok.text)
        if tok.kind == "op" and tok.text == "(":
            value = self.or_()
            self.expect(")")
            return value
        if tok.kind == "word":
            if tok.text in ("true", "false"):
                return tok.text == "true"
            if tok.text in CONSTANTS:
                return CONSTANTS[tok.text]
            if tok.text in FUNCTIONS:
                return self.call(tok.text)
            raise ExpressionError(f"unknown name {_cut(tok.text)!r} at {tok.pos}")
        found = repr(_cut(tok.text)) if tok.kind != "end" else "the end"
        raise ExpressionError(f"expected a value at {tok.pos}, found {found}")

    def call(self, name: str) -> float:
        arity, fn = FUNCTIONS[name]
        self.expect("(")
        args = [_number(self.or_(), name)]
        while self.peek().text == "," and self.peek().kind == "op":
            self.take()
            args.append(_number(self.or_(), name))
        self.expect(")")
        if len(args) != arity:
            raise ExpressionError(f"{name} takes {arity} argument(s), got {len(args)}")
        try:
            result = float(fn(*args))
        except (ValueError, OverflowError):  # sin(inf), floor of a huge value, ...
            raise ExpressionError(f"{name}: argument out of range") from None
        return finite(result, name)


def evaluate(text: str, lookup: Lookup) -> Value:
    """The value of the expression `text` (the part inside `${...}`), with `$name`
    references looked up by `lookup`; `ExpressionError` when it is malformed or fails."""
    value = _Evaluator(text, lookup).run()
    if isinstance(value, float) and not math.isfinite(value):
        raise ExpressionError("result out of range")
    return value
