"""Every Python block of the README and of docs/ runs as written, from a directory outside the
repository (so that the packaged inputs, not the clone's, are what the snippets find)."""

from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
PAGES = [REPO / "README.md", *sorted((REPO / "docs").glob("*.md"))]
BLOCK = re.compile(r"^```python\n(.*?)^```", flags=re.M | re.S)
#: A snippet that runs one of FLORIS's yaw optimisers (a steered study) or starts a Dask cluster is
#: a long study: marked ``study``, it runs in .ci/run after the fast suite (README, "Set up").
STUDY = re.compile(r"YawOptimization|LocalCluster")


def snippets():
    for page in PAGES:
        text = page.read_text()
        for match in BLOCK.finditer(text):
            line = text[: match.start()].count("\n") + 1
            marks = pytest.mark.study if STUDY.search(match[1]) else ()
            yield pytest.param(match[1], id=f"{page.relative_to(REPO)}:{line}", marks=marks)


SNIPPETS = list(snippets())


def test_the_pages_have_snippets():
    assert len(SNIPPETS) >= 8  # README's quick start and the user guide's examples


@pytest.mark.parametrize("code", SNIPPETS)
def test_snippet_runs_as_written(code, tmp_path):
    script = tmp_path / "snippet.py"
    script.write_text(code)
    env = {**os.environ, "MPLBACKEND": "Agg",
           "PYTHONPATH": os.pathsep.join(filter(None, [str(REPO), os.environ.get("PYTHONPATH")]))}
    run = subprocess.run([sys.executable, str(script)], cwd=tmp_path, env=env,
                         capture_output=True, text=True, timeout=600)
    assert run.returncode == 0, f"the snippet failed:\n{code}\n--- stderr:\n{run.stderr[-3000:]}"
    # and silently: no warning of the package nor FLORIS's (docs/user_guide.md#warnings)
    assert not re.search(r"\w+Warning: ", run.stderr), f"the snippet warned:\n{run.stderr[-3000:]}"


@pytest.mark.parametrize("example", ["quick_start.py", "day_and_night.py"])
def test_canonical_examples_run_silently(example, tmp_path):
    """The first examples a user runs say nothing on stderr: no warning the user cannot act on
    (FLORIS's TI and a library turbine's thrust table are logged, not warned:
    docs/user_guide.md#warnings). (yaw_study.py, a long study, is run by
    tests/docs/test_yaw_study_example.py.)"""
    env = {**os.environ, "MPLBACKEND": "Agg",
           "PYTHONPATH": os.pathsep.join(filter(None, [str(REPO), os.environ.get("PYTHONPATH")]))}
    run = subprocess.run([sys.executable, str(REPO / "examples" / example)], cwd=tmp_path,
                         env=env, capture_output=True, text=True, timeout=600)
    assert run.returncode == 0, run.stderr[-3000:]
    assert run.stderr == ""
