# Sourced by the CLI tests (cli_input_tests.cmake, cli_outputs_tests.cmake,
# cli_limits_tests.cmake): the one check that a command fails and says why.
# fails_with [--regex] LOG PATTERN... -- COMMAND...: COMMAND must exit non-zero within 60 s with
# every PATTERN on its stderr (kept in LOG; its stdout in LOG.out). Patterns are fixed strings,
# or with --regex grep's basic regular expressions.
fails_with() {
  match=-F
  [ "$1" != "--regex" ] || { match=-G; shift; }
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
    [ -z "$p" ] || grep -q "$match" -- "$p" "$log" || { echo "FAIL: '$*': no '$p' in:"; cat "$log"; exit 1; }
  done
}
