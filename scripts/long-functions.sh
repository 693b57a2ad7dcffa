#!/usr/bin/env bash
# Functions longer than LIMIT lines (default 80, the project's rule) in the C++ sources, longest
# first, from Universal Ctags' start and end lines. Exit status 1 when there is one.
# Usage: scripts/long-functions.sh [LIMIT]
set -euo pipefail
cd "$(dirname "$0")/.."
limit="${1:-80}"
command -v ctags >/dev/null || { echo "long-functions.sh: ctags not found (apt-get install universal-ctags)" >&2; exit 2; }
list="$(ctags -R --languages=C++ --kinds-C++=f --fields=+ne -x --_xformat='%{line} %{end} %F %N' \
          src apps include bench tools tests fuzz 2>/dev/null |
        awk -v limit="$limit" '$2 - $1 + 1 > limit { print $2 - $1 + 1, $3 ":" $1, $4 }' | sort -rn)"
[ -z "$list" ] && { echo "no function over $limit lines"; exit 0; }
printf '%s\n' "$list"
echo "$(printf '%s\n' "$list" | wc -l) functions over $limit lines"
exit 1
