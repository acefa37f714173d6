"""Reading at start, in the background, what the first pages on a big store need, so that their user
does not wait for it.

On OWLS-TC (180,000 triples) the first matchmaking page after a start took 4.6 s (the taxonomy index,
the requirements, the derived prefixes) and the tasks page 11 s in Chromium (the camera's picture of the
idle home). ``cbrs serve`` starts :func:`warm_up` once it listens: one thread reads, one after another,
the same per-generation values the pages read (:func:`cbrs.web.context.per_generation`), so a page asked
meanwhile waits for the value under way instead of reading it a second time, and finds the others ready.
A store under ``CBRS_WARM_UP_TRIPLES`` triples (the bundled one has 7,800) reads fast enough as it is,
and a remote store keeps nothing between pages, so neither is warmed up. Until it is done, every page
says what is being read (:meth:`WarmUp.note`), and the log has a line for each step.

Whatever the store, the first page anyone opens of a server :func:`warm_up` started also starts
importing, in a thread of its own, the libraries the first service, matchmaking, plans and tasks pages
load (the planner and networkx, the matchmaker, the simulation's list of skills): on the bundled store
they were 0.4 to 0.7 s of each of those first pages (``CBRS_PRELOAD_MODULES``; an empty list imports
nothing). Not at start: they take about 30 MB, which a server only programs query (``/sparql``, the
graph store, component registrations) never needs.
"""

from __future__ import annotations

import importlib
import logging
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass, field

from flask import Flask

from cbrs.web import context

log = logging.getLogger("cbrs.web")

DEFAULT_TRIPLES = 50_000  # CBRS_WARM_UP_TRIPLES: a store this big or bigger is warmed up at start
# CBRS_PRELOAD_MODULES: imported at start for every store, in the order the first pages need them
PRELOADED = ("cbrs.matchmakers", "cbrs.reasoner.matchmaker", "cbrs.actions.composer", "cbrs.sim")


def _steps() -> list[tuple[str, Callable[[], object]]]:
    """What is read, in the order a user opens the pages: every page's prefixes, the overview, the
    services page's rows, the matchmaking page and its first ranking, the tasks and plans pages, the
    taxonomy, and last the camera's picture, which holds the store lock for seconds."""
    from cbrs.web import matchmaking, overview, plans, prefixes, services, tasks, taxonomy

    def service_rows() -> object:
        """The services page's tables (1.15 s of its first showing on OWLS-TC); the overview counts
        them too, but need not."""
        kb = context.kb()
        return services.advertisement_rows(kb), services.requirement_rows(kb)

    def matchmaker() -> object:
        with context.lock():
            return matchmaking.matchmaker("sem-str")

    def ranking() -> object:
        """One ranking reads and compiles every advertisement, which the first ranking page paid for."""
        stored = matchmaking.requirements()
        if not stored:
            return None
        with context.lock():
            return matchmaking.matchmaker("sem-str").rank(str(stored[0]["iri"]), explain=0)

    def composer() -> object:
        """The plans page's composer and its pool of services (the first plan paid 1.7 s for them on OWLS-TC)."""
        from cbrs.actions.composer import Objective

        with context.lock():
            return context.composers().get(Objective(plans.default_objective())).pool

    return [
        ("the store's namespaces", prefixes.by_namespace),
        ("the overview's counts", overview.at_a_glance),
        ("the services page's rows", service_rows),
        ("the stored requirements", matchmaking.requirements),
        ("the taxonomy index", matchmaker),
        ("the concepts", matchmaking.concepts),
        ("the advertisements", ranking),
        ("the tasks and components", tasks.choices),
        ("the plans page's tasks", plans.task_options),
        ("the plans page's services", composer),
        ("the taxonomy", taxonomy.current_taxonomy),
        ("the camera's first picture", lambda: context.tasks().frame()),
    ]


@dataclass
class WarmUp:
    """Where the warm-up is: how many steps are done and which one is under way."""

    steps: tuple[str, ...]
    done: int = 0
    current: str | None = None
    seconds: dict[str, float] = field(default_factory=dict)
    finished: threading.Event = field(default_factory=threading.Event)

    def note(self) -> str | None:
        """What the pages say while it runs; None once it is done."""
        if self.finished.is_set() or self.current is None:
            return None
        return (
            f"Getting ready: reading {self.current} (step {self.done + 1} of {len(self.steps)}); "
            "a page that needs it waits for it."
        )


def warm_up(app: Flask) -> WarmUp | None:
    """Start reading in the background what the first pages need (``app.extensions["cbrs.warm_up"]``);
    None when the store is remote or smaller than ``CBRS_WARM_UP_TRIPLES``. The libraries are imported
    for every store, once a page is asked (:func:`preload_once`)."""
    app.extensions["cbrs.preload_armed"] = True
    threshold = int(app.config.get("CBRS_WARM_UP_TRIPLES", DEFAULT_TRIPLES))
    with app.app_context():
        kb = context.kb()
        if getattr(kb.store, "generation", None) is None:
            return None
        if sum(context.per_generation("graph_statistics", kb.statistics).values()) < threshold:
            return None
        steps = _steps()
    state = WarmUp(tuple(label for label, _ in steps))
    app.extensions["cbrs.warm_up"] = state
    threading.Thread(target=_run, args=(app, state, steps), name="cbrs-warm-up", daemon=True).start()
    return state


def preload(app: Flask) -> threading.Thread | None:
    """Import ``CBRS_PRELOAD_MODULES`` in a background thread (``app.extensions["cbrs.preload"]``); it
    reads nothing of the store and takes no lock. None when the list is empty."""
    modules = tuple(app.config.get("CBRS_PRELOAD_MODULES", PRELOADED))
    if not modules:
        return None
    thread = threading.Thread(target=_import, args=(modules,), name="cbrs-preload", daemon=True)
    app.extensions["cbrs.preload"] = thread
    thread.start()
    return thread


_PRELOAD_GUARD = threading.Lock()


def preload_once(app: Flask) -> None:
    """:func:`preload`, the first time a page of a server whose warm-up started is asked."""
    if not app.extensions.get("cbrs.preload_armed") or "cbrs.preload" in app.extensions:
        return
    with _PRELOAD_GUARD:
        if "cbrs.preload" not in app.extensions:
            app.extensions["cbrs.preload"] = None  # asked once, even when the list is empty
            preload(app)


def _import(modules: tuple[str, ...]) -> None:
    for module in modules:
        try:
            importlib.import_module(module)
        except ImportError as error:  # an optional part not installed: its pages say so when asked
            log.info("browser: not preloading %s: %s", module, error)
        except Exception:  # the page that needs it imports it again and shows the error
            log.exception("browser: importing %s failed", module)


def current(app: Flask) -> WarmUp | None:
    found: WarmUp | None = app.extensions.get("cbrs.warm_up")
    return found


def _run(app: Flask, state: WarmUp, steps: list[tuple[str, Callable[[], object]]]) -> None:
    began = time.monotonic()
    closing: threading.Event = app.extensions["cbrs.closing"]
    try:
        for label, read in steps:
            if closing.is_set():
                return
            state.current = label
            log.info("browser: reading %s (step %d of %d)", label, state.done + 1, len(steps))
            start = time.monotonic()
            try:
                with app.app_context():
                    read()
            except Exception:  # the page that needs it reads it again and shows the error
                log.exception("browser: reading %s failed", label)
            state.seconds[label] = round(time.monotonic() - start, 3)
            state.done += 1
        log.info("browser: ready, read in %.1f s", time.monotonic() - began)
    finally:
        state.current = None
        state.finished.set()
