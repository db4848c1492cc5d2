#!/bin/bash
# Fogs a long shot on a Slurm cluster: one array task per chunk of CHUNK frames, each task a plain
# `fogcl apply --frames A-B` on the cores Slurm gave it. fogcl schedules nothing itself: retries,
# priorities and node choice stay the farm's. Outputs are written atomically (a killed or
# pre-empted task leaves complete frames only; its stale temporaries on a file system without
# O_TMPFILE, e.g. NFS, are swept by the task that reruns the chunk), so a failed task is just rerun.
#
# The shot is described by environment variables (sbatch passes the submitter's environment on):
#   FIRST, LAST     the shot's first and last frame numbers                              (required)
#   COLOR           the renderer's frames, e.g. 'render/shot.####.exr'                   (required)
#   OUT             where the fogged frames go, e.g. 'fogged/shot.####.exr'; its folder
#                   is created                                                           (required)
#   NEAR, MODE      camera near plane [world units]; fog mode exp, exp2, linear or off   (required)
#   FAR             camera far plane [world units] (required unless FOGCL_ARGS has --infinite-far)
#   CHUNK           frames per array task (default 50)
#   DEPTH           depth frames, e.g. 'render/depth.####.exr' (default: the color file's depth channel)
#   DEPTH_CHANNEL, DEPTH_KIND   the depth channel's name (Z) and kind: raw, eye or distance (raw)
#   DENSITY, FOG_COLOR, START, END   exp/exp2 density [1/world unit], fog color 'R,G,B', linear
#                   fog start and end [world units] (fogcl's defaults where unset)
#   PIXEL_TYPE, COMPRESSION   output half or float, and its OpenEXR compression (fogcl's defaults:
#                   float, the input's compression)
#   DEVICE          cpu, gpu, scalar or part of an OpenCL device name. Default: FOGCL_DEVICE if set,
#                   else PoCL's CPU device (the fastest device of a CPU farm node; fogcl picks PoCL
#                   among CPU drivers) where an OpenCL platform is registered, else the scalar C++
#                   path, which the task log then says. GPU nodes: DEVICE=gpu
#   FOGCL           the fogcl binary (default: fogcl from PATH)
#   FOGCL_ARGS      further `fogcl apply` flags, split on blanks, e.g. '--fov 40 --reversed-z'
#
#   export FIRST=1001 LAST=2000 CHUNK=50 COLOR='render/shot.####.exr' OUT='fogged/shot.####.exr' \
#          DEPTH_KIND=eye NEAR=0.1 FAR=2000 MODE=exp2 DENSITY=0.004 FOG_COLOR=0.6,0.7,0.8
#   sbatch --array=0-19 examples/slurm_fog_shot.sh
#   (array size = ceil((LAST - FIRST + 1) / CHUNK); resubmit failed indices with --array=3,7; the
#   #SBATCH lines below are defaults that sbatch's own flags override, e.g. --cpus-per-task=4)
#
# Other farm schedulers run the same command: the chunk's first and last frame go to --frames and
# the cores the scheduler reserved to --threads; everything else is the shot's and the same for
# every chunk.
#   OpenCue: a layer with range FIRST-LAST and chunk size CHUNK whose command is
#     fogcl apply --frames #FRAME_START#-#FRAME_END# --threads $CUE_THREADS <the shot's flags>
#     (RQD sets CUE_THREADS to the cores booked for the frame; cuebots before the 2023 fix of
#     #FRAME_END# give the last, shorter chunk an end past LAST, which fogcl reports as missing
#     input frames: there, clamp it to LAST as this script does).
#   Deadline: a command line job, Frames=FIRST-LAST and ChunkSize=CHUNK, executable fogcl and
#     arguments 'apply --frames <STARTFRAME>-<ENDFRAME> <the shot's flags>' (deadlinecommand
#     -SubmitCommandLineJob -executable fogcl -arguments '...' -frames FIRST-LAST -chunksize CHUNK);
#     leave --threads out: fogcl's default is every core of its CPU affinity, which the Worker's
#     affinity settings restrict.
#SBATCH --job-name=fogcl-shot
#SBATCH --cpus-per-task=16
#SBATCH --mem=8G
#SBATCH --time=01:00:00
#SBATCH --output=fogcl-%A_%a.log
set -euo pipefail
: "${FIRST:?set FIRST, the first frame of the shot}" "${LAST:?set LAST, the last frame of the shot}"
: "${COLOR:?set COLOR, the input frames (e.g. render/shot.####.exr)}"
: "${OUT:?set OUT, the output frames (e.g. fogged/shot.####.exr)}"
: "${NEAR:?set NEAR, the camera near plane}" "${MODE:?set MODE, the fog mode (exp, exp2, linear or off)}"
: "${SLURM_ARRAY_TASK_ID:?run as a Slurm array job: sbatch --array=0-N examples/slurm_fog_shot.sh}"
CHUNK=${CHUNK:-50}
FOGCL=${FOGCL:-fogcl}
first=$((FIRST + SLURM_ARRAY_TASK_ID * CHUNK))
last=$((first + CHUNK - 1))
[ "$last" -gt "$LAST" ] && last=$LAST
task="fogcl-shot: task ${SLURM_ARRAY_JOB_ID:-?}_$SLURM_ARRAY_TASK_ID on ${SLURMD_NODENAME:-$(hostname)}"
if [ "$first" -gt "$LAST" ]; then  # an array larger than the shot
  echo "$task: no frames (the shot ends at $LAST)"
  exit 0
fi

# The device: the submitter's choice, else PoCL's CPU device where the OpenCL ICD loader has a
# platform to load (OCL_ICD_FILENAMES, or an .icd file in OCL_ICD_VENDORS or /etc/OpenCL/vendors),
# else the scalar path.
device=${DEVICE:-${FOGCL_DEVICE:-}}
if [ -z "$device" ]; then
  vendors=${OCL_ICD_VENDORS:-/etc/OpenCL/vendors}
  if [ -n "${OCL_ICD_FILENAMES:-}" ] || [ -f "$vendors" ] || compgen -G "$vendors/*.icd" > /dev/null; then
    device=cpu
  else
    device=scalar
    echo "$task: no OpenCL platform on this node (no ICD in $vendors): fogging on the scalar C++ path" \
         "(one thread per frame; install pocl-opencl-icd for the node's every core)"
  fi
fi
threads=${SLURM_CPUS_PER_TASK:-1}

args=(apply --frames "$first-$last" --threads "$threads" --device "$device" --verbose
      --color "$COLOR" --out "$OUT" --near "$NEAR" --mode "$MODE")
[ -n "${FAR:-}" ] && args+=(--far "$FAR")
[ -n "${DEPTH:-}" ] && args+=(--depth "$DEPTH")
[ -n "${DEPTH_CHANNEL:-}" ] && args+=(--depth-channel "$DEPTH_CHANNEL")
[ -n "${DEPTH_KIND:-}" ] && args+=(--depth-kind "$DEPTH_KIND")
[ -n "${DENSITY:-}" ] && args+=(--density "$DENSITY")
[ -n "${FOG_COLOR:-}" ] && args+=(--fog-color "$FOG_COLOR")
[ -n "${START:-}" ] && args+=(--start "$START")
[ -n "${END:-}" ] && args+=(--end "$END")
[ -n "${PIXEL_TYPE:-}" ] && args+=(--pixel-type "$PIXEL_TYPE")
[ -n "${COMPRESSION:-}" ] && args+=(--compression "$COMPRESSION")
read -r -a extra <<< "${FOGCL_ARGS:-}"  # split on blanks, no globbing
args+=("${extra[@]}")

mkdir -p "$(dirname "$OUT")"
echo "$task: frames $first-$last of $FIRST-$LAST, device $device, $threads thread(s)"
# --threads: the cores of this task, not of the node (fogcl's default, the affinity mask, is the
# same where Slurm binds tasks to cores). exec: a signal to the task (scancel) reaches fogcl.
exec "$FOGCL" "${args[@]}"
