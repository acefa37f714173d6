"""A new user running the named queries and loading JSON-LD: a required parameter left out is named
with what it takes (not ``binding description=None``), and a JSON-LD file with a remote @context is
refused in words that say why (cbrs fetches nothing) rather than in Oxigraph's."""

from __future__ import annotations

from pathlib import Path

import pytest

from cbrs.kb import KnowledgeBase, RdfParseError
from cbrs.kb.errors import BindingError


def test_a_missing_parameter_says_what_it_takes(bundled_kb: KnowledgeBase) -> None:
    with pytest.raises(BindingError) as caught:
        bundled_kb.select("description")
    message = str(caught.value)
    assert message.startswith("binding description: query 'description' needs this parameter (iri: ")
    assert "None" not in message
    assert caught.value.variable == "description" and caught.value.value is None


def test_a_wrong_value_still_shows_the_value(bundled_kb: KnowledgeBase) -> None:
    with pytest.raises(BindingError, match=r"binding description='42': not a valid iri"):
        bundled_kb.select("description", {"description": "42"})


@pytest.mark.parametrize("context", ['"https://schema.org/"', '["https://schema.org/", {"x": "https://e.org/x"}]'])
def test_a_remote_json_ld_context_is_refused_in_plain_words(tmp_path: Path, context: str) -> None:
    path = tmp_path / "thing.jsonld"
    path.write_text('{"@context": ' + context + ', "@id": "https://e.org/a", "name": "x"}', encoding="utf-8")
    kb = KnowledgeBase.open(":memory:")
    before = kb.store.dump()
    with pytest.raises(RdfParseError) as caught:
        kb.load([path])
    message = str(caught.value)
    assert "https://schema.org/" in message and "fetches nothing" in message
    assert "LoadDocumentCallback" not in message
    assert kb.store.dump() == before


def test_white_space_around_a_bound_iri_is_a_paste_s(bundled_kb: KnowledgeBase) -> None:
    rows = bundled_kb.select("description", {"description": " svc:LocateMobileRobot_CeilingCamera01\n"})
    assert {row["description"].value for row in rows} == {
        "https://w3id.org/cbrs/service#LocateMobileRobot_CeilingCamera01"
    }
