# Sourced by the CLI tests of tests/cli_limits_tests.cmake.
# fails_with LOG PATTERN... -- COMMAND...: COMMAND must exit non-zero within 60 s with every
# fixed-string PATTERN on its stderr (kept in LOG).
fails_with() {
  log=$1; shift
  patterns=""
  while [ "$1" != "--" ]; do patterns="$patterns
$1"; shift; done
  shift
  timeout 60 "$@" > "$log.out" 2> "$log"
  status=$?
  [ $status -ne 0 ] || { echo "FAIL: '$*' succeeded"; return 1; }
  [ $status -ne 124 ] || { echo "FAIL: '$*' ran for 60 s"; return 1; }
  printf '%s\n' "$patterns" | while IFS= read -r p; do
    [ -z "$p" ] || grep -qF -- "$p" "$log" || { echo "FAIL: '$*': no '$p' in:"; cat "$log"; exit 1; }
  done
}
