"""A new store seeded from the kept copy of the bundle's seed holds exactly what a full seed gives."""

from __future__ import annotations

from pathlib import Path

import pytest

from cbrs.kb import seed_cache
from cbrs.kb.knowledge_base import KnowledgeBase
from cbrs.kb.resources import BundledFile
from cbrs.kb.seed_cache import SeedCache, bundle_digest
from cbrs.kb.store import Store


def _full_seed() -> KnowledgeBase:
    kb = KnowledgeBase(Store.open(":memory:"))
    kb.seed()
    return kb


@pytest.fixture(autouse=True)
def no_process_copy() -> None:
    seed_cache._kept.clear()  # each test starts with nothing kept in the process


def test_a_seed_from_the_kept_copy_equals_a_full_seed(tmp_path: Path) -> None:
    cache = SeedCache(tmp_path)
    first = KnowledgeBase.open(":memory:", seed_cache=cache)  # seeds in full and keeps the result
    kept = cache.path(bundle_digest())
    assert kept is not None and kept.is_file()
    seed_cache._kept.clear()  # the next store is seeded from the file, as in a new process
    copied = KnowledgeBase.open(":memory:", seed_cache=cache)
    full = _full_seed()
    assert copied.store.dump() == full.store.dump() == first.store.dump()
    assert copied.store.graphs() == full.store.graphs()
    assert [ad.iri for ad in copied.advertisements()] == [ad.iri for ad in full.advertisements()]


def test_an_on_disk_store_is_seeded_from_the_copy_too(tmp_path: Path) -> None:
    cache = SeedCache(tmp_path / "cache")
    KnowledgeBase.open(":memory:", seed_cache=cache)
    on_disk = KnowledgeBase.open(tmp_path / "store", seed_cache=cache)
    try:
        assert on_disk.store.dump() == _full_seed().store.dump()
    finally:
        on_disk.close()


def test_a_copy_that_cannot_be_read_is_ignored_and_made_anew(tmp_path: Path) -> None:
    cache = SeedCache(tmp_path)
    kept = cache.path(bundle_digest())
    assert kept is not None
    kept.write_bytes(b"<http://example.org/a> <http://example.org/b> this is not N-Quads .\n")
    kb = KnowledgeBase.open(":memory:", seed_cache=cache)
    assert kb.store.dump() == _full_seed().store.dump()
    assert b"not N-Quads" not in kept.read_bytes()  # replaced by the seed just made


def test_without_a_folder_nothing_is_written_and_the_process_keeps_its_copy(tmp_path: Path) -> None:
    cache = SeedCache(None)
    first = KnowledgeBase.open(":memory:", seed_cache=cache)
    assert bundle_digest() in seed_cache._kept
    second = KnowledgeBase.open(":memory:", seed_cache=cache)
    assert second.store.dump() == first.store.dump()
    assert list(tmp_path.iterdir()) == []


def test_the_environment_chooses_the_folder_or_turns_it_off(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("CBRS_SEED_CACHE", str(tmp_path))
    assert SeedCache.default().folder == tmp_path
    monkeypatch.setenv("CBRS_SEED_CACHE", "off")
    assert SeedCache.default().folder is None


def test_an_unwritable_folder_costs_only_the_copy(tmp_path: Path) -> None:
    blocker = tmp_path / "a-file"
    blocker.write_text("not a folder")
    kb = KnowledgeBase.open(":memory:", seed_cache=SeedCache(blocker / "cache"))
    assert kb.store.is_seeded()


def test_only_the_newest_copies_are_kept(tmp_path: Path) -> None:
    for n in range(seed_cache.KEEP + 2):
        (tmp_path / f"seed-old{n}.nq").write_bytes(b"")
    KnowledgeBase.open(":memory:", seed_cache=SeedCache(tmp_path))
    left = sorted(path.name for path in tmp_path.glob("seed-*.nq"))
    assert len(left) == seed_cache.KEEP
    assert f"seed-{bundle_digest()}.nq" in left


def test_the_digest_follows_the_bundled_files(monkeypatch: pytest.MonkeyPatch, tmp_path: Path) -> None:
    before = bundle_digest()
    changed = tmp_path / "bundled.ttl"
    changed.write_text("# a bundled file that says something else\n")
    original = seed_cache.bundled_files

    def files() -> list[BundledFile]:
        items = original()
        return [BundledFile(changed, items[0].graph), *items[1:]]

    monkeypatch.setattr(seed_cache, "bundled_files", files)
    assert bundle_digest() != before


def test_a_store_seeded_over_a_labs_graph_keeps_no_copy_of_it(tmp_path: Path) -> None:
    """A lab's graph loaded into an unseeded store, then the store seeded (opened again as usual): its whole
    contents were kept as the bundle's seed, so every later ``:memory:`` store of the process held the lab's
    graph too (the final suite's test_backup and test_remote_store met test_check_write_back's)."""
    lab = tmp_path / "lab.ttl"
    lab.write_text("<urn:lab:a> <urn:lab:b> <urn:lab:c> .\n", encoding="utf-8")
    cache = SeedCache(tmp_path / "cache")
    unseeded = KnowledgeBase.open(tmp_path / "store", seed=False)
    unseeded.load([lab], graph="https://example.org/lab/graph")
    unseeded.close()
    seeded = KnowledgeBase.open(tmp_path / "store", seed_cache=cache)
    try:
        assert "https://example.org/lab/graph" in seeded.store.graphs()
    finally:
        seeded.close()
    later = KnowledgeBase.open(":memory:", seed_cache=cache)
    assert later.store.dump() == _full_seed().store.dump()
