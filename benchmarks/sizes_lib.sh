# Shared by the benchmarks that run `buckle run` on scenes written for several chain lengths
# (wall_sliding.sh, self_contact_hook.sh): `sizes_setup NAME DEFAULT_N... -- "$@"` reads
# [BUILD_DIR] [n ...] from the arguments and sets ROOT, BUCKLE, SIZES and TMP (a temporary
# directory removed at exit); it prints the machine's load.
sizes_setup() {
  local name=$1
  shift
  local defaults=()
  while (($#)) && [[ $1 != -- ]]; do defaults+=("$1"); shift; done
  (($#)) && shift
  ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
  local build=${1:-build}
  shift $(( $# > 1 ? 1 : $# ))
  SIZES=("$@")
  ((${#SIZES[@]})) || SIZES=("${defaults[@]}")
  [[ $build == /* ]] || build=$ROOT/$build
  BUCKLE=$build/bin/buckle
  [[ -x $BUCKLE ]] || { echo "no $BUCKLE: build it first" >&2; exit 2; }
  TMP=$(mktemp -d "${TMPDIR:-/tmp}/buckle-$name.XXXXXX")
  trap 'rm -rf "$TMP"' EXIT
  echo "load: $(uptime)"
}
