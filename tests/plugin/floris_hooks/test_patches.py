"""The one table of FLORIS patches (plugin/floris_hooks/patches.py, docs/coupling.md#what-is-patched): every
attribute the package patches has its row, the page shows the installed table, the FLORIS version
each row was checked against is the installed one, and the mechanism installs once and restores
FLORIS's own."""

from __future__ import annotations

import runpy
from pathlib import Path

import floris
from floris.core import Core, FlowField

from floris_ekman_veer import registry
from floris_ekman_veer.plugin.floris_hooks import patches, patching
from floris_ekman_veer.plugin.floris_tools import optimizer_hooks

REPO = Path(__file__).resolve().parents[3]


def dotted(owner, name: str) -> str:
    path = f"{owner.__module__}.{owner.__qualname__}" if isinstance(owner, type) else owner.__name__
    return f"{path}.{name}"


def rows():
    return [row for table in registry.patch_tables() for row in table]


def test_every_patched_attribute_has_its_row():
    """Every patched attribute has exactly one row: the plugin's 27 and the yaw optimisers' 7
    (their constructors and optimize(), plugin/floris_tools/optimizer_hooks.py)."""
    patched = {dotted(owner, name) for owner, name in patching.ORIGINALS}
    plugin = [row.owner for row in patches.PATCHES]
    optimizers = [row.owner for row in optimizer_hooks.PATCHES]
    assert len(plugin) == len(set(plugin)) == 27
    assert len(optimizers) == len(set(optimizers)) == 7
    assert all(name.rpartition(".")[2] in ("__init__", "optimize")
               and ".yaw_optimization." in name for name in optimizers)
    assert set(plugin) | set(optimizers) == patched
    assert len(rows()) == len(patched)


def test_the_docs_patch_table_is_the_installed_one():
    script = runpy.run_path(str(REPO / "scripts" / "patch_table.py"))
    text = script["PAGE"].read_text()
    assert script["with_table"](text) == text
    for row in rows():
        assert f"| `{row.owner}` | {row.why} | {row.checked_against} |" in text


def test_rows_were_checked_against_the_installed_floris():
    major, minor = (int(part) for part in floris.__version__.split(".")[:2])
    lower, upper = patching.SUPPORTED_FLORIS
    assert lower <= (major, minor) < upper
    for row in rows():
        assert row.checked_against == f"{major}.{minor}", row.owner
        assert row.why and row.why[0].isalpha()


def test_install_is_idempotent_and_uninstall_gives_floris_back():
    before = dict(patching.ORIGINALS)
    wrapper = FlowField.__dict__["initialize_velocity_field"]
    for row in rows():
        row.install()
    assert patching.ORIGINALS == before
    assert FlowField.__dict__["initialize_velocity_field"] is wrapper
    own = patching.original(Core, "solve_for_viz")
    assert Core.__dict__["solve_for_viz"].__wrapped__ is own
    patching.uninstall()
    try:
        assert not patching.is_installed()
        assert Core.__dict__["solve_for_viz"] is own
        assert patching.original(Core, "solve_for_viz") is own
        patching.reinstall()
        assert set(patching.ORIGINALS) == set(before)
        assert Core.__dict__["solve_for_viz"].__wrapped__ is own
    finally:
        registry.register()
    assert set(patching.ORIGINALS) == set(before)
