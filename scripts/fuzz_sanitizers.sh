#!/usr/bin/env bash
# scripts/fuzz_sanitizers.sh: builds the core library and test/fuzz_test.cpp with AddressSanitizer and
# UndefinedBehaviorSanitizer (plain g++, no catkin) and runs the fuzz test. Too slow for CI; run by hand.
set -euo pipefail
REPO="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
OUT="$REPO/out/sanitizers"
mkdir -p "$OUT"
echo "[fuzz_sanitizers] building with -fsanitize=address,undefined"
g++ -std=c++17 -O1 -g -fsanitize=address,undefined -fno-sanitize-recover=undefined -fno-omit-frame-pointer \
  -I"$REPO/include" -I/usr/include/eigen3 "$REPO"/src/core/*/*.cpp "$REPO"/src/sim/*.cpp "$REPO"/src/offline/*.cpp \
  "$REPO/test/fuzz_test.cpp" \
  -lyaml-cpp -lgtest -lgtest_main -pthread -o "$OUT/fuzz_test"
echo "[fuzz_sanitizers] running"
ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1 "$OUT/fuzz_test"
