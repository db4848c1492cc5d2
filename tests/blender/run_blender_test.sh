#!/usr/bin/env bash
# fogcl against a real renderer: Blender's Cycles renders a small scene headless (tests/blender/
# scene.py: planes and spheres, Z and Mist passes; then the same with a Volume Absorption sphere),
# examples/blender_camera.py prints the scene camera's fogcl flags, and fogcl apply fogs the first
# render with those flags. tests/blender/compare.py then checks, each with a tolerance derived and
# printed, and each with negative controls that must fail:
#   1. fogcl's linear distance fog (--sky infinite) against Cycles' Mist pass (same start and end,
#      falloff linear): controls: the fog end 1 % long; the Z pass read as radial distance; the
#      focal length 0.1 % long;
#   2. fogcl's physical volume pass, a homogeneous pure absorber (albedo 0) of density sigma,
#      against Cycles' Volume Absorption sphere (colour black, density sigma): control: sigma 1 % high.
#
#   tests/blender/run_blender_test.sh FOGCL
#
# Installs Debian's blender where it is missing (apt-get, root only). Without root or apt the test
# is skipped (exit 77) unless FOGCL_BLENDER_TEST=required, as in .ci/run, which makes it fail instead.
# FOGCL_BLENDER_TEST=skip skips it; FOGCL_BLENDER_KEEP=1 keeps the scratch folder.
set -euo pipefail

[ "${FOGCL_BLENDER_TEST:-}" = skip ] && { echo "blender test: SKIP: FOGCL_BLENDER_TEST=skip"; exit 77; }
if [ $# -ne 1 ]; then
  echo "usage: $0 FOGCL" >&2
  exit 2
fi
fogcl=$(readlink -f "$1")
here=$(cd "$(dirname "$0")" && pwd)
camera_script=$here/../../examples/blender_camera.py
TEST_NAME="blender test" TEST_GATE=FOGCL_BLENDER_TEST
# shellcheck source=tests/support/script_test.sh
. "$here/../support/script_test.sh"
started=$SECONDS

# ---- Blender, installed where missing ------------------------------------------------------------
if ! command -v blender > /dev/null; then
  [ "$(id -u)" -eq 0 ] || skip_or_fail "blender is not installed and installing it needs root"
  command -v apt-get > /dev/null || skip_or_fail "blender is not installed and apt-get is missing"
  install_started=$SECONDS
  apt_update_if_needed skip_or_fail blender
  apt_install blender || skip_or_fail "apt-get install blender failed"
  say "blender installed in $((SECONDS - install_started)) s"
  started=$SECONDS  # the test's own time starts now
fi
command -v python3 > /dev/null || skip_or_fail "python3 is missing (the comparison runs on it)"
say "$(blender -b --factory-startup -noaudio --version 2> /dev/null | head -n 1)"

scratch=$(mktemp -d "${TMPDIR:-/tmp}/fogcl-blender.XXXXXX")
cleanup() {
  if [ "${FOGCL_BLENDER_KEEP:-0}" = 1 ]; then say "scratch kept: $scratch"; else rm -rf "$scratch"; fi
}
trap cleanup EXIT

# Blender runs with a home of its own in the scratch folder: nothing of the user's is read or written.
mkdir -p "$scratch/home"
blender_run() {
  HOME=$scratch/home blender -b --factory-startup -noaudio "$@" > "$scratch/blender.log" 2>&1 || {
    tail -n 30 "$scratch/blender.log" >&2
    fail "blender $* failed"
  }
}

# ---- 1. Cycles renders the scene -----------------------------------------------------------------
mist_start=9
mist_end=34
sigma=1.6666667  # the absorber's diameter is 3: sigma * diameter = 5
t=$SECONDS
blender_run --python-exit-code 1 --python "$here/scene.py" -- "$scratch" "$mist_start" "$((mist_end - mist_start))" "$sigma"
say "Cycles rendered surfaces.exr and absorber.exr in $((SECONDS - t)) s"

# ---- 2. The camera, as a user takes it from Blender ----------------------------------------------
blender_run "$scratch/scene.blend" --python-exit-code 1 --python "$camera_script"
grep -E '^(--camera-to-world|# )' "$scratch/blender.log" > "$scratch/camera.txt" || true
camera=$(grep -E '^--camera-to-world' "$scratch/camera.txt" || true)
[ -n "$camera" ] || fail "examples/blender_camera.py printed no flags (log: $scratch/blender.log)"
say "camera: $camera"

# ---- 3. fogcl apply ------------------------------------------------------------------------------
read -r -a camera_flags <<< "$camera"
fogcl_apply() {
  local out=$1
  shift
  "$fogcl" apply --color "$scratch/surfaces.exr" --layer ViewLayer.Combined --depth-channel ViewLayer.Depth.Z \
    "${camera_flags[@]}" --compression none --out "$scratch/$out" "$@" || fail "fogcl apply ... --out $out $* failed"
}
t=$SECONDS
# Fog colour black: the output is the colour times fogcl's fog factor, which compare.py divides out.
fog=(--mode linear --distance --start "$mist_start" --fog-color 0,0,0 --sky infinite --fog-skybox)
fogcl_apply fogcl-fog.exr --depth-kind eye "${fog[@]}" --end "$mist_end"
fogcl_apply fogcl-fog-end-off.exr --depth-kind eye "${fog[@]}" --end "$(awk "BEGIN { print $mist_end * 1.01 }")"
fogcl_apply fogcl-fog-radial.exr --depth-kind distance "${fog[@]}" --end "$mist_end"
# The same fog through a lens 0.1 % long: a control on the camera (the other runs take it as printed).
lens_off=("${camera_flags[@]}")
for i in "${!lens_off[@]}"; do
  if [ "${lens_off[$i]}" = --focal-length ]; then lens_off[i + 1]=$(awk "BEGIN { print ${lens_off[i + 1]} * 1.001 }"); fi
done
"$fogcl" apply --color "$scratch/surfaces.exr" --layer ViewLayer.Combined --depth-channel ViewLayer.Depth.Z \
  "${lens_off[@]}" --compression none --out "$scratch/fogcl-fog-lens-off.exr" --depth-kind eye "${fog[@]}" \
  --end "$mist_end" || fail "fogcl apply ... --out fogcl-fog-lens-off.exr failed"
volume=(--depth-kind eye --integrator physical --volume-resolution full)
fogcl_apply fogcl-absorber.exr "${volume[@]}" --volumes "$scratch/absorber.json"
fogcl_apply fogcl-absorber-off.exr "${volume[@]}" --volumes "$scratch/absorber-off.json"
say "fogcl apply ran 6 times in $((SECONDS - t)) s"

# ---- 4. Comparison -------------------------------------------------------------------------------
t=$SECONDS
python3 "$here/compare.py" "$scratch" || fail "fogcl does not agree with Cycles (above)"
say "compared in $((SECONDS - t)) s"
say "PASS in $((SECONDS - started)) s (not counting an install)"
