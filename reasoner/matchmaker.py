"""The matchmaker: rank every advertisement against a requirement, and say why.

A candidate's score combines up to five parts, each in [0, 1]; parts the requirement does not state are
left out and the weights of the rest renormalised (MatchConfig):

- outputs: each requested output's best CSS against the advertised outputs, averaged;
- inputs: both ways, averaged: each advertised input's best CSS against the inputs the requirement
  provides (can it be invoked?) and each provided input's best CSS against the advertised inputs (does
  it use what the requester offers?);
- effects: each requested effect's best statement similarity against the advertised effects;
- deletes: likewise for what the requirement asks to stop being true, against the advertised delete
  effects;
- preconditions: each advertised precondition's best statement similarity against the
  preconditions the requirement guarantees (only when it states any); all must hold, so the lowest
  counts (MatchConfig.precondition_conjunction).

The SEA and QoS of the requirement act as filters. "No acceptable match" is a status.
"""

from __future__ import annotations

import gc
import math
import threading
from collections.abc import Callable, Sequence
from dataclasses import asdict, dataclass
from enum import Enum
from typing import TYPE_CHECKING, Any, overload

from cbrs.kb import (
    Advertisement,
    EffectiveArea,
    KnowledgeBase,
    NotFoundError,
    Parameter,
    PartNode,
    QoSValue,
    Requirement,
    Statement,
)
from cbrs.kb.namespaces import expand
from cbrs.reasoner.config import MatchConfig
from cbrs.reasoner.degrees import Degree, degree_of_match
from cbrs.reasoner.methods import REFINED, Method, make_method
from cbrs.reasoner.names import local_name
from cbrs.reasoner.sea import uncovered
from cbrs.reasoner.similarity import SemStr, Similarity
from cbrs.reasoner.spans import PairMatch, SpanMatch, conceptual_span_similarity, span
from cbrs.reasoner.statements import StatementMatch, best_statement_matches, contradiction_factor, reported, undoes
from cbrs.reasoner.steps import Achiever, achievers, at_or_above, establishes, feeds, works_towards
from cbrs.reasoner.taxonomy import TaxonomyIndex
from cbrs.reasoner.text import description_text

if TYPE_CHECKING:  # numpy and the batch scorer load with the first ranking: importing cbrs stays fast
    from cbrs.reasoner.batch import CompiledPool
    from cbrs.reasoner.strict import StrictScorer
    from cbrs.reasoner.text import TextIndex
    from cbrs.reasoner.vectors import FloatArray


class MatchStatus(Enum):
    MATCHED = "matched"
    NO_ACCEPTABLE_MATCH = "no-acceptable-match"


@dataclass(frozen=True)
class EntityPair:
    """One compared pair: which requirement entity met which advertised one, how, and how well."""

    role: str  # output, input, effect, precondition
    requested: str
    advertised: str | None
    similarity: float
    how: str
    degree: str
    #: The rule that gave a partial share when no is-a link did: "reports" (an output observes the
    #: requested state) or "step" (an output an achiever of the effect needs); "" for a plain comparison.
    rule: str = ""

    def shown_degree(self, pair_threshold: float = MatchConfig().pair_threshold) -> str:
        """The degree as a person reads it. A pair with no is-a link that Sem-Str still matched (siblings
        with the same parts, a synonym in another branch) is "Similar"; a share given by a rule is named
        by the rule ("Reports", "Step"); "Fail" is left for a pair below the threshold and no rule."""
        if self.degree != Degree.FAIL.value:
            return self.degree
        if self.rule:
            return self.rule.capitalize()
        return "Similar" if self.similarity >= pair_threshold else self.degree


@dataclass(frozen=True)
class Candidate:
    advertisement: str
    label: str | None
    score: float
    parts: dict[str, float]
    pairs: tuple[EntityPair, ...]
    lacks: tuple[str, ...]
    rejected_by: tuple[str, ...]  # SEA / QoS filters (and, for strict logic, a failed output)
    acceptable: bool  # passes the filters and reaches the acceptance score
    explained: bool = True  # pairs and lacks filled in (only the first candidates of a big pool are)

    def to_dict(self) -> dict[str, Any]:
        return asdict(self)


@dataclass(frozen=True)
class MatchResult:
    requirement: str
    method: str
    status: MatchStatus
    candidates: Sequence[Candidate]  # ranked by score, best first; those a filter rejects after the rest

    def to_dict(self, top: int | None = None) -> dict[str, Any]:
        return {
            "requirement": self.requirement,
            "method": self.method,
            "status": self.status.value,
            "candidates": [c.to_dict() for c in self.candidates[:top]],
        }


class Matchmaker:
    """Ranks the advertisements in a knowledge base; the taxonomy index is built once."""

    def __init__(
        self,
        kb: KnowledgeBase,
        method: str = "sem-str",
        config: MatchConfig | None = None,
        index: TaxonomyIndex | None = None,
        advertisements: Sequence[Advertisement] | None = None,
    ) -> None:
        self.kb = kb
        config = config or MatchConfig()
        refined = method in REFINED
        self.config = config if refined else config.published()  # the baselines stay as published
        self.index = index or TaxonomyIndex.from_kb(kb)
        self.method: Method = make_method(method, self.index, self.config)
        self._advertisements = list(advertisements) if advertisements is not None else None
        self._pool: CompiledPool | None = None
        self._pool_source: list[Advertisement] | None = None
        self._text: TextIndex | None = None
        self._text_source: list[Advertisement] | None = None
        self._requirements: dict[str, Requirement] = {}
        self._requirements_at: object = None  # the store generation they were read at
        self._strict_scorer: StrictScorer | None = None
        self._achievers_of: tuple[Requirement, list[Advertisement], list[Achiever]] | None = None  # _step's
        self._lock = threading.RLock()  # rankings and the explanations read from them share the caches

    def prepare(self) -> Matchmaker:
        """Do the one-time work now (read the advertisements and the store's requirements, lay the pool
        out as arrays), so that the first ranking is as fast as the rest."""
        ads = self.advertisements
        if self._generation() is not None:
            self._requirements = {r.iri: r for r in self.kb.requirements()}
            self._requirements_at = self._generation()
        space = self._compiled(ads).space
        space.warm()
        if isinstance(self.method.measure, SemStr):
            space.warm_lexical(self.method.measure)
        if self.method.text:
            self._text_index(ads)
        # The set-up leaves many new long-lived objects, which make a full garbage collection due: run
        # it now rather than in the middle of a later ranking (some 50 ms over OWLS-TC in cbrs eval).
        gc.collect()
        return self

    def _text_index(self, ads: list[Advertisement]) -> TextIndex:
        if self._text is None or self._text_source is not ads:
            from cbrs.reasoner.text import TextIndex

            self._text = TextIndex(ads)
            self._text_source = ads
        return self._text

    def _compiled(self, ads: list[Advertisement]) -> CompiledPool:
        if self._pool is None or self._pool_source is not ads:
            from cbrs.reasoner.batch import CompiledPool
            from cbrs.reasoner.vectors import VectorSpace

            self._pool = CompiledPool(ads, VectorSpace(self.index), self.method.use_parts)
            self._pool_source = ads
        return self._pool

    @property
    def advertisements(self) -> list[Advertisement]:
        if self._advertisements is None:
            self._advertisements = self.kb.advertisements()
        return self._advertisements

    def rank(self, requirement: Requirement | str, explain: int | None = None) -> MatchResult:
        """Score every advertisement against ``requirement`` (a Requirement, its IRI, ``prefix:local``, or a
        bare name taken in ``req:``, as ``cbrs match`` takes it), best first.

        The whole pool is scored at once (reasoner/batch.py); the first ``explain`` candidates (all
        when None) also carry their explanation (entity pairs and what they lack), worked out when a
        candidate is first read: a caller that reads three of ten explained candidates pays for three.
        """
        with self._lock:
            if isinstance(requirement, str):
                requirement = self._requirement(expand(requirement if ":" in requirement else "req:" + requirement))
            ads = self.advertisements
            gone = self.kb.liveness.unavailable()  # read at every ranking: a component may leave at any time
            candidates = self._rank_batch(requirement, ads, len(ads) if explain is None else explain, gone)
            matched = candidates.first_acceptable()
        status = MatchStatus.MATCHED if matched else MatchStatus.NO_ACCEPTABLE_MATCH
        return MatchResult(requirement.iri, self.method.name, status, candidates)

    def _strict(self, pool: CompiledPool) -> StrictScorer:
        """The strict scorer of this pool, kept with it (its degree arrays are cached per concept)."""
        from cbrs.reasoner.strict import StrictScorer

        if self._strict_scorer is None or self._strict_scorer.pool is not pool:
            self._strict_scorer = StrictScorer(pool, self.method.measure, self.config, self.filters)
        return self._strict_scorer

    def _requirement(self, iri: str) -> Requirement:
        """The requirement ``iri`` as the store has it: read once per store generation (an embedded store
        counts its writes; a remote one is read every time)."""
        generation = self._generation()
        if generation is not None and generation != self._requirements_at:
            self._requirements = {}
            self._requirements_at = generation
        found = self._requirements.get(iri) if generation is not None else None
        if found is None:
            description = self.kb.description(iri)
            if not isinstance(description, Requirement):
                raise NotFoundError(iri, "requirement (it is an advertisement)")
            found = description
            if generation is not None:
                self._requirements[iri] = found
        return found

    def _generation(self) -> object:
        return getattr(self.kb.store, "generation", None)

    def _rank_batch(
        self, requirement: Requirement, ads: list[Advertisement], explain: int, gone: set[str] | frozenset[str]
    ) -> _Ranking:
        import numpy as np

        from cbrs.reasoner.batch import BatchScorer, BatchScores, first_ranked, ranking_keys

        pool = self._compiled(ads)
        if self.method.strict:  # degrees of match, not similarities
            scores = self._strict(pool).score(requirement)
        else:
            scorer = BatchScorer(
                pool,
                self.method.measure,
                self.config,
                self.filters,
                plugin_inputs=self.plugin_inputs,
                plugin_outputs=self.plugin_outputs,
            )
            scores = scorer.score(requirement)
        text = description_text(requirement)
        if self.method.text and text:
            similarity = self._text_index(ads).similarities(text)
            hybrid = _mix(scores.score, similarity, self.config.text_weight)
            scores = BatchScores(
                hybrid,
                {**scores.parts, "text": similarity},
                scores.rejected_by,
                scores.rejected,
                scores.score,
                scores.tie,
            )
        keys = ranking_keys(scores, pool)
        size = len(ads)
        if gone:  # unavailable components sort past every key and are left out of the ranking
            away = np.array([ad.iri in gone for ad in ads], dtype=bool)
            keys = np.where(away, np.iinfo(np.int64).max, keys)
            size -= int(away.sum())
        first = first_ranked(keys, max(1, min(explain, size))).tolist() if size else []
        best = first[0] if first else -1  # what the status is read from, explained or not
        first = first[: min(explain, size)]

        def rest() -> list[int]:  # the whole order, sorted only when a candidate past the head is read
            order: list[int] = np.argsort(keys)[len(first) : size].tolist()
            return order

        def unexplained(i: int) -> Candidate:
            ad = ads[i]
            parts = {name: float(values[i]) for name, values in scores.parts.items() if not math.isnan(values[i])}
            score = float(scores.score[i])
            basis = score if scores.accepted_on is None else float(scores.accepted_on[i])
            rejected = scores.rejected_by[i]
            acceptable = not rejected and basis >= self.config.accept_score
            return Candidate(ad.iri, ad.label, score, parts, (), (), rejected, acceptable, explained=False)

        def explained(i: int) -> Candidate:
            with self._lock:  # the caller may read the ranking after letting go of the store's lock
                return self.score(requirement, ads[i])

        return _Ranking(first, explained, rest, size - len(first), unexplained, best)

    def score(self, requirement: Requirement, ad: Advertisement) -> Candidate:
        pairs: list[EntityPair] = []
        lacks: list[str] = []
        parts: dict[str, float] = {}
        cfg = self.config
        brings_about = 0.0  # the share as a step that brings about an achiever's precondition
        if requirement.outputs:
            parts["outputs"] = self._parameters(requirement.outputs, ad.outputs, "output", pairs, lacks)
        needed: float | None = None  # how well the requester can supply the advertised inputs
        if ad.inputs:
            needed = self._parameters(ad.inputs, requirement.inputs, "input", pairs, lacks)
        if requirement.inputs:
            used = self._parameters(requirement.inputs, ad.inputs, "provided input", [], lacks) if ad.inputs else 0.0
            if not ad.inputs:  # the inputs part's half it loses, said (the part alone showed it)
                lacks.extend(f"provided input {_short(p.type)}: it takes no input" for p in requirement.inputs)
            u = cfg.input_use_weight
            if needed is None and not cfg.no_input_invocable:
                parts["inputs"] = used
            else:
                parts["inputs"] = (1 - u) * (1.0 if needed is None else needed) + u * used
        elif needed is not None:
            parts["inputs"] = needed
        if requirement.effects:
            matches = best_statement_matches(requirement.effects, ad.effects, self.method.measure, cfg)
            if not ad.effects and ad.outputs and cfg.observed_state_weight > 0:
                parts["effects"] = self._observed(requirement.effects, ad.outputs, pairs)
            else:
                parts["effects"] = self._statements(matches, "effect", pairs, lacks)
            if (
                not ad.effects
                and ad.outputs
                and cfg.decomposition_weight > 0
                and isinstance(self.method.measure, SemStr)
            ):
                parts["effects"] = max(parts["effects"], self._step(requirement, ad, pairs))
            if (
                ad.effects
                and cfg.precondition_steps
                and cfg.decomposition_weight > 0
                and isinstance(self.method.measure, SemStr)
            ):
                brings_about = self._precondition_step(requirement, ad, pairs)
                parts["effects"] = max(parts["effects"], brings_about)
        if requirement.deletes:
            matches = best_statement_matches(requirement.deletes, ad.deletes, self.method.measure, cfg)
            parts["deletes"] = self._statements(matches, "delete effect", pairs, lacks)
        if ad.preconditions and requirement.preconditions:
            matches = best_statement_matches(ad.preconditions, requirement.preconditions, self.method.measure, cfg)
            every = cfg.precondition_conjunction  # all must hold: the worst one decides
            parts["preconditions"] = self._statements(matches, "precondition", pairs, lacks, every)
        weights = cfg.part_weights
        total = sum(weights[name] for name in parts)
        score = sum(weights[name] * value for name, value in parts.items()) / total if total else 0.0
        score *= 1 - cfg.input_gate + cfg.input_gate * (needed if needed is not None else 1.0)
        if not brings_about:  # a step towards the effect does not undo it, though its own effect clashes
            score *= contradiction_factor(requirement.effects, ad.effects, self.method.measure, cfg)
        score *= self._undone_state(requirement, ad, lacks)
        rejected = self.filters(requirement, ad.area, ad.qos)
        if self.method.strict:
            results = ("output", "effect", "delete effect")
            failed = [pair for pair in pairs if pair.role in results and pair.degree == Degree.FAIL.value]
            if failed:
                rejected.append(f"strict logic: {failed[0].role} {_short(failed[0].requested)} has no accepted match")
        score = round(score, 6)
        acceptable = not rejected and score >= cfg.accept_score
        text = description_text(requirement) if self.method.text else ""
        if text:  # the hybrid: text helps rank, the IO/PE score alone decides acceptability
            parts["text"] = self._text_index(self.advertisements).similarity(text, ad)
            import numpy as np  # loaded by the text index already

            score = float(_mix(np.array([score]), np.array([parts["text"]]), cfg.text_weight)[0])
        return Candidate(ad.iri, ad.label, score, parts, tuple(pairs), tuple(lacks), tuple(rejected), acceptable)

    # -- parts ---------------------------------------------------------------------------------

    def _parameters(
        self,
        wanted: tuple[Parameter, ...],
        offered: tuple[Parameter, ...],
        role: str,
        pairs: list[EntityPair],
        lacks: list[str],
    ) -> float:
        """Each wanted parameter's best CSS against the offered ones. Pairs are recorded requirement
        side first, whichever side wants."""
        flip = role == "input"  # the advertisement wants, the requirement offers
        values = []
        for parameter in wanted:
            scored = [(self._trees(parameter, other, invoking=flip, role=role), other) for other in offered]
            if not scored:
                values.append(0.0)
                lacks.append(f"{role} {_short(parameter.type)}: nothing on the other side")
                pairs.append(self._pair(False, role, parameter.type, None, 0.0, "no partner"))
                continue
            match, other = max(scored, key=lambda item: item[0].value)
            values.append(match.value)
            if self.method.strict:
                pairs.append(self._pair(flip, role, parameter.type, other.type, match.value, "degree"))
                continue
            for pair in match.pairs:
                how = pair.similarity.explain()
                if pair.span > 1:
                    how += f", covers {pair.span} parts"
                elif pair.span == 0:
                    how += ", its parts carry the match"
                pairs.append(self._pair(flip, role, pair.requested, pair.advertised, pair.similarity.value, how))
            if not match.pairs:
                how = "best partner, below the pair threshold"
                pairs.append(self._pair(flip, role, parameter.type, other.type, match.value, how))
                best = f"best {_short(other.type)}, {match.value:.2f}"
                lacks.append(f"{role} {_short(parameter.type)}: no match ({best})")
                continue
            if not any(pair.requested == parameter.type for pair in match.pairs):
                how = "below the pair threshold; its parts matched"
                pairs.append(self._pair(flip, role, parameter.type, other.type, match.value, how))
            for leaf in match.uncovered:
                lacks.append(f"{role} {_short(parameter.type)}: nothing matches its part {_short(leaf)}")
        return sum(values) / len(values) if values else 0.0

    def _pair(self, flip: bool, role: str, wanted: str, offered: str | None, value: float, how: str) -> EntityPair:
        if flip and offered is not None:
            degree = degree_of_match(self.index, offered, wanted)
            return EntityPair(role, offered, wanted, value, how, degree.value)
        degree = degree_of_match(self.index, wanted, offered) if offered else Degree.FAIL
        return EntityPair(role, wanted, offered, value, how, degree.value)

    def _trees(self, wanted: Parameter, offered: Parameter, invoking: bool = False, role: str = "") -> SpanMatch:
        """CSS of two parameters' trees. ``invoking``: ``wanted`` is an advertised input and ``offered``
        what the requester provides; the same concept or a subclass can be passed as it is. ``role``
        "output" or "provided input": a pair that delivers by subclass has a floor (plugin_outputs)."""
        if self.method.strict:
            degree = degree_of_match(self.index, wanted.type, offered.type)
            return SpanMatch(_DEGREE_SCORE[degree], (), () if degree.accepted else (wanted.type,))
        whole = span(wanted.tree) if wanted.tree and self.method.use_parts else 1
        if invoking and self.plugin_inputs and self._subsumes(wanted.type, offered.type):
            return SpanMatch(1.0, (PairMatch(wanted.type, offered.type, Similarity(1.0, "plug-in"), whole),), ())
        css = self._css(wanted, offered)
        links = None
        step, situation = self.config.specialisation_step, "delivered"
        if self.plugin_outputs and role == "output":
            links = self._links_below(wanted.type, offered.type)
        elif self.plugin_outputs and role == "provided input":
            links = self._links_below(offered.type, wanted.type)
        elif invoking and self.plugin_inputs:  # an advertised input narrower than what is provided
            links = self._links_below(offered.type, wanted.type)
            step, situation = self.config.narrower_input_step, "narrower"
        if links is not None:
            floor = max(0.0, 1.0 - step * links)
            if floor > css.value:
                how = Similarity(floor, situation, links=(links, 0))
                return SpanMatch(floor, (PairMatch(wanted.type, offered.type, how, whole),), ())
        factor = self.config.unrelated_output_factor
        if self.plugin_outputs and role == "output" and factor < 1 and not self._related(wanted.type, offered.type):
            return SpanMatch(css.value * factor, css.pairs, css.uncovered)
        return css

    def _related(self, first: str, second: str) -> bool:
        """The same concept, or one a subclass of the other (is-a links)."""
        if first == second:
            return True
        return self._links_below(first, second) is not None or self._links_below(second, first) is not None

    def _links_below(self, upper: str, lower: str) -> int | None:
        """is-a links from ``lower`` up to ``upper`` when ``lower`` is ``upper`` or a subclass of it."""
        if upper not in self.index or lower not in self.index:
            return None
        return self.index.is_a_ancestors(lower).get(self.index.canonical(upper))

    def _css(self, wanted: Parameter, offered: Parameter) -> SpanMatch:
        return conceptual_span_similarity(
            wanted.tree or PartNode(wanted.type),
            offered.tree or PartNode(offered.type),
            self.method.measure,
            self.config.pair_threshold,
            use_parts=self.method.use_parts,
            implied=self.implied_parts(wanted.type, offered.type) if self.method.use_parts else frozenset(),
            weight=self.index.part_weight,
            inherited=self.config.inherited_parts and self._subsumes(wanted.type, offered.type),
            value=self._value,
        )

    def _value(self, first: str, second: str) -> float:
        """The measure's value of a pair, from a similarity vector of the pool when one is cached."""
        if self._pool is not None and isinstance(self.method.measure, SemStr):
            found = self._pool.space.cached_value(self.method.measure, first, second)
            if found is not None:
                return found
        return self.method.measure(first, second).value

    @property
    def plugin_inputs(self) -> bool:
        return self.config.plugin_inputs and self.method.taxonomy

    @property
    def plugin_outputs(self) -> bool:
        return self.config.plugin_outputs and self.method.taxonomy

    def _subsumes(self, upper: str, lower: str) -> bool:
        """Is ``lower`` the same concept as ``upper`` or a subclass of it (is-a links)?"""
        return degree_of_match(self.index, upper, lower) in (Degree.EXACT, Degree.SUBCLASS_OF)

    def implied_parts(self, first: str, second: str) -> frozenset[str]:
        """Parts both concepts have through their common superclass: no evidence of their own."""
        if first not in self.index or second not in self.index:
            return frozenset()
        common = self._pool.space.cached_superclass(first, second) if self._pool is not None else None
        if common is None:
            common, _, _ = self.index.common_ancestor(first, second)
        return self.index.parts_of(common)

    def _observed(
        self, effects: tuple[Statement, ...], outputs: tuple[Parameter, ...], pairs: list[EntityPair]
    ) -> float:
        """An advertisement that changes nothing but outputs the state a requested effect is about: each
        effect's best Sem-Str of an output that reports one of its terms (statements.reported), times
        observed_state_weight."""
        measure, weight = self.method.measure, self.config.observed_state_weight
        values = []
        for effect in effects:
            found = [
                (
                    measure(out.type, term)
                    if term in reported(self.index, self.config, out.type, effect)
                    else _UNRELATED,
                    out.type,
                    term,
                )
                for out in outputs
                for term in (effect.object, effect.subject)
            ]
            best, output, term = max(found, key=lambda item: item[0].value)
            text = f"({_short(effect.subject)}, {_short(effect.predicate)}, {_short(effect.object)})"
            how = f"no effect; output {_short(output)} reports {_short(term)} ({best.value:.2f}) x {weight:g}"
            rule = "reports"
            if best is _UNRELATED:  # no output reports a term of it: said "reports", shown as the rule's degree
                how, rule = f"no effect; no output reports it ({_short(output)}: {best.situation})", ""
            pairs.append(EntityPair("effect", text, output, weight * best.value, how, Degree.FAIL.value, rule))
            values.append(weight * best.value)
        return sum(values) / len(values)

    def _step(self, requirement: Requirement, ad: Advertisement, pairs: list[EntityPair]) -> float:
        """An advertisement that changes nothing but outputs an input an achiever of the requested effects
        needs and the requester lacks, or takes it towards the same goal (reasoner/steps.py):
        decomposition_weight x the achiever's effects part x the output's delivered floor (1 for a taker),
        with its pair when it is above 0."""
        cfg = self.config
        best, why, output = 0.0, "", ""
        for achiever in self._achievers(requirement):
            needs = f"{_short(achiever.advertisement.iri)} needs to achieve it ({achiever.value:.2f})"
            for needed in achiever.missing:
                offers = [
                    (
                        feeds(self.index, out.type, needed, cfg.specialisation_step),
                        out.type,
                        f"output {_short(out.type)} is the {_short(needed)} that {needs}",
                    )
                    for out in ad.outputs
                ]
                if cfg.consumer_steps and works_towards(self.index, requirement, ad, needed):
                    offers.append((1.0, needed, f"takes the {_short(needed)} that {needs}, towards the same goal"))
                for feed, concept, what in offers:
                    value = cfg.decomposition_weight * achiever.value * feed
                    if value > best:
                        best, output = value, concept
                        why = f"no effect; {what} x {cfg.decomposition_weight:g}"
        if best > 0:
            text = ", ".join(
                f"({_short(e.subject)}, {_short(e.predicate)}, {_short(e.object)})" for e in requirement.effects
            )
            pairs.append(EntityPair("effect", text, output, best, why, Degree.FAIL.value, "step"))
        return best

    def _achievers(self, requirement: Requirement) -> list[Achiever]:
        """The achievers of ``requirement``'s effects that need something it lacks (steps.achievers), listed
        once per requirement and pool."""
        found = self._achievers_of
        if found is None or found[0] is not requirement or found[1] is not self.advertisements:
            listed = achievers(self.index, requirement, self.advertisements, self.method.measure, self.config)
            found = self._achievers_of = (requirement, self.advertisements, listed)
        return found[2]

    def _precondition_step(self, requirement: Requirement, ad: Advertisement, pairs: list[EntityPair]) -> float:
        """An advertisement one of whose effects brings about a precondition an achiever of the requested
        effects needs and the requester does not guarantee (reasoner/steps.py): decomposition_weight x the
        achiever's effects part, with its pair when it is above 0."""
        weight = self.config.decomposition_weight
        best, why, offered = 0.0, "", ""
        for achiever in self._achievers(requirement):
            for condition in achiever.unmet:
                effect = next((e for e in ad.effects if establishes(self.index, e, condition)), None)
                if effect is not None and weight * achiever.value > best:
                    best, offered = weight * achiever.value, _statement_text(effect)
                    why = (
                        f"effect {offered} brings about {_statement_text(condition)}, which"
                        f" {_short(achiever.advertisement.iri)} needs before it achieves it ({achiever.value:.2f})"
                        f" x {weight:g}"
                    )
        if best > 0:
            text = ", ".join(_statement_text(e) for e in requirement.effects)
            pairs.append(EntityPair("effect", text, offered, best, why, Degree.FAIL.value, "step"))
        return best

    def _undone_state(self, requirement: Requirement, ad: Advertisement, lacks: list[str]) -> float:
        """MatchConfig.undone_state_factor when one of the advertisement's effects achieves no requested
        effect and makes a precondition the requirement guarantees false (statements.undoes), else 1."""
        factor = self.config.undone_state_factor
        if factor >= 1 or not requirement.preconditions:
            return 1.0
        for effect in ad.effects:
            if any(self._states_at_least(effect, wanted) for wanted in requirement.effects):
                continue
            for held in requirement.preconditions:
                if undoes(held, effect, self.method.measure, self.config):
                    lacks.append(f"effect {_text(effect)} undoes the guaranteed {_text(held)}: score x{factor:g}")
                    return factor
        return 1.0

    def _states_at_least(self, effect: Statement, wanted: Statement) -> bool:
        """Does ``effect`` state at least the change ``wanted`` asks for (each position the requested one or
        an is-a superclass of it, as an achiever's does: steps.py)?"""
        return all(
            at_or_above(self.index, getattr(wanted, position), getattr(effect, position))
            for position in ("subject", "predicate", "object")
        )

    def _statements(
        self,
        matches: list[StatementMatch],
        role: str,
        pairs: list[EntityPair],
        lacks: list[str],
        conjunction: bool = False,
    ) -> float:
        """The statements' best matches, averaged, or their lowest when they form a ``conjunction``."""
        values = []
        for match in matches:
            wanted = match.requested
            text = f"({_short(wanted.subject)}, {_short(wanted.predicate)}, {_short(wanted.object)})"
            if match.advertised is None:
                lacks.append(f"{role} {text}: none offered")
                pairs.append(EntityPair(role, text, None, 0.0, "no partner", Degree.FAIL.value))
                values.append(0.0)
                continue
            got = match.advertised
            degrees = [
                degree_of_match(self.index, a, b)
                for a, b in (
                    (wanted.subject, got.subject),
                    (wanted.predicate, got.predicate),
                    (wanted.object, got.object),
                )
            ]
            degree = min(degrees, key=_DEGREE_SCORE.__getitem__)
            value = _DEGREE_SCORE[degree] if self.method.strict else match.value
            offered = f"({_short(got.subject)}, {_short(got.predicate)}, {_short(got.object)})"
            how = "s/p/o: " + ", ".join(f"{s.value:.2f}" for s in match.parts or ())
            if match.contradicts:
                clash = _short(getattr(got, match.contradicts)), _short(getattr(wanted, match.contradicts))
                how += f"; contradicts: {clash[0]} is {match.relation} {clash[1]}"
            pairs.append(EntityPair(role, text, offered, value, how, degree.value))
            if value < self.config.pair_threshold:
                lacks.append(f"{role} {text}: best offer {offered} scores {value:.2f}")
            values.append(value)
        if conjunction and values:
            return min(values)
        return sum(values) / len(values) if values else 0.0

    # -- filters ---------------------------------------------------------------------------------

    def filters(self, requirement: Requirement, offered: EffectiveArea | None, qos: tuple[QoSValue, ...]) -> list[str]:
        """Why an advertisement with this SEA and QoS fails the requirement's filters (empty: it passes)."""
        reasons = uncovered(self.index, requirement.area, offered)
        offered_qos = {q.metric: q.value for q in qos}
        for bound in requirement.qos:
            value = offered_qos.get(bound.metric)
            name = _short(bound.metric)
            if value is None:
                # an advertisement that states no QoS at all (an OWL-S service) is not judged on it
                if self.config.qos_missing_fails and qos:
                    reasons.append(f"QoS: states no {name} (needs {bound.value:g})")
            elif bound.better_when == "lower" and value > bound.value:
                reasons.append(f"QoS: {name} {value:g} > {bound.value:g}")
            elif bound.better_when == "higher" and value < bound.value:
                reasons.append(f"QoS: {name} {value:g} < {bound.value:g}")
        return reasons


class _Ranking(Sequence[Candidate]):
    """Ranked candidates, each made on first access: the head explained (``explain``), the rest from the
    batch scores, ordered only when a candidate past the head is read (a pool of thousands is ranked far
    more often than it is read to the end, and its explanations are read for a few candidates at most)."""

    def __init__(
        self,
        head: list[int],
        explain: Callable[[int], Candidate],
        rest: Callable[[], list[int]],
        remaining: int,
        make: Callable[[int], Candidate],
        best: int,
    ) -> None:
        self._head = head
        self._best = best  # the advertisement ranked first (-1: none)
        self._explain = explain
        self._order = rest  # the positions past the head, computed on first need
        self._rest: list[int] | None = None
        self._remaining = remaining
        self._made: dict[int, Candidate] = {}
        self._make = make

    def __len__(self) -> int:
        return len(self._head) + self._remaining

    def __repr__(self) -> str:
        """The count and the first three, by label and score: a notebook showing a result saw an address."""
        first = ", ".join(f"{c.label or c.advertisement} {c.score:.3f}" for c in self[:3])
        return f"<{len(self)} candidates: {first}{', ...' if len(self) > 3 else ''}>"

    def first_acceptable(self) -> bool:
        """Is the best candidate acceptable? Read from the batch scores, without explaining it (tests check
        that the batch and the explanation agree on acceptability)."""
        return self._best >= 0 and self._make(self._best).acceptable

    def _position(self, position: int) -> int:
        """The advertisement at ``position``, past the head."""
        if self._rest is None:
            self._rest = self._order()
        return self._rest[position - len(self._head)]

    @overload
    def __getitem__(self, position: int) -> Candidate: ...

    @overload
    def __getitem__(self, position: slice) -> list[Candidate]: ...

    def __getitem__(self, position: int | slice) -> Candidate | list[Candidate]:
        if isinstance(position, slice):
            return [self[i] for i in range(*position.indices(len(self)))]
        if position < 0:
            position += len(self)
        if not 0 <= position < len(self):
            raise IndexError(position)
        found = self._made.get(position)
        if found is None:
            if position < len(self._head):
                found = self._explain(self._head[position])
            else:
                found = self._make(self._position(position))
            self._made[position] = found
        return found


_UNRELATED = Similarity(0.0, "not the state asked about, nor an is-a relative of it")
_DEGREE_SCORE = {Degree.EXACT: 1.0, Degree.SUBCLASS_OF: 0.8, Degree.HAS_SUBCLASS: 0.6, Degree.FAIL: 0.0}


def _mix(score: FloatArray, text: FloatArray, weight: float) -> FloatArray:
    """The hybrid's ranking score: (1 - w) IO/PE score + w text similarity, rounded as scores are."""
    import numpy as np

    return np.round((1 - weight) * score + weight * text, 6).astype(np.float64)


def _statement_text(statement: Statement) -> str:
    return f"({_short(statement.subject)}, {_short(statement.predicate)}, {_short(statement.object)})"


def _short(iri: str) -> str:
    return local_name(iri) if "://" in iri else iri


def _text(statement: Statement) -> str:
    return f"({_short(statement.subject)}, {_short(statement.predicate)}, {_short(statement.object)})"
