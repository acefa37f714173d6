"""Every tunable parameter of matchmaking in one place, with the defaults docs/matchmaking.md explains."""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class MatchConfig:
    # Sem-Str, Situation 3: weights of the core word and of the complementary words (alpha > beta).
    alpha: float = 0.7
    beta: float = 0.3
    # Sem-Str, Situation 3: Jaro-Winkler at or below this is chance agreement between different words and
    # counts 0; above it, values are stretched back to [0, 1] (about 95 % of pairs of different words in
    # the bundled ontologies score below 0.65).
    jaro_winkler_floor: float = 0.65
    # A pair of entities counts as matched when its similarity reaches this threshold (CSS, PE).
    pair_threshold: float = 0.5
    # Weights of subject, predicate and object in an RDF statement's similarity (equation 8).
    subject_weight: float = 1 / 3
    predicate_weight: float = 1 / 3
    object_weight: float = 1 / 3
    # How the parts of a match combine; parts the requirement does not state are left out and the
    # remaining weights renormalised.
    output_weight: float = 0.4
    input_weight: float = 0.2
    effect_weight: float = 0.3
    precondition_weight: float = 0.1
    # An advertised input the requester offers as the same concept or a subclass can be given as it is:
    # the advertisement can be invoked with it (OWL-S plug-in), so the "can it be invoked?" side scores 1.
    plugin_inputs: bool = True
    # An advertised concept that is a subclass of the requested one inherits every part of it: those parts
    # count as covered (similarity 1) in CSS instead of being left out as implied.
    inherited_parts: bool = True
    # The hybrid method (sem-str-text): the share of the TF-IDF cosine of names and text descriptions in
    # the ranking score; the rest is the Sem-Str IO/PE score, which alone decides acceptability.
    text_weight: float = 0.3
    # A candidate that passes the SEA and QoS filters is acceptable from this combined score up.
    accept_score: float = 0.5
    # An advertisement that states no value for a QoS metric the requirement bounds: fail it?
    qos_missing_fails: bool = True

    def __post_init__(self) -> None:
        if not self.alpha > self.beta >= 0 or abs(self.alpha + self.beta - 1) > 1e-9:
            raise ValueError(f"need alpha > beta >= 0 and alpha + beta = 1, got {self.alpha}, {self.beta}")
        if not 0 <= self.jaro_winkler_floor < 1:
            raise ValueError(f"jaro_winkler_floor must lie in [0, 1), got {self.jaro_winkler_floor}")
        for name in ("pair_threshold", "accept_score", "text_weight"):
            value = getattr(self, name)
            if not 0 <= value <= 1:
                raise ValueError(f"{name} must lie in [0, 1], got {value}")
        spo = self.subject_weight + self.predicate_weight + self.object_weight
        if abs(spo - 1) > 1e-9:
            raise ValueError(f"subject, predicate and object weights must sum to 1, got {spo}")
