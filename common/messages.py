"""One-line error messages: whitespace folded, length bounded.

Values are shortened where a message names them (`repr` cut at 80 characters); this is the
last guard of the command lines, so no message, whatever it quotes, is longer than LINE_LIMIT
characters or holds a word longer than WORD_LIMIT (a megabyte scene string, a path): the middle
goes, the beginning (naming the key) and the end (saying what was expected) stay.
"""
from __future__ import annotations

WORD_LIMIT = 240
LINE_LIMIT = 600


def _cut(text: str, limit: int) -> str:
    if len(text) <= limit:
        return text
    head = (limit - 5) * 2 // 3
    return text[:head] + " ... " + text[len(text) - (limit - 5 - head):]


def one_line(message: object) -> str:
    """`message` (an exception or text) on one line, every word and the whole line bounded."""
    words = str(message).split() or [type(message).__name__]
    return _cut(" ".join(_cut(w, WORD_LIMIT) for w in words), LINE_LIMIT)
