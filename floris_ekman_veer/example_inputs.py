"""The package's FLORIS inputs (the repository's ``inputs/``), wherever the package is.

They ship in the wheel as the data package ``floris_ekman_veer.inputs``; in a clone of the
repository they are its top-level ``inputs/``. ``example_input("farm_sbl6")`` gives the path of
either, so that ``FlorisModel(floris_ekman_veer.example_input("farm_sbl6"))`` works from any
directory after ``pip install floris-ekman-veer``. The inputs include their turbines
(``!include turbines/...`` resolves next to the file).
"""

from __future__ import annotations

from pathlib import Path

_HERE = Path(__file__).resolve().parent
#: Where the inputs are: installed (the wheel's data package), then a clone's top-level inputs/.
_LOCATIONS = (_HERE / "inputs", _HERE.parent / "inputs")


def inputs_directory() -> Path:
    """The directory holding the package's FLORIS inputs."""
    for location in _LOCATIONS:
        if (location / "farm_sbl6.yaml").is_file():
            return location
    raise FileNotFoundError(
        "the package's FLORIS inputs are missing: looked in "
        + " and ".join(str(p) for p in _LOCATIONS) + " (reinstall floris-ekman-veer)"
    )


def example_inputs() -> list[str]:
    """The names ``example_input`` takes: every input, and the turbines as ``turbines/<name>``."""
    directory = inputs_directory()
    return sorted(str(p.relative_to(directory).with_suffix("")) for p in directory.rglob("*.yaml"))


def example_input(name: str) -> Path:
    """The path of the package's FLORIS input ``name`` (e.g. ``"farm_sbl6"``, ``"sbl6"``,
    ``"cnbl"``, ``"turbines/actuator_disk_les"``; ``.yaml`` optional; a data file by its full
    name, e.g. ``"site/synthetic_mast.csv"``). ValueError for a name
    that is not one of :func:`example_inputs`."""
    if not isinstance(name, str):
        raise ValueError(f"example_input name must be a string, one of {example_inputs()}; "
                         f"got {name!r}")
    suffix = Path(name).suffix
    if suffix and suffix != ".yaml":
        # Data files beside the inputs (the synthetic mast records, site/synthetic_mast.csv).
        path = inputs_directory() / name
        if not path.is_file():
            raise ValueError(f"example_input: no file {name!r} among the package's inputs")
        return path
    stem = name[:-5] if name.endswith(".yaml") else name
    path = inputs_directory() / f"{stem}.yaml"
    if stem not in example_inputs() or not path.is_file():
        raise ValueError(f"example_input: no input named {name!r}; the inputs are "
                         f"{example_inputs()}")
    return path
