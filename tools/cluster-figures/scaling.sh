#!/usr/bin/env bash
# Frames per second of a 96-frame 256x256 16-spp sweep against Slurm slices on the local cluster
# (tools/slurm-local/start.sh first), and a single process for comparison.
set -eu
. "$(dirname "$0")/common.sh"
scene=$(board256 16)
SUBMIT=$ROOT/tools/slurm-local/submit.sh
cd "$WORK"
wait_job() {
  while :; do
    s=$(scontrol show job -o "$1" | grep -o 'JobState=[A-Z]*' | cut -d= -f2)
    case $s in
      COMPLETED) return 0 ;;
      PENDING | RUNNING | CONFIGURING | COMPLETING) sleep 0.2 ;;
      *) echo "job $1 ended $s" >&2; return 1 ;;
    esac
  done
}
rm -rf sc_single; t0=$(date +%s.%N)
"$XYLEM" sweep "$scene" --frames 96 --out sc_single --quiet --threads 2 >/dev/null
echo "one process, 2 threads: $(echo "$(date +%s.%N) - $t0" | bc) s"
for cfg in "1 2" "2 1" "4 1" "8 1"; do
  set -- $cfg
  rm -rf sc_out logs; t0=$(date +%s.%N)
  ids=$(XYLEM=$XYLEM SCENE=$scene FRAMES=96 OUT=sc_out TASKS=$1 CPUS=$2 "$SUBMIT")
  wait_job "${ids#* }"
  t=$(echo "$(date +%s.%N) - $t0" | bc)
  same=yes; for f in sc_single/*; do cmp -s "$f" "sc_out/${f#sc_single/}" || same=no; done
  echo "Slurm, $1 tasks x $2 CPUs: $t s, files identical to one process: $same"
done
