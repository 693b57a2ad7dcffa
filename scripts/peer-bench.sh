#!/usr/bin/env bash
# Peer benchmark (docs/benchmarks.md): configures and builds kartograf_peer_bench
# (-DKARTOGRAF_BUILD_PEER_BENCH=ON; needs Debian's libopen3d-dev and libpcl-dev) and runs it once
# per thread count, OMP_NUM_THREADS (Open3D, PCL) and KARTOGRAF_CPU_THREADS (Kartograf) pinned to
# the same n. The Markdown tables go to stdout, progress to stderr. KARTOGRAF_PEER_ONLY=planes (or
# registration) runs one of its two parts (--suite).
#
#   scripts/peer-bench.sh [build-dir] [kartograf_peer_bench options...]
#   KARTOGRAF_PEER_THREADS="1 2" (default) sets the thread counts to run.
#   e.g. scripts/peer-bench.sh build-peer --no-chain --max-calls 3
set -euo pipefail

repo="$(cd "$(dirname "$0")/.." && pwd)"
build="${1:-$repo/build-peer}"
[ $# -gt 0 ] && shift

for package in libopen3d-dev libpcl-dev; do
  if ! dpkg-query -W -f='${Status}' "$package" 2>/dev/null | grep -q "install ok installed"; then
    echo "peer-bench: $package is not installed (apt-get install $package)" >&2
    exit 2
  fi
done

cmake -S "$repo" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release -DKARTOGRAF_BUILD_PEER_BENCH=ON >&2
cmake --build "$build" --target kartograf_peer_bench >&2

for threads in ${KARTOGRAF_PEER_THREADS:-1 2}; do
  echo
  echo "<!-- OMP_NUM_THREADS=$threads KARTOGRAF_CPU_THREADS=$threads -->"
  OMP_NUM_THREADS=$threads KARTOGRAF_CPU_THREADS=$threads \
    "$build/bench/peer/kartograf_peer_bench" --suite "${KARTOGRAF_PEER_ONLY:-all}" "$@"
done
