#!/bin/sh
# Usage: expect_lines.sh PROGRAM ARGS... -- PREFIX...
# Runs PROGRAM ARGS, prints its output, and fails unless every PREFIX begins some output line.
command=""
while [ $# -gt 0 ] && [ "$1" != "--" ]; do command="$command \"$1\""; shift; done
[ "$1" = "--" ] && shift
out=$(eval "$command") || { echo "FAIL: $command exited non-zero"; exit 1; }
printf '%s\n' "$out"
for prefix in "$@"; do
  printf '%s\n' "$out" | grep -q "^$prefix" || { echo "FAIL: no line starting with '$prefix'"; exit 1; }
done
