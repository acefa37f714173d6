"""Every tunable parameter of matchmaking in one place, with the defaults docs/matchmaking.md explains.

Also read from text (``name=value``, as ``cbrs match --param`` and the ``match_params`` setting give
them) by ``MatchConfig.with_params``, so a deployment can turn a rule on or off without code.
"""

from __future__ import annotations

import difflib
import math
from collections.abc import Iterable
from dataclasses import dataclass, fields, replace
from typing import Any


class MatchParameterError(ValueError):
    """A matchmaking parameter that does not exist, or a value it cannot take."""

    def __init__(self, name: str, value: str | None, reason: str) -> None:
        shown = repr(name) if value is None else f"{name}={value!r}"
        super().__init__(f"matchmaking parameter {shown}: {reason}")
        self.name, self.value, self.reason = name, value, reason


_WORDS = {"1": True, "true": True, "yes": True, "on": True, "0": False, "false": False, "no": False, "off": False}


@dataclass(frozen=True)
class MatchConfig:
    # Sem-Str, Situation 3: weights of the core word and of the complementary words (alpha > beta).
    alpha: float = 0.7
    beta: float = 0.3
    # Sem-Str, Situation 3: Jaro-Winkler at or below this is chance agreement between different words and
    # counts 0; above it, values are stretched back to [0, 1] (about 95 % of pairs of different words in
    # the bundled ontologies score below 0.65).
    jaro_winkler_floor: float = 0.65
    # Lexical knowledge for core words (reasoner/lexicon.py, WordNet 3.0 nouns): Situation 3 compares words
    # by the larger of rescaled Jaro-Winkler and WordNet similarity; two concepts the taxonomy relates only
    # through the root, whose core words are the same lemma or WordNet neighbours within lexical_links
    # hypernym links, score at least cross_branch_weight times that Situation 3 value.
    lexicon: bool = False  # off by default: bench/matchmaking_ablation.py shows no robust gain (docs)
    lexical_links: int = 2
    cross_branch_weight: float = 0.8
    # Two taxonomy concepts that are not is-a related (siblings, cousins, other branches) and both have
    # complementary words (the words before the core word): their Sem-Str is multiplied by
    # (1 - complement_weight) + complement_weight * Comp(complementary words), so PersonLocation is further
    # from RobotLocation than the taxonomy alone says (docs/matchmaking.md, "Complementary words").
    complement_weight: float = 0.2
    # A concept outside the taxonomy is placed as the index places a class with no declared parent: under the
    # root. Against a taxonomy concept of depth d it scores at least Situation 1 through the root, 1 / (2 + d),
    # and Situation 3 (the names) only raises that; two concepts outside the taxonomy keep Situation 3 alone.
    # False: Situation 3 alone (Definition 1 as written), so an undeclared concept scores below every declared
    # unrelated one (docs/matchmaking.md, section 9).
    unknown_under_root: bool = True
    # A pair of entities counts as matched when its similarity reaches this threshold (CSS, PE).
    pair_threshold: float = 0.5
    # Weights of subject, predicate and object in an RDF statement's similarity (equation 8).
    subject_weight: float = 1 / 3
    predicate_weight: float = 1 / 3
    object_weight: float = 1 / 3
    # How the three positions of a statement combine: "arithmetic" (the weighted mean, one wrong position
    # costs its weight) or "geometric" (the weighted geometric mean: a statement is about as good as its
    # worst position, so (Robot, isLocatedIn, ChargingStation) is no near miss for (Robot, isLocatedIn, Room)).
    statement_mean: str = "geometric"
    # Two predicates the property hierarchy relates only through the root (no subproperty path) name
    # different relations: their Sem-Str (Situation 1, 1/3 for two top-level properties) is multiplied by
    # this factor, unless they are namesakes across ontologies (cross-branch links). 1 keeps Sem-Str.
    unrelated_predicate_factor: float = 0.0
    # A statement whose subject or object is declared disjoint (owl:disjointWith, owl:AllDisjointClasses;
    # inherited by subclasses) with the requested one contradicts it: similarity 0, however alike the
    # names or the places in the taxonomy ((Door, hasStatus, Closed) for (Door, hasStatus, Opened)).
    disjoint_statements: bool = True
    # A statement whose subject or object is named by a WordNet antonym of the requested one's core word
    # (Closed for Opened, Unlocked for Locked, Off for On; reasoner/antonyms.py) contradicts it too:
    # similarity 0, for taxonomies that leave such opposite states undeclared siblings.
    antonym_statements: bool = True
    # A contradiction is the same fact with an incompatible value: a disjoint or opposite subject counts only
    # when the predicates and objects are is-a related, a disjoint or opposite object only when the subjects
    # and predicates are. (Medication, isDeliveredTo, OlderAdult) does not contradict (OlderAdult, receives,
    # MedicationReminder), though a person is no reminder: it is another fact. False: any position clashes.
    same_fact_contradictions: bool = True
    # An advertisement with an effect that contradicts a requested effect (above) does the opposite of what
    # is asked (closes the door it should open): its whole score is multiplied by this factor, so that
    # matching inputs cannot rank it above services that help. 1 leaves only that statement at 0.
    contradiction_factor: float = 0.0
    # An advertisement with an effect that contradicts a precondition the requirement guarantees (the state
    # the requester is in: an is-a related subject and predicate, an object declared disjoint with or named
    # by the opposite of the guaranteed one), and that achieves no requested effect, undoes that state as a
    # side effect (it opens the door the requester said was closed and asked to lock): a planner's threat.
    # Its whole score is multiplied by this factor; 1 (the default) leaves such offers as they are. Off: on the
    # OWLS-TC development part it moves one pair of one query (docs/matchmaking.md 9.5).
    undone_state_factor: float = 1.0
    # A requested effect and an advertisement that changes nothing (no effects) but outputs the state the
    # effect is about (DoorState for (Door, hasState, Opened)): a sensing step towards it. Its effects part
    # is observed_state_weight times the best Sem-Str of its outputs with the effect's object or subject.
    observed_state_weight: float = 0.5
    # Which outputs report the requested state: True, only a kind of the requested value (a strict is-a
    # superclass of the effect's object: DoorState for Opened, Room for Kitchen); a service that outputs the
    # object itself produces it (a speech recogniser outputs the SpeechText a person should hear) and one that
    # outputs the subject finds it (a door detector). False: the object, the subject or an is-a relative of
    # either (the first rule).
    observed_state_kind: bool = True
    # A step of the decomposition towards a requested effect (reasoner/steps.py): an advertisement that
    # changes nothing but outputs an input that an achiever of the effect needs and the requester does not
    # provide (the grasp planner's GraspPose, for a pick-up service that achieves (Cup, isHeldBy, Robot)).
    # Its effects part is at least this weight times the achiever's effects part. 0 turns it off.
    decomposition_weight: float = 0.5
    # A step may also take what the achiever lacks: an advertisement that changes nothing, accepts such an
    # input as it is (the input's concept or an is-a superclass of it: the path planner's NavigationGoal, for
    # navigate_to_goal) and needs nothing the requester asks to get works on the achiever's goal before it
    # is reached (plans the path, the arm's trajectory), with a producer's share. One that needs a requested
    # output comes after the request, not before (the price of the book being ordered). False: only
    # producers are steps.
    consumer_steps: bool = True
    # A step may also bring about what the achiever needs to hold: when an achiever has a precondition the
    # requester does not guarantee (hand over the item the robot holds), an advertisement whose effect
    # brings it about (picks the item up) is a step too, with a producer's share: the paper's composition by
    # preconditions and effects, as producers are its composition by inputs and outputs. False: off.
    precondition_steps: bool = True
    # How the parts of a match combine; parts the requirement does not state are left out and the
    # remaining weights renormalised.
    output_weight: float = 0.4
    input_weight: float = 0.2
    effect_weight: float = 0.3
    precondition_weight: float = 0.1
    # What a requirement asks to stop being true (cbrs:hasDeleteEffect, a cbrs extension: the paper's PE
    # has effects only) is a result like an effect: each requested delete effect's best statement match
    # among the advertised delete effects, averaged, weighed as much as the effects.
    delete_weight: float = 0.3
    # An advertisement's preconditions must all hold before it can be invoked (a conjunction): its
    # preconditions part is the lowest of their best matches among what the requirement guarantees.
    # False: their mean, so one guaranteed precondition made up for one nothing guarantees.
    precondition_conjunction: bool = True
    # An advertised input the requester offers as the same concept or a subclass can be given as it is:
    # the advertisement can be invoked with it (OWL-S plug-in), so the "can it be invoked?" side scores 1.
    plugin_inputs: bool = True
    # An advertised input narrower than what the requester provides, k is-a links below it (the service
    # takes an Author, the requester has a Person): the requester's instance may be one, OWL-S's "subsumes"
    # degree for inputs, weaker than plug-in but no failure. The "can it be invoked?" side scores at least
    # 1 - narrower_input_step * k for it (the step of a delivered subclass); 1 turns it off.
    narrower_input_step: float = 0.02
    # An advertised concept that is a subclass of the requested one inherits every part of it: those parts
    # count as covered (similarity 1) in CSS instead of being left out as implied.
    inherited_parts: bool = True
    # A requested output the advertisement delivers as a subclass (k is-a links below it) is delivered:
    # that pair scores at least 1 - specialisation_step * k, whatever the depth-bound Wu-Palmer says. The
    # same holds for an advertised input that accepts what the requester provides as a subclass
    # (docs/matchmaking.md, "Delivered as a subclass"); plugin_outputs false turns it off.
    plugin_outputs: bool = True
    specialisation_step: float = 0.02
    # A requested output met only by a concept that is neither the same, a subclass nor a superclass of it
    # (a sibling, a cousin, another branch) is not the thing asked for, however alike: its CSS is
    # multiplied by this factor (1 keeps Sem-Str's value; strict logic would make it 0).
    unrelated_output_factor: float = 1.0
    # The inputs part: (1 - input_use_weight) * invocable + input_use_weight * used, where invocable says
    # how well the requester can supply what the advertisement needs (1 when it needs nothing) and used
    # how much of what the requester provides the advertisement takes.
    input_use_weight: float = 0.5
    # An advertisement that needs no input can be invoked by anyone: its invocable side is 1. False: only
    # the used side counts for it (the published behaviour, which the baselines keep).
    no_input_invocable: bool = True
    # Input gating: the score is multiplied by (1 - input_gate) + input_gate * invocable, invocable being
    # the mean over the advertised inputs of how well the requester can supply each (1 when it provides
    # the concept or a subclass, else the best similarity to what it provides; 1 with no inputs).
    input_gate: float = 0.0
    # Candidates with equal scores are put in order by their result part (outputs, effects and delete
    # effects, weighted as in the score, to three decimals) before their IRI: what the requester asked for
    # before how the service is invoked. False: by IRI alone (the published order, which the baselines keep).
    tie_break_result: bool = True
    # The hybrid method (sem-str-text): the share of the TF-IDF cosine of names and text descriptions in
    # the ranking score; the rest is the Sem-Str IO/PE score, which alone decides acceptability.
    text_weight: float = 0.3
    # A candidate that passes the SEA and QoS filters is acceptable from this combined score up.
    accept_score: float = 0.5
    # An advertisement that states no value for a QoS metric the requirement bounds: fail it?
    qos_missing_fails: bool = True

    @classmethod
    def parameter_names(cls) -> tuple[str, ...]:
        return tuple(f.name for f in fields(cls))

    def with_params(self, params: Iterable[str]) -> MatchConfig:
        """This configuration with each ``name=value`` of ``params`` set (1/true/yes/on and 0/false/no/off
        for a yes/no parameter); a later one wins. Raises MatchParameterError naming the first parameter
        that does not exist, whose value is not of its type or lies outside its range."""
        types = {f.name: f.type for f in fields(self)}
        values: dict[str, Any] = {}
        written: dict[str, str] = {}  # each value as given, for the refusal: '2', not the '2.0' it was read as
        for item in params:
            name, equals, text = item.partition("=")
            name, text = name.strip(), text.strip()
            if not equals:
                raise MatchParameterError(item.strip(), None, "expected NAME=VALUE")
            if name not in types:
                close = difflib.get_close_matches(name, types, n=3)
                hint = f"; did you mean {' or '.join(close)}?" if close else "; cbrs match --params lists them"
                raise MatchParameterError(name, text, "no such parameter" + hint)
            values[name] = _parsed(name, text, str(types[name]))
            written[name] = text
        try:
            return replace(self, **values)
        except ValueError as error:  # __post_init__'s range checks name the field
            name = next((n for n in values if n in str(error)), next(iter(values)))
            raise MatchParameterError(name, written[name], str(error)) from error

    @property
    def part_weights(self) -> dict[str, float]:
        """The weight of each part of a score, by the part's name (the parts a requirement does not
        state are left out and the rest renormalised)."""
        return {
            "outputs": self.output_weight,
            "inputs": self.input_weight,
            "effects": self.effect_weight,
            "deletes": self.delete_weight,
            "preconditions": self.precondition_weight,
        }

    def published(self) -> MatchConfig:
        """This configuration with every refinement of docs/matchmaking.md section 9 turned off: how the
        baselines (and Sem-Str as first published here) score."""
        return replace(
            self,
            plugin_outputs=False,
            narrower_input_step=1.0,
            unrelated_output_factor=1.0,
            input_gate=0.0,
            input_use_weight=0.5,
            no_input_invocable=False,
            statement_mean="arithmetic",
            lexicon=False,
            disjoint_statements=False,
            antonym_statements=False,
            same_fact_contradictions=False,
            contradiction_factor=1.0,
            undone_state_factor=1.0,
            tie_break_result=False,
            complement_weight=0.0,
            unrelated_predicate_factor=1.0,
            observed_state_weight=0.0,
            decomposition_weight=0.0,
            consumer_steps=False,
            precondition_steps=False,
            unknown_under_root=False,
            precondition_conjunction=False,
        )

    def __post_init__(self) -> None:
        if not self.alpha > self.beta >= 0 or abs(self.alpha + self.beta - 1) > 1e-9:
            raise ValueError(f"need alpha > beta >= 0 and alpha + beta = 1, got {self.alpha}, {self.beta}")
        if not 0 <= self.jaro_winkler_floor < 1:
            raise ValueError(f"jaro_winkler_floor must lie in [0, 1), got {self.jaro_winkler_floor}")
        for name in (
            "pair_threshold",
            "accept_score",
            "text_weight",
            "specialisation_step",
            "narrower_input_step",
            "input_gate",
            "cross_branch_weight",
            "input_use_weight",
            "unrelated_output_factor",
            "complement_weight",
            "unrelated_predicate_factor",
            "observed_state_weight",
            "decomposition_weight",
            "contradiction_factor",
            "undone_state_factor",
        ):
            value = getattr(self, name)
            if not 0 <= value <= 1:
                raise ValueError(f"{name} must lie in [0, 1], got {value}")
        if self.statement_mean not in ("arithmetic", "geometric"):
            raise ValueError(f"statement_mean must be 'arithmetic' or 'geometric', got {self.statement_mean!r}")
        spo = self.subject_weight + self.predicate_weight + self.object_weight
        if abs(spo - 1) > 1e-9:
            raise ValueError(f"subject, predicate and object weights must sum to 1, got {spo}")


def _parsed(name: str, text: str, kind: str) -> Any:
    """``text`` as the type a MatchConfig field is declared with."""
    if kind == "bool":
        if text.lower() not in _WORDS:
            raise MatchParameterError(name, text, "expected a yes/no value (1, true, yes, on / 0, false, no, off)")
        return _WORDS[text.lower()]
    try:
        if kind == "int":
            return int(text)
        if kind == "float":
            value = float(text)
            if not math.isfinite(value):
                raise ValueError(text)
            return value
    except ValueError:
        raise MatchParameterError(name, text, f"expected a number ({kind})") from None
    return text
