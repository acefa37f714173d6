"""Names of concepts as words: the local name of an IRI, and the core / complementary word split.

English compounds put their head last: in RobotPosition the core word is Position and Robot is the
complementary word that narrows it (Song's core-word method, the paper's reference [22]).
"""

from __future__ import annotations

import re

_WORD = re.compile(r"[A-Z]+(?=[A-Z][a-z]|\d|\b|_)|[A-Z]?[a-z]+|[A-Z]+|\d+")


def local_name(iri: str) -> str:
    """The part of an IRI after its last ``#`` or ``/`` (the whole string if it has neither)."""
    for separator in ("#", "/", ":"):
        if separator in iri:
            tail = iri.rsplit(separator, 1)[1]
            if tail:
                return tail
    return iri


def words(name: str) -> list[str]:
    """Lower-case words of a camelCase, snake_case, kebab-case or spaced name."""
    return [w.lower() for w in _WORD.findall(name.replace("-", " ").replace("_", " "))]


def core_split(name: str) -> tuple[str, str]:
    """(core word, complementary words) of a compound name: RobotPosition -> ("position", "robot")."""
    parts = words(name)
    if not parts:
        return name.lower(), ""
    return parts[-1], " ".join(parts[:-1])
