#!/usr/bin/env bash
# The whole test suite under AddressSanitizer + UndefinedBehaviorSanitizer (gcc), in build-asan/
# (or $KARTOGRAF_ASAN_BUILD_DIR). Any ASan or UBSan report fails the test that caused it.
# Usage: scripts/sanitize.sh [extra ctest arguments, e.g. -R Cli]
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
build_dir="${KARTOGRAF_ASAN_BUILD_DIR:-build-asan}"
cmake -S . -B "$build_dir" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DKARTOGRAF_SANITIZE=ON \
  -DKARTOGRAF_BUILD_TESTS=ON -DKARTOGRAF_BUILD_BENCH=OFF >/dev/null
cmake --build "$build_dir" --parallel "$(nproc)"
# Leak checks are off: the Vulkan and OpenCL drivers (lavapipe, PoCL) keep process-lifetime
# allocations that LeakSanitizer reports as leaks; ASan's memory errors and UBSan stay fatal.
export ASAN_OPTIONS="detect_leaks=0:abort_on_error=1:halt_on_error=1:strict_string_checks=1"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"
ctest --test-dir "$build_dir" --output-on-failure --parallel "$(nproc)" --timeout 1800 "$@"
