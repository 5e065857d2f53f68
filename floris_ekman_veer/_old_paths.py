"""The package's old import paths, kept as aliases of the modules that moved
(docs/architecture.md#old-import-paths).

Up to 0.1.0 the FLORIS plugin and the studies stood side by side in ``coupling/`` and the
validation study in ``validation/``; they now live in ``plugin/``, ``studies/`` and
``registry.py``. A user's ``import`` of an old path gets the very module object of the new one
(not a copy), so monkeypatching it, ``isinstance`` with its classes and pickles that name it
keep working. Nothing in the package imports the old paths.
"""

from __future__ import annotations

import importlib
import sys


def keep_old_paths(package: str, moves: dict[str, str]) -> None:
    """Make ``package.<old>`` the module ``moves[old]`` for every old name: in ``sys.modules``
    (``import package.old``) and as an attribute of the package (``from package import old``)."""
    parent = sys.modules[package]
    for old, new in moves.items():
        module = importlib.import_module(new)
        sys.modules[f"{package}.{old}"] = module
        setattr(parent, old, module)
