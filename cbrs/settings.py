"""The one table of cbrs settings: name, default, help and environment variable.

The CLI's global options, ``cbrs settings`` and docs/settings.md all come from ``SETTINGS``;
a value is taken from the command line, else the environment, else the default.
"""

from __future__ import annotations

import os
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from platformdirs import user_data_dir


def _default_store() -> str:
    return str(Path(user_data_dir("cbrs", appauthor=False)) / "store")


@dataclass(frozen=True)
class Setting:
    name: str
    default: Callable[[], Any]
    help: str
    env: str
    parse: Callable[[str], Any] = str

    def resolve(self, given: Any = None, environ: Mapping[str, str] | None = None) -> Any:
        if given is not None:
            return given
        raw = (os.environ if environ is None else environ).get(self.env)
        if raw not in (None, ""):
            try:
                return self.parse(raw)
            except ValueError as error:
                raise ValueError(f"environment variable {self.env}={raw!r}: {error}") from error
        return self.default()


SETTINGS: tuple[Setting, ...] = (
    Setting(
        "store",
        _default_store,
        "Where the knowledge base lives: a directory for the embedded Oxigraph store "
        "(created and seeded on first use), or :memory: for a throw-away one.",
        "CBRS_STORE",
    ),
    Setting(
        "format",
        lambda: "table",
        "Default output format of cbrs query: table, json, csv or tsv.",
        "CBRS_FORMAT",
    ),
)

BY_NAME = {setting.name: setting for setting in SETTINGS}


def setting(name: str) -> Setting:
    return BY_NAME[name]
