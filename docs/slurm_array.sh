#!/bin/bash
# Render a long sequence as a Slurm job array, then merge the .glb (docs/DISTRIBUTED.md "Frames across
# processes"). Each array task renders one shard of the frames (frames k with k - first = I mod N);
# PLY/OBJ frames go straight to OUT/<model>/, the .glb's frames into OUT/shards/. A second job,
# started only when every task succeeded, assembles OUT/<model>.glb, byte-identical to one process.
#
#   sbatch --array=0-15 docs/slurm_array.sh SCENE OUT [render options...]
#   (this script submits the merge job itself, with --dependency=afterok on the array)
#
# Every task must see the same scene, meshes and options (merge checks a fingerprint of them) and
# write to the same OUT on a shared file system. Set APPARENT to the binary (default: build/apparent).
#SBATCH --job-name=apparent-shard
#SBATCH --cpus-per-task=4
#SBATCH --output=apparent-%A_%a.log
set -euo pipefail

scene=$1
out=$2
shift 2
apparent=${APPARENT:-build/apparent}
shards=${SLURM_ARRAY_TASK_COUNT:?run with sbatch --array=0-(N-1)}
task=$SLURM_ARRAY_TASK_ID
# Array ids may start above 0 (--array=1-16): the shard number is the task's place in the array.
part=$((task - ${SLURM_ARRAY_TASK_MIN:-0}))

"$apparent" render "$scene" --out "$out" --shard "$part/$shards" --threads "${SLURM_CPUS_PER_TASK:-0}" --quiet "$@"

# The first task submits the merge, to run after every task of the array has succeeded.
if [ "$part" -eq 0 ]; then
    sbatch --dependency="afterok:${SLURM_ARRAY_JOB_ID}" --job-name=apparent-merge \
        --output="apparent-merge-%j.log" --wrap="$(printf '%q merge %q' "$apparent" "$out")"
fi
