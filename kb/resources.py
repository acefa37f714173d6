"""Where the bundled ontologies and named queries are, installed or in a checkout."""

from __future__ import annotations

import tomllib
from dataclasses import dataclass
from pathlib import Path

from cbrs.kb.namespaces import GraphName


def _data_dir(name: str) -> Path:
    """``name`` inside the installed kb package, else at the top of the checkout kb came from.

    pyproject installs the top-level ontologies/ and queries/ folders inside kb, so that a plain
    ``pip install .`` carries them; an editable install or a checkout finds them beside kb/.
    """
    here = Path(__file__).resolve().parent
    for candidate in (here / name, here.parent / name):
        if candidate.is_dir():
            return candidate
    raise FileNotFoundError(f"bundled folder {name!r} is missing beside {here}; reinstall cbrs")


def ontology_dir() -> Path:
    return _data_dir("ontologies")


def query_dir() -> Path:
    return _data_dir("queries")


@dataclass(frozen=True)
class BundledFile:
    path: Path
    graph: GraphName


def bundled_files() -> list[BundledFile]:
    """The files a new store is seeded with, in load order, from ``ontologies/bundle.toml``."""
    folder = ontology_dir()
    manifest = tomllib.loads((folder / "bundle.toml").read_text(encoding="utf-8"))
    return [BundledFile(folder / entry["file"], GraphName(entry["graph"])) for entry in manifest["file"]]
