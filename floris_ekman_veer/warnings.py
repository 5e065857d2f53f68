"""The package's warnings: their classes, and how they reach the user (docs/user_guide.md#warnings).

Every warning of the package is a :class:`FlorisEkmanVeerWarning`, importable from the package's
top level (``from floris_ekman_veer import ShallowBoundaryLayerWarning``), and each is

* located at the user's own line: the frames of FLORIS, of this package and of the standard
  library's context managers are skipped (a frame walk, so it works on every supported Python),
  so ``python -W`` filters and ``warnings.filterwarnings(..., module=...)`` see the user's module;
* summarised: one warning per run (the thrust limit) or per model build (the shallow boundary
  layer, the model settings) says how many conditions or turbines it concerns and which wind
  speeds;
* said once per study: a warning is repeated only when it concerns wind speeds (or settings) not
  reported yet in this process, so a yaw optimiser's many re-builds and runs, an annual-energy
  study's classes and a script's repeated ``set()`` report each condition once. A recording
  context (``warnings.catch_warnings(record=True)``, ``pytest.warns``) starts afresh;
* said by the process the user runs: in ParFlorisModel's worker processes (multiprocessing,
  concurrent, Dask) the warnings are recorded and travel back with each chunk's result, and the
  parent reports them as a serial run would (one thrust-limit summary counting all the run's
  conditions; nothing the parent already said), at the user's line (plugin/floris_tools/parallel.py).

The classes and the silencing setting are ``floris_ekman_veer.warning_classes``; this module
raises them, and is where the rest of the package imports them from.
"""

from __future__ import annotations

import contextlib
import contextvars
import os
import sys
import warnings
from pathlib import Path

from floris_ekman_veer.warning_classes import (  # the classes and the setting: imported from here
    CLASSES, ENVIRONMENT_VARIABLE, DirectionUnitsWarning, FlorisEkmanVeerWarning,
    HeterogeneousInflowWarning, ModelSettingsWarning, ReferenceWindWarning,
    ShallowBoundaryLayerWarning, ThrustLimitWarning, TurbinePlacementWarning, apply_setting,
    silence_warnings, silenced, warnings_setting)

#: The classes and the setting, with what this module defines: the package imports them here.
__all__ = [
    "CLASSES", "ENVIRONMENT_VARIABLE", "DirectionUnitsWarning", "FlorisEkmanVeerWarning",
    "HeterogeneousInflowWarning", "ModelSettingsWarning", "ReferenceWindWarning",
    "ShallowBoundaryLayerWarning", "ThrustLimitWarning", "TurbinePlacementWarning",
    "apply_setting", "silence_warnings", "warnings_setting",
    "WorkerRecords", "carrying", "collecting", "discard_from_workers", "discarding",
    "in_worker_process", "note_thrust_limit", "range_text", "report_from_workers", "run_scope",
    "speeds_text", "study_scope", "user_frame", "values_seen", "warn", "warn_shallow",
]


# ------------------------------------------------------------------------- the user's location
_PACKAGE_DIR = str(Path(__file__).resolve().parent)
_SKIPPED_FILES = (contextlib.__file__,)


def _library_dirs() -> tuple[str, ...]:
    import floris

    return (_PACKAGE_DIR, str(Path(floris.__file__).resolve().parent))


def _is_library(filename: str, libraries: tuple[str, ...]) -> bool:
    if filename.startswith("<"):
        return filename.startswith("<attrs generated")
    if filename in _SKIPPED_FILES:
        return True
    path = os.path.realpath(filename)
    return any(path == d or path.startswith(d + os.sep) for d in libraries)


def user_frame():
    """The innermost frame outside FLORIS, this package, attrs' generated code and contextlib
    (the outermost frame if every frame is theirs)."""
    libraries = _library_dirs()
    frame = sys._getframe(1)
    last = frame
    while frame is not None:
        if not _is_library(frame.f_code.co_filename, libraries):
            return frame
        last, frame = frame, frame.f_back
    return last


# --------------------------------------------------------------------------- once per study
def _recorder():
    """What shows warnings now: ``catch_warnings(record=True)`` (and so ``pytest.warns`` and
    pytest's per-test capture) installs its own list's ``append`` there."""
    return getattr(warnings, "_showwarnmsg_impl", None) or warnings.filters


class _Reported:
    """Items reported per warning class; forgotten when a recording context starts."""

    def __init__(self):
        self.recorder = None
        self.items: dict = {}

    def new(self, key, items) -> bool:
        recorder = _recorder()
        if self.recorder is not recorder:
            # a warnings.catch_warnings(record=True) (pytest.warns, pytest's capture of each
            # test) starts afresh: what it records is all it sees. (Held, so that its id is not
            # reused by a later one.)
            self.recorder, self.items = recorder, {}
        seen = self.items.setdefault(key, set())
        fresh = set(items) - seen
        seen.update(fresh)
        return bool(fresh)


_REPORTED = _Reported()


def warn(message: str, category: type, items=()) -> None:
    """Issue ``message`` at the user's line, unless silenced or every one of its ``items`` (wind
    speeds, settings; none: the message itself) has been reported before. In a worker process
    of the parent's ParFlorisModel run, the warning is recorded for the parent instead
    (:func:`collecting`)."""
    records = _COLLECTING.get()
    if records is not None:
        records.append(("warn", message, category, tuple(items)))
        return
    if silenced(category) or not _REPORTED.new(category, tuple(items) or (message,)):
        return
    frame = user_frame()
    filename, lineno = frame.f_code.co_filename, frame.f_lineno
    module_globals = frame.f_globals
    # (no module_globals: its loader would be asked for the source of a script run from stdin)
    warnings.warn_explicit(
        message, category, filename, lineno,
        module=module_globals.get("__name__", "<unknown>"),
        registry=module_globals.setdefault("__warningregistry__", {}),
    )


def values_seen(key: str, values) -> set:
    """Record ``values`` under ``key`` for this study (forgotten, as :func:`warn`'s items, when a
    recording context starts) and return every value recorded under it so far."""
    _REPORTED.new(key, tuple(values))
    return _REPORTED.items[key]


def speeds_text(speeds) -> str:
    """The distinct wind speeds of a list to 0.01 m/s, as text: '8, 9 and 11 m/s'; more than
    eight as their range: '0.27 to 11.4 m/s (1,204 distinct)'."""
    values = sorted({round(float(s), 2) for s in speeds})
    if len(values) > 8:
        return f"{values[0]:g} to {values[-1]:g} m/s ({len(values):,} distinct)"
    shown = [f"{v:g}" for v in values]
    text = shown[0] if len(shown) == 1 else ", ".join(shown[:-1]) + " and " + shown[-1]
    return f"{text} m/s"


def range_text(values, unit: str) -> str:
    """'90.1 to 125 m', or '125 m' for one value."""
    low, high = float(min(values)), float(max(values))
    return f"{low:.4g} {unit}" if f"{low:.4g}" == f"{high:.4g}" else f"{low:.4g} to {high:.4g} {unit}"


def _conditions_text(count, total, runs):
    """'3 of 8 conditions', or over a study's runs '30 of 80 conditions evaluated in its 10 FLORIS
    runs' (a condition run by several models or optimiser steps counts each time)."""
    if runs > 1:
        return f"{count:,} of {total:,} conditions evaluated in the study's {runs:,} FLORIS runs"
    return f"{count} of {total} conditions"


def warn_shallow(count, total, speeds, heights, top, hub, hub_above, reference_height,
                 policy_path, runs=1) -> None:
    """The ShallowBoundaryLayerWarning of ``count`` of ``total`` conditions (their wind speeds
    and ABL heights ``heights``; the highest rotor's ``top`` and ``hub``; ``hub_above`` of them
    with h at or below the hub; over ``runs`` FLORIS runs); in a study or a worker, recorded for
    its one summary."""
    records = _COLLECTING.get()
    if records is not None:
        records.append(("shallow", int(count), int(total), [float(v) for v in speeds],
                        [float(v) for v in heights], float(top), float(hub), int(hub_above),
                        float(reference_height), policy_path))
        return
    warn(
        f"{_conditions_text(count, total, runs)} (wind speeds {speeds_text(speeds)} at "
        f"{reference_height:.6g} m; h = {range_text(heights, 'm')}) have a boundary layer "
        f"shallower than the rotor top ({top:.6g} m; hub {hub:.6g} m, {hub_above} of them with "
        "h at or below the hub), outside the paper's validated range: above h the inflow is the "
        "geostrophic wind and the wake expansion falls continuously to its floor "
        f"(docs/atmosphere.md#shallow-boundary-layer). Set {policy_path}: raise to refuse "
        "them, or ignore (or call floris_ekman_veer.silence_warnings()) to silence this.",
        ShallowBoundaryLayerWarning,
        items=[(round(float(s), 6), round(float(d), 3)) for s, d in zip(speeds, heights)],
    )


# ------------------------------------------------------------------------------ once per run
_RUN: contextvars.ContextVar = contextvars.ContextVar("floris_ekman_veer_run", default=None)


@contextlib.contextmanager
def run_scope(wind_speeds, reference_height):
    """Collect the per-wake notes of one FLORIS solve (:func:`note_thrust_limit`) and issue one
    summary warning at its end. Nested scopes report to the outermost."""
    if _RUN.get() is not None:
        yield
        return
    notes: dict = {}
    token = _RUN.set(notes)
    try:
        yield
    finally:
        _RUN.reset(token)
    if not notes:
        return
    records = _COLLECTING.get()
    if records is None:
        _issue_thrust_limit(notes, wind_speeds, reference_height)
        return
    for limit, (_count, conditions) in notes.items():
        flagged, total = _flagged(conditions, wind_speeds)
        records.append(("thrust", limit, flagged, total, reference_height))


def note_thrust_limit(heavy, limit: float) -> None:
    """Record the wakes (``heavy``: boolean, condition axis first) evaluated at the thrust
    limit; reported once at the end of the run, or now outside a run."""
    import numpy as np

    heavy = np.asarray(heavy)
    conditions = heavy.reshape(heavy.shape[0], -1).any(axis=1) if heavy.ndim else heavy[None]
    notes = _RUN.get()
    if notes is None:
        _issue_thrust_limit({limit: [int(np.count_nonzero(heavy)), conditions]}, None, None)
        return
    entry = notes.setdefault(limit, [0, np.zeros(conditions.shape, dtype=bool)])
    entry[0] += int(np.count_nonzero(heavy))
    if entry[1].shape == conditions.shape:
        entry[1] |= conditions
    else:  # a full-flow solve of one condition inside a run of many: no per-condition summary
        entry[1] = np.zeros(0, dtype=bool)


def _flagged(conditions, wind_speeds):
    """(wind speeds of the flagged conditions, number of conditions), or (None, None) where the
    conditions are not those of the run (a full-flow solve of one condition)."""
    import numpy as np

    if wind_speeds is None or conditions.size != np.size(wind_speeds):
        return None, None
    speeds = np.asarray(wind_speeds, dtype=float).reshape(-1)[conditions]
    return [float(v) for v in speeds], int(conditions.size)


def _issue_thrust_limit(notes, wind_speeds, reference_height) -> None:
    for limit, (_count, conditions) in notes.items():
        _warn_thrust_limit(limit, *_flagged(conditions, wind_speeds), reference_height)


def _warn_thrust_limit(limit, flagged, total, reference_height, runs=1) -> None:
    where = ""
    if flagged is not None:
        where = (f" in {_conditions_text(len(flagged), total, runs)} (wind speeds "
                 f"{speeds_text(flagged)} at {float(reference_height):g} m)")
    # The loading comes from the turbines' own thrust tables (C_T cos^2(yaw) only falls with
    # yaw), so a stock turbine above the limit near cut-in meets it in every wind rose: said once
    # per study and limit, not again for each new set of wind speeds.
    warn(
        f"turbine wakes{where} have C_T cos^2(yaw) > {limit:g}, beyond momentum "
        f"theory: evaluated at C_T cos^2(yaw) = {limit:g} "
        "(wake.wake_velocity_parameters.ekman_veer.max_thrust_coefficient; "
        "docs/conventions.md#thrust-coefficient-and-yaw); said once per study",
        ThrustLimitWarning, (("max_thrust_coefficient", float(limit)),),
    )


# -------------------------------------------------------------------- from worker processes
#: Set while a worker process runs a chunk of the parent's conditions: the warnings of the
#: chunk, recorded (:func:`warn`) to travel back with its result.
_COLLECTING: contextvars.ContextVar = contextvars.ContextVar("floris_ekman_veer_collecting",
                                                             default=None)
#: Records that arrived with workers' results in this process, not yet reported.
_ARRIVED: list = []


def in_worker_process() -> bool:
    """Whether this process was started by another (a multiprocessing, concurrent.futures or
    Dask worker)."""
    import multiprocessing

    return multiprocessing.parent_process() is not None


@contextlib.contextmanager
def study_scope():
    """Record the package's warnings during a study (many FLORIS runs: chunks, models, an
    optimiser's runs) and issue one summary per warning class at its end, at the user's line
    (:func:`report_from_workers`). Nested in a study or a worker: nothing of its own."""
    if _COLLECTING.get() is not None:
        yield
        return
    records: list = []
    token = _COLLECTING.set(records)
    try:
        yield
    finally:
        _COLLECTING.reset(token)
    _ARRIVED.append(records)
    report_from_workers()


@contextlib.contextmanager
def discarding():
    """Drop the package's warnings of an auxiliary computation whose results the user sees
    through another call (which warns for itself)."""
    token = _COLLECTING.set([])
    try:
        yield
    finally:
        _COLLECTING.reset(token)


@contextlib.contextmanager
def collecting():
    """Record the package's warnings (and the per-run thrust-limit notes) instead of issuing
    them, in a worker process; yields the list of records (None in the main process, where
    warnings are issued as usual)."""
    if not in_worker_process():
        yield None
        return
    records: list = []
    token = _COLLECTING.set(records)
    try:
        yield records
    finally:
        _COLLECTING.reset(token)


def _arrive(records):
    _ARRIVED.append(records)


class WorkerRecords:
    """The records of a worker's chunk, attached to its result: unpickled in the parent, they
    join the records to report (:func:`report_from_workers`)."""

    def __init__(self, records):
        self.records = records

    def __reduce__(self):
        return _arrive, (self.records,)


def _arrive_with(array, records):
    _ARRIVED.append(records)
    return array


class _RecordsArray:
    """Pickles an array result as the plain array, with the records arriving beside it."""

    def __init__(self, array, records):
        self.array, self.records = array, records

    def __reduce__(self):
        return _arrive_with, (self.array, self.records)


def carrying(result, records):
    """A worker's result that brings its warning ``records`` to the parent when unpickled
    there."""
    if not records:
        return result
    if hasattr(result, "__array__") and not hasattr(result, "__dict__"):
        return _RecordsArray(result, records)
    result._floris_ekman_veer_warnings = WorkerRecords(records)
    return result


def discard_from_workers() -> None:
    """Forget records left by an earlier, failed parallel run."""
    _ARRIVED.clear()


def report_from_workers(n_conditions: int | None = None) -> None:
    """Issue, at the user's line, what the workers of the parallel run just finished recorded:
    each warning once (the parent's own reports count: a warning the parent already gave is not
    repeated), and one thrust-limit summary over all chunks, out of the parent's
    ``n_conditions``."""
    arrived = [record for records in _ARRIVED for record in records]
    _ARRIVED.clear()
    thrust: dict = {}
    shallow: dict = {}
    for record in arrived:
        if record[0] == "warn":
            warn(*record[1:])
            continue
        if record[0] == "shallow":
            # (one summary per rotor and reference height: the counts, speeds and depths add)
            entry = shallow.setdefault(record[5:7] + record[8:], [0, 0, [], [], 0, 0])
            for k, value in enumerate((record[1], record[2], record[3], record[4], record[7], 1)):
                entry[k] += value
            continue
        _, limit, flagged, total, reference_height = record
        entry = thrust.setdefault(limit, [[], 0, reference_height, True])
        if flagged is None:
            entry[3] = False
        else:
            entry[0].extend(flagged)
            entry[1] += total
    for (top, hub, reference_height, policy_path), (count, total, speeds, heights, hub_above,
                                                    runs) in shallow.items():
        warn_shallow(count, total, speeds, heights, top, hub, hub_above, reference_height,
                     policy_path, runs)
    for limit, (flagged, total, reference_height, counted) in thrust.items():
        if counted:
            _warn_thrust_limit(limit, flagged, n_conditions or total, reference_height)
        else:
            _warn_thrust_limit(limit, None, None, reference_height)

