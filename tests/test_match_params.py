"""Matchmaking parameters set from text: `cbrs match --param`, the match_params setting, cbrs serve."""

from __future__ import annotations

import json

import pytest
from click.testing import CliRunner

from cbrs.cli import cli
from cbrs.kb import KnowledgeBase
from cbrs.kb.store import Store
from cbrs.matchmakers import Matchmakers
from cbrs.reasoner.config import MatchConfig, MatchParameterError
from cbrs.settings import setting
from cbrs.sparql_service import EndpointConfig, SparqlService


def test_each_kind_of_parameter_is_read_as_its_type() -> None:
    config = MatchConfig().with_params(
        ["consumer_steps=off", "complement_weight=0.3", "statement_mean=arithmetic", "lexical_links=1", "lexicon=yes"]
    )
    assert config.consumer_steps is False and config.lexicon is True
    assert config.complement_weight == 0.3 and config.lexical_links == 1 and config.statement_mean == "arithmetic"
    assert MatchConfig().with_params(["input_gate=0.2", "input_gate=0.4"]).input_gate == 0.4  # the last wins
    assert MatchConfig().with_params([]) == MatchConfig()


@pytest.mark.parametrize(
    ("given", "name", "says"),
    [
        ("consumer_step=off", "consumer_step", "did you mean consumer_steps"),
        ("complement_weight=abc", "complement_weight", "expected a number"),
        ("complement_weight=2", "complement_weight", "must lie in [0, 1]"),
        ("statement_mean=median", "statement_mean", "'arithmetic' or 'geometric'"),
        ("consumer_steps=maybe", "consumer_steps", "yes/no"),
        ("lexical_links=1.5", "lexical_links", "expected a number (int)"),
        ("output_weight=nan", "output_weight", "expected a number (float)"),
        ("complement_weight", "complement_weight", "expected NAME=VALUE"),
    ],
)
def test_a_wrong_parameter_is_refused_naming_it(given: str, name: str, says: str) -> None:
    with pytest.raises(MatchParameterError) as caught:
        MatchConfig().with_params(["input_gate=0.1", given])
    assert caught.value.name == name and says in str(caught.value)


def test_the_setting_reads_comma_separated_pairs_and_refuses_other_text() -> None:
    item = setting("match_params")
    assert item.resolve(environ={}) == ()
    environ = {item.env: " consumer_steps = off, input_gate=0.4 ,"}
    assert item.resolve(environ=environ) == ("consumer_steps=off", "input_gate=0.4")
    assert item.resolve(("lexicon=on",), environ=environ) == ("lexicon=on",)  # the command line wins
    with pytest.raises(ValueError, match=r"CBRS_MATCH_PARAMS.*not NAME=VALUE"):
        item.resolve(environ={item.env: "consumer_steps"})


def _scores(*args: str, env: dict[str, str] | None = None) -> dict[str, float]:
    result = CliRunner().invoke(
        cli, ["--store", ":memory:", "match", "req:RobotSelfPosition", "--json", "--top", "53", *args], env=env
    )
    assert result.exit_code == 0, result.output
    given = [a for a in args if "=" in a] or [v for v in (env or {}).values() if v]
    # which parameters are set goes to standard error, so that the JSON stays the same
    assert ("matchmaking parameters: " in result.stderr) == bool(given)
    return {c["advertisement"]: c["score"] for c in json.loads(result.stdout)["candidates"]}


def test_cbrs_match_ranks_with_the_parameters_given() -> None:
    default = _scores(env={"CBRS_MATCH_PARAMS": ""})
    heavier = _scores("--param", "output_weight=0.9", env={"CBRS_MATCH_PARAMS": ""})
    assert heavier.keys() == default.keys() and heavier != default
    assert _scores(env={"CBRS_MATCH_PARAMS": "output_weight=0.9"}) == heavier  # from the environment too
    # --param replaces the setting, it does not add to it
    assert _scores("--param", "input_gate=0", env={"CBRS_MATCH_PARAMS": "output_weight=0.9"}) == default


def test_cbrs_match_names_a_wrong_parameter_and_lists_the_right_ones() -> None:
    runner = CliRunner()
    result = runner.invoke(cli, ["--store", ":memory:", "match", "req:RobotSelfPosition", "--param", "consumer_step=0"])
    assert result.exit_code == 1
    assert "consumer_step='0'" in result.output and "did you mean consumer_steps" in result.output
    listed = runner.invoke(cli, ["--store", ":memory:", "match", "--params"])
    assert listed.exit_code == 0
    rows = dict(line.split(None, 1) for line in listed.output.splitlines()[2:] if not line.startswith("("))
    assert set(rows) == set(MatchConfig.parameter_names())
    assert rows["consumer_steps"].strip() == "True" and rows["decomposition_weight"].strip() == "0.5"


def test_the_servers_matchmakers_use_the_parameters_and_keep_the_baselines_published() -> None:
    sparql = SparqlService(KnowledgeBase(Store.open(":memory:")), EndpointConfig())
    matchmakers = Matchmakers(sparql, ("consumer_steps=off", "output_weight=0.9"))
    with sparql.lock:
        refined, baseline = matchmakers.get("sem-str").config, matchmakers.get("wu-palmer").config
    assert refined.consumer_steps is False and refined.output_weight == 0.9
    assert baseline.decomposition_weight == 0 and baseline.output_weight == 0.9
    wrong = Matchmakers(sparql, ("consumer_step=off",))
    with sparql.lock, pytest.raises(MatchParameterError):
        wrong.get("sem-str")


def test_cbrs_serve_refuses_a_wrong_parameter_before_it_listens() -> None:
    result = CliRunner().invoke(
        cli, ["--store", ":memory:", "serve", "--port", "0", "--bridge-port", "0", "--match-param", "lexicon=perhaps"]
    )
    assert result.exit_code == 1 and "lexicon='perhaps'" in result.output and "yes/no" in result.output
