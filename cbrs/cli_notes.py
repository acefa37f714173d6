"""What the ``cbrs`` command says at its edges besides its output: errors as JSON for a command asked for
JSON, the notes an error gathered on its way up, a store the command made where none was, and one it
upgraded."""

from __future__ import annotations

import logging
import sys
from pathlib import Path

import click

from cbrs.kb.errors import without_password
from cbrs.kb.store import MEMORY, is_remote
from cbrs.kb.upgrade import UpgradeReport
from cbrs.kb.upgrade import log as upgrade_log
from cbrs.settings import setting


def wants_json(args: list[str], command: str | None) -> bool:
    """Whether the command was asked for JSON (--json, --format json, or CBRS_FORMAT=json for cbrs query):
    then an error is a JSON object on standard output too, beside the line on standard error, so that a
    program reading the output always gets JSON (it got nothing)."""
    if "--json" in args or "--format=json" in args:
        return True
    if "--format" in args:
        given = args.index("--format") + 1
        return given < len(args) and args[given] == "json"
    if command != "query":
        return False
    try:
        return bool(setting("format").resolve() == "json")
    except ValueError:
        return False


def with_notes(error: BaseException) -> str:
    """The error's message with the notes added to it on its way up (what a failed write left behind,
    kb/staged_writes.py), which ``str`` leaves out."""
    notes = [str(note) for note in getattr(error, "__notes__", ())]
    return "; ".join([str(error), *notes])


def _at_terminal() -> bool:
    return sys.stderr.isatty()


def no_store_at(location: str) -> bool:
    return location != MEMORY and not is_remote(location) and not Path(location).expanduser().exists()


def note_new_store(location: str) -> None:
    """Say that the command made the store it used: a mistyped path (CBRS_STORE=~/cbrs-stroe) gave a new
    store of the bundled data without a word, and the user's own looked lost. To a person at a terminal
    only, as the progress line: a script that starts from a fresh directory means to."""
    if _at_terminal() and Path(location).expanduser().is_dir():
        click.echo(
            f"note: there was no store at {location}: a new one was made there, seeded with the bundled data "
            "(is the path right? cbrs init makes one on purpose)",
            err=True,
        )


def note_upgraded_store(location: str, report: UpgradeReport) -> None:
    """Say that opening the store brought it up to the bundled ontologies, and from which versions to which:
    it changed the user's store, once, and a command said nothing of it. Said whether or not a person is at
    a terminal (a cron job's mail or a unit's journal should carry it too), unless the log already says it
    (``cbrs serve`` logs the upgrade at INFO)."""
    if upgrade_log.isEnabledFor(logging.INFO) and upgrade_log.hasHandlers():
        return
    # no version changed: conditions rewritten, or an emptied map given the bundled one
    what = ", ".join(report.versions) or f"{report.removed} quads out, {report.added} in"
    click.echo(
        f"note: upgraded the store at {without_password(location)} to this cbrs's bundled ontologies: {what}",
        err=True,
    )
