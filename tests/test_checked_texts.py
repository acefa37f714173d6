"""The store remembers the query texts that passed its checks (kb.store.CHECKED_TEXTS), and only those.

A text asked again skips the nesting and remote-access scans and the guard; a text that failed is
refused every time; a text differing by one character, or checked against other allowed prefixes,
is checked afresh.
"""

from __future__ import annotations

import contextlib
from collections.abc import Iterator
from typing import Any

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import cbrs.kb.store as store_module
from cbrs.kb.errors import QuerySyntaxError
from cbrs.kb.remote_access import RemoteAccessError
from cbrs.kb.store import MAX_NESTING, EmbeddedStore

GOOD = "SELECT ?s WHERE { ?s ?p ?o } LIMIT 3"
REACHING = "SELECT * WHERE { SERVICE <http://a.example/sparql> { ?s ?p ?o } }"
DEEP = "SELECT * WHERE " + "{" * (MAX_NESTING + 1) + "}" * (MAX_NESTING + 1)


class Counting:
    """Counts the calls of the checks ``check_query`` makes."""

    def __init__(self, monkeypatch: pytest.MonkeyPatch, store: EmbeddedStore) -> None:
        self.scans = 0
        self.admitted = 0
        nesting, admit = store_module.refuse_deep_nesting, store.guard.admit

        def counted_nesting(text: str) -> None:
            self.scans += 1
            nesting(text)

        def counted_admit(kind: Any, text: str) -> None:
            self.admitted += 1
            admit(kind, text)

        monkeypatch.setattr(store_module, "refuse_deep_nesting", counted_nesting)
        monkeypatch.setattr(store, "guard", _Guard(counted_admit), raising=False)


class _Guard:
    def __init__(self, admit: Any) -> None:
        self.admit = admit


@pytest.fixture
def store() -> Iterator[EmbeddedStore]:
    opened = EmbeddedStore.open(":memory:")
    yield opened
    opened.close()


def test_a_text_that_passed_is_not_scanned_again(store: EmbeddedStore, monkeypatch: pytest.MonkeyPatch) -> None:
    counting = Counting(monkeypatch, store)
    for _ in range(3):
        store.check_query(GOOD)
    assert (counting.scans, counting.admitted) == (1, 1)
    assert list(store.query(GOOD)) == []  # and it still runs


@pytest.mark.parametrize(
    ("text", "error"), [(REACHING, RemoteAccessError), (DEEP, QuerySyntaxError)], ids=["reaching", "deep"]
)
def test_a_text_that_failed_is_refused_every_time(
    store: EmbeddedStore, monkeypatch: pytest.MonkeyPatch, text: str, error: type[Exception]
) -> None:
    counting = Counting(monkeypatch, store)
    for _ in range(3):
        with pytest.raises(error):
            store.check_query(text)
    assert counting.scans == 3


def test_a_text_allowed_under_some_prefixes_is_checked_again_under_others(store: EmbeddedStore) -> None:
    store.remote_access = ("http://a.example/",)
    store.check_query(REACHING)  # allowed, and remembered
    store.remote_access = ()
    with pytest.raises(RemoteAccessError):
        store.check_query(REACHING)


def test_a_text_one_character_away_from_a_passed_one_is_refused(store: EmbeddedStore) -> None:
    store.remote_access = ("http://a.example/",)
    store.check_query(REACHING)
    with pytest.raises(RemoteAccessError):
        store.check_query(REACHING.replace("http://a.", "http://b."))


@settings(max_examples=200, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(position=st.integers(min_value=0, max_value=len(GOOD) - 1), character=st.characters(codec="utf-8"))
def test_any_one_character_change_is_checked_afresh(
    store: EmbeddedStore, monkeypatch: pytest.MonkeyPatch, position: int, character: str
) -> None:
    changed = GOOD[:position] + character + GOOD[position + 1 :]
    store.check_query(GOOD)
    with monkeypatch.context() as patch:
        counting = Counting(patch, store)
        with contextlib.suppress(QuerySyntaxError, RemoteAccessError):
            store.check_query(changed)
        assert counting.scans == (0 if changed == GOOD else 1)


def test_the_remembered_texts_are_bounded(store: EmbeddedStore, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(store, "checked_texts", 2)
    texts = [f"{GOOD} # {n}" for n in range(3)]
    for text in texts:
        store.check_query(text)
    counting = Counting(monkeypatch, store)
    store.check_query(texts[2])
    store.check_query(texts[1])
    assert counting.scans == 0
    store.check_query(texts[0])  # the least recently used went out
    assert counting.scans == 1
