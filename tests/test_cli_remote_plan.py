"""``cbrs plan`` against a running server without its token: the plan is shown with --no-store, and the
refusal to record it says so and names both ways out. Loopback only."""

from __future__ import annotations

from click.testing import CliRunner

from cbrs.cli import cli
from cbrs.server import Server
from tests.test_live_components import TOKEN, server

__all__ = ["server"]  # the fixture, used by name


def test_a_plan_the_server_refuses_to_record_names_the_token_and_no_store(server: Server) -> None:
    store = f"http://127.0.0.1:{server.http_port}"
    refused = CliRunner().invoke(cli, ["--store", store, "plan", "FetchMyPen"], env={"CBRS_UPDATE_TOKEN": None})
    assert refused.exit_code == 1
    assert "HTTP 403" in refused.output and "--no-store" in refused.output and "CBRS_UPDATE_TOKEN" in refused.output
    shown = CliRunner().invoke(cli, ["--store", store, "plan", "FetchMyPen", "--no-store"])
    assert shown.exit_code == 0 and "FetchMyPen: planned" in shown.output
    recorded = CliRunner().invoke(cli, ["--store", store, "plan", "FetchMyPen"], env={"CBRS_UPDATE_TOKEN": TOKEN})
    assert recorded.exit_code == 0, recorded.output
