#!/usr/bin/env bash
# Where fogcl apply loses to OpenEXR alone on the 16-core machine. Run under gpu-run.sh exec.
set -u
bin=$1; out=$2; mkdir -p "$out"; data=$(mktemp -d)
echo "perf: $(which perf 2>&1)"; echo "nproc $(nproc)"; echo "vendors: $OCL_ICD_VENDORS: $(ls $OCL_ICD_VENDORS)"
pocl_only=$(mktemp -d); cp /etc/OpenCL/vendors/*.icd "$pocl_only/"; echo "pocl_only: $(ls $pocl_only)"
FOG="--near 0.3 --far 1000 --fov 60 --mode exp2 --density 0.02"
mkdir -p "$data/tiny"; "$bin/fogcl_make_sequence" "$data/tiny" 64 64 1 half zip >/dev/null &
mkdir -p "$data/4kzip"; "$bin/fogcl_make_sequence" "$data/4kzip" 3840 2160 12 half zip >/dev/null &
mkdir -p "$data/4kpiz"; "$bin/fogcl_make_sequence" "$data/4kpiz" 3840 2160 12 half piz >/dev/null &
mkdir -p "$data/hdzip"; "$bin/fogcl_make_sequence" "$data/hdzip" 1920 1080 24 half zip >/dev/null &
wait
cat > "$data/rus.py" <<'PY'
import resource, subprocess, sys, time
b = resource.getrusage(resource.RUSAGE_CHILDREN); t = time.perf_counter()
r = subprocess.run(sys.argv[2:], stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
w = time.perf_counter() - t; a = resource.getrusage(resource.RUSAGE_CHILDREN)
line = [l for l in r.stderr.splitlines() if l.startswith("stages")]
print(f"{sys.argv[1]:34s} rc {r.returncode} wall {w:6.2f} user {a.ru_utime-b.ru_utime:6.2f} sys {a.ru_stime-b.ru_stime:5.2f} "
      f"minflt {a.ru_minflt-b.ru_minflt:7d} nvcsw {a.ru_nvcsw-b.ru_nvcsw} nivcsw {a.ru_nivcsw-b.ru_nivcsw} {line[0] if line else r.stderr[-200:]}", flush=True)
PY
R() { python3 "$data/rus.py" "$@"; }
echo "== startup (64x64, 1 frame)"
for rep in 1 2 3; do
  R "tiny cpu nvidia+pocl" "$bin/fogcl" apply --color "$data/tiny/color.####.exr" --depth "$data/tiny/depth.####.exr" --out "$data/o.####.exr" $FOG --device cpu
  OCL_ICD_VENDORS=$pocl_only R "tiny cpu pocl-only" "$bin/fogcl" apply --color "$data/tiny/color.####.exr" --depth "$data/tiny/depth.####.exr" --out "$data/o.####.exr" $FOG --device cpu
  R "tiny scalar" "$bin/fogcl" apply --color "$data/tiny/color.####.exr" --depth "$data/tiny/depth.####.exr" --out "$data/o.####.exr" $FOG --device scalar
done
for c in 4kzip 4kpiz hdzip; do for t in 1 16; do
  [ $c = hdzip ] && [ $t = 16 ] && continue
  n=12; [ $c = hdzip ] && n=24
  pin="taskset -c 0-$((t-1))"
  for rep in 1 2; do
    R "$c t$t peer" $pin "$bin/fogcl_exr_peer" "$data/$c/color.%04d.exr" "$data/$c/depth.%04d.exr" "$data/p.%04d.exr" 1 $n $t half input
    R "$c t$t fogcl cpu nvidia+pocl" $pin "$bin/fogcl" apply --color "$data/$c/color.####.exr" --depth "$data/$c/depth.####.exr" --out "$data/f.####.exr" $FOG --threads $t --device cpu --pixel-type half --verbose
    OCL_ICD_VENDORS=$pocl_only R "$c t$t fogcl cpu pocl-only" $pin "$bin/fogcl" apply --color "$data/$c/color.####.exr" --depth "$data/$c/depth.####.exr" --out "$data/f.####.exr" $FOG --threads $t --device cpu --pixel-type half --verbose
    R "$c t$t fogcl scalar" $pin "$bin/fogcl" apply --color "$data/$c/color.####.exr" --depth "$data/$c/depth.####.exr" --out "$data/f.####.exr" $FOG --threads $t --device scalar --pixel-type half --verbose
  done
done; done
rm -rf "$data" "$pocl_only"
