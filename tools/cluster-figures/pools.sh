#!/usr/bin/env bash
# Dask against Ray: three captures of the built-in fit scene fitted (64x64 texels) on a local
# pool of 2 one-thread workers. Needs a Python with the staged xylem package on PYTHONPATH
# (crates/xylem-cli/tests/python.rs stages it in target/python-test/site) and `pip install "dask[distributed]" ray`.
set -eu
. "$(dirname "$0")/common.sh"
PY=${PY:-python3}
cd "$WORK"
rm -rf caps dask_out ray_out; mkdir caps
for k in 1 2 3; do "$XYLEM" sweep fit_maple_sweep --frames 3 --spp 1 --out caps/board_$k --quiet >/dev/null; done
/usr/bin/time -f "dask: %M KiB driver peak, %e s in all" "$PY" "$ROOT/tools/cluster-figures/pools.py" dask
/usr/bin/time -f "ray: %M KiB driver peak, %e s in all" "$PY" "$ROOT/tools/cluster-figures/pools.py" ray
for k in 1 2 3; do cmp dask_out/board_$k/maps.exr ray_out/board_$k/maps.exr && echo "board_$k: same maps"; done
