"""How well a search text matches a term's names and labels: the order of the search page's matches
and of the taxonomy's. An exact name first, then names that start with the text, then names with a word
that does, then the rest, then labels that have the text only further in."""

from __future__ import annotations

from collections.abc import Iterable

EXACT, PREFIX, WORD, CONTAINS, IN_LABEL = range(5)


def rank(needle: str, names: Iterable[str | None], labels: Iterable[str | None] = ()) -> int | None:
    """How well ``needle`` (case-folded) matches the best of ``names``: :data:`EXACT`, :data:`PREFIX`,
    :data:`WORD` (a word in it starts with the text), :data:`CONTAINS`, or ``None``. A label that is
    the text or starts with it counts as a name; one that has it further in comes after every name
    (:data:`IN_LABEL`): on OWLS-TC, "price" found ``arbitrage`` by its comment-like label before
    ``EuropeTaxedPrice``."""
    found = [_rank(needle, names)]
    by_label = _rank(needle, labels)
    if by_label is not None:
        found.append(by_label if by_label <= PREFIX else IN_LABEL)
    return min((r for r in found if r is not None), default=None)


def _rank(needle: str, names: Iterable[str | None]) -> int | None:
    best: int | None = None
    for name in names:
        if not name:
            continue
        folded = name.casefold()
        if needle not in folded:
            continue
        if folded == needle:
            return EXACT
        if folded.startswith(needle):
            found = PREFIX
        elif any(word.startswith(needle) for word in _words(folded)):
            found = WORD
        else:
            found = CONTAINS
        best = found if best is None else min(best, found)
    return best


def _words(text: str) -> list[str]:
    return "".join(c if c.isalnum() else " " for c in text).split()
