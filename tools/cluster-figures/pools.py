"""pools.py dask|ray: fits caps/* into <pool>_out/ on 2 local one-thread workers, timing the
pool's start and the fits (tools/cluster-figures/pools.sh)."""

import os
import pathlib
import sys
import time

import xylem


def fit_one(capture, out):
    report = xylem.fit(capture, out, texels=(64, 64), threads=1)
    return os.getpid()


def main(pool):
    caps = sorted(str(p) for p in pathlib.Path("caps").iterdir())
    outs = [f"{pool}_out/{pathlib.Path(c).name}" for c in caps]
    t0 = time.time()
    if pool == "dask":
        from dask.distributed import Client, LocalCluster

        with LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                          dashboard_address=None) as cluster, Client(cluster) as client:
            t1 = time.time()
            pids = client.gather([client.submit(fit_one, c, o, pure=False)
                                  for c, o in zip(caps, outs)])
            t2 = time.time()
    else:
        import ray

        ray.init(num_cpus=2, include_dashboard=False, log_to_driver=False)
        t1 = time.time()
        remote = ray.remote(num_cpus=1)(fit_one)
        pids = ray.get([remote.remote(c, o) for c, o in zip(caps, outs)])
        t2 = time.time()
        ray.shutdown()
    print(f"{pool}: pool started in {t1 - t0:.1f} s, 3 boards fitted in {t2 - t1:.1f} s "
          f"by {len(set(pids))} workers")


if __name__ == "__main__":
    main(sys.argv[1])
