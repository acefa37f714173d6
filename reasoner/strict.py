"""The strict logic baseline (Paolucci et al.) over a whole pool at once: degrees of match as arrays.

Same numbers and rejections as ``Matchmaker.score`` for the ``logic`` method (tests compare them), which
scored the advertisements one by one (about 60 ms per OWLS-TC query). A pair's degree is Exact 1,
SubClassOf 0.8, HasSubClass 0.6 or Fail 0 (``degrees.py``); every requested output and effect needs an
accepted degree or the advertisement is rejected. A statement's partner is the most similar one by the
method's entity measure (the first on ties), scored by its worst position's degree.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import numpy.typing as npt

from cbrs.kb import EffectiveArea, QoSValue, Requirement, Statement
from cbrs.reasoner.batch import PARTS, BatchScores, CompiledPool, _Segments
from cbrs.reasoner.config import MatchConfig
from cbrs.reasoner.names import local_name
from cbrs.reasoner.similarity import EntityMeasure
from cbrs.reasoner.statements import combine
from cbrs.reasoner.vectors import ARRAY_CACHE_BYTES, FloatArray, IntArray, _Lru, _nbytes

EXACT, SUBCLASS_OF, HAS_SUBCLASS = 1.0, 0.8, 0.6  # matchmaker._DEGREE_SCORE


class StrictScorer:
    def __init__(
        self,
        pool: CompiledPool,
        measure: EntityMeasure,
        config: MatchConfig,
        filters: Callable[[Requirement, EffectiveArea | None, tuple[QoSValue, ...]], list[str]],
    ) -> None:
        self.pool = pool
        self.measure = measure
        self.config = config
        self.filters = filters
        self._degrees: _Lru[str, FloatArray] = _Lru(ARRAY_CACHE_BYTES, _nbytes)  # per concept
        self._inverse: _Lru[str, FloatArray] = _Lru(ARRAY_CACHE_BYTES, _nbytes)

    def degrees(self, requested: str) -> FloatArray:
        """The degree score of every concept id as the advertised partner of ``requested``."""
        found = self._degrees.get(requested)
        if found is None:
            space = self.pool.space
            found = np.zeros(len(space), dtype=np.float64)
            if requested in space.index:
                index = space.index
                ids, _ = space.below_is_a(requested)
                found[ids] = SUBCLASS_OF
                found[[space.ids[a] for a in index.is_a_ancestors(requested)]] = HAS_SUBCLASS
                found[space.ids[index.canonical(requested)]] = EXACT
            elif requested in space.ids:
                found[space.ids[requested]] = EXACT
            self._degrees[requested] = found
        return found

    def inverse(self, advertised: str) -> FloatArray:
        """The degree score of ``advertised`` as the partner of every concept id (requested)."""
        found = self._inverse.get(advertised)
        if found is None:
            found = self.degrees(advertised).copy()
            below, above = found == SUBCLASS_OF, found == HAS_SUBCLASS
            found[below], found[above] = HAS_SUBCLASS, SUBCLASS_OF
            self._inverse[advertised] = found
        return found

    def score(self, requirement: Requirement) -> BatchScores:
        pool, cfg = self.pool, self.config
        n = len(pool.ads)
        parts: dict[str, FloatArray] = {name: np.full(n, np.nan) for name in PARTS}
        failed: list[tuple[str, npt.NDArray[np.bool_]]] = []  # (what, where), in Matchmaker.score's pair order
        if requirement.outputs:
            per = []
            for output in requirement.outputs:
                best = pool.outputs.max(self.degrees(output.type)[pool.root_ids])
                per.append(best)
                failed.append((f"output {_short(output.type)}", best <= 0))
            parts["outputs"] = np.mean(per, axis=0)
        self._inputs(requirement, parts)
        for part, role, wanted, offered in (
            ("effects", "effect", requirement.effects, pool.effects),
            ("deletes", "delete effect", requirement.deletes, pool.deletes),
        ):
            if wanted:  # each requested result needs an accepted match, as an output does
                per = []
                for statement in wanted:
                    best = self._statements(statement, offered, inverse=False)
                    per.append(best)
                    text = f"({_short(statement.subject)}, {_short(statement.predicate)}, {_short(statement.object)})"
                    failed.append((f"{role} {text}", best <= 0))
                parts[part] = np.mean(per, axis=0)
        if requirement.preconditions:
            parts["preconditions"] = self._preconditions(requirement.preconditions)
        weights = cfg.part_weights
        numerator, denominator = np.zeros(n), np.zeros(n)
        for name, values in parts.items():
            present = ~np.isnan(values)
            numerator += np.where(present, weights[name] * np.nan_to_num(values), 0.0)
            denominator += np.where(present, weights[name], 0.0)
        ratio = np.where(denominator > 0, numerator / np.maximum(denominator, 1e-300), 0.0)
        score = np.round(ratio.astype(np.float64), 6).astype(np.float64)
        reasons, rejected = pool.filtered(requirement, self.filters)
        why = np.full(n, -1, dtype=np.int64)  # the first failed output or effect names the rejection
        for k in range(len(failed) - 1, -1, -1):
            why[failed[k][1]] = k
        for i in np.flatnonzero(why >= 0).tolist():
            reasons.add(i, f"strict logic: {failed[why[i]][0]} has no accepted match")
        return BatchScores(score, parts, reasons, rejected | (why >= 0))

    def _inputs(self, requirement: Requirement, parts: dict[str, FloatArray]) -> None:
        """Matchmaker.score's inputs part with degrees: how well the requester supplies each advertised
        input (needed) and how much of what it provides the advertisement takes (used)."""
        pool, cfg = self.pool, self.config
        has_inputs = pool.inputs.present
        if not requirement.inputs and not np.any(has_inputs):
            return
        supplied = np.zeros(len(pool.root_ids))
        for provided in requirement.inputs:
            supplied = np.maximum(supplied, self.inverse(provided.type)[pool.root_ids])
        needed = pool.inputs.mean(supplied)
        if not requirement.inputs:
            parts["inputs"] = np.where(has_inputs, needed, np.nan)
            return
        used = np.mean([pool.inputs.max(self.degrees(p.type)[pool.root_ids]) for p in requirement.inputs], axis=0)
        u = cfg.input_use_weight
        inputs = (1 - u) * np.where(has_inputs, needed, 1.0) + u * used
        parts["inputs"] = inputs if cfg.no_input_invocable else np.where(has_inputs, inputs, used)

    def _statements(self, wanted: Statement, segments: _Segments, inverse: bool) -> FloatArray:
        """Per advertisement, the degree score of its statement most similar to ``wanted`` (0 if none)."""
        pool = self.pool
        space = pool.space
        cfg = self.config
        s = space.vector(self.measure, wanted.subject)[pool.s_ids]
        p = space.vector(self.measure, wanted.predicate)[pool.p_ids]
        o = space.vector(self.measure, wanted.object)[pool.o_ids]
        if cfg.statement_mean == "geometric":  # statements.combine, element-wise
            similarity = s**cfg.subject_weight * p**cfg.predicate_weight * o**cfg.object_weight
        else:
            similarity = cfg.subject_weight * s + cfg.predicate_weight * p + cfg.object_weight * o
        degree = self.inverse if inverse else self.degrees
        worst = np.minimum.reduce(
            [
                degree(wanted.subject)[pool.s_ids],
                degree(wanted.predicate)[pool.p_ids],
                degree(wanted.object)[pool.o_ids],
            ]
        )
        chosen = _first_best(np.asarray(similarity, dtype=np.float64), segments)
        return np.where(chosen >= 0, worst[np.maximum(chosen, 0)], 0.0)

    def _preconditions(self, guaranteed: tuple[Statement, ...]) -> FloatArray:
        """Each advertised precondition's partner among the guaranteed ones (by similarity), scored by
        degree, averaged per advertisement; NaN where the advertisement states none."""
        pool = self.pool
        statements = pool.statements
        values = np.zeros(len(statements))
        for i in np.unique(pool.preconditions.flat[:-1]).tolist():
            advertised = statements[i]
            options = [_similarity(self.config, self.measure, advertised, g) for g in guaranteed]
            best = guaranteed[int(np.argmax(options))]
            values[i] = min(
                self.inverse(best.subject)[pool.s_ids[i]],
                self.inverse(best.predicate)[pool.p_ids[i]],
                self.inverse(best.object)[pool.o_ids[i]],
            )
        return np.where(pool.preconditions.present, pool.preconditions.mean(values), np.nan)


def _similarity(config: MatchConfig, measure: EntityMeasure, wanted: Statement, offered: Statement) -> float:
    return float(
        combine(
            config,
            measure(wanted.subject, offered.subject).value,
            measure(wanted.predicate, offered.predicate).value,
            measure(wanted.object, offered.object).value,
        )
    )


def _first_best(values: FloatArray, segments: _Segments) -> IntArray:
    """Per segment, the flat statement index of its largest value, the first one on ties (-1 if empty)."""
    n = len(segments.counts)
    owner = np.repeat(np.arange(n), segments.counts)
    flat = segments.flat[:-1]
    if not len(flat):
        return np.full(n, -1, dtype=np.int64)
    position = np.arange(len(flat))
    order = np.lexsort((position, -values[flat], owner))
    first = np.ones(len(order), dtype=bool)
    first[1:] = owner[order][1:] != owner[order][:-1]
    chosen = np.full(n, -1, dtype=np.int64)
    chosen[owner[order][first]] = flat[order][first]
    return chosen


def _short(iri: str) -> str:
    return local_name(iri) if "://" in iri else iri
