"""The wheel ships the FLORIS inputs: ``pip install .`` into a fresh virtual environment, then
``floris_ekman_veer.example_input`` from another directory gives installed, loadable inputs.

Slow (a fresh environment installs FLORIS and its dependencies: about a minute): marked
``slow``, skipped by ``python -m pytest`` and run by ``.ci/run`` (``python -m pytest -m slow
tests/docs/test_packaging.py``)."""

from __future__ import annotations

import subprocess
import sys
import venv
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]

pytestmark = pytest.mark.slow

SCRIPT = """
import floris_ekman_veer as f
from pathlib import Path
path = f.example_input("farm_sbl6")
print(path)
assert Path(path).is_file() and "site-packages" in str(path), path
assert sorted(f.example_inputs()) == sorted(NAMES), f.example_inputs()
mast = f.example_input("site/synthetic_mast.csv")  # the synthetic mast records ship too
assert "site-packages" in str(mast) and mast.read_text().startswith("# SYNTHETIC"), mast
from floris import FlorisModel
fmodel = FlorisModel(f.example_input("sbl6"))  # with its !include turbines/...
fmodel.run()
assert (fmodel.get_turbine_powers() > 0).all()
from floris_ekman_veer.studies.validation.cases import HORNS_REV
from floris_ekman_veer.studies.validation.reference_data import DATA  # the validation data ship
assert "site-packages" in str(DATA) and (DATA / "PyWake-LICENSE.txt").is_file(), DATA
assert HORNS_REV.layout[0].size == 80 and len(list(DATA.glob("*.dat"))) == 60  # Lillgrund too
assert (DATA / "Lillgrund_layout.csv").is_file() and (DATA / "SWT-2.3-93_power_ct.csv").is_file()
import floris_ekman_veer.plugin.inflow.inflow, floris_ekman_veer.studies.energy.energy  # every layer ships
"""


def test_wheel_ships_the_inputs(tmp_path):
    environment = tmp_path / "venv"
    venv.create(environment, with_pip=True)
    python = environment / "bin" / "python"
    install = subprocess.run([str(python), "-m", "pip", "install", "-q", str(REPO)],
                             capture_output=True, text=True, cwd=tmp_path)
    assert install.returncode == 0, install.stderr[-3000:]
    names = sorted(str(p.relative_to(REPO / "inputs").with_suffix(""))
                   for p in (REPO / "inputs").rglob("*.yaml"))
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    run = subprocess.run([str(python), "-c", f"NAMES = {names!r}\n" + SCRIPT],
                         capture_output=True, text=True, cwd=elsewhere)
    assert run.returncode == 0, run.stderr[-3000:]
    assert Path(run.stdout.splitlines()[0]).is_file()
    assert sys.executable != str(python)
