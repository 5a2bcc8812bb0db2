#!/usr/bin/env bash
# Peak RSS (/usr/bin/time -v) of 256x256 1-spp sweeps of 48, 480, 4800 frames against --memory.
# Run from the repository root after cargo build --release.
set -eu
. "$(dirname "$0")/common.sh"
scene=$(board256 1)
cd "$WORK"
for mem in 100M 128M default; do
  for n in 48 480 4800; do
    [ "$mem" = default ] && [ "$n" = 4800 ] && continue
    rm -rf out_$n
    opt=(); [ "$mem" != default ] && opt=(--memory "$mem")
    /usr/bin/time -v "$XYLEM" sweep "$scene" --frames $n --out out_$n --quiet --threads 2 "${opt[@]}" > log.txt 2>&1
    echo "$mem $n: $(grep 'Maximum resident' log.txt | awk '{print $NF}') KiB, $(grep '^rendered' log.txt | sed 's/ into.*//')"
  done
done
rm -rf out_*
