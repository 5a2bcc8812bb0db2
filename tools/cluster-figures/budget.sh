#!/usr/bin/env bash
# Render time of a 480-frame 256x256 sweep against --memory (batch size), 1 and 8 spp.
set -eu
. "$(dirname "$0")/common.sh"
cd "$WORK"
for spp in 1 8; do
  scene=$(board256 $spp)
  for mem in 24M 64M 128M 256M 512M 1G; do
    rm -rf tb
    /usr/bin/time -f "%M KiB %e s" "$XYLEM" sweep "$scene" --frames 480 --out tb --quiet --threads 2 --memory $mem > log.txt 2>&1
    echo "spp $spp --memory $mem: $(grep '^rendered' log.txt | sed 's/ into.*//') | $(tail -1 log.txt)"
  done
done
rm -rf tb
