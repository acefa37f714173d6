"""Opposite states by their names: WordNet 3.0's antonyms, shipped in ``reasoner/data/wordnet_antonyms.json``.

A taxonomy that does not declare ``Opened`` disjoint with ``Closed`` cannot tell the two apart from
synonyms: both are siblings under a door state. Their names can. WordNet records antonymy between words
(open/closed, open/close, lock/unlock, on/off, full/empty), and a requested effect whose subject or
object is named by the antonym of what an advertisement states is contradicted by it, as a declared
disjointness contradicts it (statements.py, MatchConfig.antonym_statements).

Only the core words (the last word of a name, names.py) are compared, after reducing inflected forms
(``opened`` -> ``open``, ``closed`` -> ``close``, ``stopped`` -> ``stop``) to the words WordNet lists.
The data file maps each single-word lemma of an adjective, verb or noun to its direct antonyms (both
directions); it is made from Debian's ``wordnet-base`` by
``python -m cbrs.reasoner.antonyms build /usr/share/wordnet`` (licence: reasoner/data/WORDNET_LICENSE).
Nothing is downloaded at run time; without the file no two words are antonyms.
"""

from __future__ import annotations

import json
import sys
from functools import cache
from pathlib import Path

from cbrs.reasoner.names import core_split, local_name

DATA_FILE = Path(__file__).parent / "data" / "wordnet_antonyms.json"
MIN_LETTERS = 2  # "on" and "off" are states; single letters are not words here
_POSES = ("adj", "verb", "noun")
_POS_OF = {"a": "adj", "s": "adj", "v": "verb", "n": "noun"}  # a pointer's part-of-speech letter


@cache
def table(path: Path = DATA_FILE) -> dict[str, frozenset[str]]:
    """Word -> its antonyms, loaded once per process (empty when the file is absent)."""
    if not path.exists():
        return {}
    data = json.loads(path.read_text(encoding="utf-8"))
    return {word: frozenset(others) for word, others in data["antonyms"].items()}


def forms(word: str) -> frozenset[str]:
    """The word and the base forms its inflection may come from (``opened`` -> open; ``closed`` -> close,
    closed; ``stopped`` -> stop; ``switches`` -> switch), whether or not WordNet lists them."""
    word = word.lower()
    found = {word}
    for suffix, replacements in (("ed", ("", "e")), ("ing", ("", "e")), ("es", ("",)), ("s", ("",))):
        if word.endswith(suffix) and len(word) > len(suffix) + 2:
            stem = word[: -len(suffix)]
            found.update(stem + r for r in replacements)
            if suffix in ("ed", "ing") and len(stem) > 2 and stem[-1] == stem[-2]:
                found.add(stem[:-1])  # stopped -> stop
    return frozenset(found)


@cache
def antonymous_words(first: str, second: str) -> bool:
    """Are two words (any inflection) WordNet antonyms?"""
    if min(len(first), len(second)) < MIN_LETTERS or first.lower() == second.lower():
        return False
    known = table()
    other = forms(second)
    return any(not known.get(f, frozenset()).isdisjoint(other) for f in forms(first))


def opposite(first: str, second: str) -> bool:
    """Do two concepts (IRIs) name opposite states: their core words WordNet antonyms?"""
    return antonymous_words(core_split(local_name(first))[0], core_split(local_name(second))[0])


# -- building the data file from a WordNet 3.0 database folder -------------------------------------


def build(wordnet: Path, out: Path = DATA_FILE) -> dict[str, int]:
    """Write the data file from ``wordnet`` (a folder with data.adj, data.verb and data.noun)."""
    synsets: dict[tuple[str, str], list[str]] = {}
    pointers: list[tuple[str, int, tuple[str, str]]] = []  # (source word, target word number, target synset)
    for pos in _POSES:
        for line in (wordnet / f"data.{pos}").read_text(encoding="latin-1").splitlines():
            if line.startswith(" "):
                continue  # the licence header
            fields = line.split(" ")
            count = int(fields[3], 16)
            words = [fields[4 + 2 * i].split("(")[0].lower() for i in range(count)]
            synsets[(pos, fields[0])] = words
            at = 4 + 2 * count
            for p in range(int(fields[at])):
                symbol, target, target_pos, link = fields[at + 1 + 4 * p : at + 5 + 4 * p]
                if symbol == "!" and target_pos in _POS_OF:
                    source_word = words[int(link[:2], 16) - 1]
                    pointers.append((source_word, int(link[2:], 16), (_POS_OF[target_pos], target)))
    antonyms: dict[str, set[str]] = {}
    for source_word, target_number, synset in pointers:
        target_word = synsets[synset][target_number - 1]
        if "_" in source_word or "_" in target_word or not (source_word + target_word).isalpha():
            continue  # single plain words only: core words are single words
        antonyms.setdefault(source_word, set()).add(target_word)
        antonyms.setdefault(target_word, set()).add(source_word)
    out.write_text(
        json.dumps({"antonyms": {w: sorted(a) for w, a in sorted(antonyms.items())}}, separators=(",", ":")),
        encoding="utf-8",
    )
    return {"words": len(antonyms), "pairs": sum(len(a) for a in antonyms.values()) // 2}


if __name__ == "__main__":
    if len(sys.argv) == 3 and sys.argv[1] == "build":
        print(build(Path(sys.argv[2])))
    else:
        print("usage: python -m cbrs.reasoner.antonyms build WORDNET_DIR   (e.g. /usr/share/wordnet)")
