"""``cbrs serve``: a thin command over :class:`cbrs.server.Server`."""

from __future__ import annotations

import errno
import ipaddress
import logging
import socket
from pathlib import Path
from typing import Any

import click

from cbrs.app import App, pass_app
from cbrs.kb.errors import without_password
from cbrs.settings import LOG_LEVELS, setting
from cbrs.sparql_service import EndpointConfig


def _help(name: str) -> str:
    item = setting(name)
    return f"{item.help} [env {item.env}]"


@click.command()
@click.option("--host", help=_help("host"))
@click.option("--port", type=click.IntRange(0, 65535), help=_help("port") + " [default 8080; 0 picks a free port]")
@click.option(
    "--bridge-port", type=click.IntRange(0, 65535), help=_help("bridge_port") + " [default 9090; 0 picks a free port]"
)
@click.option(
    "--update-token-file",
    type=click.Path(exists=True, dir_okay=False, path_type=Path),
    help="Read the update token from the first line of FILE (instead of CBRS_UPDATE_TOKEN). There is no "
    "option taking the token itself: a command line is visible to every user of the machine.",
)
@click.option("--read-only", is_flag=True, default=None, help=_help("read_only"))
@click.option("--cors-origin", "cors_origins", multiple=True, metavar="ORIGIN", help=_help("cors_origins"))
@click.option("--server-name", "server_names", multiple=True, metavar="NAME", help=_help("server_names"))
@click.option(
    "--log-level", type=click.Choice(LOG_LEVELS, case_sensitive=False), help=_help("log_level") + " [default INFO]"
)
@click.option("--run-queue", type=click.IntRange(0), metavar="N", help=_help("run_queue") + " [default 0]")
@click.option(
    "--match-param",
    "match_params",
    multiple=True,
    metavar="NAME=VALUE",
    help=_help("match_params") + " (repeatable; cbrs match --params lists them)",
)
@pass_app
def serve(
    app: App,
    host: str | None,
    port: int | None,
    bridge_port: int | None,
    update_token_file: Path | None,
    read_only: bool | None,
    cors_origins: tuple[str, ...],
    server_names: tuple[str, ...],
    log_level: str | None,
    match_params: tuple[str, ...],
    run_queue: int | None,
) -> None:
    """Serve the knowledge base: SPARQL 1.1 at /sparql on the HTTP port, rosbridge v2 on the bridge port.

    Binds to 127.0.0.1 unless told otherwise. Updates need the update token; without one the endpoint is
    read-only, and --read-only refuses every write (updates, task runs, recorded plans). Ctrl-C stops both
    listeners cleanly.
    """
    from cbrs.server import ServeConfig, Server  # Granian, Flask and websockets load only for this command

    level = setting("log_level").resolve(log_level.upper() if log_level else None)
    logging.basicConfig(format="%(asctime)s %(name)s %(levelname)s: %(message)s")
    logging.getLogger().setLevel(level)  # also when something has configured logging before
    logging.getLogger("websockets").setLevel(_websockets_level(level))
    config = ServeConfig(
        host=setting("host").resolve(host),
        port=setting("port").resolve(port),
        bridge_port=setting("bridge_port").resolve(bridge_port),
        endpoint=EndpointConfig(
            timeout=setting("query_timeout").resolve(),
            workers=setting("query_workers").resolve(),
            max_result_bytes=setting("max_result_bytes").resolve(),
            max_query_bytes=setting("max_query_bytes").resolve(),
            update_token=setting("update_token").resolve(_read_token(update_token_file)),
            read_only=setting("read_only").resolve(read_only),
            isolate_memory=True,  # a query past its deadline is stopped whatever the store
        ),
        cors_origins=setting("cors_origins").resolve(_option("cors_origins", cors_origins, "--cors-origin")),
        server_names=setting("server_names").resolve(_option("server_names", server_names, "--server-name")),
        match_params=setting("match_params").resolve(_option("match_params", match_params, "--match-param")),
        run_queue=setting("run_queue").resolve(run_queue),
    )
    if config.endpoint.update_token:
        _redact_in_log(config.endpoint.update_token)
    if config.match_params:  # a wrong name or value fails now, not at the first ranking
        from cbrs.reasoner.config import MatchConfig

        MatchConfig().with_params(config.match_params)
    _check_free(config.host, config.port, "--port", "CBRS_PORT")
    _check_free(config.host, config.bridge_port, "--bridge-port", "CBRS_BRIDGE_PORT")
    if not _is_loopback(config.host):  # after the checks: a host it cannot listen on is no warning but an error
        click.echo(f"warning: listening on {config.host}, reachable from other machines", err=True)
        if not config.server_names:
            click.echo(
                "warning: any host name is answered: give --server-name (CBRS_SERVER_NAMES) with the names "
                "clients use, so that a web page whose name resolves to this machine is refused (DNS rebinding) "
                "and the browser's pages under those names may start tasks",
                err=True,
            )
    # One query before anything listens: a store that cannot answer as cbrs needs (a remote server whose
    # default graph is not the union of its graphs, found only once the seed is in) stops the command
    # with its reason, instead of a server that answers every request with that error.
    app.kb.query("ASK { ?s ?p ?o }")
    server = Server(app.kb, config)

    def ready(running: Server) -> None:
        host_text = f"[{config.host}]" if ":" in config.host else config.host
        if config.endpoint.read_only:
            access = "read-only: no updates, task runs or recorded plans"
        else:
            access = "read-write with the update token" if running.sparql.writable else "read-only"
        click.echo(f"cbrs serving {without_password(app.kb.store.location)} ({access})")
        click.echo(f"  browser   http://{host_text}:{running.http_port}/")  # the knowledge browser (docs/web.md)
        click.echo(
            f"  SPARQL    http://{host_text}:{running.http_port}/sparql "
            f"({config.endpoint.workers} query workers, {config.endpoint.timeout:g} s timeout)"
        )
        click.echo(f"  rosbridge ws://{host_text}:{running.bridge_port}")
        if config.match_params:
            click.echo(f"  matchmaking parameters: {', '.join(config.match_params)}")
        click.echo("Ctrl-C stops.", nl=True)

    try:
        server.serve_forever(ready)
    except OSError as error:  # a port taken between the check above and the listen, or a host not ours
        raise click.ClickException(
            f"cannot listen on {config.host} (HTTP port {config.port}, bridge port {config.bridge_port}): "
            f"{error.strerror or error}"
        ) from None
    click.echo("stopped")


class _Redacted(logging.Filter):
    """Writes ``***`` for the update token wherever a log line would carry it: at DEBUG the websockets
    library logs every frame it reads, the bridge's ``auth`` op (``"mac": "<token>"``) among them."""

    def __init__(self, secret: str) -> None:
        super().__init__()
        self.secret = secret

    def filter(self, record: logging.LogRecord) -> bool:
        message = record.getMessage()
        if self.secret in message:
            record.msg, record.args = message.replace(self.secret, "***"), None
        return True


def _redact_in_log(token: str) -> None:
    """Keep ``token`` out of every line the root logger's handlers write (cbrs serve's standard error)."""
    for handler in logging.getLogger().handlers:
        handler.addFilter(_Redacted(token))


def _websockets_level(level: str) -> int:
    """websockets' own INFO lines ("connection open", "connection closed") double cbrs.rosbridge's, which
    name the client: four lines a connection. They show at DEBUG; its warnings as the level says."""
    chosen = int(logging.getLevelName(level))
    return chosen if chosen <= logging.DEBUG else max(chosen, logging.WARNING)


def _option(name: str, values: tuple[str, ...], option: str) -> Any:
    try:
        return setting(name).from_options(values)
    except ValueError as error:
        raise click.BadParameter(str(error), param_hint=option) from None


def _check_free(host: str, port: int, option: str, env: str) -> None:
    """Fail with a message naming the port, or the host, when it cannot be listened on. Port 0 is probed too:
    it tells whether the host is an address of this machine (Granian's bind said so with a Rust backtrace)."""
    try:
        family, kind, proto, _, address = socket.getaddrinfo(host, port, type=socket.SOCK_STREAM)[0]
    except socket.gaierror as error:
        raise click.BadParameter(f"cannot resolve host {host!r}: {error}", param_hint="--host") from None
    with socket.socket(family, kind, proto) as probe:
        probe.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)  # as both listeners do
        try:
            probe.bind(address)
        except OSError as error:
            if error.errno == errno.EADDRINUSE:
                raise click.ClickException(
                    f"port {port} on {host} is already in use (another cbrs serve?); stop that process or "
                    f"choose another port with {option} or {env} (0 picks a free one)"
                ) from None
            if error.errno == errno.EADDRNOTAVAIL:
                raise click.BadParameter(
                    f"{host} is no address of this machine ({error.strerror}): give one of its own, 127.0.0.1 "
                    "(the default) or 0.0.0.0 for all of them",
                    param_hint="--host or CBRS_HOST",
                ) from None
            raise click.ClickException(f"cannot listen on {host} port {port}: {error.strerror or error}") from None


def _read_token(path: Path | None) -> str | None:
    if path is None:
        return None
    try:
        lines = path.read_text(encoding="utf-8").splitlines()
    except (OSError, UnicodeDecodeError) as error:
        raise click.BadParameter(f"cannot read {path}: {error}", param_hint="--update-token-file") from None
    token = lines[0].strip() if lines else ""
    if not token:
        later = next((n for n, line in enumerate(lines[1:], start=2) if line.strip()), None)
        said = f"{path}: its first line is blank, and line {later} is not" if later else f"{path} is empty"
        raise click.BadParameter(f"{said}: the token must be on the first line", param_hint="--update-token-file")
    return token


def _is_loopback(host: str) -> bool:
    if host == "localhost":
        return True
    try:
        return ipaddress.ip_address(host).is_loopback
    except ValueError:
        return False
