#!/usr/bin/env bash
# Submits a light sweep to Slurm: a job array of frame slices (sweep_array.sbatch), then an
# assembly job that runs only once every slice succeeded (--dependency=afterok; it is cancelled
# if one fails). Prints the two job ids. Run it from the folder the paths are relative to.
# Settings (defaults: the README's 48-frame board in 8 slices of 8 CPUs): XYLEM, SCENE,
# FRAMES, OUT, TASKS, CPUS.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
export XYLEM=${XYLEM:-target/release/xylem}
export SCENE=${SCENE:-scenes/sweep_board.toml}
export FRAMES=${FRAMES:-48}
export OUT=${OUT:-out/sweep_board}
TASKS=${TASKS:-8}
CPUS=${CPUS:-8}
export PER_TASK=$(( (FRAMES + TASKS - 1) / TASKS ))
TASKS=$(( (FRAMES + PER_TASK - 1) / PER_TASK ))
mkdir -p logs
ARRAY=$(sbatch --parsable --array=0-$(( TASKS - 1 )) --cpus-per-task="$CPUS" \
  --export=ALL "$here/sweep_array.sbatch")
ASSEMBLE=$(sbatch --parsable --dependency=afterok:"$ARRAY" --kill-on-invalid-dep=yes \
  --job-name=xylem-assemble --output=logs/assemble_%j.out --export=ALL \
  --wrap='"$XYLEM" sweep --assemble "$OUT"')
echo "$ARRAY $ASSEMBLE"
