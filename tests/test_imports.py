"""The package's imports point one way: no module imports, at module level or inside a function,
a module that (directly or through others) imports it back; and the layers of
docs/architecture.md#what-each-folder-may-import hold: the physics (``atmosphere/``, ``wake/``)
imports no FLORIS and nothing of the plugin or the studies, the plugin (``plugin/``) nothing of
the studies (``studies/``).

The graph is read from the source with ``ast``, so a cycle hidden in a function-level import
counts as much as one at the top of a file. A package's own ``__init__`` that Python runs before
any of its modules is not an edge; an explicit ``import floris_ekman_veer`` is.
"""

from __future__ import annotations

import ast
from pathlib import Path

PACKAGE = "floris_ekman_veer"
ROOT = Path(__file__).resolve().parents[1] / PACKAGE


def module_name(path: Path) -> str:
    parts = path.relative_to(ROOT.parent).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


MODULES = {module_name(p): p for p in sorted(ROOT.rglob("*.py"))}


def imported_names(path: Path) -> set[str]:
    """Every absolute or relative module name the file imports, anywhere in it."""
    name = module_name(path)
    package = name if path.name == "__init__.py" else name.rpartition(".")[0]
    found = set()
    for node in ast.walk(ast.parse(path.read_text(), filename=str(path))):
        if isinstance(node, ast.Import):
            found.update(alias.name for alias in node.names)
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                anchor = package.split(".")[: len(package.split(".")) - node.level + 1]
                base = ".".join(anchor + ([base] if base else []))
            found.add(base)
            # ``from pkg import module`` imports that module.
            found.update(f"{base}.{alias.name}" for alias in node.names)
    return found


def internal_edges() -> dict[str, set[str]]:
    return {name: {other for other in imported_names(path) if other in MODULES and other != name}
            for name, path in MODULES.items()}


def find_cycle(graph: dict[str, set[str]]) -> list[str] | None:
    state: dict[str, int] = {}  # 1: on the current path, 2: done
    path: list[str] = []

    def visit(node):
        state[node] = 1
        path.append(node)
        for nxt in sorted(graph[node]):
            if state.get(nxt) == 1:
                return path[path.index(nxt):] + [nxt]
            if nxt not in state and (cycle := visit(nxt)):
                return cycle
        state[node] = 2
        path.pop()
        return None

    for start in sorted(graph):
        if start not in state and (cycle := visit(start)):
            return cycle
    return None


def test_the_graph_is_read():
    edges = internal_edges()
    # Known edges, so that an empty graph (a broken parser) cannot pass the cycle test.
    assert "floris_ekman_veer.plugin.inflow" in edges["floris_ekman_veer.plugin.parallel"]
    assert "floris_ekman_veer.plugin.turbine" in edges["floris_ekman_veer.registry"]
    assert "floris_ekman_veer.registry" in edges[PACKAGE]


def test_find_cycle_detects_a_cycle():
    assert find_cycle({"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": set()}) == ["a", "b", "c", "a"]
    assert find_cycle({"a": {"b"}, "b": set()}) is None


def test_no_import_cycles():
    assert find_cycle(internal_edges()) is None


def test_physics_does_not_import_floris():
    for name, path in MODULES.items():
        if name.startswith((f"{PACKAGE}.atmosphere", f"{PACKAGE}.wake")):
            floris = {n for n in imported_names(path) if n == "floris" or n.startswith("floris.")}
            assert not floris, f"{name} imports {sorted(floris)}"


# The layers, lowest first (docs/architecture.md#what-each-folder-may-import): a module may import
# its own layer and the ones below it. The base is the package's shared helpers (input checks,
# warnings, version, example inputs); the top is the package itself and the registry, which wire
# the plugin and the studies into FLORIS.
LAYERS = ("base", "physics", "plugin", "studies", "top")
BASE = {f"{PACKAGE}._validation", f"{PACKAGE}._version", f"{PACKAGE}.warnings",
        f"{PACKAGE}.example_inputs"}


def layer(name: str) -> str:
    if name in BASE:
        return "base"
    part = name.split(".")[1] if "." in name else ""
    return {"atmosphere": "physics", "wake": "physics", "plugin": "plugin",
            "studies": "studies"}.get(part, "top")


def test_every_module_has_its_layer():
    layers = {name: layer(name) for name in MODULES}
    assert layers[f"{PACKAGE}.atmosphere.ekman"] == layers[f"{PACKAGE}.wake.deficit"] == "physics"
    assert layers[f"{PACKAGE}.plugin.models"] == layers[f"{PACKAGE}.plugin.inflow"] == "plugin"
    assert layers[f"{PACKAGE}.studies.optimization"] == "studies"
    assert layers[f"{PACKAGE}.studies.validation.cases"] == "studies"
    assert layers[f"{PACKAGE}.registry"] == layers[PACKAGE] == "top"
    # every layer holds modules, so that no rule below passes on an empty layer
    assert set(layers.values()) == set(LAYERS)


def test_imports_point_down_the_layers():
    wrong = [f"{name} ({layer(name)}) imports {other} ({layer(other)})"
             for name, others in internal_edges().items() for other in sorted(others)
             if LAYERS.index(layer(other)) > LAYERS.index(layer(name))]
    assert not wrong, "\n".join(wrong)

