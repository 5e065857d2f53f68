"""The wheel's package list (pyproject's ``[tool.setuptools] packages``) names every folder of
the package that holds an ``__init__.py``: a sub-package left out installs without its modules,
and ``import floris_ekman_veer`` then fails on a user's machine while every test on the clone
passes (the installed wheel itself is checked by the slow tests/docs/test_packaging.py)."""

from __future__ import annotations

from pathlib import Path

import pytest

tomllib = pytest.importorskip("tomllib")  # Python >= 3.11

REPO = Path(__file__).resolve().parents[2]


def test_every_sub_package_is_in_the_wheels_package_list():
    listed = tomllib.loads((REPO / "pyproject.toml").read_text())["tool"]["setuptools"]["packages"]
    folders = {
        ".".join(init.parent.relative_to(REPO).parts)
        for init in (REPO / "floris_ekman_veer").rglob("__init__.py")
        if "__pycache__" not in init.parts
    }
    code = {name for name in listed if not name.startswith("floris_ekman_veer.inputs")}
    assert folders - code == set(), "sub-packages missing from pyproject's packages"
    assert code - folders == set(), "pyproject names packages that do not exist"
