"""The one table of cbrs settings: name, default, help and environment variable.

The CLI's global options, ``cbrs settings`` and docs/settings.md all come from ``SETTINGS``;
a value is taken from the command line, else the environment, else the default.
"""

from __future__ import annotations

import os
import re
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any
from urllib.parse import urlsplit

from platformdirs import user_cache_dir, user_data_dir

from cbrs.kb.errors import without_password


def _default_store() -> str:
    return str(Path(user_data_dir("cbrs", appauthor=False)) / "store")


def _default_seed_cache() -> str:
    return user_cache_dir("cbrs", appauthor=False)


def _number(kind: Callable[[str], Any], text: str) -> Any:
    """``kind(text)`` (int or float), refused in words: Python's own "invalid literal for int() with base
    10: 'abc'" was what CBRS_PORT=abc said."""
    try:
        return kind(text)
    except ValueError:
        what = "a whole number" if kind is int else "a number"
        raise ValueError(f"{text!r} is not {what}") from None


def _port(text: str) -> int:
    port: int = _number(int, text)
    if not 0 <= port <= 65535:
        raise ValueError(f"{port} is not a TCP port (0-65535)")
    return port


def _positive(kind: Callable[[str], float]) -> Callable[[str], Any]:
    def parse(text: str) -> Any:
        value = _number(kind, text)
        if not value > 0:  # NaN too: float("nan") compares false, and a deadline of NaN never comes
            raise ValueError(f"{text} must be positive")
        return value

    return parse


def _non_negative(text: str) -> int:
    value: int = _number(int, text)
    if value < 0:
        raise ValueError(f"{text} must not be negative")
    return value


def _non_negative_seconds(text: str) -> float:
    value: float = _number(float, text)
    if not value >= 0:  # NaN too
        raise ValueError(f"{text} must be a number of seconds, 0 or more")
    return value


def _metres(most: float) -> Callable[[str], float]:
    """A parser of a length in metres from 0 to ``most``: a larger one is most likely millimetres or
    centimetres, and refused saying so rather than taken."""

    def parse(text: str) -> float:
        value: float = _number(float, text)
        if not 0.0 <= value <= most:  # NaN too
            raise ValueError(f"{text} must be a length in metres from 0 to {most:g} (5 mm is 0.005)")
        return value

    return parse


def _flag(text: str) -> bool:
    word = text.strip().lower()
    if word in ("1", "true", "yes", "on"):
        return True
    if word in ("0", "false", "no", "off"):
        return False
    raise ValueError(f"{text!r} is not a yes/no value (1, true, yes, on / 0, false, no, off)")


def _origins(text: str) -> tuple[str, ...]:
    return tuple(origin.strip() for origin in text.split(",") if origin.strip())


_prefixes = _origins  # a comma-separated list of IRI prefixes reads the same way


def _web_origins(text: str) -> tuple[str, ...]:
    """Origins as a browser sends them in ``Origin`` (``https://lab.example:8443``); a trailing slash is
    dropped. Anything else would never match a request, and the page it was meant for would be refused."""
    found = []
    for origin in _origins(text):
        origin = origin.rstrip("/")
        parts = urlsplit(origin)
        if parts.scheme not in ("http", "https") or not parts.hostname or parts.path or parts.query:
            raise ValueError(f"{origin!r} is not a web origin: give scheme://host[:port], e.g. https://lab.example")
        found.append(origin)
    return tuple(found)


def _server_names(text: str) -> tuple[str, ...]:
    """Host names as a client puts them in ``Host`` (``labhost``, ``cbrs.lab.example``), lower case, no
    port: a URL or a name with a port would never match a request, and every page would be refused."""
    found = []
    for name in _origins(text):
        label = r"[a-z0-9]([a-z0-9-]{0,61}[a-z0-9])?"
        if not re.fullmatch(rf"{label}(\.{label})*\.?", name.lower()):
            raise ValueError(f"{name!r} is not a host name: give a name such as labhost or cbrs.lab.example, no port")
        found.append(name.lower().rstrip("."))
    return tuple(found)


def _match_params(text: str) -> tuple[str, ...]:
    """Comma-separated ``name=value`` pairs; only their form is checked here (the names and values are
    checked against MatchConfig where a matchmaker is made, so that reading settings loads no reasoner)."""
    pairs = _origins(text)
    for pair in pairs:
        name, equals, _ = pair.partition("=")
        if not equals or not name.strip().isidentifier():
            raise ValueError(f"{pair!r} is not NAME=VALUE")
    return tuple("=".join(part.strip() for part in pair.partition("=")[::2]) for pair in pairs)


def _batch(text: str) -> int | str:
    """``auto`` (chosen by the server) or a positive number of quads."""
    if text.strip().lower() == "auto":
        return "auto"
    parsed: int = _positive(int)(text)
    return parsed


def _one_of(choices: tuple[str, ...], what: str, case: Callable[[str], str] = str.lower) -> Callable[[str], str]:
    """A parser of one word among ``choices`` (compared in ``case``), refusing another naming ``what``."""

    def parse(text: str) -> str:
        word = case(text.strip())
        if word not in choices:
            raise ValueError(f"{text!r} is not {what} ({', '.join(choices)})")
        return word

    return parse


EVENT_LOOPS = ("auto", "uvloop", "asyncio")
_event_loop = _one_of(EVENT_LOOPS, "an event loop")

NON_FINITE = ("null", "tokens")  # cbrs.rosbridge.protocol.NON_FINITE, kept here so settings load no bridge
_non_finite = _one_of(NON_FINITE, "a way to write NaN and infinities")

CONTRADICTIONS = ("fail", "warn")  # cbrs.actions.answers.CONTRADICTIONS, kept here so settings load no planner
_contradictions = _one_of(CONTRADICTIONS, "a way to treat an answer that contradicts its step's effect")

LOG_LEVELS = ("DEBUG", "INFO", "WARNING", "ERROR", "CRITICAL")
_log_level = _one_of(LOG_LEVELS, "a log level", str.upper)


@dataclass(frozen=True)
class Setting:
    name: str
    default: Callable[[], Any]
    help: str
    env: str
    parse: Callable[[str], Any] = str
    secret: bool = False

    def shown(self, value: Any) -> str:
        """The value as ``cbrs settings`` prints it: a secret only says whether it is set."""
        if self.secret:
            return "(set)" if value else "(not set)"
        if isinstance(value, tuple):
            return ", ".join(value) or "(none)"
        return "" if value is None else without_password(str(value))  # a store URL's basic credentials

    def plain(self, value: Any) -> Any:
        """The value as ``cbrs settings --json`` gives it: JSON's own types, a secret only whether it is set."""
        if self.secret:
            return bool(value)
        if isinstance(value, tuple):
            return list(value)
        if isinstance(value, str):
            return without_password(value)
        return value if value is None or isinstance(value, bool | int | float) else str(value)

    def from_options(self, values: tuple[str, ...]) -> Any:
        """The value of a repeatable CLI option, each occurrence read as the environment variable is (a
        comma-separated list split, its form checked); None when the option was not given. Taken as they
        came, ``--match-param a=1,b=2`` was one parameter whose value was ``1,b=2``, though the help says
        comma-separated."""
        return self.parse(",".join(values)) if values else None

    def resolve(self, given: Any = None, environ: Mapping[str, str] | None = None) -> Any:
        if given is not None:
            return given
        raw = (os.environ if environ is None else environ).get(self.env)
        if raw not in (None, ""):
            try:
                return self.parse(raw)
            except ValueError as error:
                raise ValueError(f"environment variable {self.env}={raw!r}: {error}") from error
        return self.default()


SETTINGS: tuple[Setting, ...] = (
    Setting(
        "store",
        _default_store,
        "Where the knowledge base lives: a directory for the embedded Oxigraph store "
        "(created and seeded on first use), :memory: for a throw-away one, or the http:// URL of a SPARQL "
        "server shared by many robots (oxigraph serve --union-default-graph; see docs/remote-store.md).",
        "CBRS_STORE",
    ),
    Setting(
        "format",
        lambda: "table",
        "Default output format of cbrs query: table, json, csv or tsv.",
        "CBRS_FORMAT",
    ),
    Setting(
        "host",
        lambda: "127.0.0.1",
        "Address cbrs serve binds its HTTP and rosbridge ports to; loopback unless you open it on purpose.",
        "CBRS_HOST",
    ),
    Setting("port", lambda: 8080, "HTTP port of cbrs serve (/sparql and the browser).", "CBRS_PORT", _port),
    Setting("bridge_port", lambda: 9090, "Websocket port of the rosbridge v2 interface.", "CBRS_BRIDGE_PORT", _port),
    Setting(
        "update_token",
        lambda: None,
        "Bearer token that SPARQL updates must carry; without one the endpoint is read-only.",
        "CBRS_UPDATE_TOKEN",
        str.strip,  # $(cat token) keeps a CRLF file's CR, which --update-token-file drops
        secret=True,
    ),
    Setting(
        "read_only",
        lambda: False,
        "Refuse every write, even with the update token: SPARQL updates, task runs, recorded plans.",
        "CBRS_READ_ONLY",
        _flag,
    ),
    Setting(
        "query_timeout",
        lambda: 30.0,
        "Seconds a SPARQL query may run (and be serialised) before the endpoint answers 503.",
        "CBRS_QUERY_TIMEOUT",
        _positive(float),
    ),
    Setting(
        "query_workers",
        lambda: 4,
        "SPARQL queries the endpoint runs at once; one more is refused with 503 busy rather than queued.",
        "CBRS_QUERY_WORKERS",
        _positive(int),
    ),
    Setting(
        "query_workers_per_client",
        lambda: 2,
        "SPARQL queries one client (an IP address) may run at once, on HTTP and the bridge together; one "
        "more is refused with 503 busy, so no client can take every query worker.",
        "CBRS_QUERY_WORKERS_PER_CLIENT",
        _positive(int),
    ),
    Setting(
        "query_memory",
        lambda: 1024 * 1024 * 1024,
        "Bytes of memory one SPARQL query may hold (its worker process's resident size); a query that "
        "needs more is stopped and refused with 422. 0 sets no limit.",
        "CBRS_QUERY_MEMORY",
        _non_negative,
    ),
    Setting(
        "query_worker_idle",
        lambda: 30.0,
        "Seconds a SPARQL query worker process may sit idle before it is stopped, giving its memory back; "
        "the next query that needs one starts it again (tens of milliseconds).",
        "CBRS_QUERY_WORKER_IDLE",
        _positive(float),
    ),
    Setting(
        "stream_limit",
        lambda: 8,
        "Event and camera streams (/tasks/events, /camera.mjpg) open at once; each has a thread of its own "
        "beside the 16 that answer requests, and one more is refused with 503.",
        "CBRS_STREAM_LIMIT",
        _positive(int),
    ),
    Setting(
        "http_loop",
        lambda: "auto",
        "The asyncio event loop cbrs serve's HTTP front runs on: uvloop (written in C, quicker per request), "
        "asyncio (the standard library's), or auto (uvloop when it is installed).",
        "CBRS_HTTP_LOOP",
        _event_loop,
    ),
    Setting(
        "streams_per_client",
        lambda: 4,
        "Event and camera streams one client (an IP address) may have open at once: the tasks page holds "
        "two, and one more for a moment while it restarts its camera stream.",
        "CBRS_STREAMS_PER_CLIENT",
        _positive(int),
    ),
    Setting(
        "bridge_connections_per_client",
        lambda: 64,
        "Websocket connections one client (an IP address) may hold on the rosbridge port; one more is "
        "accepted and closed at once with code 1013 (try again later).",
        "CBRS_BRIDGE_CONNECTIONS_PER_CLIENT",
        _positive(int),
    ),
    Setting(
        "action_workers",
        lambda: 4,
        "Threads that run the bridge's own actions (the /cbrs/run_task action): a goal holds one until it "
        "ends, so these are apart from the service threads and a long task never delays a service call.",
        "CBRS_ACTION_WORKERS",
        _positive(int),
    ),
    Setting(
        "run_queue",
        lambda: 0,
        "Task runs that may wait while one goes (a Start on the tasks page, a /cbrs/run_task call or goal): "
        "each starts, planned on the world as the run before left it, when that run ends; one more is refused "
        "saying the queue is full. 0: none wait, a run started while one goes is refused, as before "
        "(docs/web.md).",
        "CBRS_RUN_QUEUE",
        _non_negative,
    ),
    Setting(
        "bridge_non_finite",
        lambda: "null",
        "How the bridge's JSON text frames write a NaN or an infinity, which JSON has no number for: null "
        "(as rosbridge_suite does; every JSON parser reads it) or tokens (NaN, Infinity, as Python writes "
        "them: roslibpy reads them, roslibjs drops the message). CBOR subscribers get the floats either way.",
        "CBRS_BRIDGE_NON_FINITE",
        _non_finite,
    ),
    Setting(
        "bridge_max_message_bytes",
        lambda: 1024 * 1024,
        "Largest message a rosbridge client may send, whole or in fragments; a larger one gets an error "
        "status. rosbridge_suite allows 10 MB: raise it for raw images (a 640x480 RGB image is about "
        "1.2 MB of base64).",
        "CBRS_BRIDGE_MAX_MESSAGE_BYTES",
        _positive(int),
    ),
    Setting(
        "late_answer_wait",
        lambda: 30.0,
        "Seconds cbrs run --bridge waits, once the run is over, for the answers of actuators whose calls it "
        "gave up, so that what they did is believed (docs/reliability.md); 0: it does not wait.",
        "CBRS_LATE_ANSWER_WAIT",
        _non_negative_seconds,
    ),
    Setting(
        "component_lease",
        lambda: 3.0,
        "Seconds a component registered live over the bridge stays available without a heartbeat; when "
        "its session closes or its lease lapses it is marked unavailable (docs/components.md).",
        "CBRS_COMPONENT_LEASE",
        _positive(float),
    ),
    Setting(
        "query_check_timeout",
        lambda: 10.0,
        "Seconds an isolated checker may take to parse a query or update longer than 512 characters "
        "before it reaches the store; texts that crash or outlast it are refused (docs/security.md).",
        "CBRS_QUERY_CHECK_TIMEOUT",
        _positive(float),
    ),
    Setting(
        "check_timeout",
        lambda: 300.0,
        "Seconds cbrs check gives the HermiT reasoner (a Java process) before it is stopped and the check fails "
        "saying so; the bundled ontologies take a few seconds, a large lab ontology may need more "
        "(docs/ontologies.md).",
        "CBRS_CHECK_TIMEOUT",
        _positive(float),
    ),
    Setting(
        "federation_allow",
        lambda: (),
        "Comma-separated IRI prefixes that SPARQL SERVICE (federated queries) and LOAD may reach; none by "
        "default, so no request can make the server fetch a URL, read a file or probe the network.",
        "CBRS_FEDERATION_ALLOW",
        _prefixes,
    ),
    Setting(
        "remote_timeout",
        lambda: 60.0,
        "Seconds to wait for a remote store (an http:// store) to answer one request before giving up.",
        "CBRS_REMOTE_TIMEOUT",
        _positive(float),
    ),
    Setting(
        "remote_call_timeout",
        lambda: 10.0,
        "Seconds a component in another process (invoked over the bridge) has to answer one call of a "
        "task run, unless its advertisement states a cbrs:responseTime three times which is longer "
        "(docs/execution.md).",
        "CBRS_REMOTE_CALL_TIMEOUT",
        _positive(float),
    ),
    Setting(
        "remote_breaker_timeouts",
        lambda: 1,
        "Calls in a row to a component in another process that time out before task runs pass it over for "
        "remote_breaker_cooldown seconds (its circuit breaker opens; then one trial call); 0 never passes one "
        "over (docs/execution.md).",
        "CBRS_REMOTE_BREAKER_TIMEOUTS",
        _non_negative,
    ),
    Setting(
        "remote_breaker_cooldown",
        lambda: 30.0,
        "Seconds task runs pass over a component in another process whose calls timed out, before one trial "
        "call: an answer in time brings it back, another timeout passes it over again (docs/execution.md).",
        "CBRS_REMOTE_BREAKER_COOLDOWN",
        _positive(float),
    ),
    Setting(
        "remote_contradictions",
        lambda: "fail",
        "What a task run does with an answer of a component in another process that the store says contradicts "
        "its step's effect (a light asked to switch on answering SwitchedOff): fail (the step fails and nothing "
        "of it is believed) or warn (taken, and logged; docs/execution.md).",
        "CBRS_REMOTE_CONTRADICTIONS",
        _contradictions,
    ),
    Setting(
        "precondition_sensing",
        lambda: True,
        "Whether a task run asks the store's sensors about a precondition on a status the store defines by a "
        "measured quantity (a room dark below 50 lx), before its first step; off: such a precondition is taken "
        "as given, as one no test decides (docs/execution.md).",
        "CBRS_PRECONDITION_SENSING",
        _flag,
    ),
    Setting(
        "precondition_sensing_timeout",
        lambda: 10.0,
        "Seconds one sensor has to give a task run its reading of a precondition before the next is asked (the "
        "precondition is taken as given, saying so, when none answers); a component in another process also has "
        "its own call timeout (docs/execution.md).",
        "CBRS_PRECONDITION_SENSING_TIMEOUT",
        _positive(float),
    ),
    Setting(
        "remote_batch",
        lambda: "auto",
        "Most quads one write request to a remote store carries; a larger write (the seed, a load) is "
        "staged in batches this size and published by one operation. auto: 100000 on Oxigraph, 250 on "
        "other servers (docs/remote-store.md).",
        "CBRS_REMOTE_BATCH",
        _batch,
    ),
    Setting(
        "seed_cache",
        _default_seed_cache,
        "Folder where the seed of a new embedded store is kept, by a digest of the bundled files and the kb "
        "code, so that later new stores copy it (milliseconds instead of a third of a second); off keeps it "
        "only within a process. Read by cbrs.kb itself, so it applies to library use too.",
        "CBRS_SEED_CACHE",
    ),
    Setting(
        "max_result_bytes",
        lambda: 64 * 1024 * 1024,
        "Largest serialised SPARQL result the endpoint returns; larger ones are refused with 422.",
        "CBRS_MAX_RESULT_BYTES",
        _positive(int),
    ),
    Setting(
        "max_query_bytes",
        lambda: 1024 * 1024,
        "Largest SPARQL query or update request accepted; larger ones are refused with 413.",
        "CBRS_MAX_QUERY_BYTES",
        _positive(int),
    ),
    Setting(
        "cors_origins",
        lambda: (),
        "Comma-separated origins of web pages allowed to call the HTTP API (CORS) and open the rosbridge "
        "websocket, besides the server's own pages; none by default.",
        "CBRS_CORS_ORIGINS",
        _web_origins,
    ),
    Setting(
        "server_names",
        lambda: (),
        "Comma-separated host names clients reach cbrs serve by when it listens on a routable address "
        "(e.g. labhost,cbrs.lab.example): a request naming another host is refused (DNS rebinding), and "
        "the browser's pages under these names may start tasks. None: any name is answered.",
        "CBRS_SERVER_NAMES",
        _server_names,
    ),
    Setting(
        "match_params",
        lambda: (),
        "Comma-separated NAME=VALUE matchmaking parameters (MatchConfig fields, e.g. consumer_steps=off, "
        "undone_state_factor=0) for cbrs match, cbrs eval and cbrs serve's rankings; none by default.",
        "CBRS_MATCH_PARAMS",
        _match_params,
    ),
    Setting(
        "spot_inset",
        lambda: 0.005,  # cbrs.sim.place_spots.SPOT_INSET, kept here so settings load no simulation
        "Metres a set-down spot's centre keeps inside the edge of a place too small for the thing's whole "
        "footprint (docs/simulation.md, a spot's centre inside its place); 0 to 0.05.",
        "CBRS_SPOT_INSET",
        _metres(0.05),
    ),
    Setting(
        "seen_short",
        lambda: 0.01,  # cbrs.sim.grasping.SEEN_SHORT, kept here so settings load no simulation
        "Metres less of its height than a thing has that perception may see and the grasp still take the "
        "middle of what was seen; seen shorter, it takes the seen top less half the height; 0 to 0.1.",
        "CBRS_SEEN_SHORT",
        _metres(0.1),
    ),
    Setting(
        "log_level",
        lambda: "INFO",
        "Lowest level of the log lines cbrs serve writes to standard error (INFO and below: a line per HTTP "
        "request too; WARNING leaves those out): " + ", ".join(LOG_LEVELS) + ".",
        "CBRS_LOG_LEVEL",
        _log_level,
    ),
)

BY_NAME = {setting.name: setting for setting in SETTINGS}


def setting(name: str) -> Setting:
    return BY_NAME[name]
