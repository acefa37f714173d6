"""The matching methods behind one interface: an entity measure and how it is applied."""

from __future__ import annotations

from dataclasses import dataclass

from cbrs.reasoner.config import MatchConfig
from cbrs.reasoner.similarity import EntityMeasure, Lin, SemStr, StringMatch, WuPalmer
from cbrs.reasoner.taxonomy import TaxonomyIndex

METHODS = ("sem-str", "string", "wu-palmer", "lin", "logic", "sem-str-text")
# The methods that use the refinements of docs/matchmaking.md section 9; the baselines keep the published
# frame (MatchConfig.published).
REFINED = frozenset({"sem-str", "sem-str-text"})


@dataclass(frozen=True)
class Method:
    """``use_parts``: compare part trees (CSS) or roots only; ``strict``: logic degrees, every
    requested output must match (Paolucci et al.); ``taxonomy``: the method reads is-a links, so an
    input offered as a subclass of the advertised one counts as invocable (MatchConfig.plugin_inputs);
    ``text``: the ranking score mixes in the text similarity of the descriptions (MatchConfig.text_weight)."""

    name: str
    measure: EntityMeasure
    use_parts: bool
    strict: bool = False
    taxonomy: bool = True
    text: bool = False


def make_method(name: str, index: TaxonomyIndex, config: MatchConfig) -> Method:
    if name == "sem-str":
        return Method(name, SemStr(index, config), use_parts=True)
    if name == "sem-str-text":
        return Method(name, SemStr(index, config), use_parts=True, text=True)
    if name == "wu-palmer":
        return Method(name, WuPalmer(index), use_parts=False)
    if name == "lin":
        return Method(name, Lin(index), use_parts=False)
    if name == "string":
        return Method(name, StringMatch(), use_parts=False, taxonomy=False)
    if name == "logic":
        return Method(name, WuPalmer(index), use_parts=False, strict=True)
    raise ValueError(f"unknown matching method {name!r}; use one of {', '.join(METHODS)}")
