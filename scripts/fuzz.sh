#!/usr/bin/env bash
# Builds the libFuzzer targets with clang (ASan + UBSan) in build-fuzz/ and runs each for a given
# time. Usage: scripts/fuzz.sh [SECONDS_PER_TARGET=300] [TARGET...]
# Targets: the fuzz_*.cpp files in fuzz/ (default: all). A crash stops the script with libFuzzer's
# report and leaves the crashing input as build-fuzz/crash-*; otherwise it prints exec counts.
set -euo pipefail
cd "$(dirname "$0")/.."
seconds="${1:-300}"
shift || true
targets=("$@")
if [ ${#targets[@]} -eq 0 ]; then
  for source in fuzz/fuzz_*.cpp; do targets+=("$(basename "$source" .cpp | sed 's/^fuzz_//')"); done
fi

cxx="$(command -v clang++ || true)"
[ -n "$cxx" ] || { echo "fuzz.sh: clang++ not found (apt-get install clang libclang-rt-14-dev)"; exit 1; }
cmake -S . -B build-fuzz -G Ninja -DCMAKE_CXX_COMPILER="$cxx" -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DKARTOGRAF_BUILD_FUZZ=ON -DKARTOGRAF_BUILD_TESTS=OFF -DKARTOGRAF_BUILD_BENCH=OFF >/dev/null
ninja -C build-fuzz "${targets[@]/#/fuzz_}"

for target in "${targets[@]}"; do
  corpus="build-fuzz/corpus/$target"
  mkdir -p "$corpus"
  seeds="fuzz/corpus/$target"
  echo "== fuzz_$target for ${seconds}s"
  log="build-fuzz/fuzz_$target.log"
  (cd build-fuzz && ASAN_OPTIONS=detect_leaks=1 "./fuzz/fuzz_$target" -max_total_time="$seconds" \
     -max_len=65536 -rss_limit_mb=2048 -timeout=10 -print_final_stats=1 \
     "corpus/$target" "../$seeds") >"$log" 2>&1 || { tail -60 "$log"; echo "fuzz_$target FAILED"; exit 1; }
  grep -E "stat::number_of_executed_units|stat::peak_rss_mb" "$log" | sed "s/^/fuzz_$target /"
done
