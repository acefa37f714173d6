"""The seeded bundle, kept: a new store's first contents worked out once and copied afterwards.

What a seed writes (the bundled files parsed, converted and skolemised, then graph:entailed worked out
from them) depends on nothing but the bundled files and the code that reads them, and costs about a
third of a second. Every ``:memory:`` store, every ``cbrs --store :memory: ...`` command and every new
on-disk store starts with it, so :class:`SeedCache` keeps the result as N-Quads, by a digest of those
inputs, in the process and in a cache folder; a later seed with the same digest has Oxigraph read
that copy in one transaction instead (tens of milliseconds). Any change to a bundled file, a named
query or a module of ``cbrs.kb`` gives another digest, so a stale copy is never used; one that cannot
be read is removed and made anew.
"""

from __future__ import annotations

import contextlib
import hashlib
import logging
import os
import tempfile
from pathlib import Path

import pyoxigraph as ox

from cbrs.kb.resources import bundled_files, ontology_dir, query_dir
from cbrs.kb.store import EmbeddedStore

_log = logging.getLogger(__name__)

ENVIRONMENT = "CBRS_SEED_CACHE"
"""A folder for the kept seeds, or ``off`` to keep them only in the process (docs/settings.md)."""

KEEP = 4
"""Kept seeds per folder, the newest: other cbrs versions may share the folder, so not only the last."""

_kept: dict[str, bytes] = {}  # digest -> N-Quads, this process's copy (one entry)


def default_folder() -> Path | None:
    """``$CBRS_SEED_CACHE``, else the user's cache folder for cbrs; None when the variable says ``off``."""
    value = os.environ.get(ENVIRONMENT, "").strip()
    if value.lower() in ("off", "0", "no", "false"):
        return None
    if value:
        return Path(value)
    from platformdirs import user_cache_dir  # only a seed needs it

    return Path(user_cache_dir("cbrs", appauthor=False))


def bundle_digest() -> str:
    """A digest of everything a seed's result depends on: the bundled files, the named queries and
    the kb package's modules (names and bytes, in a fixed order)."""
    code = Path(__file__).resolve().parent
    inputs = [ontology_dir() / "bundle.toml", *(item.path for item in bundled_files())]
    inputs += sorted(query_dir().glob("*.rq")) + sorted(code.glob("*.py"))
    digest = hashlib.sha256()
    for path in inputs:
        for part in (path.name.encode("utf-8"), path.read_bytes()):
            digest.update(part)
            digest.update(b"\0")
    return digest.hexdigest()[:32]


class SeedCache:
    """Seeds kept in this process and, unless ``folder`` is None, in ``folder/seed-<digest>.nq``."""

    def __init__(self, folder: Path | None) -> None:
        self.folder = folder

    @classmethod
    def default(cls) -> SeedCache:
        return cls(default_folder())

    def path(self, digest: str) -> Path | None:
        return None if self.folder is None else self.folder / f"seed-{digest}.nq"

    def restore(self, digest: str, store: EmbeddedStore) -> bool:
        """Add the seed kept under ``digest`` to ``store`` in one transaction; False when none is kept
        (or the kept file cannot be read: it is removed, and ``store`` is left as it was)."""
        data = _kept.get(digest)
        path = self.path(digest)
        if data is None and path is not None and path.is_file():
            with contextlib.suppress(OSError):
                data = path.read_bytes()
        if data is None:
            return False
        try:
            store.add_nquads(data)
        except SyntaxError as error:
            _log.warning("ignoring the kept seed %s, which cannot be read (it is made anew): %s", path, error)
            _kept.pop(digest, None)
            if path is not None:
                with contextlib.suppress(OSError):
                    path.unlink()
            return False
        _remember(digest, data)
        return True

    def keep(self, digest: str, store: EmbeddedStore) -> None:
        """Keep what ``store`` holds (a seed just made) under ``digest``: in the process, and in the
        folder when it can be written (a read-only or full disk costs later processes a full seed)."""
        data = ox.serialize(list(store.quads()), format=ox.RdfFormat.N_QUADS) or b""
        _remember(digest, data)
        path = self.path(digest)
        if path is None or path.is_file():
            return
        try:
            path.parent.mkdir(parents=True, exist_ok=True)
            handle, partial = tempfile.mkstemp(prefix=".seed-", suffix=".part", dir=path.parent)
            try:
                with os.fdopen(handle, "wb") as out:
                    out.write(data)
                os.replace(partial, path)  # whole or absent: a reader never sees half a file
            finally:
                with contextlib.suppress(FileNotFoundError):
                    os.unlink(partial)
            _prune(path.parent, KEEP)
        except OSError as error:
            _log.info("the seed could not be kept in %s: %s", path.parent, error)


def _remember(digest: str, data: bytes) -> None:
    if digest not in _kept:
        _kept.clear()  # one bundle per process; an older digest's seed is of no further use
        _kept[digest] = data


def _prune(folder: Path, keep: int) -> None:
    kept = sorted(folder.glob("seed-*.nq"), key=lambda path: path.stat().st_mtime, reverse=True)
    for old in kept[keep:]:
        with contextlib.suppress(FileNotFoundError):
            old.unlink()
