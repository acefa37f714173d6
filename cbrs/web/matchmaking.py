"""The matchmaking page: rank the advertisements for a stored or a written requirement, with several
methods side by side, and say why each candidate ranks where it does."""

from __future__ import annotations

import difflib
import re
from typing import Any, Literal

from flask import Blueprint, request

from cbrs.iri_tail import tail_parts
from cbrs.kb import NotFoundError, Parameter, Requirement, Statement
from cbrs.kb.namespaces import PREFIXES, shorten
from cbrs.kb.vocab import CBRS
from cbrs.reasoner.degrees import Degree
from cbrs.reasoner.matchmaker import Candidate, Matchmaker, MatchResult
from cbrs.reasoner.methods import METHODS
from cbrs.reasoner.taxonomy import TaxonomyIndex
from cbrs.web import context
from cbrs.web.links import display_text, expand_name, short
from cbrs.web.pages import FormError, Page, page, wants_json
from cbrs.web.prefixes import derived

blueprint = Blueprint("matchmaking", __name__)

WRITTEN_IRI = "urn:cbrs:web:written-requirement"
DEFAULT_TOP = 10
MAX_TOP = 50
CONCEPT_FIELDS = ("inputs", "outputs")
STATEMENT_FIELDS = ("preconditions", "effects", "deletes")
# Weakest first: a candidate's degree is the weakest degree among its output and effect pairs.
DEGREE_ORDER = [Degree.FAIL.value, Degree.HAS_SUBCLASS.value, Degree.SUBCLASS_OF.value, Degree.EXACT.value]


def matchmaker(method: str) -> Matchmaker:
    """The cached matchmaker for ``method`` over the store as it is now; call with ``context.lock()`` held."""
    return context.matchmakers().get(method)


@page(blueprint, "/match")
def matchmaking() -> Page:
    form = _form()
    data = {"form": form, "methods": list(METHODS), "requirements": requirements(), "rankings": []}
    shown = Page("matchmaking.html", "Matchmaking", data)
    if not wants_json():
        shown.data["concepts"] = concepts()  # for the inputs' completion; the twin need not carry them
    if not _asked(form):
        return shown
    errors = _check_options(form)
    if errors:
        raise FormError(errors, page=shown)
    with context.lock():
        matchmakers = {method: matchmaker(method) for method in form["methods"]}
        requirement = _requirement(form, next(iter(matchmakers.values())), shown)
        results = [m.rank(requirement, explain=form["top"]) for m in matchmakers.values()]
    # titled by the requirement once it is known: a refused one titled the error page as if ranked
    shown.title = "Matchmaking: " + (form["requirement"] or "a written requirement")
    shown.data.update(
        requirement=_requirement_dict(requirement),
        rankings=[_ranking(result, form["top"], requirement) for result in results],
    )
    return shown


def concepts() -> list[str]:
    """The form's completion list: every concept of the taxonomy index a declared prefix names, once per
    store generation (shortening OWLS-TC's 16,000 nodes took 0.2 s of each page)."""

    def read() -> list[str]:
        with context.lock():
            nodes = matchmaker("sem-str").index.nodes()
        return sorted(name for name in map(shorten, nodes) if "://" not in name)

    return context.per_generation("match_concepts", read)


# -- the form ------------------------------------------------------------------------------------


def _form() -> dict[str, Any]:
    args = request.args
    form: dict[str, Any] = {name: args.get(name, "").strip() for name in ("requirement", "top")}
    for name in (*CONCEPT_FIELDS, *STATEMENT_FIELDS):
        form[name] = args.get(name, "").strip()
    # ``method``, as `cbrs match --method` and the bridge's /cbrs/match spell it, is read too: it was ignored
    asked = args.getlist("methods") + args.getlist("method")
    form["methods"] = [m for m in asked if m] or ["sem-str"]
    return form


def _asked(form: dict[str, Any]) -> bool:
    """Whether the form was sent (any of its fields is in the URL), even with nothing in it."""
    return any(name in request.args for name in ("requirement", *CONCEPT_FIELDS, *STATEMENT_FIELDS))


def _check_options(form: dict[str, Any]) -> dict[str, str]:
    errors = {}
    unknown = [m for m in form["methods"] if m not in METHODS]
    if unknown:
        errors["methods"] = f"no method {', '.join(map(repr, unknown))}; choose among {', '.join(METHODS)}"
    form["methods"] = [m for m in dict.fromkeys(form["methods"]) if m in METHODS] or ["sem-str"]
    top = form["top"] or str(DEFAULT_TOP)
    if not top.isdigit() or not 1 <= int(top) <= MAX_TOP:
        errors["top"] = f"{form['top']!r} is not a number from 1 to {MAX_TOP}"
    else:
        form["top"] = int(top)
    written = any(form[name] for name in (*CONCEPT_FIELDS, *STATEMENT_FIELDS))
    if form["requirement"] and written:
        errors["requirement"] = "choose a stored requirement or write one below, not both (clear this choice)"
    elif not form["requirement"] and not written:
        errors["requirement"] = "choose a stored requirement, or write one: inputs, outputs, effects"
    return errors


def _requirement(form: dict[str, Any], any_matchmaker: Matchmaker, shown: Page) -> Requirement:
    if form["requirement"]:
        return _stored(form["requirement"], shown)
    index = any_matchmaker.index
    errors: dict[str, str] = {}
    concepts: dict[str, list[str]] = {}
    statements: dict[str, list[Statement]] = {}
    for name in CONCEPT_FIELDS:
        try:
            concepts[name] = [_concept(term, index) for term in _terms(form[name])]
        except ValueError as error:
            errors[name] = str(error)
    for name in STATEMENT_FIELDS:
        try:
            statements[name] = _statements(form[name], index)
        except ValueError as error:
            errors[name] = str(error)
    if errors:
        raise FormError(errors, page=shown)
    kb = context.kb()

    def parameters(direction: Literal["input", "output"]) -> tuple[Parameter, ...]:
        return tuple(
            Parameter(f"{WRITTEN_IRI}/{direction}{i}", direction, c, None, kb.part_tree(c))
            for i, c in enumerate(concepts[direction + "s"], start=1)
        )

    return Requirement(
        iri=WRITTEN_IRI,
        types=(CBRS.Requirement,),
        label="written requirement",
        inputs=parameters("input"),
        outputs=parameters("output"),
        preconditions=tuple(statements["preconditions"]),
        effects=tuple(statements["effects"]),
        deletes=tuple(statements["deletes"]),
    )


def _stored(name: str, shown: Page) -> Requirement:
    try:
        iri = expand_name(name if ":" in name else f"req:{name}")
        found = context.kb().description(iri)
    except ValueError as error:
        raise FormError({"requirement": str(error)}, page=shown) from None
    except NotFoundError:  # it said "no service description <...>", and nothing of the list above it
        raise FormError({"requirement": _no_such_requirement(name)}, page=shown) from None
    if not isinstance(found, Requirement):
        raise FormError({"requirement": f"{name} is an advertisement, not a requirement"}, page=shown)
    return found


def _no_such_requirement(name: str) -> str:
    names = [str(r["name"]) for r in requirements()]
    near = difflib.get_close_matches(name if ":" in name else f"req:{name}", names, n=3, cutoff=0.75)
    hint = f"did you mean {' or '.join(near)}? " if near else ""
    return f"no stored requirement {name}; {hint}choose one of the {len(names)} in the list, or write one below"


def _terms(text: str) -> list[str]:
    return [t for t in re.split(r"[\s,;]+", text) if t]


def _concept(term: str, index: TaxonomyIndex) -> str:
    if ":" not in term and "#" in term:  # as the pages show an IRI no prefix shortens: file.owl#Name
        return _by_tail(term, index)
    prefix = term.partition(":")[0]
    known = prefix in PREFIXES or prefix in derived()  # the prefixes the pages show, the store's own included
    if ":" not in term:  # a class page's name after its prefix: MarkerColour for home:MarkerColour
        near = _by_local_name(term, index)
        hint = f"did you mean {' or '.join(near)}?" if near else "concepts are prefixed names, e.g. home:Cup"
        raise ValueError(f"{term} has no prefix; {hint}")
    if not term.startswith("<") and not known and prefix not in ("http", "https", "urn"):
        near = _by_local_name(term.partition(":")[2], index)
        hint = f"did you mean {' or '.join(near)}?" if near else f"use one of {', '.join(PREFIXES)}"
        raise ValueError(f"{term}: {prefix}: is not a known prefix; {hint}")
    iri = expand_name(term)
    if iri not in index:
        near = difflib.get_close_matches(term, [display_text(n) for n in index.nodes()], n=3, cutoff=0.75)
        hint = f"; did you mean {' or '.join(near)}?" if near else "; concepts are prefixed names, e.g. home:Cup"
        raise ValueError(f"{term} is not a concept or property of the ontology{hint}")
    return iri


def _by_local_name(local: str, index: TaxonomyIndex) -> list[str]:
    """The concepts (as the pages name them) whose local name is ``local`` with case aside, else the
    closest few: a name typed without its prefix, or with a slipped one, names its class still."""
    names: dict[str, list[str]] = {}
    for node in index.nodes():
        shown = display_text(node)
        names.setdefault(re.split(r"[:#/]", shown)[-1].casefold(), []).append(shown)
    key = local.casefold()
    close = [key] if key in names else difflib.get_close_matches(key, list(names), n=3, cutoff=0.75)
    return sorted({shown for name in close for shown in names[name]})[:3]


def _by_tail(term: str, index: TaxonomyIndex) -> str:
    """The concept named ``term`` by its tail (``my_ontology.owl#Car``, ``links.tail_parts``): OWLS-TC's IRIs
    have no prefix, so before, a user had to type ``http://127.0.0.1/ontology/my_ontology.owl#Car``."""

    def read() -> dict[str, list[str]]:
        tails: dict[str, list[str]] = {}
        for node in index.nodes():
            if shorten(node) == node:
                tails.setdefault("".join(tail_parts(node)), []).append(node)
        return tails

    found = sorted(context.per_generation("concept_tails", read).get(term, []))
    if len(found) == 1:
        return found[0]
    if found:
        raise ValueError(f"{term} names {len(found)} concepts, {', '.join(found)}: give the whole IRI")
    tails = list(context.per_generation("concept_tails", read))
    near = difflib.get_close_matches(term, tails, n=3, cutoff=0.75)
    hint = f"; did you mean {' or '.join(near)}?" if near else ""
    raise ValueError(f"{term} is not a concept or property of the ontology{hint}")


def _statements(text: str, index: TaxonomyIndex) -> list[Statement]:
    """One statement a line: ``subject predicate object``, prefixed names (brackets and commas allowed)."""
    found = []
    for number, line in enumerate(text.splitlines(), start=1):
        terms = _terms(line.strip().strip("()"))
        if not terms:
            continue
        if len(terms) != 3:
            raise ValueError(f"line {number}: {line.strip()!r} is not 'subject predicate object'")
        s, p, o = (_concept(t, index) for t in terms)
        found.append(Statement(s, p, o))
    return found


def requirements() -> list[dict[str, str | None]]:
    """The stored requirements the form offers, once per store generation: reading them took 0.6 s of
    every matchmaking page on OWLS-TC."""

    def read() -> list[dict[str, str | None]]:
        with context.lock():
            found = context.kb().requirements()
        return [{"iri": r.iri, "name": short(r.iri), "label": r.label} for r in sorted(found, key=lambda r: r.iri)]

    return context.per_generation("match_requirements", read)


# -- the answer ----------------------------------------------------------------------------------


def _requirement_dict(requirement: Requirement) -> dict[str, Any]:
    def statement(s: Statement) -> list[str]:
        return [s.subject, s.predicate, s.object]

    return {
        "iri": requirement.iri,
        "name": short(requirement.iri),
        "label": requirement.label,
        "written": requirement.iri == WRITTEN_IRI,
        "inputs": [p.type for p in requirement.inputs],
        "outputs": [p.type for p in requirement.outputs],
        "preconditions": [statement(s) for s in requirement.preconditions],
        "effects": [statement(s) for s in requirement.effects],
        "deletes": [statement(s) for s in requirement.deletes],
    }


def _ranking(result: MatchResult, top: int, requirement: Requirement) -> dict[str, Any]:
    outputs = {p.type for p in requirement.outputs}
    return {
        "method": result.method,
        "status": result.status.value,
        "count": len(result.candidates),
        "candidates": [_candidate(rank, c, outputs) for rank, c in enumerate(result.candidates[:top], start=1)],
    }


def _candidate(rank: int, c: Candidate, outputs: set[str]) -> dict[str, Any]:
    # The logic degree of the whole: the weakest over the requested outputs (not their parts), effects and
    # delete effects.
    degrees = [
        p.degree
        for p in c.pairs
        if ((p.role == "output" and p.requested in outputs) or p.role in ("effect", "delete effect"))
        and p.degree in DEGREE_ORDER
    ]
    return {
        "rank": rank,
        "advertisement": c.advertisement,
        "name": short(c.advertisement),
        "label": c.label,
        "score": c.score,
        "parts": c.parts,
        "degree": min(degrees, key=DEGREE_ORDER.index) if degrees else None,
        "acceptable": c.acceptable,
        "rejected_by": list(c.rejected_by),
        "lacks": list(c.lacks),
        "explanation": [
            {
                "role": p.role,
                "wanted": p.requested,
                "offered": p.advertised,
                "similarity": round(p.similarity, 4),
                "degree": p.shown_degree(),
                "how": p.how,
            }
            for p in c.pairs
        ],
    }
