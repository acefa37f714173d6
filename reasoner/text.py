"""Text similarity of service descriptions: TF-IDF cosine over names, labels and text descriptions.

The hybrid method (``sem-str-text``) adds it to the Sem-Str IO/PE score, as OWLS-MX adds text retrieval
to logic matching. The vocabulary and the inverse document frequencies come from the advertisement
pool being ranked, so a word that every service uses (``service``) weighs little. Names are split into
words first (``BookPriceService`` -> book price service), with the same splitter as Situation 3.
"""

from __future__ import annotations

from collections.abc import Sequence
from functools import cache
from typing import TYPE_CHECKING

from cbrs.extras import require
from cbrs.kb import ServiceDescription
from cbrs.reasoner.names import words

if TYPE_CHECKING:
    from sklearn.feature_extraction.text import TfidfVectorizer  # type: ignore[import-untyped]

    from cbrs.reasoner.vectors import FloatArray


def description_text(description: ServiceDescription) -> str:
    """The words a person reads about a service: its label, service name and text description (any of
    them may be absent; a description without any has no text)."""
    seen: list[str] = []
    for part in (description.label, description.service_name, description.comment):
        if part and part not in seen:
            seen.append(part)
    return " ".join(seen)


@cache
def _stop_words() -> frozenset[str]:
    # scikit-learn (with scipy) takes over half a second to import: only the text method loads it
    require("eval", "the text-aware method (sem-str-text)")
    from sklearn.feature_extraction.text import ENGLISH_STOP_WORDS

    return frozenset(ENGLISH_STOP_WORDS)


def _analyse(text: str) -> list[str]:
    stop_words = _stop_words()
    return [word for word in words(text) if word not in stop_words and not word.isdigit()]


class TextIndex:
    """TF-IDF vectors of a pool of descriptions; cosine similarity of any text against all of them."""

    def __init__(self, descriptions: Sequence[ServiceDescription]) -> None:
        texts = [description_text(d) for d in descriptions]
        self.size = len(texts)
        self._rows = {d.iri: i for i, d in enumerate(descriptions)}
        self._vectorizer: TfidfVectorizer | None = None
        if any(_analyse(text) for text in texts):
            from sklearn.feature_extraction.text import TfidfVectorizer

            self._vectorizer = TfidfVectorizer(analyzer=_analyse, sublinear_tf=True)
            self._matrix = self._vectorizer.fit_transform(texts)

    def similarities(self, text: str) -> FloatArray:
        """Cosine of ``text`` against every description of the pool, in pool order (0 where either has
        no known word)."""
        import numpy as np  # loaded with the first ranking (reasoner.matchmaker), not with this module

        if self._vectorizer is None or not text:
            return np.zeros(self.size, dtype=np.float64)
        query = self._vectorizer.transform([text])
        product = self._matrix @ query.T  # rows are L2-normalised: the dot product is the cosine
        return np.clip(np.asarray(product.toarray()).ravel().astype(np.float64), 0.0, 1.0)

    def similarity(self, text: str, description: ServiceDescription) -> float:
        """Cosine of ``text`` against one description (of the pool or not)."""
        import numpy as np

        row = self._rows.get(description.iri)
        if row is not None:
            return float(self.similarities(text)[row])
        if self._vectorizer is None or not text:
            return 0.0
        pair = self._vectorizer.transform([text, description_text(description)])
        return float(np.clip((pair[0] @ pair[1].T).toarray()[0, 0], 0.0, 1.0))
