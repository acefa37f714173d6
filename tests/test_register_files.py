"""``cbrs register FILES``: several description files in one transaction. A lab keeps each component (and
the devices it needs) in a file of its own; ``cbrs register a.ttl b.ttl`` took only one file, so a lab
registered them one by one, and a bad second file left the first registered."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from .test_cli import run

SENSOR = """@prefix cbrs: <https://w3id.org/cbrs/core#> . @prefix home: <https://w3id.org/cbrs/home#> .
@prefix lab: <https://example.org/lab#> .
lab:Read{name}_Sensor{n} a cbrs:DynamicPerceptionComponent ;
    cbrs:deviceName "Sensor{n}" ; cbrs:serviceName "Read{name}" ;
    cbrs:hasOWLSModel [ a cbrs:OWLSModel ;
        cbrs:hasOutput [ a cbrs:Parameter ; cbrs:parameterName "reading" ; cbrs:parameterType home:{kind} ] ] .
"""
LAB = "https://example.org/lab#"


def _file(folder: Path, name: str, text: str) -> Path:
    path = folder / name
    path.write_text(text, encoding="utf-8")
    return path


@pytest.fixture
def store(tmp_path: Path) -> str:
    location = str(tmp_path / "store")
    code, out = run("init", store=location)
    assert code == 0, out
    return location


def _registered(store: str) -> set[str]:
    code, out = run("services", "--json", store=store)
    assert code == 0, out
    return {row["service"] for row in json.loads(out)}


def test_several_files_register_together(store: str, tmp_path: Path) -> None:
    one = _file(tmp_path, "one.ttl", SENSOR.format(name="Temperature", n=1, kind="RoomTemperature"))
    two = _file(tmp_path, "two.ttl", SENSOR.format(name="Humidity", n=2, kind="RoomTemperature"))
    before = _registered(store)
    code, out = run("register", str(one), str(two), store=store)
    assert code == 0, out
    assert "registered lab:ReadTemperature_Sensor1" in out and "registered lab:ReadHumidity_Sensor2" in out
    assert _registered(store) - before == {LAB + "ReadTemperature_Sensor1", LAB + "ReadHumidity_Sensor2"}


def test_a_bad_file_registers_none_of_them(store: str, tmp_path: Path) -> None:
    good = _file(tmp_path, "good.ttl", SENSOR.format(name="Temperature", n=1, kind="RoomTemperature"))
    misspelt = _file(tmp_path, "bad.ttl", SENSOR.format(name="Humidity", n=2, kind="RoomTemprature"))
    before = _registered(store)
    code, out = run("register", str(good), str(misspelt), store=store)
    assert code == 1 and "RoomTemperature" in out  # the misspelt class, with its did-you-mean
    assert _registered(store) == before


def test_one_advertisement_in_two_files_is_refused_naming_the_second(store: str, tmp_path: Path) -> None:
    text = SENSOR.format(name="Temperature", n=1, kind="RoomTemperature")
    one, again = _file(tmp_path, "one.ttl", text), _file(tmp_path, "again.ttl", text)
    before = _registered(store)
    code, out = run("register", str(one), str(again), store=store)
    assert code == 1
    assert f"{again} is not a valid service description: it describes" in out
    assert f"ReadTemperature_Sensor1, which {one} describes too" in out
    assert _registered(store) == before


def test_update_brings_several_files_in_line_at_once(store: str, tmp_path: Path) -> None:
    one = _file(tmp_path, "one.ttl", SENSOR.format(name="Temperature", n=1, kind="RoomTemperature"))
    assert run("register", str(one), store=store)[0] == 0
    two = _file(tmp_path, "two.ttl", SENSOR.format(name="Humidity", n=2, kind="RoomTemperature"))
    code, out = run("register", str(one), str(two), store=store)
    assert code == 1 and f"cbrs register --update {one} {two}" in out  # one is registered already
    code, out = run("register", "--update", "--json", str(one), str(two), store=store)
    assert code == 0, out
    assert json.loads(out) == {
        "registered": [LAB + "ReadHumidity_Sensor2"],
        "updated": [LAB + "ReadTemperature_Sensor1"],
    }
