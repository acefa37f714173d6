"""The taxonomy: the class and property trees (is-a links, each class with its hasPart children), a search
over them, and a page per term with its neighbours and the service descriptions that use it.

Everything is read with the named queries the taxonomy index reads (``taxonomy_links``,
``taxonomy_terms``), plus ``concept_parts``, ``concept_usage`` and ``resource_triples`` for one term.
"""

from __future__ import annotations

import difflib
import itertools
from collections.abc import Iterator, Set
from dataclasses import dataclass, field
from typing import Any

import pyoxigraph as ox
from flask import Blueprint, current_app, g, request, url_for
from markupsafe import Markup, escape

from cbrs.kb import KnowledgeBase
from cbrs.kb.catalog import is_built_in
from cbrs.kb.errors import NotFoundError
from cbrs.kb.namespaces import OWL, RDF, RDFS, GraphName, shorten
from cbrs.kb.vocab import CBRS
from cbrs.output import Expression, class_expression, manchester, node_view
from cbrs.web import context, diagram, ranking, resource, services
from cbrs.web.links import display_name, display_text, iri_link, short
from cbrs.web.pages import Page, page, wants_json

blueprint = Blueprint("taxonomy", __name__)
blueprint.record_once(resource.attach)  # the page of any IRI comes with the taxonomy (it is not in the nav)

MAX_PATHS = 12  # ancestor paths shown per search match
# Tree nodes a taxonomy page shows at most, per tree: the levels that fit, the rest a link away. OWLS-TC's
# class tree has 18,687 nodes, a page of 9 MB that took 2.5 s to serve and longer to lay out.
MAX_TREE_NODES = 2000
MAX_PICTURE_ROW = 10  # subclasses (and parts) drawn in a class's picture; the rest is one "N more" box
MAX_MATCHES = 200  # search matches listed with their paths; the count says how many there are
MAX_MEMBERS = 100  # individuals listed on a class's page; the count says how many there are
# How a service description reaches a concept, walking incoming triples back to the description.
_USE_LINKS = {
    CBRS.parameterType: "parameter",
    CBRS.conditionSubject: "condition",
    CBRS.conditionPredicate: "condition",
    CBRS.conditionObject: "condition",
}
_EXPRESSION_LINKS = {RDFS + "subClassOf", OWL + "equivalentClass"}
# The links by which a class expression names a class or property.
_IN_EXPRESSIONS = {
    *(OWL + name for name in ("someValuesFrom", "allValuesFrom", "hasValue", "onClass", "onDataRange")),
    *(OWL + name for name in ("onProperty", "inverseOf", "complementOf", "onDatatype")),
    RDF + "first",
}
_ROLE_LINKS = {
    CBRS.hasInput: "input",
    CBRS.hasOutput: "output",
    CBRS.hasPrecondition: "precondition",
    CBRS.hasEffect: "effect",
}


def local_name(iri: str) -> str:
    return iri.rsplit("#", 1)[-1].rsplit("/", 1)[-1]


def concept_url(iri: str) -> str:
    # expanded again by iri_parameter; declared prefixes only, so that a link stays good when a derived
    # prefix is renumbered (a namespace deriving the same name added to the store)
    return url_for("taxonomy.concept", iri=shorten(iri))


@blueprint.app_template_global("concept_link")
def concept_link(iri: str, label: str | None = None) -> Markup:
    """A link to the taxonomy page of a class or property."""
    return Markup(f'<a href="{escape(concept_url(iri))}" title="{escape(iri)}">{display_name(iri, label)}</a>')


@dataclass
class Taxonomy:
    """The terms and links of the store's taxonomy, as read for one request."""

    kinds: dict[str, str] = field(default_factory=dict)  # term -> "class" | "property"
    labels: dict[str, str] = field(default_factory=dict)
    parents: dict[str, set[str]] = field(default_factory=dict)  # is-a
    children: dict[str, set[str]] = field(default_factory=dict)
    parts: dict[str, set[str]] = field(default_factory=dict)  # whole -> its own declared parts
    wholes: dict[str, set[str]] = field(default_factory=dict)
    same: dict[str, set[str]] = field(default_factory=dict)

    @classmethod
    def read(cls, kb: KnowledgeBase) -> Taxonomy:
        found = cls()
        for row in kb.select("taxonomy_terms"):
            term = row["term"].value
            found.kinds[term] = row["kind"].value
            if "label" in row:
                found.labels[term] = row["label"].value
        links = [(row["child"].value, row["parent"].value, row["link"].value) for row in kb.select("taxonomy_links")]
        for child, parent, link in links:
            if link == "is-a":
                found.parents.setdefault(child, set()).add(parent)
                found.children.setdefault(parent, set()).add(child)
            elif link == "has-part":
                found.parts.setdefault(parent, set()).add(child)
                found.wholes.setdefault(child, set()).add(parent)
            else:
                found.same.setdefault(child, set()).add(parent)
                found.same.setdefault(parent, set()).add(child)
        # Terms only links mention (an imported class, dul:hasPart) take the kind of their neighbours.
        for child, parent, _ in links:
            for term, other in ((child, parent), (parent, child)):
                if term not in found.kinds:
                    found.kinds[term] = "property" if found.kinds.get(other) == "property" else "class"
        return found

    def __contains__(self, term: object) -> bool:
        return term in self.kinds

    def sorted(self, terms: set[str] | None) -> list[str]:
        return sorted(terms or (), key=lambda t: (short(t).casefold(), t))

    def term(self, iri: str) -> dict[str, Any]:
        return {"iri": iri, "name": short(iri), "label": self.labels.get(iri)}

    def roots(self, kind: str) -> list[str]:
        return self.sorted({t for t, k in self.kinds.items() if k == kind and not self.parents.get(t)})

    def tree(
        self,
        kind: str,
        keep: Set[str] | None = None,
        matches: Set[str] = frozenset(),
        limit: int | None = None,
        root: str | None = None,
    ) -> list[dict[str, Any]]:
        """Nested nodes from the roots (or from ``root``) down; a term with two parents appears under
        both. With ``keep``, only those terms. With ``limit``, only the levels whose nodes fit in it:
        a node cut off there has no ``children`` but ``more``, the number of its children not shown."""
        tops = [root] if root is not None else [r for r in self.roots(kind) if keep is None or r in keep]
        depth = self._depth_within(tops, keep, limit) if limit is not None else None
        return [self._node(top, (), keep, matches, depth) for top in tops]

    def _below(self, iri: str, path: tuple[str, ...], keep: Set[str] | None) -> list[str]:
        return [c for c in self.sorted(self.children.get(iri)) if c not in path and (keep is None or c in keep)]

    def _depth_within(self, tops: list[str], keep: Set[str] | None, limit: int) -> int | None:
        """The deepest level (0 for the tops) down to which the tree has at most ``limit`` nodes, or
        ``None`` when the whole tree fits. Walks level by level and stops once past the limit, so a
        tree of any size costs at most about ``limit`` nodes' work."""
        level: list[tuple[str, tuple[str, ...]]] = [(top, ()) for top in tops]
        total = len(level)
        depth = 0
        while level:
            below = [(c, (*path, iri)) for iri, path in level for c in self._below(iri, path, keep)]
            if not below:
                return None
            total += len(below)
            if total > limit:
                return depth
            level, depth = below, depth + 1
        return None

    def _node(
        self, iri: str, path: tuple[str, ...], keep: Set[str] | None, matches: Set[str], depth: int | None
    ) -> dict[str, Any]:
        below = self._below(iri, path, keep)
        node = self.term(iri)
        node["parts"] = [self.term(part) for part in self.sorted(self.parts.get(iri))]
        if matches:
            node["match"] = iri in matches
        if depth is not None and len(path) >= depth and below:
            node["children"] = []
            node["more"] = len(below)
            return node
        node["children"] = [self._node(child, (*path, iri), keep, matches, depth) for child in below]
        return node

    def search(self, text: str) -> list[str]:
        """Terms whose label or local name contains ``text``, ignoring case."""
        needle = text.casefold()
        return self.sorted(
            {
                term
                for term in self.kinds
                if needle in local_name(term).casefold() or needle in self.labels.get(term, "").casefold()
            }
        )

    def ranked(self, text: str) -> list[str]:
        """:meth:`search`'s terms, best match first (:func:`ranking.rank`): the list shows the first
        ``MAX_MATCHES``, and in name order OWLS-TC's ``Car`` was 72nd of 406 terms containing "car"."""
        needle = text.casefold()

        def score(term: str) -> int:
            found = ranking.rank(needle, (local_name(term),), (self.labels.get(term),))
            return ranking.IN_LABEL if found is None else found

        return sorted(self.search(text), key=score)  # stable: in name order within a score

    def paths(self, iri: str) -> list[list[str]]:
        """The is-a paths from a root down to ``iri`` (``iri`` excluded), at most ``MAX_PATHS``."""
        found: list[list[str]] = []

        def up(term: str, below: tuple[str, ...]) -> Iterator[list[str]]:
            parents = [p for p in self.sorted(self.parents.get(term)) if p not in below]
            if not parents:
                yield list(reversed(below[1:]))
            for parent in parents:
                yield from up(parent, (*below, parent))

        for path in up(iri, (iri,)):
            found.append(path)
            if len(found) == MAX_PATHS:
                break
        return found

    def ancestors(self, iri: str) -> set[str]:
        seen: set[str] = set()
        stack = [iri]
        while stack:
            for parent in self.parents.get(stack.pop(), ()):
                if parent not in seen:
                    seen.add(parent)
                    stack.append(parent)
        return seen


def current_taxonomy() -> Taxonomy:
    """The store's taxonomy, read once per store generation (:func:`context.per_generation`): reading
    it runs two queries over every term, about 1.5 s a page on OWLS-TC (16,000 terms), which every
    class page paid again."""
    kb = context.kb()
    return context.per_generation("taxonomy", lambda: Taxonomy.read(kb))


@page(blueprint, "/taxonomy")
def taxonomy() -> Page:
    found = current_taxonomy()
    query = (request.args.get("q") or "").strip()
    root = resource.iri_parameter("root") if (request.args.get("root") or "").strip() else None
    if root is not None and root not in found:
        raise NotFoundError(root, "class or property")
    kinds = list(found.kinds.values())
    counts = {"classes": kinds.count("class"), "properties": kinds.count("property")}
    limit = int(current_app.config.get("CBRS_TAXONOMY_NODES", MAX_TREE_NODES))
    data: dict[str, Any] = {"q": query or None, "root": None, "counts": counts, "limit": limit}
    keep: set[str] | None = None
    matches: list[str] = []
    if query:
        matches = found.ranked(query)
        keep = set(matches).union(*(found.ancestors(m) for m in matches))
        data["match_count"] = len(matches)
        data["matches"] = [
            {**found.term(m), "kind": found.kinds[m], "paths": _paths(found, m)} for m in matches[:MAX_MATCHES]
        ]
    if root is not None:
        data["root"] = {**found.term(root), "kind": found.kinds[root], "paths": _paths(found, root)}
        if not wants_json():  # the root among its ancestors and children, as on its class page
            data["picture"] = _picture(found, root, [])
        if keep is not None:
            keep.add(root)
    for kind, key in (("class", "classes"), ("property", "properties")):
        shown = root is None or found.kinds[root] == kind
        data[key] = found.tree(kind, keep, set(matches), limit, root) if shown else []
    title = "Taxonomy"
    if root is not None:
        title += f" below {display_text(root)}"
    if query:
        title += f": “{query}”"
    return Page("taxonomy.html", title, data)


def _paths(found: Taxonomy, iri: str) -> list[list[dict[str, Any]]]:
    return [[found.term(t) for t in p] for p in found.paths(iri)]


@page(blueprint, "/taxonomy/class")
def concept() -> Page:
    iri = resource.iri_parameter()
    kb = context.kb()
    found = current_taxonomy()
    triples = kb.select("resource_triples", {"resource": ox.NamedNode(iri)})
    if iri not in found:
        return _undeclared(kb, found, iri, triples)
    g.taxonomy_terms = found.kinds  # what expression_html links to a taxonomy page
    comment = min((r["other"].value for r in triples if _out(r, RDFS + "comment")), default=None)  # rows unordered
    kind = found.kinds[iri]
    data = {
        **found.term(iri),
        "kind": kind,
        "comment": comment,
        "paths": _paths(found, iri),
        "superclasses": [found.term(t) for t in found.sorted(found.parents.get(iri))],
        "subclasses": [found.term(t) for t in found.sorted(found.children.get(iri))],
        "equivalents": [found.term(t) for t in found.sorted(found.same.get(iri))],
        "parts": _parts(kb, iri) if kind == "class" else [],
        "part_of": [found.term(t) for t in found.sorted(found.wholes.get(iri))],
        "restrictions": _restrictions(kb, triples) if kind == "class" else [],
        "named_in": _named_in(kb, triples),
        "usage": _usage(kb, iri, triples),
        "members": _members(triples) if kind == "class" else {"count": 0, "shown": []},
    }
    hierarchy = _sub_actions(iri) if kind == "class" else None
    if hierarchy is not None:
        data["sub_actions"] = hierarchy
    if not wants_json():  # markup, so not in the twin, which has the same facts as lists
        data["picture"] = _picture(found, iri, data["parts"])
        if hierarchy is not None:
            data["hierarchy"] = _hierarchy_picture(iri, hierarchy)
    noun = "Class" if kind == "class" else "Property"
    return Page("class.html", f"{noun} {display_text(iri)}", data)


def _picture(found: Taxonomy, iri: str, parts: list[dict[str, Any]]) -> Markup:
    """The term among its ancestors (every is-a path up, as the breadcrumbs), its direct subclasses and
    its parts, as a picture: arrows point from a class to its superclass, dashed ones to its parts."""
    distance: dict[str, int] = {}
    edges: list[diagram.Edge] = []
    for path in found.paths(iri):
        chain = [*path, iri]
        for step, term in enumerate(path):
            distance[term] = max(distance.get(term, 0), len(path) - step)
        edges += [diagram.Edge(lower, upper) for upper, lower in itertools.pairwise(chain)]
    edges = list(dict.fromkeys(edges))

    def box(term: str, kind: str = "node") -> diagram.Box:
        label = found.labels.get(term)
        title = f"{term}" + (f" ({label})" if label else "")
        return diagram.Box(term, display_text(term), title, concept_url(term), kind)

    rows = [
        [box(t) for t in found.sorted({t for t, d in distance.items() if d == level})]
        for level in range(max(distance.values(), default=0), 0, -1)
    ]
    rows.append([box(iri, "focus")])
    below = found.sorted(found.children.get(iri))
    row = [box(t) for t in below[:MAX_PICTURE_ROW]]
    edges += [diagram.Edge(t, iri) for t in below[:MAX_PICTURE_ROW]]
    if len(below) > MAX_PICTURE_ROW:
        rest = len(below) - MAX_PICTURE_ROW
        href = url_for("taxonomy.taxonomy", root=short(iri))
        row.append(diagram.Box("more", f"{rest} more", f"{rest} more: the tree below", href, "more"))
        edges.append(diagram.Edge("more", iri))
    for part in parts[:MAX_PICTURE_ROW]:  # beside the subclasses, reached by dashed arrows down
        key = "part:" + part["iri"]
        row.append(diagram.Box(key, display_text(part["iri"]), part["iri"], concept_url(part["iri"]), "part"))
        edges.append(diagram.Edge(iri, key, local_name(part["property"]), dashed=True))
    if row:
        rows.append(row)
    nouns = "subclasses" if found.kinds.get(iri) == "class" else "subproperties"
    what = f"{len(distance)} ancestors, {len(below)} direct {nouns}"
    return diagram.layered(rows, edges, f"{display_text(iri)} in the taxonomy", f"{what} and {len(parts)} parts")


def _sub_actions(iri: str) -> list[dict[str, Any]] | None:
    """An action class's sub-actions as the composer decomposes it (each its own, in their order, down to
    the composer's ``MAX_DEPTH`` levels, as deep as it decomposes a task): ``[{iri, name, order,
    sub_actions}]``; None for a class that is no action with sub-actions. A robotics class looked at
    FetchMyPen's four sub-actions as four lines of Manchester syntax among its restrictions: no picture drew
    the hierarchy a task is planned by."""
    from cbrs.actions.composer import MAX_DEPTH
    from cbrs.actions.model import ActionLibrary  # the planner's model; networkx loads with it

    library = context.per_generation("action_library", lambda: ActionLibrary.from_kb(context.kb()))
    if iri not in library or not library.get(iri).sub_actions:
        return None

    def below(action: str, depth: int, seen: tuple[str, ...]) -> list[dict[str, Any]]:
        if depth >= MAX_DEPTH or action not in library:
            return []
        return [
            {
                "iri": sub,
                "name": short(sub),
                "order": n,
                "sub_actions": [] if sub in seen else below(sub, depth + 1, (*seen, sub)),
            }
            for n, sub in enumerate(library.get(action).ordered_sub_actions(), start=1)
        ]

    return below(iri, 0, (iri,))


def _hierarchy_picture(iri: str, tree: list[dict[str, Any]]) -> Markup:
    """The action on top, each level of sub-actions a row below, an arrow from an action to each of its
    sub-actions named by its place in the order; a sub-action under two actions is drawn once, on the
    lower row."""
    depth: dict[str, int] = {iri: 0}
    order: dict[str, tuple[int, ...]] = {iri: ()}  # where a sub-action first comes: (1, 2) is 1's second
    edges: list[diagram.Edge] = []

    def walk(parent: str, nodes: list[dict[str, Any]], level: int) -> None:
        for node in nodes:
            depth[node["iri"]] = max(depth.get(node["iri"], 0), level)
            order.setdefault(node["iri"], (*order[parent], node["order"]))
            edges.append(diagram.Edge(parent, node["iri"], note=f"sub-action {node['order']}"))
            walk(node["iri"], node["sub_actions"], level + 1)

    walk(iri, tree, 1)
    edges = [e for e in dict.fromkeys(edges) if depth[e.target] > depth[e.source]]  # no arrow back up a cycle

    def box(term: str) -> diagram.Box:
        number = ".".join(map(str, order[term]))
        text = f"{number}. {display_text(term)}" if number else display_text(term)
        return diagram.Box(term, text, term, concept_url(term), "focus" if term == iri else "node")

    rows = [
        [box(term) for term in sorted((t for t, d in depth.items() if d == level), key=lambda t: order[t])]
        for level in range(max(depth.values()) + 1)
    ]
    levels = len(rows) - 1
    said = f"{len(depth) - 1} sub-actions on {levels} level{'' if levels == 1 else 's'}, numbered in their order"
    return diagram.layered(rows, edges, f"{display_text(iri)} and its sub-actions", said, ident="hierarchy")


def _undeclared(kb: KnowledgeBase, found: Taxonomy, iri: str, triples: list[dict[str, Any]]) -> Page:
    """The page of a concept that descriptions use but no ontology of the store declares (a lab's typo,
    or a concept of its own): what uses it, and the declared classes with a name like it. Service pages
    link every parameter type and statement term here, so such a term led to a 404."""
    usage = _usage(kb, iri, triples)
    if not (usage["advertisements"] or usage["requirements"] or usage["actions"]):
        raise NotFoundError(iri, "class or property")
    similar: list[dict[str, Any]] = []
    built_in = is_built_in(iri)  # rdf:type, a statement's predicate: every store knows it
    if not built_in:
        names: dict[str, list[str]] = {}
        for term in found.kinds:
            names.setdefault(local_name(term).casefold(), []).append(term)
        close = difflib.get_close_matches(local_name(iri).casefold(), list(names), n=3, cutoff=0.75)
        similar = [found.term(term) for name in close for term in found.sorted(set(names[name]))]
    empty: list[Any] = []
    data = {
        **found.term(iri),
        "kind": "built-in" if built_in else "undeclared",
        "comment": None,
        "paths": empty,
        "superclasses": empty,
        "subclasses": empty,
        "equivalents": empty,
        "parts": empty,
        "part_of": empty,
        "restrictions": empty,
        "named_in": empty,
        "similar": similar,
        "usage": usage,
        "members": {"count": 0, "shown": empty},
    }
    title = f"{'Built-in term' if built_in else 'Undeclared concept'} {display_text(iri)}"
    return Page("class.html", title, data)


@blueprint.app_template_global("expression_html")
def expression_html(expression: Expression) -> Markup:
    """A class expression (:func:`cbrs.output.class_expression`) in Manchester syntax, its classes and
    properties linked to their taxonomy pages (those the taxonomy has) and anything else to its triples."""

    terms = g.get("taxonomy_terms", ())

    def name(kind: str, iri: str) -> str:
        return str(concept_link(iri) if kind in ("class", "property") and iri in terms else iri_link(iri))

    return Markup(manchester(expression, name=name, plain=lambda text: str(escape(text))))


def _restrictions(kb: KnowledgeBase, triples: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """The class's anonymous superclasses and equivalents (restrictions, intersections...), every one,
    where the parts table shows only the hasPart family's."""
    found = []
    for row in triples:
        if row["direction"].value != "out" or row["predicate"].value not in _EXPRESSION_LINKS:
            continue
        expression = class_expression(lambda node: kb.store.quads(node), row["other"])
        if expression is not None:
            found.append(_expression_row(row["predicate"].value, expression))
    return sorted(found, key=lambda r: (r["relation_name"], r["text"].casefold()))


def _named_in(kb: KnowledgeBase, triples: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """The classes whose restrictions (or other class expressions) name this term."""
    entailed = GraphName.ENTAILED.node

    def into(node: ox.NamedNode) -> list[ox.Quad]:
        return [q for q in kb.store.quads(None, None, node) if q.graph_name != entailed]

    found: dict[tuple[str, str, str], dict[str, Any]] = {}
    for row in triples:
        if row["direction"].value != "in" or row["predicate"].value not in _IN_EXPRESSIONS:
            continue  # a parameter's cbrs:parameterType, say: not read (on a remote store each costs requests)
        view = node_view(lambda node: kb.store.quads(node), into, row["other"], "in")
        if view is None or "expression" not in view or "owner" not in view:
            continue
        owner = view["owner"]["iri"]
        item = {"iri": owner, "name": short(owner), **_expression_row(view["owner"]["path"][0], view["expression"])}
        found.setdefault((owner, item["relation"], item["text"]), item)
    return sorted(found.values(), key=lambda r: (r["name"].casefold(), r["text"].casefold()))


def _expression_row(relation: str, expression: Expression) -> dict[str, Any]:
    return {
        "relation": relation,
        "relation_name": short(relation),
        "text": manchester(expression),
        "expression": expression,
    }


def _members(triples: list[dict[str, Any]]) -> dict[str, Any]:
    """The named individuals stated of the class (``rdf:type`` it, not a subclass): the pen, the kitchen,
    the lab's visitor were reached from their class only through its "all triples" page."""
    found = sorted(
        {r["other"].value for r in triples if _in(r, RDF + "type") and isinstance(r["other"], ox.NamedNode)},
        key=lambda t: (short(t).casefold(), t),
    )
    return {"count": len(found), "shown": [{"iri": t, "name": short(t)} for t in found[:MAX_MEMBERS]]}


def _in(row: dict[str, Any], predicate: str) -> bool:
    return bool(row["direction"].value == "in" and row["predicate"].value == predicate)


def _out(row: dict[str, Any], predicate: str) -> bool:
    return bool(row["direction"].value == "out" and row["predicate"].value == predicate)


def _parts(kb: KnowledgeBase, iri: str) -> list[dict[str, Any]]:
    """The concept's hasPart children, own and inherited (own first when a part is both)."""
    parts: dict[tuple[str, str], dict[str, Any]] = {}
    for row in kb.select("concept_parts", {"concept": ox.NamedNode(iri)}):
        key = (row["property"].value, row["part"].value)
        owner = row["owner"].value
        if key in parts and parts[key]["inherited_from"] is None:
            continue
        parts[key] = {
            "iri": key[1],
            "name": short(key[1]),
            "property": key[0],
            "property_name": short(key[0]),
            "inherited_from": None if owner == iri else owner,
        }
    return sorted(parts.values(), key=lambda p: (p["inherited_from"] is not None, p["name"].casefold()))


def _usage(kb: KnowledgeBase, iri: str, triples: list[dict[str, Any]]) -> dict[str, Any]:
    """Which advertisements, requirements and actions use the concept, and as what (input, effect, ...)."""
    uses = _usage_counts(kb).get(iri, 0)
    roles: dict[str, set[str]] = {}
    for row in triples:
        if row["direction"].value == "in" and row["predicate"].value in _USE_LINKS:
            for description, role in _descriptions_of(kb, row["other"].value):
                roles.setdefault(description, set()).add(role)
    advertisements, requirements = _description_labels(kb)
    groups: dict[str, list[dict[str, Any]]] = {"advertisements": [], "requirements": [], "actions": []}
    for description in sorted(roles, key=lambda d: short(d).casefold()):
        group = "actions"
        if description in advertisements:
            group = "advertisements"
        elif description in requirements:
            group = "requirements"
        groups[group].append(
            {
                "iri": description,
                "name": short(description),
                "label": advertisements.get(description) or requirements.get(description),
                "roles": sorted(roles[description]),
            }
        )
    return {"uses": uses, **groups}


def _usage_counts(kb: KnowledgeBase) -> dict[str, int]:
    """How often each concept is used (``concept_usage``, which counts every concept at once: read once
    per store generation, as the taxonomy is)."""

    def read() -> dict[str, int]:
        return {row["concept"].value: int(row["uses"].value) for row in kb.select("concept_usage")}

    return context.per_generation("concept_usage", read)


def _description_labels(kb: KnowledgeBase) -> tuple[dict[str, str | None], dict[str, str | None]]:
    """The advertisements' and the requirements' labels by IRI, from the services tables' rows (read
    once per store generation): on OWLS-TC listing the 1,136 advertisements took half a class page's time."""
    return (
        {row["service"]: row["label"] for row in services.advertisement_rows(kb)},
        {row["requirement"]: row["label"] for row in services.requirement_rows(kb)},
    )


def _descriptions_of(kb: KnowledgeBase, node: str) -> list[tuple[str, str]]:
    """(description, role) for a parameter or statement node: node <- model (role) <- description."""
    found = []
    for edge in kb.select("resource_triples", {"resource": node}):
        role = _ROLE_LINKS.get(edge["predicate"].value)
        if edge["direction"].value != "in" or role is None:
            continue
        for up in kb.select("resource_triples", {"resource": edge["other"].value}):
            if up["direction"].value == "in" and up["predicate"].value == CBRS.hasOWLSModel:
                found.append((up["other"].value, role))
    return found
