"""Fit many boards' captures in parallel on a local Dask cluster, one board per worker process.

    python fit_boards_dask.py OUT CAPTURE_DIR [CAPTURE_DIR ...] [--workers N] [--texels N]

Each capture folder (a sweep's manifest.json and frames, as ``xylem sweep`` writes them) is
fitted by ``xylem.fit`` into OUT/<folder name>, one fit per worker with one thread each, so N
workers use N cores. On a real cluster, replace ``LocalCluster`` by the scheduler's address
(``Client("tcp://scheduler:8786")``); the folders must then be on a shared file system.
notes/cluster.md says why Dask rather than Ray.
"""

import argparse
import os
import pathlib
import sys

from dask.distributed import Client, LocalCluster

import xylem


def fit_one(capture, out, texels):
    """One board: its maps into ``out``; returns (capture, report with the worker's pid)."""
    size = (texels, texels) if texels else None
    report = xylem.fit(capture, out, texels=size, threads=1)
    report["worker_pid"] = os.getpid()
    return capture, report


def fit_boards(captures, out, workers, texels=None):
    """Fits every capture folder into ``out/<name>`` on ``workers`` local processes; returns
    the reports by capture folder. A failed board raises its error after the others finish."""
    out = pathlib.Path(out)
    names = [pathlib.Path(c).name for c in captures]
    if len(set(names)) != len(names):
        raise ValueError(f"capture folders share names: {names}; their maps would collide")
    with LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                      dashboard_address=None) as cluster, Client(cluster) as client:
        futures = [client.submit(fit_one, str(c), str(out / n), texels, pure=False)
                   for c, n in zip(captures, names)]
        results = client.gather(futures, errors="skip")
        failed = [f for f in futures if f.status == "error"]
        if failed:
            raise failed[0].exception()
        return dict(results)


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("out")
    p.add_argument("captures", nargs="+")
    p.add_argument("--workers", type=int, default=os.cpu_count() or 1)
    p.add_argument("--texels", type=int, default=None)
    a = p.parse_args(argv)
    for capture, r in fit_boards(a.captures, a.out, a.workers, a.texels).items():
        print(f"{capture}: {r['texels'][0]}x{r['texels'][1]} texels, "
              f"median residual {r['median_relative_residual']:.4f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
