#!/bin/bash
# docs/slurm_array.sh as Slurm would run it: three array tasks (ids 4..6, so the shard number is
# the task's place in the array), each with the variables Slurm sets, and a stand-in `sbatch` on
# PATH that records the merge job task 0 submits; that job's command then runs. The merged .glb
# and the PLY frames must be the one-process run's bytes.
# Usage: slurm_array_test.sh APPARENT SOURCE_DIR
set -u
apparent=$1
cd "$2"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
mkdir -p "$work/bin"
cat > "$work/bin/sbatch" <<'STUB'
#!/bin/bash
# Records the submission; runs nothing (the test runs the --wrap command itself).
printf '%s\n' "$@" > "$SBATCH_RECORD"
STUB
chmod +x "$work/bin/sbatch"
export PATH="$work/bin:$PATH" SBATCH_RECORD="$work/submitted" APPARENT="$apparent"
options=(--format glb,ply --frames 0:40)
"$apparent" render data/scenes/flanges.json --out "$work/one" --quiet "${options[@]}" || { echo "FAIL: one process"; exit 1; }
for task in 4 5 6; do
    SLURM_ARRAY_TASK_ID=$task SLURM_ARRAY_TASK_MIN=4 SLURM_ARRAY_TASK_COUNT=3 SLURM_ARRAY_JOB_ID=777 \
        SLURM_CPUS_PER_TASK=1 bash docs/slurm_array.sh data/scenes/flanges.json "$work/array" "${options[@]}" ||
        { echo "FAIL: task $task"; exit 1; }
done
grep -qx -- '--dependency=afterok:777' "$work/submitted" || { echo "FAIL: merge not submitted after the array"; cat "$work/submitted"; exit 1; }
wrap=$(sed -n 's/^--wrap=//p' "$work/submitted")
[ -n "$wrap" ] || { echo "FAIL: no --wrap command"; exit 1; }
bash -c "$wrap" || { echo "FAIL: the merge job: $wrap"; exit 1; }
diff -r -x shards "$work/one" "$work/array" || { echo "FAIL: outputs differ from one process"; exit 1; }
echo "slurm_array_test: the array's merged outputs are the one-process bytes"
