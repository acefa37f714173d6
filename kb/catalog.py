"""Offline resolution of ontology IRIs to local files.

A :class:`Catalogue` answers "which local file holds the ontology ``<iri>``?" from three kinds of
entry, tried in this order:

1. exact entries (an IRI and a file), from an OASIS XML catalogue (``<uri name=... uri=...>``, the
   ``catalog-v001.xml`` that Protégé reads) or a two-column TSV file;
2. prefix entries (an IRI prefix and a folder): ``<rewriteURI uriStartString=... rewritePrefix=...>``
   in an XML catalogue, a TSV row whose IRI ends in ``/``, and for a folder catalogue the prefix
   ``http://127.0.0.1/ontology/`` (where the OWLS-TC collection puts its ontologies);
3. folders searched by the IRI's last path segment: ``http://example.org/onto/books.owl#Book`` is
   looked up as ``DIR/books.owl``.

Nothing is ever fetched: an IRI no entry covers resolves to ``None``, and the caller reports it.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from urllib.parse import unquote, urlsplit

from cbrs.kb.errors import CatalogueError
from cbrs.kb.namespaces import OWL, RDF, RDFS, XSD

OWLS_TC_PREFIX = "http://127.0.0.1/ontology/"
OASIS_NS = "urn:oasis:names:tc:entity:xmlns:xml:catalog"

PROTEGE_CATALOGUE = "catalog-v001.xml"
"""The catalogue Protégé reads from, and writes into, the folder of an ontology it opens."""

# Vocabularies every RDF tool knows: importing them needs no file, so they are never "unresolved".
BUILT_IN = tuple(ns.rstrip("#") for ns in (RDF, RDFS, OWL, XSD))


def ontology_iri(iri: str) -> str:
    """The document part of an IRI: without its fragment, or the IRI itself when it has none."""
    return iri.split("#", 1)[0]


def namespace_document(term: str) -> str:
    """The ontology a term most likely belongs to: before ``#``, else up to the last ``/``."""
    if "#" in term:
        return term.split("#", 1)[0]
    head, sep, _ = term.rpartition("/")
    return head if sep and "://" in head else term


def is_built_in(iri: str) -> bool:
    document = ontology_iri(iri).rstrip("/")
    return document in BUILT_IN


@dataclass
class Catalogue:
    """Maps ontology IRIs to local files, without ever using the network."""

    entries: dict[str, Path] = field(default_factory=dict)
    prefixes: list[tuple[str, Path]] = field(default_factory=list)
    folders: list[Path] = field(default_factory=list)
    source: str = "<catalogue>"

    # -- construction -----------------------------------------------------------------------

    @classmethod
    def open(cls, location: str | Path) -> Catalogue:
        """A folder catalogue for a directory, else a mapping file (OASIS XML or TSV)."""
        path = Path(location)
        if path.is_dir():
            return cls.from_directory(path)
        if path.is_file():
            return cls.from_file(path)
        raise CatalogueError(str(path), "no such file or directory")

    @classmethod
    def from_directory(cls, folder: str | Path, prefixes: Iterable[str] = (OWLS_TC_PREFIX,)) -> Catalogue:
        """Every file in ``folder`` answers for IRIs ending in its name, and for ``prefixes`` + its path;
        first, the ``catalog-v001.xml`` Protégé keeps in the folder of an ontology, if there is one (its
        entries were passed over: an import of ``http://lab/glassware`` mapped there to ``glassware.ttl``
        was unresolved, the folder having no file named ``glassware``)."""
        path = Path(folder)
        if not path.is_dir():
            raise CatalogueError(str(path), "is not a directory")
        catalogue = cls(prefixes=[(prefix, path) for prefix in prefixes], folders=[path], source=str(path))
        protege = path / PROTEGE_CATALOGUE
        if protege.is_file():
            kept = cls.from_file(protege)
            catalogue.entries.update(kept.entries)
            catalogue.prefixes[:0] = kept.prefixes
        return catalogue

    @classmethod
    def from_file(cls, path: str | Path) -> Catalogue:
        """Read an OASIS XML catalogue or a TSV file (``IRI<TAB>file``; ``#`` starts a comment)."""
        path = Path(path)
        try:
            raw = path.read_bytes()
        except OSError as error:
            raise CatalogueError(str(path), f"cannot read: {error.strerror or error}") from error
        if raw.lstrip().startswith(b"<"):
            return cls._from_xml(path, raw)
        return cls._from_tsv(path, raw)

    @classmethod
    def _from_xml(cls, path: Path, raw: bytes) -> Catalogue:
        try:
            root = ET.fromstring(raw)
        except ET.ParseError as error:
            raise CatalogueError(str(path), f"not well-formed XML: {error}") from error
        if _local(root.tag) != "catalog":
            raise CatalogueError(str(path), f"root element is <{_local(root.tag)}>, not an OASIS <catalog>")
        catalogue = cls(source=str(path))
        catalogue._read_xml(root, path.parent, path, set())
        return catalogue

    def _read_xml(self, element: ET.Element, base: Path, path: Path, seen: set[Path]) -> None:
        seen.add(path.resolve())
        xml_base = element.get("{http://www.w3.org/XML/1998/namespace}base")
        if xml_base:
            base = base / xml_base
        for child in element:
            tag = _local(child.tag)
            if tag == "uri" and child.get("name") and child.get("uri"):
                self.entries[str(child.get("name"))] = _file_target(base, str(child.get("uri")))
            elif tag == "rewriteURI" and child.get("uriStartString") and child.get("rewritePrefix"):
                target = _file_target(base, str(child.get("rewritePrefix")))
                self.prefixes.append((str(child.get("uriStartString")), target))
            elif tag == "group":
                self._read_xml(child, base, path, seen)
            elif tag == "nextCatalog" and child.get("catalog"):
                nested = _file_target(base, str(child.get("catalog")))
                if nested.resolve() in seen or not nested.is_file():
                    continue  # a missing or cyclic next catalogue adds nothing
                try:
                    root = ET.fromstring(nested.read_bytes())
                except (OSError, ET.ParseError) as error:
                    raise CatalogueError(str(nested), str(error)) from error
                self._read_xml(root, nested.parent, nested, seen)

    @classmethod
    def _from_tsv(cls, path: Path, raw: bytes) -> Catalogue:
        catalogue = cls(source=str(path))
        try:
            text = raw.decode("utf-8-sig")
        except UnicodeDecodeError as error:
            raise CatalogueError(str(path), f"not UTF-8: byte {error.start}") from error
        for number, line in enumerate(text.splitlines(), start=1):
            if not line.strip() or line.lstrip().startswith("#"):
                continue
            columns = [c.strip() for c in line.split("\t")]
            if len(columns) != 2 or not all(columns):
                raise CatalogueError(f"{path}:{number}", "expected two tab-separated columns: IRI and file")
            catalogue._add(columns[0], path.parent / columns[1])
        return catalogue

    def _add(self, iri: str, target: Path) -> None:
        if iri.endswith("/"):
            self.prefixes.append((iri, target))
        else:
            self.entries[iri] = target

    # -- lookup ------------------------------------------------------------------------------

    def resolve(self, iri: str) -> Path | None:
        """The local file for ``iri`` (its fragment ignored), or None; never touches the network."""
        document = ontology_iri(iri)
        for key in (iri, document, document.rstrip("/"), document + "#"):
            target = self.entries.get(key)
            if target is not None and target.is_file():
                return target
        for prefix, folder in sorted(self.prefixes, key=lambda item: -len(item[0])):
            if document.startswith(prefix):
                target = _inside(folder, unquote(document[len(prefix) :]))
                if target is not None and target.is_file():
                    return target
        segment = _last_segment(document)
        if segment:
            for folder in self.folders:
                target = folder / segment
                if target.is_file():
                    return target
        return None

    def iri_for(self, path: str | Path) -> str | None:
        """The ontology IRI this catalogue maps to the file ``path`` (its exact entries first, then
        its prefixes), or None; a file read for that IRI takes it as its base."""
        wanted = Path(path).resolve()
        for iri, target in self.entries.items():
            if target.resolve() == wanted:
                return iri
        for prefix, folder in self.prefixes:
            try:
                relative = wanted.relative_to(folder.resolve())
            except ValueError:
                continue
            return prefix + relative.as_posix()
        return None


def _inside(folder: Path, rest: str) -> Path | None:
    """``folder/rest`` if it stays inside ``folder``: an IRI must not reach other files through ``..``,
    an absolute path (``/etc/passwd`` or ``%2Fetc``, which ``Path`` joins by replacing) or a symlink."""
    if not rest or "\x00" in rest:
        return None
    target = (folder / rest).resolve()
    return target if target.is_relative_to(folder.resolve()) else None


@dataclass(frozen=True)
class Unresolved:
    """An ontology IRI that no catalogue entry covers, and the file whose load needed it."""

    iri: str
    needed_by: str
    reason: str  # "owl:imports" or "namespace"


def merge(catalogues: Sequence[Catalogue]) -> Catalogue:
    """One catalogue asking each of ``catalogues`` in turn (their entries, prefixes and folders)."""
    merged = Catalogue(source=", ".join(c.source for c in catalogues))
    for catalogue in catalogues:
        for iri, target in catalogue.entries.items():
            merged.entries.setdefault(iri, target)
        merged.prefixes.extend(catalogue.prefixes)
        merged.folders.extend(catalogue.folders)
    return merged


def _local(tag: str) -> str:
    return tag.rsplit("}", 1)[-1]


def _file_target(base: Path, reference: str) -> Path:
    """A catalogue's ``uri`` attribute: a relative path or a ``file:`` URI."""
    if reference.startswith("file:"):
        return Path(unquote(urlsplit(reference).path))
    return base / unquote(reference)


def _last_segment(document: str) -> str:
    path = urlsplit(document).path if "://" in document else document
    segment = unquote(path.rstrip("/").rsplit("/", 1)[-1])
    return segment if segment not in ("", ".", "..") else ""
