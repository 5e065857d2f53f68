"""How the package replaces a FLORIS attribute, keeps FLORIS's own and gives it back.

FLORIS 4.7 has no extension point for another inflow, another rotor or the bookkeeping of
per-condition atmospheres, so the package wraps a few of its functions and methods. Every one of
them is a row of the patch table, :data:`floris_ekman_veer.plugin.floris_hooks.patches.PATCHES` (what, why,
which FLORIS version it was checked against), installed by ``registry.register()`` walking the
table; this module is the mechanism the rows use (docs/coupling.md#what-is-patched):

* :func:`patch` replaces ``owner.name`` (a class's or a module's attribute) by
  ``make_wrapper(original)`` once (idempotent) and keeps the original;
* :func:`original` is FLORIS's own attribute behind a patch;
* :func:`uninstall` gives FLORIS back every original (plain FLORIS, for comparisons and tests),
  :func:`reinstall` puts the package's wrappers back (a worker process that inherited an
  uninstalled FLORIS), :func:`is_installed` says whether any patch is in place.

A leaf module: the modules that define the wrappers and the table that names them import it,
it imports none of them.
"""

from __future__ import annotations

import re
from collections.abc import Callable

import floris

#: [lower, upper): the FLORIS versions the patches were checked against (its internals).
SUPPORTED_FLORIS = ((4, 7), (4, 8))


def check_floris_version(version: str) -> None:
    """Raise ImportError unless ``version`` is in [4.7, 4.8)."""
    match = re.match(r"(\d+)\.(\d+)", version)
    lower, upper = SUPPORTED_FLORIS
    if match is None or not lower <= (int(match[1]), int(match[2])) < upper:
        raise ImportError(
            f"floris_ekman_veer patches FLORIS internals and supports "
            f"floris>={lower[0]}.{lower[1]},<{upper[0]}.{upper[1]}, but floris {version} is "
            f"installed. Install a supported FLORIS (pip install 'floris>=4.7,<4.8')."
        )


check_floris_version(floris.__version__)

#: (owner, name) -> FLORIS's own attribute, for every patch in place.
ORIGINALS: dict = {}
#: (owner, name) -> the ``make_wrapper`` of every patch installed in this process, for
#: :func:`reinstall`.
_WRAPPERS: dict = {}


def patch(owner, name: str, make_wrapper: Callable) -> None:
    """Replace ``owner.name`` by ``make_wrapper(original)`` once (idempotent); the original is
    kept for :func:`original` and :func:`uninstall`."""
    _WRAPPERS.setdefault((owner, name), make_wrapper)
    if (owner, name) in ORIGINALS:
        return
    own = owner.__dict__[name]
    ORIGINALS[(owner, name)] = own
    setattr(owner, name, make_wrapper(own))


def original(owner, name: str):
    """FLORIS's own ``owner.name`` (the attribute itself where it is not patched)."""
    return ORIGINALS.get((owner, name), owner.__dict__[name])


def uninstall() -> None:
    """Restore every patched FLORIS attribute (plain FLORIS)."""
    for (owner, name), own in list(ORIGINALS.items()):
        setattr(owner, name, own)
        del ORIGINALS[(owner, name)]


def reinstall() -> None:
    """Put back every patch installed in this process (idempotent)."""
    for (owner, name), make_wrapper in list(_WRAPPERS.items()):
        patch(owner, name, make_wrapper)


def is_installed() -> bool:
    """Whether any patch is in place."""
    return bool(ORIGINALS)
