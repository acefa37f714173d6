"""``cbrs serve``: a thin command over :class:`cbrs.server.Server`."""

from __future__ import annotations

import ipaddress
import logging

import click

from cbrs.app import App, pass_app
from cbrs.settings import setting
from cbrs.sparql_service import EndpointConfig


def _help(name: str) -> str:
    item = setting(name)
    return f"{item.help} [env {item.env}]"


@click.command()
@click.option("--host", help=_help("host"))
@click.option("--port", type=click.IntRange(0, 65535), help=_help("port") + " [default 8080; 0 picks a free port]")
@click.option("--bridge-port", type=click.IntRange(0, 65535), help=_help("bridge_port") + " [default 9090]")
@click.option(
    "--update-token",
    help=_help("update_token") + " Prefer the environment variable: a command line is visible to other users.",
)
@click.option("--cors-origin", "cors_origins", multiple=True, metavar="ORIGIN", help=_help("cors_origins"))
@pass_app
def serve(
    app: App,
    host: str | None,
    port: int | None,
    bridge_port: int | None,
    update_token: str | None,
    cors_origins: tuple[str, ...],
) -> None:
    """Serve the knowledge base: SPARQL 1.1 at /sparql on the HTTP port, rosbridge v2 on the bridge port.

    Binds to 127.0.0.1 unless told otherwise. Updates need the update token; without one the endpoint is
    read-only. Ctrl-C stops both listeners cleanly.
    """
    from cbrs.server import ServeConfig, Server  # waitress and websockets load only for this command

    logging.basicConfig(level=logging.INFO, format="%(asctime)s %(name)s %(levelname)s: %(message)s")
    config = ServeConfig(
        host=setting("host").resolve(host),
        port=setting("port").resolve(port),
        bridge_port=setting("bridge_port").resolve(bridge_port),
        endpoint=EndpointConfig(
            timeout=setting("query_timeout").resolve(),
            max_result_bytes=setting("max_result_bytes").resolve(),
            max_query_bytes=setting("max_query_bytes").resolve(),
            update_token=setting("update_token").resolve(update_token),
        ),
        cors_origins=setting("cors_origins").resolve(cors_origins or None),
    )
    if not _is_loopback(config.host):
        click.echo(f"warning: listening on {config.host}, reachable from other machines", err=True)
    server = Server(app.kb, config)

    def ready(running: Server) -> None:
        host_text = f"[{config.host}]" if ":" in config.host else config.host
        access = "read-write with the update token" if running.sparql.writable else "read-only"
        click.echo(f"cbrs serving {app.kb.store.location} ({access})")
        click.echo(f"  SPARQL    http://{host_text}:{running.http_port}/sparql")
        click.echo(f"  rosbridge ws://{host_text}:{running.bridge_port}")
        click.echo("Ctrl-C stops.", nl=True)

    server.serve_forever(ready)
    click.echo("stopped")


def _is_loopback(host: str) -> bool:
    if host == "localhost":
        return True
    try:
        return ipaddress.ip_address(host).is_loopback
    except ValueError:
        return False
