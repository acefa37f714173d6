"""Lexical knowledge for core words: WordNet 3.0's nouns, shipped in ``reasoner/data/wordnet_nouns.json``.

The taxonomy says how the concepts of the loaded ontologies relate; it says nothing about two names from
different ontologies (or branches) that mean the same thing: ``City`` in SUMO and ``City`` in another
ontology, ``Picture`` against ``Image``. The lexicon compares the *core words* of two names (names.py):
the same lemma scores 1 (plural and singular, ``People``/``Person`` by WordNet's exceptions), two lemmas
of one synset or of synsets a few hypernym links apart score WordNet's Wu-Palmer, anything further 0.

The data file holds, for every noun lemma without capitals (proper names left out), its first senses in
WordNet's order, and for every synset its hypernyms and its depth. It is made from Debian's
``wordnet-base`` by ``python -m cbrs.reasoner.lexicon build /usr/share/wordnet`` (WordNet 3.0 licence:
reasoner/data/WORDNET_LICENSE). Nothing is downloaded at run time; without the file the lexicon knows
only equal words.
"""

from __future__ import annotations

import json
import sys
from functools import cache
from pathlib import Path

DATA_FILE = Path(__file__).parent / "data" / "wordnet_nouns.json"
MIN_LETTERS = 3  # shorter words get no lexical relations
SENSES = 3  # senses per lemma kept (WordNet orders them by frequency)

_SUFFIXES = (
    ("ses", "s"),
    ("xes", "x"),
    ("zes", "z"),
    ("ches", "ch"),
    ("shes", "sh"),
    ("men", "man"),
    ("ies", "y"),
    ("s", ""),
)


class Lexicon:
    """Noun lemmas, their senses and the hypernym graph; ``similarity`` of two words in [0, 1]."""

    def __init__(
        self,
        lemmas: dict[str, list[int]],
        hypernyms: list[list[int]],
        depth: list[int],
        exceptions: dict[str, str],
        max_links: int = 2,
    ) -> None:
        self._lemmas = lemmas
        self._hypernyms = hypernyms
        self._depth = depth
        self._exceptions = exceptions
        self.max_links = max_links
        self._members: dict[int, list[str]] | None = None
        self._related: dict[str, dict[str, float]] = {}

    @classmethod
    def empty(cls) -> Lexicon:
        return cls({}, [], [], {})

    @classmethod
    def load(cls, path: Path = DATA_FILE, max_links: int = 2) -> Lexicon:
        """The bundled WordNet nouns (an empty lexicon, equal words only, when the file is absent)."""
        if not path.exists():
            return cls.empty()
        data = json.loads(path.read_text(encoding="utf-8"))
        return cls(data["lemmas"], data["hypernyms"], data["depth"], data["exceptions"], max_links)

    def __bool__(self) -> bool:
        return bool(self._lemmas)

    def lemma(self, word: str) -> str:
        """The WordNet lemma of a noun form (``people`` -> ``person``, ``boxes`` -> ``box``), else the word."""
        word = word.lower()
        if word in self._lemmas or not self._lemmas:
            return word
        if word in self._exceptions:
            return self._exceptions[word]
        for suffix, replacement in _SUFFIXES:
            if word.endswith(suffix) and len(word) > len(suffix) + 1:
                base = word[: -len(suffix)] + replacement
                if base in self._lemmas:
                    return base
        return word

    def _ancestors(self, synset: int) -> dict[int, int]:
        """Synsets up to ``max_links`` hypernym links above ``synset`` (itself included), with distance."""
        found = {synset: 0}
        frontier = [synset]
        for distance in range(1, self.max_links + 1):
            frontier = [h for s in frontier for h in self._hypernyms[s] if h not in found]
            for h in frontier:
                found.setdefault(h, distance)
        return found

    def similarity(self, first: str, second: str) -> float:
        """1 for the same lemma; WordNet Wu-Palmer (2D / (N1 + N2 + 2D), D the depth of the common
        hypernym plus one) over the first senses when they meet within ``max_links`` links; else 0."""
        a, b = self.lemma(first), self.lemma(second)
        if a == b:
            return 1.0
        if min(len(a), len(b)) < MIN_LETTERS:
            return 0.0  # letters and abbreviations (e, d: vitamins to WordNet) are no words here
        return self.related(a).get(b, 0.0)

    def related(self, word: str) -> dict[str, float]:
        """Every lemma with a positive similarity to ``word`` (a lemma), with the similarity."""
        found = self._related.get(word)
        if found is None:
            found = self._related[word] = _related(self, word) if len(word) >= MIN_LETTERS else {}
        return found

    def members(self) -> dict[int, list[str]]:
        """Synset -> its lemmas (those kept), built on first use."""
        if self._members is None:
            members: dict[int, list[str]] = {}
            for lemma, senses in self._lemmas.items():
                for s in senses:
                    members.setdefault(s, []).append(lemma)
            self._members = members
        return self._members

    def hyponyms(self) -> dict[int, list[int]]:
        return _hyponyms(self)

    def warm(self) -> None:
        """Build the inverted tables now rather than on the first lookup."""
        if self:
            self.members()
            self.hyponyms()


def _related(lexicon: Lexicon, word: str) -> dict[str, float]:
    senses = lexicon._lemmas.get(word, [])
    members = lexicon.members()
    below = lexicon.hyponyms()
    out: dict[str, float] = {}
    for sense in senses:
        for ancestor, up in lexicon._ancestors(sense).items():
            # every synset within the remaining links below the common hypernym
            level = {ancestor: 0}
            frontier = [ancestor]
            for down in range(1, lexicon.max_links - up + 1):
                frontier = [c for s in frontier for c in below.get(s, ()) if c not in level]
                for c in frontier:
                    level.setdefault(c, down)
            d = lexicon._depth[ancestor] + 1
            for synset, down in level.items():
                value = 2 * d / (up + down + 2 * d)
                for lemma in members.get(synset, ()):
                    if lemma != word and value > out.get(lemma, 0.0):
                        out[lemma] = value
    return out


_HYPONYMS: dict[int, dict[int, list[int]]] = {}


def _hyponyms(lexicon: Lexicon) -> dict[int, list[int]]:
    key = id(lexicon)
    found = _HYPONYMS.get(key)
    if found is None:
        found = {}
        for synset, parents in enumerate(lexicon._hypernyms):
            for parent in parents:
                found.setdefault(parent, []).append(synset)
        _HYPONYMS[key] = found
    return found


@cache
def bundled(max_links: int = 2) -> Lexicon:
    """The lexicon from the bundled data file, loaded once per process."""
    return Lexicon.load(DATA_FILE, max_links)


# -- building the data file from a WordNet 3.0 database folder -------------------------------------


def build(wordnet: Path, out: Path = DATA_FILE) -> dict[str, int]:
    """Write the data file from ``wordnet`` (a folder with data.noun, index.noun, noun.exc)."""
    offsets: dict[str, int] = {}
    raw_hypernyms: list[list[str]] = []
    for line in (wordnet / "data.noun").read_text(encoding="latin-1").splitlines():
        if line.startswith(" "):
            continue  # the licence header
        fields = line.split(" ")
        offsets[fields[0]] = len(raw_hypernyms)
        words = int(fields[3], 16)
        pointers_at = 4 + 2 * words
        count = int(fields[pointers_at])
        targets: list[str] = []
        for p in range(count):
            symbol, target = fields[pointers_at + 1 + 4 * p], fields[pointers_at + 2 + 4 * p]
            if symbol in ("@", "@i"):
                targets.append(target)
        raw_hypernyms.append(targets)
    hypernyms = [[offsets[t] for t in up] for up in raw_hypernyms]
    depth = [-1] * len(hypernyms)

    def depth_of(synset: int) -> int:
        stack = [synset]
        while stack:
            top = stack[-1]
            pending = [h for h in hypernyms[top] if depth[h] < 0]
            if pending:
                stack.extend(pending)
                continue
            stack.pop()
            depth[top] = 1 + min((depth[h] for h in hypernyms[top]), default=-1)
        return depth[synset]

    for synset in range(len(hypernyms)):
        depth_of(synset)
    lemmas: dict[str, list[int]] = {}
    for line in (wordnet / "index.noun").read_text(encoding="latin-1").splitlines():
        if line.startswith(" "):
            continue
        fields = line.split()
        lemma = fields[0]
        if lemma.lower() != lemma or not lemma.replace("_", "").isalpha():
            continue  # proper names and forms with digits or punctuation
        senses = int(fields[2])
        lemmas[lemma.replace("_", " ")] = [offsets[o] for o in fields[-senses:][:SENSES]]
    exceptions = {}
    for line in (wordnet / "noun.exc").read_text(encoding="latin-1").splitlines():
        parts = line.split()
        if len(parts) >= 2 and parts[1] in lemmas and parts[0].isalpha():
            exceptions[parts[0]] = parts[1]
    out.write_text(
        json.dumps(
            {"lemmas": lemmas, "hypernyms": hypernyms, "depth": depth, "exceptions": exceptions}, separators=(",", ":")
        ),
        encoding="utf-8",
    )
    return {"lemmas": len(lemmas), "synsets": len(hypernyms), "exceptions": len(exceptions)}


if __name__ == "__main__":
    if len(sys.argv) == 3 and sys.argv[1] == "build":
        print(build(Path(sys.argv[2])))
    else:
        print("usage: python -m cbrs.reasoner.lexicon build WORDNET_DIR   (e.g. /usr/share/wordnet)")
