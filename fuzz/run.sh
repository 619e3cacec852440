#!/usr/bin/env bash
# Builds the libFuzzer targets (clang, -DSONOMAP_FUZZ=ON, in build-fuzz/ or $SONOMAP_FUZZ_BUILD_DIR)
# and runs each for SECONDS (default 120) from its seed corpus in fuzz/corpus/<reader>/.
# New inputs go to build-fuzz/corpus/<reader>/ (the seeds in the repo stay as they are);
# a crash is saved as build-fuzz/findings/<reader>/crash-* and ends the script with status 1.
#   fuzz/run.sh [SECONDS] [READER...]     readers: circle_csv scenario_yaml tum sofa rosbag sequence_yaml mesh
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${SONOMAP_FUZZ_BUILD_DIR:-$root/build-fuzz}"
seconds="${1:-120}"
shift || true
readers=("$@")
[ ${#readers[@]} -eq 0 ] && readers=(circle_csv scenario_yaml tum sofa rosbag sequence_yaml mesh)

"$root/ci/install-deps" --fuzz
mkdir -p "$build"
CC=clang-14 CXX=clang++-14 cmake -S "$root" -B "$build" -DCMAKE_BUILD_TYPE=Release \
  -DSONOMAP_FUZZ=ON -DSONOMAP_BUILD_TESTS=OFF >"$build/configure.log" 2>&1 \
  || { cat "$build/configure.log" >&2; exit 1; }
cmake --build "$build" -j"$(nproc)" --target "${readers[@]/#/fuzz_}"

export ASAN_OPTIONS="detect_container_overflow=0:${ASAN_OPTIONS:-}"
export LSAN_OPTIONS="suppressions=$root/ci/lsan.supp:${LSAN_OPTIONS:-}"
export UBSAN_OPTIONS="halt_on_error=1:print_stacktrace=1:${UBSAN_OPTIONS:-}"
status=0
for reader in "${readers[@]}"; do
  corpus="$build/corpus/$reader" findings="$build/findings/$reader"
  mkdir -p "$corpus" "$findings"
  echo "fuzz/run.sh: $reader for ${seconds} s" >&2
  "$build/fuzz/fuzz_$reader" "$corpus" "$root/fuzz/corpus/$reader" \
    -max_total_time="$seconds" -max_len=65536 -timeout=10 -rss_limit_mb=4096 \
    -artifact_prefix="$findings/" -print_final_stats=1 2>"$build/fuzz_$reader.log" \
    || { status=1; echo "fuzz/run.sh: $reader found a problem: $findings/ ($build/fuzz_$reader.log)" >&2; }
  grep -E "^(stat::number_of_executed_units|stat::new_units_added)" "$build/fuzz_$reader.log" >&2 || true
done
exit $status
