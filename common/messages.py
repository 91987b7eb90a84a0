"""One-line error messages of the command lines: whitespace folded, length bounded.

Values are shortened where a message names them (`repr` cut at 80 characters); this is the
last guard of the command lines, so no message, whatever it quotes, is longer than LINE_LIMIT
characters or holds a word longer than WORD_LIMIT (a megabyte scene string, a path): the middle
goes, the beginning (naming the key) and the end (saying what was expected) stay.
"""
from __future__ import annotations

import sys

EXIT_BAD_INPUT = 2
EXIT_INTERRUPTED = 130
WORD_LIMIT = 240
LINE_LIMIT = 600


def short(value: object, limit: int = 80) -> str:
    """A value as a message quotes it: its repr, cut to `limit` characters."""
    text = repr(value)
    return text if len(text) <= limit else text[:limit - 3] + "..."


def _cut(text: str, limit: int) -> str:
    if len(text) <= limit:
        return text
    head = (limit - 5) * 2 // 3
    return text[:head] + " ... " + text[len(text) - (limit - 5 - head):]


def one_line(message: object) -> str:
    """`message` (an exception or text) on one line, every word and the whole line bounded."""
    words = str(message).split() or [type(message).__name__]
    return _cut(" ".join(_cut(w, WORD_LIMIT) for w in words), LINE_LIMIT)


def failed(exc: BaseException, interrupted: str = "nothing partial was kept") -> int:
    """Print the one stderr line of a failed command and return its exit status: 130 for an
    interruption (Ctrl-C, or SIGTERM turned into one), 2 for anything else (bad input)."""
    if isinstance(exc, KeyboardInterrupt):
        print(f"error: interrupted; {interrupted}", file=sys.stderr)
        return EXIT_INTERRUPTED
    print(f"error: {one_line(exc)}", file=sys.stderr)
    return EXIT_BAD_INPUT
