"""The first call's cost of the compiled rotor-cell kernel (plugin/rotor/rotor_kernel.py), each case in
a fresh process (hand-run script, not a test):

    python -m benchmarks.bench_first_call [--repeats 2] [--reference PATH]

Cases, each with numba's cache cold (an empty NUMBA_CACHE_DIR: what the first run after an
install compiles) and warm (the same directory again: every later process):

    README main     ``python examples/farm_main.py``, the README's first command (wall time);
    first 3x3       import the package, build the 3 x 3 farm of ``inputs/farm_sbl6.yaml`` and
                    run it once (wall time of the whole process, and of the first ``run()``);
    Dask task       a LocalCluster of one worker process: the first task (a 3 x 3 run) and a
                    second one on the same worker.

``--reference PATH``: the same cases with another copy of the package (e.g. the commit before
the kernel) on PYTHONPATH, for the difference. Also the read-only install: the package copied
into a folder without write permission, run with HOME set to a fresh folder and no
NUMBA_CACHE_DIR: numba then keeps its cache in the user's cache folder
(``~/.cache/numba``), which the script lists.
"""

from __future__ import annotations

import argparse
import os
import shutil
import stat
import subprocess
import sys
import tempfile
import time
from pathlib import Path

REPOSITORY = Path(__file__).resolve().parents[1]

FIRST_RUN = """
import time, warnings
start = time.perf_counter()
import numpy as np
from floris import FlorisModel
import floris_ekman_veer
warnings.simplefilter("ignore")
fmodel = FlorisModel(str(floris_ekman_veer.example_input("farm_sbl6.yaml")))
fmodel.set(wind_directions=[270.0, 275.0], wind_speeds=[8.0, 9.0],
           turbulence_intensities=[0.06, 0.06], yaw_angles=np.full((2, 9), 10.0))
run = time.perf_counter()
fmodel.run()
print(f"{time.perf_counter() - run:.3f} {time.perf_counter() - start:.3f}")
"""

DASK_TASK = """
import time, warnings
import numpy as np
from dask.distributed import Client, LocalCluster

def task():
    import warnings
    import numpy as np
    from floris import FlorisModel
    import floris_ekman_veer
    warnings.simplefilter("ignore")
    fmodel = FlorisModel(str(floris_ekman_veer.example_input("farm_sbl6.yaml")))
    fmodel.set(wind_directions=[270.0], wind_speeds=[8.0], turbulence_intensities=[0.06],
               yaw_angles=np.full((1, 9), 10.0))
    fmodel.run()
    return float(fmodel.get_farm_power()[0])

if __name__ == "__main__":
    warnings.simplefilter("ignore")
    with LocalCluster(n_workers=1, threads_per_worker=1, processes=True,
                      dashboard_address=None) as cluster, Client(cluster) as client:
        client.run(lambda: None)  # the worker is up
        times = []
        for _ in range(2):
            start = time.perf_counter()
            client.submit(task, pure=False).result()
            times.append(time.perf_counter() - start)
    print(" ".join(f"{t:.3f}" for t in times))
"""


#: As root every folder is writable: the read-only case then runs as this user (nobody).
UNPRIVILEGED = ["setpriv", "--reuid=65534", "--regid=65534", "--clear-groups"]


def run(command, package: Path, cache: Path | None, home: Path | None = None) -> tuple:
    """Wall time of a fresh process and its stdout's numbers."""
    env = dict(os.environ, PYTHONPATH=str(package))
    env.pop("NUMBA_CACHE_DIR", None)
    if cache is not None:
        env["NUMBA_CACHE_DIR"] = str(cache)
    if home is not None:
        env["HOME"] = str(home)
    start = time.perf_counter()
    out = subprocess.run(command, cwd=package, env=env, capture_output=True, text=True,
                         check=True).stdout
    wall = time.perf_counter() - start
    numbers = [float(x) for x in out.split()[-2:]] if "-c" in command else []
    return wall, numbers


def cases(package: Path, repeats: int) -> dict:
    """{(case, cold/warm): best wall [s] (and the parts)} for one copy of the package."""
    commands = {
        "README main": [sys.executable, "examples/farm_main.py"],
        "first 3x3": [sys.executable, "-c", FIRST_RUN],
        "Dask task": [sys.executable, "-c", DASK_TASK],
    }
    results = {}
    for name, command in commands.items():
        for _ in range(repeats):
            with tempfile.TemporaryDirectory() as cache:
                for state in ("cold", "warm"):
                    wall, numbers = run(command, package, Path(cache))
                    key = (name, state)
                    best = results.get(key)
                    if best is None or wall < best[0]:
                        results[key] = (wall, numbers)
    return results


def read_only_install(package: Path) -> str:
    """Where numba keeps the kernel's cache when the package's folder is read-only."""
    with tempfile.TemporaryDirectory() as root:
        Path(root).chmod(0o755)
        copy = Path(root) / "site"
        shutil.copytree(package / "floris_ekman_veer", copy / "floris_ekman_veer",
                        ignore=shutil.ignore_patterns("__pycache__"))
        shutil.copytree(package / "inputs", copy / "inputs")
        home = Path(root) / "home"
        home.mkdir()
        prefix = []
        if os.geteuid() == 0:
            os.chown(home, 65534, 65534)
            prefix = UNPRIVILEGED
        for path in copy.rglob("*"):
            path.chmod(path.stat().st_mode & ~(stat.S_IWUSR | stat.S_IWGRP | stat.S_IWOTH))
        copy.chmod(copy.stat().st_mode & ~stat.S_IWUSR)
        try:
            times = [run([*prefix, sys.executable, "-c", FIRST_RUN], copy, None, home)[0]
                     for _ in range(2)]
            cached = sorted(p.name for p in home.rglob("*.nbi"))
            in_package = sorted(p.name for p in copy.rglob("*.nbi"))
        finally:
            for path in [copy, *copy.rglob("*")]:
                path.chmod(path.stat().st_mode | stat.S_IWUSR)
    return (f"read-only package, no NUMBA_CACHE_DIR: first process {times[0]:.2f} s, second "
            f"{times[1]:.2f} s; numba's index files under HOME: {len(cached)} "
            f"({', '.join(cached[:3])}{', ...' if len(cached) > 3 else ''}), in the package: "
            f"{len(in_package)}")


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--repeats", type=int, default=2)
    parser.add_argument("--reference", type=Path, default=None)
    args = parser.parse_args(argv)
    print(f"load average {os.getloadavg()[0]:.1f} at the start")
    packages = {"this version": REPOSITORY}
    if args.reference is not None:
        packages["reference"] = args.reference.resolve()
    table = {label: cases(package, args.repeats) for label, package in packages.items()}
    print("\n| case | package | numba cache | wall [s] | first run() [s] |")
    print("|---|---|---|---:|---:|")
    for label, results in table.items():
        for (name, state), (wall, numbers) in results.items():
            first = f"{numbers[0]:.3f}" if numbers else "-"
            if name == "Dask task":
                wall, first = numbers[0], f"second task {numbers[1]:.3f}"
            print(f"| {name} | {label} | {state} | {wall:.2f} | {first} |")
    print("\n" + read_only_install(REPOSITORY))
    print(f"\nload average {os.getloadavg()[0]:.1f} at the end")


if __name__ == "__main__":
    main()
