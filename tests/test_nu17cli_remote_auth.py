"""A remote store that wants credentials says how cbrs gives them, and no message shows a password
(new-user CLI repros 03 and 04). The server is a loopback stand-in answering 401 or 403 to everything."""

from __future__ import annotations

import http.server
import threading
from collections.abc import Iterator

import pytest
from click.testing import CliRunner

from cbrs.cli import cli
from cbrs.kb.errors import without_password


class _Refusing(http.server.BaseHTTPRequestHandler):
    status = 401

    def do_POST(self) -> None:
        self.rfile.read(int(self.headers.get("Content-Length") or 0))
        body = b"<html><body><h1>Authorization Required</h1></body></html>"
        self.send_response(self.server.status)  # type: ignore[attr-defined]
        self.send_header("WWW-Authenticate", 'Basic realm="sparql"')
        self.send_header("Content-Type", "text/html")
        self.send_header("Content-Length", str(len(body)))
        self.end_headers()
        self.wfile.write(body)

    def log_message(self, *args: object) -> None:
        pass


@pytest.fixture
def refusing() -> Iterator[http.server.HTTPServer]:
    server = http.server.HTTPServer(("127.0.0.1", 0), _Refusing)
    thread = threading.Thread(target=server.serve_forever, args=(0.05,), daemon=True)
    thread.start()
    yield server
    server.shutdown()
    server.server_close()
    thread.join(timeout=5)


def _run(url: str, token: str | None = None) -> str:
    env = {"CBRS_UPDATE_TOKEN": token} if token else {"CBRS_UPDATE_TOKEN": ""}
    result = CliRunner().invoke(cli, ["--store", url, "services"], env=env)
    assert result.exit_code == 1
    return result.output


def test_401_says_how_to_give_credentials(refusing: http.server.HTTPServer) -> None:
    refusing.status = 401  # type: ignore[attr-defined]
    output = _run(f"http://127.0.0.1:{refusing.server_port}")
    assert "the server asks for credentials: put them in the store URL" in output
    assert "<html>" not in output


def test_401_with_credentials_names_them_refused_without_showing_the_password(
    refusing: http.server.HTTPServer,
) -> None:
    refusing.status = 401  # type: ignore[attr-defined]
    output = _run(f"http://robot:hunter2@127.0.0.1:{refusing.server_port}")
    assert "refused the user name and password in the store URL" in output
    assert "hunter2" not in output
    assert "http://robot:***@127.0.0.1" in output


@pytest.mark.parametrize(("token", "says"), [(None, "set CBRS_UPDATE_TOKEN"), ("wrong", "refused the token")])
def test_403_says_what_about_the_token(refusing: http.server.HTTPServer, token: str | None, says: str) -> None:
    refusing.status = 403  # type: ignore[attr-defined]
    assert says in _run(f"http://127.0.0.1:{refusing.server_port}", token)


def test_settings_show_no_password() -> None:
    result = CliRunner().invoke(cli, ["settings"], env={"CBRS_STORE": "http://robot:hunter2@127.0.0.1:7878"})
    assert "hunter2" not in result.output
    assert without_password("see https://a:b@h/x and http://h:1/") == "see https://a:***@h/x and http://h:1/"
