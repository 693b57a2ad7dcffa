#!/usr/bin/env bash
# CAPE beside Kartograf's plane extraction (issue 26; docs/benchmarks.md "Plane extraction
# modes"): fetches pedropro/CAPE (MIT licence) at a fixed commit into a folder outside the
# sources' control (default build-cape/CAPE, git-ignored as every build-* folder), then
# configures and builds kartograf_plane_bench with it (-DKARTOGRAF_CAPE_DIR) in build-cape and
# runs it with one thread. Needs the network for the clone; not part of the test command.
#
#   scripts/fetch-cape.sh [build-dir] [kartograf_plane_bench options...]
#   CAPE_SOURCE=<a local clone or mirror> uses that instead of GitHub.
set -euo pipefail

repo="$(cd "$(dirname "$0")/.." && pwd)"
build="${1:-$repo/build-cape}"
[ $# -gt 0 ] && shift
commit=404fd75586e64034d9ef16318e22cbd1da273936  # 2019-08-21, the repository's last commit
source="${CAPE_SOURCE:-https://github.com/pedropro/CAPE.git}"
checkout="$build/CAPE"

if [ ! -f "$checkout/CAPE/CAPE.cpp" ]; then
  rm -rf "$checkout"
  git clone --quiet "$source" "$checkout" >&2
fi
git -C "$checkout" checkout --quiet "$commit"

cmake -S "$repo" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release -DKARTOGRAF_BUILD_BENCH=ON \
  -DKARTOGRAF_CAPE_DIR="$checkout" >&2
cmake --build "$build" --target kartograf_plane_bench >&2
KARTOGRAF_CPU_THREADS=1 "$build/bench/kartograf_plane_bench" --no-device-backends "$@"
