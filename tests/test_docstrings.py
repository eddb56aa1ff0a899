"""Docstrings are contracts of at most 250 words, and no docstring or comment of src/ tells the history of the code.

A docstring says what a module, class or function is or does, its units and what it raises; derivations,
measurements and discussion belong to the docs page that owns the topic. What is longer is listed in EXCEPTIONS,
the one place that says why: its cap is its word count when it was listed, so it cannot grow, and an entry that no
longer needs its room fails too, so the list only shrinks. The history of a number or a design goes in commit
messages: HISTORY finds the phrases that tell it, and HISTORY_EXCEPTIONS lists the few that say something else.
"""

from __future__ import annotations

import ast
import io
import re
import tokenize
from pathlib import Path

import syntax_trees

REPO_ROOT = Path(__file__).resolve().parents[1]
SRC = REPO_ROOT / "src"
PACKAGE = SRC / "parksteer"
DOCSTRING_WORDS = 250

# Key: a module's path under src/, or "path:Qualified.name" for a class, function or method. Value: (its cap in
# words, why it is longer).
EXCEPTIONS: dict[str, tuple[int, str]] = {}

# Phrases that tell how the code or a number changed: "was 1.3 N m off", "as before", "previously", "no longer",
# "used to" (not the passive "is used to"), "last round", "formerly", "now that".
HISTORY = re.compile(
    r"\bwas\s+-?\d[\d.]*\b[^.]{0,60}?\boff\b|\bas before\b|\bpreviously\b|\bno longer\b|\bformerly\b"
    r"|(?<!\bis )(?<!\bare )(?<!\bbe )(?<!\bbeen )(?<!\bwas )(?<!\bwere )\bused to\b|\blast round\b|\bnow that\b",
    re.IGNORECASE)
# Key: "path:phrase, with the words after it" as history_phrases gives it. Value: why it is no history.
PHYSICAL_STATE = "a state within the physics or the data, not a change of the code"
HISTORY_EXCEPTIONS: dict[str, str] = {
    "parksteer/measure/importers.py:no longer describe filtered samples, but": PHYSICAL_STATE,
    "parksteer/measure/rack_fit.py:no longer reaches back into the": PHYSICAL_STATE,
    "parksteer/model/symbolic/effects/turn_slip.py:no longer carries, against the tyre_friction": PHYSICAL_STATE,
}


def docstring_words(source: str) -> dict[str, int]:
    """Words of the module's docstring (key "") and of every class's, function's and method's docstring (nested
    ones too), by qualified name."""
    words: dict[str, int] = {}

    def visit(node: ast.AST, name: str) -> None:
        doc = ast.get_docstring(node, clean=False) if isinstance(
            node, (ast.Module, ast.ClassDef, ast.FunctionDef, ast.AsyncFunctionDef)) else None
        if doc is not None:
            words[name] = max(words.get(name, 0), len(doc.split()))
        for child in ast.iter_child_nodes(node):
            if isinstance(child, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
                visit(child, f"{name}.{child.name}" if name else child.name)
            else:
                visit(child, name)

    visit(syntax_trees.tree(source), "")
    return words


def sources() -> list[tuple[str, str]]:
    """(key, text) of every module of the package, the shipped pre-derived models' folder left out."""
    return [(path.relative_to(SRC).as_posix(), path.read_text(encoding="utf-8"))
            for path in sorted(PACKAGE.rglob("*.py")) if "prebuilt" not in path.relative_to(PACKAGE).parts]


def counts() -> dict[str, int]:
    """Every docstring's words in the package, keyed as EXCEPTIONS is."""
    out: dict[str, int] = {}
    for key, text in sources():
        out.update({f"{key}:{name}" if name else key: n for name, n in docstring_words(text).items()})
    return out


def prose(source: str) -> list[str]:
    """The docstrings and the comments of a module, each with its whitespace made single spaces."""
    texts = [node.body[0].value.value for node in syntax_trees.nodes(source)
             if isinstance(node, (ast.Module, ast.ClassDef, ast.FunctionDef, ast.AsyncFunctionDef))
             and ast.get_docstring(node, clean=False) is not None]
    texts += [tok.string for tok in tokenize.generate_tokens(io.StringIO(source).readline)
              if tok.type == tokenize.COMMENT]
    return [" ".join(text.split()) for text in texts]


def history_phrases(source: str) -> list[str]:
    """Each history phrase in a module's docstrings and comments, and the four words after it."""
    return [" ".join(text[match.start():].split()[:len(match.group(0).split()) + 4])
            for text in prose(source) for match in HISTORY.finditer(text)]


def test_the_word_count_sees_every_docstring_by_its_name():
    """The counter measures every docstring the limit is about: the module's, a class's, a method under its class's
    name and a nested function under its own, each by whitespace-separated words; a string that is not the first
    statement is no docstring."""
    source = ('"""One two three."""\nclass A:\n    """Four five."""\n    def f(self):\n        """Six."""\n'
              '        def g():\n            """Seven eight\n            nine."""\n            "not a docstring"\n')
    assert docstring_words(source) == {"": 3, "A": 2, "A.f": 1, "A.f.g": 3}


def test_the_history_check_finds_history_and_not_its_lookalikes():
    """The history patterns catch a number's past, a comparison with an earlier version and a change's reason in
    docstrings and comments, and leave alone the passive "is used to", a time "now" and string literals."""
    source = ('"""The fit was 1.3 N m off at the reversals; it runs as before."""\n'
              '# previously a table, now that the model reads it\n'
              '# the value is used to scale the map; it is read now\n'
              'x = "no longer running"\n')
    assert history_phrases(source) == ["was 1.3 N m off at the reversals; it", "as before.",
                                       "previously a table, now that", "now that the model reads it"]


def test_every_docstring_is_at_most_250_words_but_the_listed():
    """Every module, class, function and method docstring of src/parksteer is at most 250 words, or listed in
    EXCEPTIONS and no longer than its cap there."""
    over = [f"{key}: {n} words, cap {EXCEPTIONS.get(key, (DOCSTRING_WORDS,))[0]}" for key, n in counts().items()
            if n > EXCEPTIONS.get(key, (DOCSTRING_WORDS,))[0]]
    assert over == []


def test_every_docstring_exception_still_needs_its_room_and_says_why():
    """Each listed exception names a docstring that exists and is still over 250 words (one cut to the limit must
    leave the list), with a cap above the limit and a reason in words."""
    measured = counts()
    assert [key for key in EXCEPTIONS if measured.get(key, 0) <= DOCSTRING_WORDS] == []
    assert [key for key, (cap, reason) in EXCEPTIONS.items()
            if cap <= DOCSTRING_WORDS or len(reason.split()) < 3] == []


def test_no_docstring_or_comment_tells_the_history_of_the_code():
    """No docstring or comment of src/parksteer tells how the code or a number changed ("was N ... off", "as
    before", "previously", "no longer", "used to", "last round", "now that"), but for the listed phrases that
    describe a state of the physics or the data; each listed phrase is still there."""
    found = {f"{key}:{phrase}" for key, text in sources() for phrase in history_phrases(text)}
    assert sorted(found - set(HISTORY_EXCEPTIONS)) == []
    assert sorted(set(HISTORY_EXCEPTIONS) - found) == []
