#!/usr/bin/env bash
# examples/slurm_fog_shot.sh against a live single-host Slurm (Debian's slurm-wlm + munge):
#   1. installs slurm-wlm and munge where missing (apt), writes a cluster of this one host (its
#      name, cores and memory from `slurmd -C`) into a scratch folder, starts munged, slurmctld and
#      slurmd as local processes on ports of their own, and waits until sinfo shows the node idle;
#   2. generates a 12-frame sequence of the demo scene (color + depth), submits the example as a
#      user would (FIRST/LAST/CHUNK giving a 3-task array), waits through squeue, and compares every
#      output frame byte for byte with one local `fogcl apply` over the whole range; each task's
#      log must name its frame range;
#   3. submits the shot again with one task's fogcl SIGKILLed mid-run (its chunk's third input
#      frame's open() is held by a preloaded gate, so the task stops there after writing two frames), resubmits
#      only that index, and checks the shot complete, byte-identical and free of temporaries.
# The daemons are stopped by their process ids and the scratch removed on every exit.
#
#   tests/slurm/run_slurm_test.sh FOGCL MAKE_SEQUENCE EXAMPLE
#
# Root only (slurmd runs jobs as their users and SlurmUser is root here; apt installs): as another
# user the test is skipped (exit 77) unless FOGCL_SLURM_TEST=required, as in .ci/run, which makes
# it fail instead. FOGCL_SLURM_TEST=skip skips it; FOGCL_SLURM_KEEP=1 keeps the scratch folder.
set -euo pipefail
# The example's device choice is the test's to make.
unset DEVICE FOGCL_DEVICE FOGCL_TEMP_FILES FOGCL_TIERING

[ "${FOGCL_SLURM_TEST:-}" = skip ] && { echo "slurm test: SKIP: FOGCL_SLURM_TEST=skip"; exit 77; }
if [ $# -ne 3 ]; then
  echo "usage: $0 FOGCL MAKE_SEQUENCE EXAMPLE" >&2
  exit 2
fi
fogcl=$(readlink -f "$1")
make_sequence=$(readlink -f "$2")
example=$(readlink -f "$3")
started=$SECONDS
TEST_NAME="slurm test" TEST_GATE=FOGCL_SLURM_TEST
here=$(cd "$(dirname "$0")" && pwd)
# shellcheck source=tests/support/script_test.sh
. "$here/../support/script_test.sh"

[ "$(id -u)" -eq 0 ] || skip_or_fail "needs root (runs slurmd with SlurmUser root, installs slurm-wlm and munge)"

# ---- 1. Slurm and munge, installed where missing -------------------------------------------------
commands=(munged slurmctld slurmd sbatch squeue sinfo scontrol scancel)
missing() {
  local c
  for c in "${commands[@]}"; do command -v "$c" > /dev/null || return 0; done
  return 1
}
if missing; then
  command -v apt-get > /dev/null || fail "slurm-wlm and munge are not installed and apt-get is missing: install them"
  apt_update_if_needed fail slurm-wlm munge
  # The packages' own services stay down: the test runs its own daemons. Debian's policy-rc.d
  # (exit 101: "action forbidden") is honoured by invoke-rc.d and deb-systemd-invoke alike.
  policy=/usr/sbin/policy-rc.d
  own_policy=0
  if [ ! -e "$policy" ]; then
    trap 'rm -f "$policy"' EXIT  # never left behind, even if the install is interrupted
    printf '#!/bin/sh\nexit 101\n' > "$policy"
    chmod 755 "$policy"
    own_policy=1
  fi
  install_ok=1
  apt_install slurm-wlm munge || install_ok=0
  if [ "$own_policy" -eq 1 ]; then
    rm -f "$policy"
    trap - EXIT
  fi
  [ "$install_ok" -eq 1 ] || fail "apt-get install slurm-wlm munge failed"
  missing && fail "still missing after the install: one of ${commands[*]}"
fi

# ---- Scratch folder, daemons, cleanup -------------------------------------------------------------
# Under /tmp, not the build folder: munged's socket path must stay short (108 bytes) and every
# folder above it searchable by all.
scratch=$(mktemp -d /tmp/fogcl-slurm.XXXXXX)
chmod 755 "$scratch"
daemon_pids=()
export SLURM_CONF=$scratch/slurm.conf

cleanup() {
  local rc=$? pid i
  trap - EXIT INT TERM
  if [ -f "$SLURM_CONF" ] && [ ${#daemon_pids[@]} -gt 0 ]; then
    # Jobs still queued or running (a failure midway) are cancelled through Slurm first.
    if [ -n "$(squeue -h -o %i 2> /dev/null)" ]; then
      scancel --full --signal=KILL --user=root 2> /dev/null || true
      for i in $(seq 50); do
        [ -z "$(squeue -h -o %i 2> /dev/null)" ] && break
        sleep 0.2
      done
    fi
  fi
  if [ "$rc" -ne 0 ] && [ "$rc" -ne 77 ]; then
    for f in "$scratch"/slurmctld.log "$scratch"/slurmd.log "$scratch"/munged.log; do
      [ -f "$f" ] && { echo "---- last lines of $f"; tail -n 15 "$f"; }
    done
  fi
  # Stopped by the ids they were started with, newest first.
  for ((i = ${#daemon_pids[@]} - 1; i >= 0; i--)); do
    pid=${daemon_pids[i]}
    kill -TERM "$pid" 2> /dev/null || continue
    for _ in $(seq 50); do kill -0 "$pid" 2> /dev/null || break; sleep 0.1; done
    kill -KILL "$pid" 2> /dev/null || true
    wait "$pid" 2> /dev/null || true
  done
  if [ "${FOGCL_SLURM_KEEP:-0}" = 1 ]; then
    echo "slurm test: scratch kept in $scratch"
  else
    rm -rf "$scratch"
  fi
  echo "slurm test: $((SECONDS - started)) s in all"
  exit "$rc"
}
trap cleanup EXIT
trap 'exit 130' INT
trap 'exit 143' TERM

# Two free TCP ports in 26000-29999 (well away from Slurm's 6817/6818), so that a real Slurm on
# this machine and a second copy of this test do not collide.
port_free() {
  local hex
  hex=$(printf '%04X' "$1")
  ! cat /proc/net/tcp /proc/net/tcp6 2> /dev/null | awk '{print $2}' | grep -qi ":$hex\$"
}
ctld_port=
for _ in $(seq 100); do
  p=$((26000 + RANDOM % 4000))
  if port_free "$p" && port_free $((p + 1)); then ctld_port=$p; break; fi
done
[ -n "$ctld_port" ] || fail "no two free TCP ports found in 26000-29999"
slurmd_port=$((ctld_port + 1))

# munge: a key of our own, its socket in the scratch folder (the system's munged, if any, is not ours).
mkdir -m 700 "$scratch/munge"
mkdir -m 755 "$scratch/run"
head -c 1024 /dev/urandom > "$scratch/munge/munge.key"
chmod 400 "$scratch/munge/munge.key"
munge_socket=$scratch/run/munge.socket
munged --foreground --force --socket="$munge_socket" --key-file="$scratch/munge/munge.key" \
  --log-file="$scratch/munged.log" --pid-file="$scratch/run/munged.pid" --seed-file="$scratch/munge/munged.seed" \
  > /dev/null 2>&1 &
daemon_pids+=($!)
for _ in $(seq 50); do [ -S "$munge_socket" ] && break; sleep 0.1; done
[ -S "$munge_socket" ] || fail "munged did not create its socket $munge_socket"

# The cluster: this host, with the cores and memory slurmd finds. No cgroup plugins (they need
# systemd or a delegated cgroup tree): processes tracked through /proc, tasks not bound.
node_line=$(slurmd -C | head -n 1)
node=$(sed -n 's/^NodeName=\([^ ]*\).*/\1/p' <<< "$node_line")
cpus=$(sed -n 's/.* CPUs=\([0-9]*\).*/\1/p' <<< "$node_line")
if [ -z "$node" ] || [ -z "$cpus" ]; then fail "cannot read this host from 'slurmd -C': $node_line"; fi
mkdir -p "$scratch/state" "$scratch/spool"
cat > "$SLURM_CONF" << EOF
ClusterName=fogcltest
SlurmctldHost=$node(127.0.0.1)
SlurmctldPort=$ctld_port
SlurmdPort=$slurmd_port
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
AuthInfo=socket=$munge_socket
CredType=cred/munge
StateSaveLocation=$scratch/state
SlurmdSpoolDir=$scratch/spool
SlurmctldPidFile=$scratch/run/slurmctld.pid
SlurmdPidFile=$scratch/run/slurmd.pid
SlurmctldLogFile=$scratch/slurmctld.log
SlurmdLogFile=$scratch/slurmd.log
SlurmctldDebug=info
SlurmdDebug=info
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/none
MpiDefault=none
SwitchType=switch/none
SchedulerType=sched/builtin
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
ReturnToService=2
KillWait=2
MailProg=/bin/true
MinJobAge=600
$node_line NodeAddr=127.0.0.1 State=UNKNOWN
PartitionName=fogcl Nodes=$node Default=YES MaxTime=INFINITE State=UP
EOF
slurmctld -D -i -f "$SLURM_CONF" > "$scratch/slurmctld.out" 2>&1 &
daemon_pids+=($!)
slurmd -D -f "$SLURM_CONF" -N "$node" > "$scratch/slurmd.out" 2>&1 &
daemon_pids+=($!)
state=
for _ in $(seq 150); do
  state=$(sinfo -h -n "$node" -o %t 2> /dev/null || true)
  [ "$state" = idle ] && break
  for pid in "${daemon_pids[@]}"; do
    kill -0 "$pid" 2> /dev/null || { cat "$scratch"/slurm*.out >&2; fail "a daemon (pid $pid) exited"; }
  done
  sleep 0.2
done
[ "$state" = idle ] || fail "node $node not idle after 30 s (sinfo: '$state')"
say "$(sinfo --version), $(munged --version 2>&1 | head -n 1)"
say "node $node idle: $cpus CPUs, slurmctld port $ctld_port, slurmd port $slurmd_port ($((SECONDS - started)) s)"

# ---- 2. The shot through Slurm, compared with one local run ---------------------------------------
shot=$scratch/shot
mkdir -p "$shot/render"
frames=12
chunk=5
tasks=$(((frames + chunk - 1) / chunk))  # 3: frames 1-5, 6-10, 11-12
"$make_sequence" "$shot/render" 160 90 "$frames" half zip > /dev/null
cd "$shot"
# The shot as its user describes it (examples/slurm_fog_shot.sh's variables). make_sequence writes
# raw depth of a 60-degree camera with near 0.3 and far 1000.
export FIRST=1 LAST=$frames CHUNK=$chunk COLOR='render/color.####.exr' DEPTH='render/depth.####.exr'
export OUT='fogged/shot.####.exr' NEAR=0.3 FAR=1000 MODE=exp2 DENSITY=0.02 FOG_COLOR=0.6,0.7,0.8
export PIXEL_TYPE=half COMPRESSION=zip FOGCL_ARGS='--fov 60' FOGCL=$fogcl
reference_args=(apply --frames "$FIRST-$LAST" --color "$COLOR" --depth "$DEPTH" --out 'reference/shot.####.exr'
                --near "$NEAR" --far "$FAR" --mode "$MODE" --density "$DENSITY" --fog-color "$FOG_COLOR"
                --pixel-type "$PIXEL_TYPE" --compression "$COMPRESSION" --fov 60)
mkdir reference
"$fogcl" "${reference_args[@]}" || fail "the local reference run failed"

# Submits the example (extra sbatch flags in $@); prints the job id. One core and little memory a
# task: the example's #SBATCH defaults are a farm's, overridden here as a user would.
submit() {
  sbatch --parsable --cpus-per-task=1 --mem=256M --time=5 "$@" "$example" | cut -d';' -f1
}
# Waits until the job has left the queue (90 s at most).
wait_job() {
  local job=$1
  for _ in $(seq 450); do
    [ -z "$(squeue -h -j "$job" -o %i 2> /dev/null)" ] && return 0
    sleep 0.2
  done
  squeue -j "$job" >&2 || true
  fail "job $job still queued or running after 90 s"
}
# "TASK STATE EXITCODE" per array task of a finished job.
task_states() {
  scontrol -o show job "$1" | sed -n 's/.*ArrayTaskId=\([0-9]*\) .*JobState=\([A-Z_]*\) .*ExitCode=\([0-9:]*\).*/\1 \2 \3/p' |
    sort -n
}
# Every frame of the shot in $1 byte for byte the reference's.
compare_shot() {
  local dir=$1 f same=0 name
  for f in $(seq "$FIRST" "$LAST"); do
    name=$(printf 'shot.%04d.exr' "$f")
    [ -f "$dir/$name" ] || fail "$dir/$name is missing"
    cmp -s "$dir/$name" "reference/$name" || fail "$dir/$name differs from the local run's: $(cmp "$dir/$name" "reference/$name")"
    same=$((same + 1))
  done
  say "$dir: all $same frames byte-identical to one local fogcl apply over $FIRST-$LAST"
}
# The log of task $2 of job $1 names its frame range and fogcl's count of frames fogged.
check_log() {
  local job=$1 task=$2 first last log
  first=$((FIRST + task * CHUNK))
  last=$((first + CHUNK - 1))
  [ "$last" -gt "$LAST" ] && last=$LAST
  log=fogcl-${job}_$task.log
  [ -f "$log" ] || fail "no task log $log"
  grep -q "frames $first-$last of $FIRST-$LAST" "$log" || { cat "$log"; fail "$log does not name frames $first-$last"; }
  grep -q "fogged $((last - first + 1)) frames" "$log" || { cat "$log"; fail "$log: fogcl did not fog $((last - first + 1)) frames"; }
}

# The tasks fog on PoCL's CPU device from their first frame (FOGCL_TIERING=off), the reference
# run on whatever its tiering picks (for frames this small, the scalar path): a chunk rerun on
# another node, or tiered differently, must give the same bits.
export FOGCL_TIERING=off
job=$(submit --array=0-$((tasks - 1)))
unset FOGCL_TIERING
say "submitted job $job: FIRST=$FIRST LAST=$LAST CHUNK=$CHUNK sbatch --array=0-$((tasks - 1)) $(basename "$example")"
wait_job "$job"
states=$(task_states "$job")
echo "$states" | sed 's/^/  task /'
[ "$(grep -c ' COMPLETED 0:0$' <<< "$states")" -eq "$tasks" ] || fail "not all $tasks tasks of job $job completed"
for t in $(seq 0 $((tasks - 1))); do check_log "$job" "$t"; done
grep -q '^device: .*Portable Computing Language' "fogcl-${job}_0.log" ||
  { cat "fogcl-${job}_0.log"; fail "task 0 did not fog on PoCL's CPU device (the example's default)"; }
compare_shot fogged
say "task log fogcl-${job}_1.log:"
sed 's/^/  | /' "fogcl-${job}_1.log"

# A node without an OpenCL platform (an ICD folder with no driver): the example falls back to the
# scalar path and says so; same bits. Task 3 is past the shot's end: nothing to do, success.
mkdir no-opencl
job=$(OCL_ICD_VENDORS=$shot/no-opencl OUT='scalar/shot.####.exr' submit --array=2-3)
wait_job "$job"
states=$(task_states "$job")
[ "$states" = $'2 COMPLETED 0:0\n3 COMPLETED 0:0' ] || { echo "$states"; fail "job $job (no OpenCL platform) did not complete"; }
check_log "$job" 2
if ! grep -q 'no OpenCL platform on this node .*scalar C++ path' "fogcl-${job}_2.log" ||
   ! grep -q '^device: scalar' "fogcl-${job}_2.log"; then
  cat "fogcl-${job}_2.log"
  fail "task 2 without OpenCL: the scalar fallback not taken or not said"
fi
grep -q 'no frames (the shot ends at' "fogcl-${job}_3.log" || { cat "fogcl-${job}_3.log"; fail "task 3 past the shot's end"; }
for f in $((LAST - 1)) "$LAST"; do
  name=$(printf 'shot.%04d.exr' "$f")
  cmp -s "scalar/$name" "reference/$name" || fail "scalar/$name differs from the local run's"
done
say "no OpenCL platform (job $job): task 2 on the scalar path, said in its log, frames byte-identical; task 3 past the end: no frames"

# ---- 3. A task that dies mid-run, then only its index again --------------------------------------
# The same shot into a fresh folder, read through links; task 1's third frame is held: its fogcl
# has tests/support/call_gate.c preloaded, whose open() of that file never returns, so the task
# stops there after two frames, deterministically (a FIFO cannot gate it: fogcl refuses one before
# any frame).
mkdir gated
for f in render/*.exr; do ln -s "../$f" "gated/$(basename "$f")"; done
gate=gated/color.$(printf '%04d' $((FIRST + CHUNK + 2))).exr
cc -shared -fPIC -O1 -Wall -Werror -o "$PWD/call_gate.so" "$here/../support/call_gate.c" -ldl || fail "cannot build the call gate (cc)"
export COLOR='gated/color.####.exr' DEPTH='gated/depth.####.exr' OUT='killed/shot.####.exr'
# Named temporaries, as on NFS, where a killed writer can leave one behind (O_TMPFILE cannot).
export FOGCL_TEMP_FILES=named
job=$(LD_PRELOAD="$PWD/call_gate.so" FOGCL_GATE_SUFFIX="$gate" submit --array=0-$((tasks - 1)))
say "submitted job $job into killed/ with task 1 held at $gate"
victim_first=$((FIRST + CHUNK))
written=("killed/$(printf 'shot.%04d.exr' "$victim_first")" "killed/$(printf 'shot.%04d.exr' $((victim_first + 1)))")
victim=
for _ in $(seq 300); do
  if [ -f "${written[0]}" ] && [ -f "${written[1]}" ] && [ -z "$victim" ]; then
    # Task 1's fogcl (the batch script exec's it): the fogcl process whose environment says so.
    task1=$(scontrol -o show job "$job" | sed -n 's/^JobId=\([0-9]*\) .*ArrayTaskId=1 .*/\1/p')
    for d in /proc/[0-9]*; do
      [ "$(cat "$d/comm" 2> /dev/null)" = fogcl ] || continue
      tr '\0' '\n' < "$d/environ" 2> /dev/null | grep -qx "SLURM_JOB_ID=$task1" && victim=${d#/proc/} && break
    done
  fi
  [ -n "$victim" ] && break
  sleep 0.2
done
[ -n "$victim" ] || { squeue; fail "task 1 of job $job did not reach its gate (two frames written) in 60 s"; }
kill -KILL "$victim"
say "task 1 (job $task1): fogcl pid $victim sent SIGKILL after writing ${written[*]}"
wait_job "$job"
states=$(task_states "$job")
echo "$states" | sed 's/^/  task /'
grep -q '^1 COMPLETED' <<< "$states" && fail "task 1 completed although its fogcl was killed"
[ "$(grep -c ' COMPLETED 0:0$' <<< "$states")" -eq $((tasks - 1)) ] || fail "the other tasks of job $job did not complete"
present=$(find killed -name 'shot.[0-9]*.exr' | wc -l)
[ "$present" -eq $((LAST - FIRST + 1 - CHUNK + 2)) ] || fail "killed/ holds $present frames, expected all but task 1's last $((CHUNK - 2))"
say "shot incomplete as expected: $present of $((LAST - FIRST + 1)) frames"
tail -n 3 "fogcl-${job}_1.log" | sed 's/^/  | /'

# The farm's retry, without the gate: only index 1 is resubmitted.
rerun=$(submit --array=1)
say "resubmitted: sbatch --array=1 (job $rerun)"
wait_job "$rerun"
states=$(task_states "$rerun")
echo "$states" | sed 's/^/  task /'
[ "$states" = "1 COMPLETED 0:0" ] || fail "the resubmitted task 1 did not complete"
check_log "$rerun" 1
compare_shot killed
leftovers=$(find killed -name '*.tmp-*' | wc -l)
[ "$leftovers" -eq 0 ] || { find killed -name '*.tmp-*'; fail "$leftovers temporary file(s) left in killed/"; }
say "no temporary file in killed/"
say "PASS ($((SECONDS - started)) s)"
