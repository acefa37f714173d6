"""A plain (non-editable) install works from any directory: the bundled data travels with it."""

from __future__ import annotations

import ast
import importlib.metadata
import json
import os
import re
import subprocess
import sys
import sysconfig
import tomllib
from pathlib import Path

import pytest

from cbrs.extras import EXTRAS

ROOT = Path(__file__).resolve().parents[1]
PYPROJECT = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))
TOP_LEVEL = sorted({name.split(".")[0] for name in PYPROJECT["tool"]["setuptools"]["packages"]})


def test_every_top_level_package_ships_py_typed() -> None:
    # PEP 561: the marker in a top-level package covers its subpackages.
    package_data = PYPROJECT["tool"]["setuptools"]["package-data"]
    for package in TOP_LEVEL:
        assert (ROOT / package / "py.typed").is_file(), f"{package}/py.typed is missing"
        assert "py.typed" in package_data.get(package, []), f"package-data does not install {package}/py.typed"


def test_licence_file_matches_the_declared_licence() -> None:
    project = PYPROJECT["project"]
    assert project["license"] == "MIT" and project["license-files"] == ["LICENSE"]
    text = (ROOT / "LICENSE").read_text(encoding="utf-8")
    assert text.startswith("MIT License") and "Permission is hereby granted, free of charge" in text


def test_changelog_has_a_section_for_the_current_version() -> None:
    from cbrs import __version__

    text = (ROOT / "CHANGELOG.md").read_text(encoding="utf-8")
    assert re.search(rf"^## \[?{re.escape(__version__)}\]?", text, re.MULTILINE), f"no section for {__version__}"
    assert re.search(r"^## \[?Unreleased\]?", text, re.MULTILINE)


def _source_folders() -> list[Path]:
    """The folders of the installed packages' code: cbrs and the folders its links (cbrs/kb...) point to."""
    folders = [ROOT / package for package in TOP_LEVEL]
    linked = [entry.resolve() for entry in (ROOT / "cbrs").iterdir() if entry.is_symlink() and entry.is_dir()]
    return folders + sorted(linked)


def _runtime_imports() -> set[str]:
    """Top-level modules imported by the installed packages' code (not tests, not bench)."""
    found: set[str] = set()
    for folder in _source_folders():
        for path in folder.rglob("*.py"):
            for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
                if isinstance(node, ast.Import):
                    found.update(alias.name.split(".")[0] for alias in node.names)
                elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
                    found.add(node.module.split(".")[0])
    return found


def test_runtime_dependencies_are_what_runtime_code_imports() -> None:
    import_names = {"pillow": "PIL", "scikit-learn": "sklearn"}
    optional = [
        dep for name, deps in PYPROJECT["project"]["optional-dependencies"].items() if name in EXTRAS for dep in deps
    ]
    declared = {
        re.split(r"[<>=!~\[ ]", dep, maxsplit=1)[0].lower()
        for dep in [*PYPROJECT["project"]["dependencies"], *optional]
    }
    imported = _runtime_imports()
    unused = sorted(dep for dep in declared if import_names.get(dep, dep).replace("-", "_") not in imported)
    assert not unused, f"declared but imported by no runtime code: {unused}"
    provided = {import_names.get(dep, dep).replace("-", "_") for dep in declared} | set(TOP_LEVEL)
    undeclared = sorted(imported - provided - set(sys.stdlib_module_names) - {"__future__"})
    assert not undeclared, f"imported by runtime code but not a declared dependency: {undeclared}"


def test_only_cbrs_is_importable_from_outside_the_checkout(tmp_path: Path) -> None:
    """kb, reasoner, actions and sim install under cbrs: a user's own `kb` cannot shadow ours, nor ours theirs."""
    env = {key: value for key, value in os.environ.items() if key != "PYTHONPATH"}
    for name in ("kb", "reasoner", "actions", "sim"):
        found = subprocess.run(
            [sys.executable, "-c", f"import importlib.util as u; print(u.find_spec({name!r}) is None)"],
            cwd=tmp_path,
            env=env,
            capture_output=True,
            text=True,
            check=True,
        )
        assert found.stdout.strip() == "True", f"{name} is importable outside the checkout"
        inside = subprocess.run(
            [sys.executable, "-c", f"import cbrs.{name}"], cwd=tmp_path, env=env, capture_output=True, text=True
        )
        assert inside.returncode == 0, inside.stderr


def _dependencies_without_extras(folder: Path) -> Path:
    """A folder of links to this interpreter's installed packages, less cbrs itself and its extras' packages.

    The new environment reads its dependencies from here instead of installing them again (40 s of the
    suite's time): what this test checks is the wheel (its code and bundled data), and the declared
    dependencies are checked against the imports by test_runtime_dependencies_are_what_runtime_code_imports.
    """
    left_out = {"cbrs", "pybullet", "pillow", "scikit-learn", "matplotlib"}
    excluded: set[str] = set()
    for dist in importlib.metadata.distributions():
        if dist.metadata["Name"].lower() in left_out:
            excluded.update(Path(str(file)).parts[0] for file in dist.files or ())
    site = Path(sysconfig.get_paths()["purelib"])
    folder.mkdir()
    for entry in site.iterdir():
        if entry.name in excluded or entry.suffix == ".pth" or entry.name.startswith("__editable__"):
            continue
        (folder / entry.name).symlink_to(entry)
    return folder


@pytest.mark.slow
def test_plain_install_runs_from_another_directory(tmp_path: Path) -> None:
    wheels = tmp_path / "wheels"
    # built with the test extra's setuptools and wheel (the build-system's requirements), not in an isolated
    # environment fetched from the index on every run (11 s here)
    build = ["wheel", "-q", "--no-deps", "--no-build-isolation", "--disable-pip-version-check", "-w", str(wheels)]
    build.append(str(ROOT))
    built = subprocess.run(
        [sys.executable, "-m", "pip", *build],
        capture_output=True,
        text=True,
        check=False,
    )
    assert built.returncode == 0, built.stderr[-3000:]
    (wheel,) = wheels.glob("cbrs-*.whl")
    venv = tmp_path / "venv"
    subprocess.run([sys.executable, "-m", "venv", "--without-pip", str(venv)], check=True)
    (venv_site,) = venv.glob("lib/python*/site-packages")
    (venv_site / "dependencies.pth").write_text(f"{_dependencies_without_extras(tmp_path / 'deps')}\n")
    install = ["install", "-q", "--no-deps", "--no-index", "--disable-pip-version-check", str(wheel)]
    pip = subprocess.run(
        [sys.executable, "-m", "pip", "--python", str(venv / "bin" / "python"), *install],
        capture_output=True,
        text=True,
        check=False,
    )
    assert pip.returncode == 0, pip.stderr[-3000:]
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    env = {**os.environ, "CBRS_STORE": str(tmp_path / "store")}
    env.pop("PYTHONPATH", None)
    cbrs = str(venv / "bin" / "cbrs")

    init = subprocess.run([cbrs, "init"], cwd=elsewhere, env=env, capture_output=True, text=True, check=False)
    assert init.returncode == 0, init.stderr
    assert "advertisements" in init.stdout

    query = subprocess.run(
        [cbrs, "query", "--name", "advertisements", "--format", "json"],
        cwd=elsewhere,
        env=env,
        capture_output=True,
        text=True,
        check=False,
    )
    assert query.returncode == 0, query.stderr
    bindings = json.loads(query.stdout)["results"]["bindings"]
    by_service = {b["service"]["value"].rsplit("#", 1)[1]: b for b in bindings}
    locate = by_service["LocateMobileRobot_CeilingCamera01"]
    assert locate["inputs"]["value"].endswith("#MarkerColour")
    assert locate["outputs"]["value"].endswith("#RobotLocation")

    # Without the [sim] extra, a command that needs the simulation says which extra to install.
    run = subprocess.run(
        [cbrs, "run", "FetchMyPen"], cwd=elsewhere, env=env, capture_output=True, text=True, check=False
    )
    assert run.returncode != 0 and "pip install 'cbrs[sim]'" in run.stderr + run.stdout

    # The installed copy, not the checkout, answered.
    where = subprocess.run(
        [str(venv / "bin" / "python"), "-c", "import cbrs.kb.resources as r; print(r.query_dir())"],
        cwd=elsewhere,
        env=env,
        capture_output=True,
        text=True,
        check=True,
    )
    assert str(venv) in where.stdout
