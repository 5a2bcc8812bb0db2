#!/usr/bin/env bash
# Kept against recomputed primary samples: render time of a 480-frame 256x256 sweep in batches
# of the same size either way (the kept samples' memory, 736 bytes a pixel sample, added to the
# budget of `keep`), and in one batch, at 1 and 8 spp, interleaved (REPS rounds, default 2).
# Run from the repository root after cargo build --release.
set -eu
. "$(dirname "$0")/common.sh"
cd "$WORK"
kept() { echo $(( 64 + 46 * $1 ))M; } # --memory 64M plus Primaries::bytes(256, 256, spp)
for rep in $(seq "${REPS:-2}"); do
  for spp in 1 8; do
    scene=$(board256 "$spp")
    for run in "one 2G auto" "recompute 64M recompute" "keep $(kept "$spp") keep"; do
      set -- $run
      rm -rf tp
      "$XYLEM" sweep "$scene" --frames 480 --out tp --quiet --threads 2 --memory "$2" --primaries "$3" > log.txt 2>&1
      echo "round $rep, spp $spp, $1 (--memory $2): $(grep '^rendered' log.txt | sed -e 's/.* in //' -e 's/ into.*//')"
    done
  done
done
rm -rf tp
