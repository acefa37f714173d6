"""The New task page points at the line of the task's text that writes the term at fault
(``cbrs.task_drafts.line_of``), not at a comment that names it: the sixth round's misspelt fridge class
(docs/examples/lab6_mistake_watch_the_fridgge.ttl) names home:Refridgerator in its header comment, and the
page said "line 1" for the class written on line 14. Seen by the example sweep's New task form."""

from __future__ import annotations

from pathlib import Path

from cbrs.task_drafts import line_of

FRIDGE = Path(__file__).resolve().parents[1] / "docs" / "examples" / "lab6_mistake_watch_the_fridgge.ttl"


def test_a_term_named_in_a_comment_is_found_where_the_turtle_writes_it() -> None:
    text = FRIDGE.read_text(encoding="utf-8")
    written = next(n for n, line in enumerate(text.splitlines(), 1) if "parameterType home:Refridgerator" in line)
    assert line_of(text, "home:Refridgerator") == written
    assert written > 1


def test_a_hash_inside_an_iri_or_a_string_starts_no_comment() -> None:
    text = '# lab:B is here\nlab:A rdfs:label "a # b lab:B" ; lab:p <https://example.org/a#B> ; lab:q lab:B .\n'
    assert line_of(text, "<https://example.org/a#B>") == 2
    assert line_of(text, "lab:B") == 2  # in the string, as the text writes it; the comment's is not
    assert line_of("lab:A lab:p lab:C . # lab:B\n", "lab:B") is None


def test_a_long_string_spanning_lines_is_no_comment_and_hides_no_term() -> None:
    text = 'lab:A rdfs:comment """one\n# not a comment lab:B\n""" ;\n  lab:p lab:B .\n'
    assert line_of(text, "lab:B") == 2
