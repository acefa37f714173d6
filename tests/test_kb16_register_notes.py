"""``cbrs register --update FILE`` of an OWL-S file says what ``cbrs load FILE`` says of the file besides its
counts: imports not followed, concepts no loaded ontology declares, conversion notes (a condition kept as
text), what was mended to read it. It converts the file as a load does (``kb.loader.prepare_owls``), but
printed only the IRIs it registered or updated, so a user who replaced a description with it never
learnt that a condition had become text only or a parameter type was unknown."""

from __future__ import annotations

from pathlib import Path

from .conftest import make_mini_kb
from .test_cli import run
from .test_load_counts import NAVIGATE
from .test_register_update_partial import TWO

NOTES = ("imports not followed", "  of which", "unresolved ", "conversion notes: ", "preconditions and effects: ")


def _noted(tmp_path: Path) -> Path:
    """navigate.owls with a PDDL precondition that does not parse (kept as text, a conversion note) and an
    rdf:ID that is not an XML name (mended)."""
    text = NAVIGATE.read_text(encoding="utf-8")
    text = text.replace("(robots:Charged ?Robot)", "(robots:Charged ?Robot").replace(
        'rdf:ID="Operator"', 'rdf:ID="1Op"'
    )
    folder = tmp_path / "edited"
    folder.mkdir(exist_ok=True)
    path = folder / NAVIGATE.name
    path.write_text(text, encoding="utf-8")
    return path


def _notes(output: str) -> list[str]:
    return [line for line in output.splitlines() if line.startswith(NOTES)]


def test_register_update_prints_the_notes_a_load_prints(tmp_path: Path) -> None:
    path = _noted(tmp_path)
    code, loaded = run("load", str(path), store=str(tmp_path / "loaded"))
    assert code == 0, loaded
    code, registered = run("register", "--update", str(path), store=str(tmp_path / "registered"))
    assert code == 0, registered
    expected = _notes(loaded)
    assert [line.split(":")[0] for line in expected] == [
        "imports not followed (no --catalog)",
        "unresolved parameter types (declared by no loaded ontology)",
        "unresolved statement terms (declared by no loaded ontology)",
        "conversion notes",
        "preconditions and effects",
    ]
    assert "PDDL expression kept as text (1 unclosed '(')" in expected[3]
    assert _notes(registered) == expected
    assert registered.splitlines()[0] == "registered navigate:NavigateService"  # as the browser names it
    mended = "(mended: rdf:ID values that are not XML names, read as rdf:about)"
    assert mended in loaded
    assert f"read {path} {mended}" in registered.splitlines()


def test_an_update_of_a_loaded_file_prints_them_too(tmp_path: Path) -> None:
    store = str(tmp_path / "store")
    assert run("load", str(NAVIGATE), store=store)[0] == 0
    code, output = run("register", "--update", str(_noted(tmp_path)), store=store)
    assert code == 0, output
    assert output.splitlines()[0] == "updated navigate:NavigateService"
    assert any(line.startswith("conversion notes: ") and "unclosed" in line for line in output.splitlines())


def test_a_turtle_update_has_no_conversion_to_report(tmp_path: Path) -> None:
    kb = make_mini_kb(":memory:")  # declares the types TWO's advertisements use
    try:
        done = kb.registry.synced(TWO, "two.ttl")
        assert done.conversion is None and len(done.registered) == 2
        converted = kb.registry.synced(_noted(tmp_path).read_bytes(), str(_noted(tmp_path)))
        assert converted.conversion is not None
        assert converted.conversion.files[0].owls is not None
        assert any("unclosed" in note for note in converted.conversion.files[0].owls.notes)
    finally:
        kb.close()
