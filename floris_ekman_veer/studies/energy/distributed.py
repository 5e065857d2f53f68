"""ParFlorisModel with a Dask interface: FLORIS's condition chunks on a dask.distributed cluster.

:class:`ParFlorisModel` is FLORIS's own ``ParFlorisModel`` (every interface it has, unchanged)
plus ``interface="dask"``, for studies too large for one machine. The conditions are cut into
contiguous chunks exactly as FLORIS cuts them for its process pools (``np.array_split`` of the
condition indices, one chunk per worker thread of the cluster by default), each chunk runs as a
plain ``FlorisModel`` on a Dask worker, and the chunks come back in order, so results are those of
the serial model (each condition is computed independently of the others). The Dask interface is
FLORIS's ``"concurrent"`` code path driven by the Executor that ``Client.get_executor()`` returns;
nothing about the chunking or the merging of results is rewritten here.

Dask workers are separate processes, often on other machines, started without this package
imported. The chunks sent to them are :class:`~floris_ekman_veer.plugin.floris_tools.parallel.WorkerDict`
inputs, which register the package's models and install the inflow hook on the worker when they
arrive (docs/coupling.md#parallel-workers); per-condition atmosphere lists are cut with the
conditions. When the model is built, every current worker imports the package once and reports its
versions: a worker without the package, or with another version of it or of FLORIS than the
client, is an error then, not a wrong number later.

``annual_energy(..., client=)`` runs its chunks of conditions (studies/energy/condition_chunks.py) as
tasks on a cluster in the same way (:func:`check_client`, :func:`run_chunks_on_cluster`).

Requires the optional extra ``dask`` (``pip install 'floris-ekman-veer[dask]'``), on the workers
too.
"""

from __future__ import annotations

import contextlib
import copy

import numpy as np
from floris import FlorisModel
from floris.par_floris_model import ParFlorisModel as _FlorisParFlorisModel

import floris_ekman_veer.warnings as package_warnings
from floris_ekman_veer._version import __version__
from floris_ekman_veer.plugin.inflow.inflow import ATMOSPHERE_KEY, PARAMETER_BLOCK
from floris_ekman_veer.plugin.floris_tools.parallel import prepare_worker
from floris_ekman_veer.studies.energy.condition_chunks import run_chunk

DASK = "dask"
#: The interfaces ParFlorisModel runs: FLORIS 4.7's own (None: serial) and the Dask one.
INTERFACES = ("multiprocessing", "pathos", "concurrent", None, DASK)


def _import_distributed():
    try:
        import distributed
    except ImportError:  # pragma: no cover - exercised only without the extra
        raise ImportError(
            'ParFlorisModel(interface="dask") needs dask.distributed: '
            "pip install 'floris-ekman-veer[dask]'"
        ) from None
    return distributed


def _versions() -> tuple[str, str]:
    """(floris_ekman_veer, floris) versions of this process, after registering the package."""
    prepare_worker()
    import floris

    return __version__, floris.__version__


def _check_workers(client) -> None:
    """Register the package on every current worker; raise if one cannot or differs."""
    try:
        reported = client.run(_versions)
    except ImportError as error:
        raise ImportError(
            f"a Dask worker of {client.scheduler.address} cannot import floris_ekman_veer "
            f"({error}); install the same floris-ekman-veer on every worker"
        ) from error
    local = _versions()
    for worker, versions in reported.items():
        if tuple(versions) != local:
            raise ValueError(
                f"Dask worker {worker} has floris_ekman_veer {versions[0]} and floris "
                f"{versions[1]}, this process {local[0]} and {local[1]}: install the same "
                "versions on the client and every worker"
            )


HANDSHAKE_ATTEMPTS = 3


def _connect(distributed, address: str):
    """A Client of the scheduler at ``address``, retried when the greeting arrives batched.

    distributed's Client asserts that the scheduler's first reply holds one message; a scheduler
    busy with other clients can batch its greeting with a broadcast, and the connection then fails
    with a bare AssertionError although the scheduler is healthy (seen on a loaded 2-core machine).
    A fresh connection succeeds, so the handshake is tried again, at most ``HANDSHAKE_ATTEMPTS``
    times.
    """
    for attempt in range(1, HANDSHAKE_ATTEMPTS + 1):
        try:
            return distributed.Client(address, set_as_default=False)
        except AssertionError:
            if attempt == HANDSHAKE_ATTEMPTS:
                raise


def _resolve_client(client):
    """A ``distributed.Client`` from a Client, a scheduler address, or None (the default one)."""
    distributed = _import_distributed()
    if isinstance(client, distributed.Client):
        return client
    if isinstance(client, str):
        try:
            # The form is checked before any Client exists: a Client whose constructor fails
            # is left to the garbage collector, and its close() there can deadlock the next
            # Client's start (both take distributed's loop-runner lock in the same thread).
            if distributed.comm.parse_address(client)[0] in ("tcp", "tls"):
                distributed.comm.get_address_host_port(client)
            return _connect(distributed, client)
        except (ValueError, TypeError) as error:
            # distributed's own answer ("missing port number in address 'x'") names neither
            # the parameter nor what an address looks like
            raise ValueError(
                f"ParFlorisModel client={client!r} is not a Dask scheduler address: give one "
                "such as 'tcp://scheduler:8786' (scheme://host:port), or a "
                f"dask.distributed.Client ({error})"
            ) from None
    if client is None:
        try:
            return distributed.default_client()
        except ValueError:
            raise ValueError(
                'ParFlorisModel(interface="dask") needs client= a dask.distributed.Client or a '
                "scheduler address such as 'tcp://scheduler:8786' (no default Client exists)"
            ) from None
    raise ValueError(
        "ParFlorisModel client must be a dask.distributed.Client or a scheduler address "
        f"string, got {type(client).__name__}"
    )


class ParFlorisModel(_FlorisParFlorisModel):
    """FLORIS's ParFlorisModel plus ``interface="dask"`` (see the module docstring).

    Args:
        configuration: As for FLORIS's ParFlorisModel (a dict, a YAML path or a FlorisModel).
        interface: ``"dask"``, or any interface of FLORIS's ParFlorisModel (``"multiprocessing"``,
            ``"pathos"``, ``"concurrent"``, None), which then behaves exactly as FLORIS's.
        max_workers: For ``"dask"``: the number of tasks the cluster runs at once; -1 (default)
            takes the total number of worker threads of the cluster when the model is built.
        n_wind_condition_splits: Number of condition chunks; -1 (default) = ``max_workers``.
        return_turbine_powers_only, print_timings: As in FLORIS.
        client: Only with ``interface="dask"``: a ``dask.distributed.Client``, or a scheduler
            address (``"tcp://host:8786"``) for which a Client is opened, or None to use the
            default Client of this process. Copies of the model (``copy()``, the optimisers'
            deep copies) share it.
    """

    def __init__(
        self,
        configuration,
        interface: str | None = "multiprocessing",
        max_workers: int = -1,
        n_wind_condition_splits: int = -1,
        return_turbine_powers_only: bool = False,
        print_timings: bool = False,
        client=None,
    ):
        for name, value in (("max_workers", max_workers),
                            ("n_wind_condition_splits", n_wind_condition_splits)):
            if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or (
                    value < 1 and value != -1):
                raise ValueError(f"ParFlorisModel {name} must be a positive integer or -1 (the "
                                 f"default); got {value!r}")
        if interface not in INTERFACES:
            # FLORIS's own list would omit "dask"
            raise ValueError(
                f"ParFlorisModel interface={interface!r} is not one of 'multiprocessing', "
                "'pathos', 'concurrent', 'dask' (pip install 'floris-ekman-veer[dask]') or None "
                "(serial)"
            )
        if interface != DASK:
            if client is not None:
                raise ValueError(
                    f'ParFlorisModel client= is only used with interface="dask", got '
                    f"interface={interface!r}"
                )
            self._client = None
            super().__init__(configuration, interface, max_workers, n_wind_condition_splits,
                             return_turbine_powers_only, print_timings)
            return
        self._client = _resolve_client(client)
        _check_workers(self._client)
        if max_workers == -1:
            max_workers = sum(self._client.nthreads().values())
        if not isinstance(max_workers, int) or max_workers < 1:
            raise ValueError(
                f"ParFlorisModel max_workers must be a positive integer (or -1 for the cluster's "
                f"worker threads), got {max_workers!r} for the cluster at "
                f"{self._client.scheduler.address}"
            )
        # FLORIS's "concurrent" set-up; the executor is the cluster's (see _on_cluster).
        super().__init__(configuration, "concurrent", max_workers, n_wind_condition_splits,
                         return_turbine_powers_only, print_timings)
        self._interface = DASK

    @property
    def client(self):
        """The ``dask.distributed.Client`` of a ``"dask"`` model (None for other interfaces)."""
        return self._client

    @contextlib.contextmanager
    def _on_cluster(self):
        """Run FLORIS's "concurrent" branch with the cluster's Executor in place of a pool."""
        if self._interface != DASK:
            yield
            return
        client, pool = self._client, self._PoolExecutor
        # The workers follow this process's silencing of the package's warnings (Dask hands
        # them the chunks' inputs as plain dicts, so WorkerDict cannot carry it).
        client.run(package_warnings.apply_setting, package_warnings.warnings_setting())
        self._interface, self._PoolExecutor = "concurrent", lambda _: client.get_executor()
        try:
            yield
        finally:
            self._interface, self._PoolExecutor = DASK, pool

    def run(self) -> None:
        with self._on_cluster():
            super().run()

    def _sample_value_at_points(self, x, y, z, value: str):
        with self._on_cluster():
            return super()._sample_value_at_points(x, y, z, value)

    @property
    def secondary_init_kwargs(self) -> dict:
        kwargs = super().secondary_init_kwargs
        if self._client is not None:
            kwargs["client"] = self._client
        return kwargs

    def __deepcopy__(self, memo):
        # A Client is a connection, not data: deep copies (FLORIS's optimisers make them) share it.
        if self._client is not None:
            memo[id(self._client)] = self._client
        new = object.__new__(type(self))
        memo[id(self)] = new
        new.__dict__.update(copy.deepcopy(self.__dict__, memo))
        return new


# ---------------------------------------------------------------------------------------------
# An annual-energy study's chunks of conditions as Dask tasks (annual_energy(..., client=))


def check_client(fmodel, client) -> None:
    """Refuse, before any run, a ``client`` that is not a ``dask.distributed.Client`` or a
    model the workers cannot rebuild as it is; register the package on every worker."""
    if isinstance(fmodel, _FlorisParFlorisModel) or not isinstance(fmodel, FlorisModel):
        raise ValueError(
            "annual energy: with client= each chunk of conditions runs on a Dask worker as a "
            f"plain FlorisModel; fmodel must be a FlorisModel, got {type(fmodel).__name__} "
            "(give its FlorisModel, or drop client= to let the model run its own chunks)"
        )
    distributed = _import_distributed()
    if not isinstance(client, distributed.Client):
        raise ValueError(
            "annual energy: client must be a dask.distributed.Client (e.g. "
            f"Client(LocalCluster()) or Client('tcp://scheduler:8786')); got "
            f"{type(client).__name__}"
        )
    _check_workers(client)


def run_chunks_on_cluster(client, template, model, chunks, ti_source, optimizer_class, bar) -> list:
    """:func:`~floris_ekman_veer.studies.energy.condition_chunks.run_chunk` of every chunk as a task on
    the Dask cluster of ``client``; the results in the chunks' order, the workers' warnings
    reported here once (floris_ekman_veer.warnings)."""
    from distributed import as_completed

    config = template.core.as_dict()
    # The workers set every chunk's conditions and atmosphere: the template's own (possibly a
    # year of per-record lists) need not travel.
    config["flow_field"].update(wind_directions=[], wind_speeds=[], turbulence_intensities=[])
    block = config["wake"]["wake_velocity_parameters"].get(PARAMETER_BLOCK)
    if block is not None:
        block.pop(ATMOSPHERE_KEY, None)
    [config] = client.scatter([config], broadcast=True)
    futures = client.map(_remote_chunk, chunks, config=config, model=model, ti_source=ti_source,
                         optimizer_class=optimizer_class,
                         setting=package_warnings.warnings_setting(), pure=False)
    sizes = {future.key: chunk.speeds.size for future, chunk in zip(futures, chunks)}
    package_warnings.discard_from_workers()
    for future in as_completed(futures):
        bar.update(sizes[future.key])
    results = client.gather(futures)
    package_warnings.report_from_workers(sum(sizes.values()))
    return [part for part, _ in results]


def _remote_chunk(chunk, config, model, ti_source, optimizer_class, setting):
    """A chunk on a Dask worker: the template rebuilt there with the chunk's conditions (a plain
    FlorisModel), then :func:`~floris_ekman_veer.studies.energy.condition_chunks.run_chunk` as in the
    serial study; the package's warnings travel back with the result."""
    prepare_worker()
    package_warnings.apply_setting(setting)
    config = copy.deepcopy(config)
    config["flow_field"].update(wind_directions=chunk.directions.tolist(),
                                wind_speeds=chunk.speeds.tolist(),
                                turbulence_intensities=chunk.wind_ti.tolist())
    parameters = config["wake"]["wake_velocity_parameters"]
    parameters.setdefault(PARAMETER_BLOCK, {})[ATMOSPHERE_KEY] = dict(chunk.atmosphere)
    with package_warnings.collecting() as records:
        part = run_chunk(FlorisModel(config), model, chunk, ti_source, optimizer_class)
    return part, package_warnings.WorkerRecords(records) if records else None
