#!/usr/bin/env bash
# Peak RSS (/usr/bin/time -v) of 256x256 1-spp sweeps of 48, 480, 4800 frames with the default
# plan and with --memory 128M, interleaved (REPS rounds, default 2), and the render time each
# run reports. Run from the repository root after cargo build --release.
set -eu
. "$(dirname "$0")/common.sh"
scene=$(board256 1)
cd "$WORK"
for rep in $(seq "${REPS:-2}"); do
  for n in 48 480 4800; do
    for mem in default 128M; do
      rm -rf out_$n
      opt=(); [ "$mem" != default ] && opt=(--memory "$mem")
      /usr/bin/time -v "$XYLEM" sweep "$scene" --frames $n --out out_$n --quiet --threads 2 "${opt[@]}" > log.txt 2>&1
      echo "round $rep, $mem, $n frames: $(grep 'Maximum resident' log.txt | awk '{print $NF}') KiB, $(grep '^rendered' log.txt | sed 's/ into.*//')"
    done
  done
done
rm -rf out_*
