#!/usr/bin/env bash
# buckle set-up: one entry point for newcomers and for CI.
#
#   scripts/setup.sh run    install missing Debian packages, build Release into build/,
#                           run the main job (results in out/)
#   scripts/setup.sh test   install missing packages (and chromium, for the browser test of
#                           report.html), build with the tests, run ctest (pytest included)
# Both build the Python package into build/python: PYTHONPATH=build/python python3 -c 'import buckle'
#
# Supports Debian bookworm (also a minimal image). Installing needs root: the script uses
# sudo when not root, and touches apt only when a package is missing (checked with
# dpkg-query), so a second run goes straight to an incremental build.
# Started through sudo by the user who owns the checkout, it installs as root and then builds
# as that user, so no root-owned files end up in build/ or out/.
#
# Knobs (environment): BUCKLE_BUILD_DIR (default <repo>/build), BUCKLE_OUT_DIR (default
# <repo>/out), BUCKLE_JOBS (default nproc), BUCKLE_TEST_TIMEOUT (seconds per test, default
# 900), BUCKLE_SKIP_INSTALL=1 (never call apt-get; for machines where you manage packages).
set -Eeuo pipefail

ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
readonly ROOT
BUILD_DIR=${BUCKLE_BUILD_DIR:-$ROOT/build}
OUT=${BUCKLE_OUT_DIR:-$ROOT/out}
JOBS=${BUCKLE_JOBS:-$(nproc)}
TEST_TIMEOUT=${BUCKLE_TEST_TIMEOUT:-900}
# ccache (used by the build when installed) hashes paths relative to the checkout, so a fresh
# clone elsewhere, e.g. CI's, reuses objects compiled from the same sources.
export CCACHE_BASEDIR=${CCACHE_BASEDIR:-$ROOT}

# Debian packages (names verified on bookworm). pybind11-dev, python3-dev, python3-numpy: the
# Python module (build/python); python3-pytest: its tests. openmpi-bin, libopenmpi-dev:
# `buckle-mpi atlas` under mpirun (and its test, mpirun -np 2/3). TEST_PACKAGES only for `test`:
# chromium renders report.html in the browser test; matplotlib and pandas, the Python package's
# optional plots and DataFrames; pip, setuptools, wheel and venv, its `pip install .` test;
# universal-ctags, the size test's function lengths (scripts/check_sizes.sh --functions); nodejs,
# the syntax check of report.html's script (apps/scene/report/report.js).
readonly PACKAGES=(build-essential cmake git pkg-config ccache libeigen3-dev libsundials-dev
                   libboost-dev catch2 libcli11-dev nlohmann-json3-dev libbenchmark-dev gnuplot-nox
                   pybind11-dev python3-dev python3-numpy python3-pytest openmpi-bin libopenmpi-dev)
readonly TEST_PACKAGES=(chromium python3-matplotlib python3-pandas python3-pip python3-setuptools python3-wheel
                        python3-venv universal-ctags nodejs)

START=$SECONDS
log() { printf '==> [setup %4ds] %s\n' "$((SECONDS - START))" "$*"; }
die() {
  printf '\nsetup.sh: ERROR: %s\n' "$*" >&2
  exit 1
}
trap 'rc=$?; printf "\nsetup.sh: ERROR: command failed (exit %d) at line %d: %s\n" "$rc" "$LINENO" "$BASH_COMMAND" >&2; exit "$rc"' ERR

usage() {
  sed -n '2,/^[^#]/{/^#/s/^# \{0,1\}//p}' "${BASH_SOURCE[0]}"
}

# ============================================================================================
# MAIN JOB: the one place that decides what `scripts/setup.sh run` computes. Runs from the
# repository root with the freshly built binary; everything it writes goes to $OUT.
# ============================================================================================
main_job() {
  local buckle=$BUILD_DIR/bin/buckle
  if [[ -f data/scenes/default.json ]] && has_subcommand "$buckle" run; then
    # into its own folder: buckle refuses to replace a directory holding anything but its own
    # output (out/ may hold other runs, e.g. out/atlas), so out/ itself is never the target
    log "main job: buckle run data/scenes/default.json --out $OUT/default"
    "$buckle" run data/scenes/default.json --out "$OUT/default"
  else
    [[ ! -f data/scenes/default.json ]] ||
      log "main job: data/scenes/default.json exists but this buckle has no 'run' subcommand"
    # Until scenes land: the first three critical loads of a 3-segment clamped-pinned column.
    local args=(critical --segments 3 --a 0.5 --b 1 --k 1 --L0 2.25 --count 3)
    log "main job: buckle ${args[*]}"
    "$buckle" "${args[@]}" | tee "$OUT/critical.txt"
    "$buckle" "${args[@]}" --json > "$OUT/critical.json"
  fi
}
# ============================================================================================

# True when `buckle --help` lists subcommand $2 (CLI11 prints "  name  description").
has_subcommand() {
  local help
  help=$("$1" --help 2>&1) || true
  grep -qE "^[[:space:]]+$2([[:space:]]|$)" <<<"$help"
}

missing_packages() {
  local p wanted=("${PACKAGES[@]}")
  [[ ${CMD:-} != test ]] || wanted+=("${TEST_PACKAGES[@]}")
  for p in "${wanted[@]}"; do
    [[ $(dpkg-query -W -f='${db:Status-Status}' "$p" 2>/dev/null) == installed ]] || echo "$p"
  done
}

install_packages() {
  [[ ${BUCKLE_SETUP_AS_USER:-0} == 1 ]] && return  # checked by the root half, before sudo -u
  if [[ ${BUCKLE_SKIP_INSTALL:-0} == 1 ]]; then
    log "packages: not checked (BUCKLE_SKIP_INSTALL=1)"
    return
  fi
  command -v dpkg-query >/dev/null ||
    die "dpkg-query not found: this script supports Debian bookworm. Install by hand: ${PACKAGES[*]}"
  local missing
  mapfile -t missing < <(missing_packages)
  if ((${#missing[@]} == 0)); then
    log "packages: all present, apt not needed"
    return
  fi
  log "packages: missing ${missing[*]}"
  local sudo=()
  if ((EUID != 0)); then
    command -v sudo >/dev/null ||
      die "installing ${missing[*]} needs root: run this script as root, or install sudo"
    sudo=(sudo)
  fi
  local apt=("${sudo[@]}" env DEBIAN_FRONTEND=noninteractive apt-get -q -o DPkg::Lock::Timeout=300)
  local hint="network? /etc/apt/sources.list?"
  ((${#sudo[@]} == 0)) || hint="root rights through sudo? $hint"
  "${apt[@]}" update || die "apt-get update failed ($hint)"
  "${apt[@]}" install -y --no-install-recommends "${missing[@]}" ||
    die "apt-get install failed for: ${missing[*]} ($hint)"
  mapfile -t missing < <(missing_packages)
  ((${#missing[@]} == 0)) || die "still not installed after apt-get: ${missing[*]}"
  log "packages: installed"
}

# Invoked as `sudo scripts/setup.sh ...` by the owner of the checkout: packages are in, now
# build as that user. Skipped when build/ or out/ already belong to someone else (e.g. root
# from an earlier run), so the script never fails on permissions it created itself.
maybe_drop_privileges() {
  ((EUID == 0)) && [[ -n ${SUDO_USER:-} && $SUDO_USER != root ]] || return 0
  command -v sudo >/dev/null || return 0
  [[ $(stat -c %U "$ROOT") == "$SUDO_USER" ]] || return 0
  local d
  for d in "$BUILD_DIR" "$OUT"; do
    [[ ! -e $d || $(stat -c %U "$d") == "$SUDO_USER" ]] || return 0
  done
  log "building as $SUDO_USER (owner of $ROOT), not as root"
  exec sudo -u "$SUDO_USER" -H -- env BUCKLE_SETUP_AS_USER=1 BUCKLE_BUILD_DIR="$BUILD_DIR" \
    BUCKLE_OUT_DIR="$OUT" BUCKLE_JOBS="$JOBS" BUCKLE_TEST_TIMEOUT="$TEST_TIMEOUT" \
    "$ROOT/scripts/setup.sh" "$CMD"
}

# configure <BUCKLE_BUILD_TESTS: ON|OFF>. Benchmarks are CI's business (.ci/run).
configure() {
  log "configure: $BUILD_DIR (Release, tests $1)"
  cmake -S "$ROOT" -B "$BUILD_DIR" -DCMAKE_BUILD_TYPE=Release -DBUCKLE_BUILD_TESTS="$1" \
    -DBUCKLE_BUILD_BENCHMARKS=OFF ||
    die "CMake configure failed (messages above). A stale cache? try: rm -rf $BUILD_DIR"
}

build() {
  log "build: cmake --build $BUILD_DIR --parallel $JOBS"
  cmake --build "$BUILD_DIR" --parallel "$JOBS" || die "build failed (compiler errors above)"
  log "build: done"
}

# The Python module is used from the build tree: PYTHONPATH names it (README, Python).
python_hint() {
  [[ -n $(compgen -G "$BUILD_DIR/python/buckle*.so") ]] || return 0
  log "Python: PYTHONPATH=$BUILD_DIR/python /usr/bin/python3 -c 'import buckle'"
}

CMD=${1:-}
case $CMD in
  run | test) ;;
  -h | --help | help) usage; exit 0 ;;
  "") usage >&2; die "missing subcommand: run or test" ;;
  *) usage >&2; die "unknown subcommand '$CMD': use run or test" ;;
esac
(($# == 1)) || die "too many arguments: $*"

install_packages
maybe_drop_privileges
cd "$ROOT"

if [[ $CMD == run ]]; then
  configure OFF
  build
  [[ -x $BUILD_DIR/bin/buckle ]] ||
    die "build finished but $BUILD_DIR/bin/buckle is missing (does apps/buckle define the buckle target?)"
  mkdir -p "$OUT"
  main_job
  log "done: results in $OUT/"
  ls -l "$OUT"
  if [[ -f $OUT/default/report.html ]]; then log "report: open $OUT/default/report.html in a browser"; fi
  python_hint
else
  configure ON
  build
  log "test: ctest --test-dir $BUILD_DIR --output-on-failure -j $JOBS"
  ctest --test-dir "$BUILD_DIR" --output-on-failure -j "$JOBS" --timeout "$TEST_TIMEOUT" ||
    die "tests failed (see the output above)"
  log "test: all passed"
  python_hint
fi
