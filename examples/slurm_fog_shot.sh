#!/bin/bash
# Fogs a long shot on a Slurm cluster: one array task per chunk of CHUNK frames, each task a plain
# `fogcl apply --frames FIRST-LAST` on the cores Slurm gave it. fogcl schedules nothing itself:
# retries, priorities and node choice stay the farm's. Outputs are written atomically (a killed or
# pre-empted task leaves complete frames only; its stale temporaries on a file system without
# O_TMPFILE, e.g. NFS, are swept by the task that reruns the chunk), so a failed task is just rerun.
#
#   FIRST=1001 LAST=2000 CHUNK=50 sbatch --array=0-19 examples/slurm_fog_shot.sh
#   (array size = ceil((LAST - FIRST + 1) / CHUNK); resubmit failed indices with --array=3,7)
#SBATCH --job-name=fogcl-shot
#SBATCH --cpus-per-task=16
#SBATCH --mem=8G
#SBATCH --time=01:00:00
#SBATCH --output=fogcl-%A_%a.log
set -euo pipefail
: "${FIRST:?set FIRST, the first frame of the shot}" "${LAST:?set LAST, the last frame of the shot}"
CHUNK=${CHUNK:-50}
first=$((FIRST + SLURM_ARRAY_TASK_ID * CHUNK))
last=$((first + CHUNK - 1))
[ "$last" -gt "$LAST" ] && last=$LAST
[ "$first" -gt "$LAST" ] && exit 0   # an array larger than the shot
# --threads: the cores of this task, not of the node (fogcl's default, the affinity mask, is the
# same where Slurm binds tasks to cores).
exec fogcl apply --frames "$first-$last" --threads "${SLURM_CPUS_PER_TASK:-1}" \
  --color 'render/shot.####.exr' --depth-channel Z --depth-kind eye \
  --out 'fogged/shot.####.exr' --pixel-type half --compression dwaa \
  --near 0.1 --far 2000 --mode exp2 --density 0.004 --fog-color 0.6,0.7,0.8 --device scalar
