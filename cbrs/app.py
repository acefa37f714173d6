"""What every command is handed: the resolved settings and, opened on first use, the knowledge base."""

from __future__ import annotations

from dataclasses import dataclass, field

import click
import pyoxigraph as ox

from cbrs.cli_notes import note_upgraded_store
from cbrs.kb import KnowledgeBase
from cbrs.kb.errors import StoreError
from cbrs.kb.namespaces import expand
from cbrs.kb.store import StoreInUseError
from cbrs.settings import setting


@dataclass
class App:
    """Settings for this run, and the knowledge base they name."""

    store_location: str
    _kb: KnowledgeBase | None = field(default=None, repr=False)

    @property
    def kb(self) -> KnowledgeBase:
        return self.open_kb()

    def open_kb(self, seed: bool = True) -> KnowledgeBase:
        """The knowledge base, opened on first use; ``seed=False`` for a command that replaces the store's
        contents whole (``cbrs restore``): a new store is not seeded, an old one not upgraded, first."""
        if self._kb is None:
            try:
                opened = KnowledgeBase.open(
                    self.store_location,
                    seed=seed,
                    remote_timeout=setting("remote_timeout").resolve(),
                    check_timeout=setting("query_check_timeout").resolve(),
                    remote_access=setting("federation_allow").resolve(),
                    remote_token=setting("update_token").resolve(),
                    remote_batch=_batch(setting("remote_batch").resolve()),
                )
            except StoreInUseError as error:  # the library advises a program; a person at the CLI, this
                hint = (
                    f"a cbrs server serves it: use --store {error.served} (the token from CBRS_UPDATE_TOKEN)"
                    if error.served
                    else "stop it or pick another store with --store"
                )
                reason = f"is in use by another process (RocksDB lock held); {hint} ({error.cause})"
                raise StoreError(error.location, reason) from error
            self._kb = opened
            if opened.upgraded is not None:
                note_upgraded_store(opened.store.location, opened.upgraded)
        return self._kb

    @property
    def opened_kb(self) -> KnowledgeBase | None:
        """The knowledge base if a command has opened it, else None (nothing is opened)."""
        return self._kb

    def close(self) -> None:
        """Flush and release the store, so the next command (even in this process) can open it."""
        if self._kb is not None:
            self._kb.close()
            self._kb = None


pass_app = click.make_pass_decorator(App)


def _batch(value: int | str) -> int | None:
    """The remote_batch setting as KnowledgeBase.open takes it: None lets the store choose."""
    return None if value == "auto" else int(value)


def parse_iri(name: str, hint: str = "IRI", default_prefix: str | None = None) -> str:
    """A full IRI from ``prefix:local`` or an absolute IRI, as a click usage error otherwise; with
    ``default_prefix``, a bare name is taken in it (``RobotSelfPosition`` as ``req:RobotSelfPosition``)."""
    if default_prefix is not None and ":" not in name:
        name = f"{default_prefix}:{name}"
    try:
        full = expand(name)
    except ValueError as error:
        raise click.BadParameter(str(error), param_hint=hint) from error
    try:  # a space or a quote left in: said of the name as typed, not "Invalid IRI code point" alone
        ox.NamedNode(full)
    except ValueError as error:
        raise click.BadParameter(f"{name!r} is not an IRI: {error}", param_hint=hint) from None
    return full
