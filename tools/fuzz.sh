#!/bin/sh
# Runs every libFuzzer target of fuzz/ for N seconds each (default 60) on a copy
# of its seed corpus, and prints a one-line summary per target.
#
#   tools/fuzz.sh [N] [BUILD_DIR] [TARGET...]     (default: every target)
#
# BUILD_DIR (default build-fuzz) is configured and built here if needed, with
# clang: CC=clang CXX=clang++ cmake -DCONTACTROM_FUZZ=ON -DCONTACTROM_BUILD_TESTS=OFF.
# Crash reproducers are written to BUILD_DIR/fuzz-findings/<target>/; the exit
# code is the number of targets that found a crash, timeout or leak.
set -u
seconds=${1:-60}
build=${2:-build-fuzz}
root=$(cd "$(dirname "$0")/.." && pwd)
if [ ! -f "$build/CMakeCache.txt" ]; then
  CC=${CC:-clang} CXX=${CXX:-clang++} cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release \
    -DCONTACTROM_FUZZ=ON -DCONTACTROM_BUILD_TESTS=OFF >/dev/null || exit 100
fi
targets="fuzz_csv fuzz_database"
[ -f "$root/fom/problem_file.hpp" ] && targets="$targets fuzz_problem_file"
[ -f "$root/rom/reduced_model_file.hpp" ] && targets="$targets fuzz_reduced_model"
[ $# -gt 2 ] && { shift 2; targets="$*"; }
cmake --build "$build" --target $targets >/dev/null || exit 100
failures=0
for target in $targets; do
  name=${target#fuzz_}
  work="$build/fuzz-work/$name"
  findings="$build/fuzz-findings/$name"
  mkdir -p "$work" "$findings"
  cp "$root/fuzz/corpus/$name"/* "$work"/ 2>/dev/null
  log="$build/fuzz-findings/$name.log"
  # -timeout: a single input running longer than 30 s is reported as a hang.
  # libhdf5's own leaks on corrupted files are suppressed (fuzz/lsan.supp), ours are not.
  LSAN_OPTIONS="suppressions=$root/fuzz/lsan.supp:print_suppressions=0" "$build/fuzz/$target" "$work" -max_total_time="$seconds" -timeout=30 -rss_limit_mb=4096 \
    -artifact_prefix="$findings/" -print_final_stats=1 >"$log" 2>&1
  rc=$?
  runs=$(grep -o 'stat::number_of_executed_units: *[0-9]*' "$log" | grep -o '[0-9]*$' | tail -1)
  if [ $rc -eq 0 ]; then
    echo "$target: ${runs:-?} runs in ${seconds} s, no crash"
  else
    failures=$((failures + 1))
    echo "$target: FAILED after ${runs:-?} runs (exit $rc); see $log and $findings/"
  fi
done
exit $failures
