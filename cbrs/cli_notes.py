"""What the ``cbrs`` command says at its edges besides its output: errors as JSON for a command asked for
JSON, the notes an error gathered on its way up, and a store the command made where none was."""

from __future__ import annotations

import sys
from pathlib import Path

import click

from cbrs.kb.store import MEMORY, is_remote
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
