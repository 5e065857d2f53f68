"""The package's imports point one way: no module imports, at module level or inside a function,
a module that (directly or through others) imports it back; no module imports another
dynamically (``importlib.import_module``, ``__import__``) or uses its private names; and the layers of
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
    assert "floris_ekman_veer.plugin.inflow.inflow" in edges["floris_ekman_veer.plugin.floris_tools.parallel"]
    assert "floris_ekman_veer.plugin.rotor.turbine" in edges["floris_ekman_veer.registry"]
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
        f"{PACKAGE}.warning_classes", f"{PACKAGE}.example_inputs"}


def layer(name: str) -> str:
    if name in BASE:
        return "base"
    part = name.split(".")[1] if "." in name else ""
    return {"atmosphere": "physics", "wake": "physics", "plugin": "plugin",
            "studies": "studies"}.get(part, "top")


def test_every_module_has_its_layer():
    layers = {name: layer(name) for name in MODULES}
    assert layers[f"{PACKAGE}.atmosphere.ekman"] == layers[f"{PACKAGE}.wake.deficit"] == "physics"
    assert layers[f"{PACKAGE}.plugin.wake_models.models"] == layers[f"{PACKAGE}.plugin.inflow.inflow"] == "plugin"
    assert layers[f"{PACKAGE}.studies.yaw.optimization"] == "studies"
    assert layers[f"{PACKAGE}.studies.validation.cases"] == "studies"
    assert layers[f"{PACKAGE}.registry"] == layers[PACKAGE] == "top"
    # every layer holds modules, so that no rule below passes on an empty layer
    assert set(layers.values()) == set(LAYERS)


def test_imports_point_down_the_layers():
    wrong = [f"{name} ({layer(name)}) imports {other} ({layer(other)})"
             for name, others in internal_edges().items() for other in sorted(others)
             if LAYERS.index(layer(other)) > LAYERS.index(layer(name))]
    assert not wrong, "\n".join(wrong)



# ------------------------------------------------------- no hidden channels between modules
# A module reaches another only through its public names: no ``importlib.import_module`` or
# ``__import__`` (an import the graph above cannot see), no ``from x import _name`` of another
# module's private name, no ``module._name`` and no ``obj._name`` where ``_name`` is private to
# another module of the package (a function, class, method or attribute it defines and this
# module does not).

def _is_private(name: str) -> bool:
    return name.startswith("_") and not name.startswith("__") and name != "_"


def private_definitions(tree: ast.AST) -> set[str]:
    """The private names a module defines: functions, classes, methods, assigned names and
    attributes (``self._cache = ...``, attrs fields)."""
    found = set()
    for node in ast.walk(tree):
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
            found.add(node.name)
        elif isinstance(node, ast.Name) and isinstance(node.ctx, ast.Store):
            found.add(node.id)
        elif isinstance(node, ast.Attribute) and isinstance(node.ctx, ast.Store):
            found.add(node.attr)
        elif isinstance(node, ast.arg):
            found.add(node.arg)
    return {name for name in found if _is_private(name)}


def hidden_channels(name: str, tree: ast.AST, private_elsewhere: dict[str, set[str]]) -> list[tuple[int, str]]:
    """(line, what) of each dynamic import and each use of another module's private name in the
    module ``name``; ``private_elsewhere`` maps each other module to the private names it defines."""
    package = name if name in PACKAGES else name.rpartition(".")[0]
    own = private_definitions(tree)
    others = set().union(*private_elsewhere.values()) if private_elsewhere else set()
    aliases: dict[str, str] = {}  # local name -> package module it is bound to
    found = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            for alias in node.names:
                if alias.name.split(".")[0] == PACKAGE:
                    aliases[alias.asname or alias.name.split(".")[0]] = alias.name if alias.asname else PACKAGE
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                anchor = package.split(".")[: len(package.split(".")) - node.level + 1]
                base = ".".join(anchor + ([base] if base else []))
            if base.split(".")[0] != PACKAGE:
                continue
            for alias in node.names:
                if f"{base}.{alias.name}" in MODULES or f"{base}.{alias.name}" in private_elsewhere:
                    aliases[alias.asname or alias.name] = f"{base}.{alias.name}"
                elif _is_private(alias.name):
                    found.append((node.lineno, f"imports {alias.name} of {base}"))
        elif isinstance(node, ast.Call):
            func = node.func
            called = func.attr if isinstance(func, ast.Attribute) else getattr(func, "id", "")
            if called in ("import_module", "__import__"):
                found.append((node.lineno, f"calls {called}"))
    for node in ast.walk(tree):
        if not (isinstance(node, ast.Attribute) and _is_private(node.attr)):
            continue
        value = node.value
        if isinstance(value, ast.Name) and value.id in aliases:
            if aliases[value.id] != name:
                found.append((node.lineno, f"uses {node.attr} of {aliases[value.id]}"))
        elif (not (isinstance(value, ast.Name) and value.id in ("self", "cls"))
              and node.attr not in own and node.attr in others):
            owners = sorted(m for m, names in private_elsewhere.items() if node.attr in names)
            found.append((node.lineno, f"uses {node.attr} of {' or '.join(owners)}"))
    return sorted(set(found))


PACKAGES = {name for name, path in MODULES.items() if path.name == "__init__.py"}

# Today's hidden channels, each "module: what" (the line numbers are in the failure message).
# An entry that is no longer found fails the test too, so that the list only shrinks.
KNOWN_VIOLATIONS: set[str] = set()


def package_channels() -> dict[str, list[tuple[int, str]]]:
    trees = {name: ast.parse(path.read_text(), filename=str(path)) for name, path in MODULES.items()}
    defined = {name: private_definitions(tree) for name, tree in trees.items()}
    return {name: hidden_channels(name, tree, {m: d for m, d in defined.items() if m != name})
            for name, tree in trees.items()}


def test_hidden_channels_are_found():
    elsewhere = {f"{PACKAGE}.plugin.inflow.inflow": {"_patch", "_cache"},
                 f"{PACKAGE}.atmosphere.ekman": {"_solved_at", "_state"}}
    source = (
        "import importlib\n"
        "from floris_ekman_veer.plugin.inflow import inflow\n"
        "from floris_ekman_veer.plugin.inflow.inflow import _cache, set_atmosphere\n"
        "physics = importlib.import_module('floris_ekman_veer.atmosphere.ekman')\n"
        "__import__('floris_ekman_veer.plugin.inflow.inflow')\n"
        "inflow._patch()\n"
        "def fit(abl):\n"
        "    return abl._solved_at(1.0), abl._own(), _own(), abl.__class__, set_atmosphere\n"
        "def _own():\n"
        "    pass\n"
    )
    found = hidden_channels(f"{PACKAGE}.atmosphere.fit.fit", ast.parse(source), elsewhere)
    assert [what for _, what in found] == [
        f"imports _cache of {PACKAGE}.plugin.inflow.inflow", "calls import_module", "calls __import__",
        f"uses _patch of {PACKAGE}.plugin.inflow.inflow", f"uses _solved_at of {PACKAGE}.atmosphere.ekman"]
    assert [line for line, _ in found] == [3, 4, 5, 6, 8]


def test_no_dynamic_imports_or_private_names_across_modules():
    found = {f"{name}: {what}": line for name, channels in package_channels().items()
             for line, what in channels}
    new = sorted(f"{key} (line {line})" for key, line in found.items() if key not in KNOWN_VIOLATIONS)
    assert not new, "\n".join(new)
    gone = sorted(KNOWN_VIOLATIONS - set(found))
    assert not gone, "no longer found, remove from KNOWN_VIOLATIONS:\n" + "\n".join(gone)


def test_nothing_edits_the_import_path():
    """Examples, benchmarks, scripts and tests import the installed package (and the repository's
    modules through pytest's pythonpath or ``python -m``), never by inserting into sys.path."""
    repository = ROOT.parent
    edits = [f"{path.relative_to(repository)}:{number}"
             for folder in ("examples", "benchmarks", "scripts", "tests")
             for path in sorted((repository / folder).rglob("*.py"))
             for number, line in enumerate(path.read_text().splitlines(), 1)
             if "sys.path." in line and not line.lstrip().startswith(("#", '"', "'"))
             and path != Path(__file__).resolve()]
    assert not edits, edits
