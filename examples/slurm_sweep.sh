#!/usr/bin/env bash
# Spread a flicker sweep over a Slurm job array, then merge the shards.
#
#   sbatch --array=0-15 examples/slurm_sweep.sh models/sweeps/impact_period.json
#   # when every task has finished:
#   flicker merge models/sweeps/impact_period.json out/impact_period.shard-*-of-16.csv --out out/impact_period.csv
#
# Each array task runs every 16th point (shard I/16) on the cores Slurm gave
# it; the merged file is byte for byte the CSV a single run writes.
#SBATCH --job-name=flicker-sweep
#SBATCH --cpus-per-task=2
#SBATCH --time=01:00:00
set -euo pipefail
sweep=${1:?usage: sbatch --array=0-N examples/slurm_sweep.sh SWEEP.json}
shards=$(( ${SLURM_ARRAY_TASK_MAX:?run as a Slurm job array} + 1 ))
stem=$(basename "$sweep" .json)
flicker sweep "$sweep" \
  --shard "${SLURM_ARRAY_TASK_ID}/${shards}" \
  --threads "${SLURM_CPUS_PER_TASK:-1}" \
  --out "out/${stem}.shard-${SLURM_ARRAY_TASK_ID}-of-${shards}.csv"
