# shellcheck shell=bash
# What tests/*/run_*_test.sh share (sourced; bash): their messages and exits, and the Debian
# packages installed where a test needs them. The caller sets TEST_NAME ("blender test") and
# TEST_GATE (the variable whose value `required` turns a skip into a failure) before sourcing,
# and runs as root with apt-get present where it installs.

say() { echo "$TEST_NAME: $*"; }
fail() {
  echo "$TEST_NAME: FAIL: $*" >&2
  exit 1
}
# Exit 77 (ctest's skip), or fail where $TEST_GATE is `required`.
skip_or_fail() {
  if [ "${!TEST_GATE:-}" = required ]; then fail "$* ($TEST_GATE=required)"; fi
  echo "$TEST_NAME: SKIP: $*"
  exit 77
}

# apt_update_if_needed ON_ERROR PKG...: apt-get update only where a clean machine has no package
# lists yet (no policy for the first package, or no candidate for one of them); ON_ERROR (the
# caller's fail or skip_or_fail) is called with the reason when the update fails.
apt_update_if_needed() {
  local on_error=$1
  shift
  export DEBIAN_FRONTEND=noninteractive
  if [ -z "$(apt-cache policy "$1" 2> /dev/null)" ] ||
     apt-cache policy "$@" 2> /dev/null | grep -q 'Candidate: (none)'; then
    local names=$1 p
    for p in "${@:2}"; do names+=" or $p"; done
    say "apt-get update (no candidate for $names yet)"
    apt-get update -qq || "$on_error" "apt-get update failed"
  fi
}

# apt_install PKG...: installs them without recommends, waiting for another apt's lock; returns
# apt-get's status (the caller names the failure).
apt_install() {
  export DEBIAN_FRONTEND=noninteractive
  say "installing $*"
  apt-get install -y -qq --no-install-recommends -o DPkg::Lock::Timeout=120 "$@" > /dev/null
}
