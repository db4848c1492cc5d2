#!/usr/bin/env bash
# Shows that the independent-reference tests (tests/independent_reference_test.cpp) fail when a
# formula constant changes: each mutant is the source tree with one constant changed by sed, in a
# copy under WORK_DIR (production code has no test hooks), built incrementally (only the objects
# that include the changed file; ccache keeps the rest) and tested with the reference tests that
# need no OpenCL device. Exit status 0 when the unchanged tree passes and every mutant fails.
#
#   scripts/mutation_check.sh SOURCE_DIR WORK_DIR
set -euo pipefail
src=$(cd "$1" && pwd)
work=$2
tree=$work/tree
build=$tree/build
mkdir -p "$tree"
work=$(cd "$work" && pwd)
tree=$work/tree
build=$tree/build

# ccache: paths relative to the copy, so that its objects hit the cache of the main build.
if command -v ccache >/dev/null; then
  export CCACHE_BASEDIR="$tree" CMAKE_CXX_COMPILER_LAUNCHER=ccache CMAKE_C_COMPILER_LAUNCHER=ccache
fi
jobs=${FOGCL_MUTATION_JOBS:-2}

# The copy: what the library and the reference tests are built from. Changed files only, with a
# fresh mtime, so that make rebuilds what depends on them.
sync_tree() {
  (cd "$src" && find CMakeLists.txt cmake src kernels tests examples -type f) | while read -r f; do
    if ! cmp -s "$src/$f" "$tree/$f"; then
      mkdir -p "$(dirname "$tree/$f")"
      cp "$src/$f" "$tree/$f"
    fi
  done
}

build_tests() {
  cmake --build "$build" -j "$jobs" --target fogcl_reference_tests >"$work/build.log" 2>&1 || {
    tail -n 40 "$work/build.log"
    return 1
  }
}

run_tests() {
  "$build/tests/fogcl_reference_tests" --gtest_filter='IndependentReference.Scalar*:IndependentReference.Quadrature*' \
    --gtest_brief=1 >"$work/test.log" 2>&1
}

sync_tree
if [ ! -f "$build/CMakeCache.txt" ]; then
  cmake -S "$tree" -B "$build" -DCMAKE_BUILD_TYPE=Release -DFOGCL_BUILD_BENCH=OFF -DFOGCL_INSTALL=OFF \
    >"$work/configure.log" 2>&1 || { cat "$work/configure.log"; exit 1; }
fi
build_tests
if ! run_tests; then
  cat "$work/test.log"
  echo "mutation check: the unchanged tree fails the reference tests"
  exit 1
fi
echo "mutation check: unchanged tree passes"

# name | file | sed expression. Each changes one constant or formula by a relative 1e-4 or so.
mutants=(
  "exp coefficient log2(e) x 1.0001|src/settings/fog_coefficients.h|s/kLog2e = 1.44269504088896340736;/kLog2e = 1.44283931039305230370;/"
  "exp2 coefficient 1/sqrt(ln 2) x 1.0001|src/settings/fog_coefficients.h|s/kInvSqrtLn2 = 1.20112240878644803896;/kInvSqrtLn2 = 1.20124252102732668376;/"
  "height fog's G(a) x 1.0001|kernels/fog_math.h|s/(FOG_REAL)1 : fmax(q, (FOG_REAL)0x1p-126f));/(FOG_REAL)1 : fmax(q, (FOG_REAL)0x1p-126f) * (FOG_REAL)1.0001f);/"
  "blend: fog color x 1.0001 in the mix|kernels/fog_math.h|s/return fma(f, c - fog_color, fog_color);/return fma(f, c - fog_color, fog_color * (FOG_REAL)1.0001f);/"
  "linear: start x 1.0001 in 1 / (end - start)|src/settings/fog_coefficients.h|s#c.b = finite(T(1) / (T(s.end) - T(s.start)));#c.b = finite(T(1) / (T(s.end) - T(s.start) * T(1.0001)));#"
  "height fog's in-scattering J = 1 - T x 1.0001|kernels/fog_math.h|s/\*j = -\*j;/*j = -*j * (FOG_REAL)1.0001f;/"
  "stylized volumes: alpha's density x 1.0001|kernels/volume_integrate.h|s/vol_saturate(vol_saturate(accumulation \/ marched) \* VOL_P(vol, VOL_V_DENSITY))/vol_saturate(vol_saturate(accumulation \/ marched) * VOL_P(vol, VOL_V_DENSITY) * (VOL_REAL)1.0001f)/"
  "stylized volumes: the seed's blend keeps 1.0001 x (1 - a)|kernels/volume_integrate.h|s/const VOL_REAL keep = (VOL_REAL)1 - c.w;/const VOL_REAL keep = ((VOL_REAL)1 - c.w) * (VOL_REAL)1.0001f;/"
)

restore() { [ -n "${current:-}" ] && cp "$src/$current" "$tree/$current"; current=""; }
trap restore EXIT
survivors=0
for m in "${mutants[@]}"; do
  IFS='|' read -r name file expr <<<"$m"
  current=$file
  sed -e "$expr" "$src/$file" >"$tree/$file"
  if cmp -s "$src/$file" "$tree/$file"; then
    echo "mutation check: '$name' changed nothing in $file (the pattern no longer matches)"
    exit 1
  fi
  build_tests
  if run_tests; then
    echo "mutation check: SURVIVED: $name"
    survivors=$((survivors + 1))
  else
    failed=$(grep -o '^\[  FAILED  \] IndependentReference\.[A-Za-z]*' "$work/test.log" | sed 's/.*IndependentReference\.//' | sort -u | tr '\n' ' ')
    echo "mutation check: caught: $name (failed: ${failed:-the run})"
  fi
  restore
done
# Leave the copy built as the source is, for the next run.
build_tests
[ "$survivors" -eq 0 ] || { echo "mutation check: $survivors mutant(s) survived"; exit 1; }
echo "mutation check: every mutant fails the reference tests"
