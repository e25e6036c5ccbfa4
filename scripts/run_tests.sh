#!/usr/bin/env bash
# THE test command: installs what is missing (apt, Debian package names), checks the formatting, builds in
# Release, and runs every test: core gtests, ROS-layer gtests, rostests on the bags in bags/, the
# launch-file check, the install smoke test (scripts/install_smoke.sh), the core tests again under
# AddressSanitizer + UndefinedBehaviorSanitizer, and a bounded libFuzzer run.
# Exits non-zero on any failure. Usage (as root on Debian 12): bash scripts/run_tests.sh
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install_deps.sh
source scripts/env.sh

echo "== format: every C++ file as .clang-format says"
unformatted=()
while IFS= read -r file; do
  clang-format --dry-run -Werror "$file" >/dev/null 2>&1 || unformatted+=("$file")
done < <(git -C "$HGLASM_ROOT" ls-files '*.cpp' '*.h' 2>/dev/null || find src include test -name '*.cpp' -o -name '*.h')
if ((${#unformatted[@]})); then
  echo "not formatted (clang-format -i them): ${unformatted[*]}" >&2
  exit 1
fi

echo "== build (Release) into $HGLASM_BUILD"
hglasm_build
hglasm_build --target tests

# ctest runs each test through devel/env.sh, which sets up the ROS environment itself.
echo "== gtest + rostest + launch check (ctest)"
(cd "$HGLASM_BUILD" && ctest --output-on-failure)

echo "== install smoke test: install into a temporary prefix, run the nodelet from the install space"
bash scripts/install_smoke.sh

echo "== core and evaluation tests under AddressSanitizer + UndefinedBehaviorSanitizer"
ASAN_BUILD="$HGLASM_ROOT/build-asan"
if [ ! -f "$ASAN_BUILD/CMakeCache.txt" ]; then
  cmake -S "$HGLASM_ROOT" -B "$ASAN_BUILD" -DHGLASM_CORE_ONLY=ON -DHGLASM_SANITIZE=ON -DCMAKE_BUILD_TYPE=RelWithDebInfo
fi
cmake --build "$ASAN_BUILD" -j"$(nproc)" --target test_core test_evaluation
for suite in test_core test_evaluation; do
  ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
    "$ASAN_BUILD/$suite" --gtest_brief=1
done

if [ -f test/fuzz/fuzz_scan_matcher.cpp ]; then
  echo "== libFuzzer: scan conversion + matching on arbitrary bytes (bounded)"
  FUZZ_BUILD="$HGLASM_ROOT/build-fuzz"
  if [ ! -f "$FUZZ_BUILD/CMakeCache.txt" ]; then
    CC=clang CXX=clang++ cmake -S "$HGLASM_ROOT" -B "$FUZZ_BUILD" -DHGLASM_CORE_ONLY=ON -DHGLASM_FUZZ=ON \
      -DCMAKE_BUILD_TYPE=RelWithDebInfo
  fi
  cmake --build "$FUZZ_BUILD" -j"$(nproc)" --target fuzz_scan_matcher
  # Every input that ever crashed is kept in test/fuzz/corpus: replayed first (regressions), then the
  # fuzzer explores from them for a bounded time; new interesting inputs go to the build's own corpus.
  mkdir -p "$FUZZ_BUILD/corpus"
  "$FUZZ_BUILD/fuzz_scan_matcher" -runs=0 test/fuzz/corpus
  "$FUZZ_BUILD/fuzz_scan_matcher" -max_total_time="${HGLASM_FUZZ_SECONDS:-60}" -rss_limit_mb=2048 \
    -print_final_stats=1 "$FUZZ_BUILD/corpus" test/fuzz/corpus
fi
echo "== all tests passed"
