#!/bin/sh
# Runs every libFuzzer target of fuzz/ for N seconds each (default 60) on a copy
# of its seed corpus, and prints a one-line summary per target.
#
#   tools/fuzz.sh [N] [BUILD_DIR] [TARGET...]     (default: every target)
#
# BUILD_DIR (default build-fuzz) is configured and built here if needed, with
# clang at -O1: CC=clang CXX=clang++ cmake -DCONTACTROM_FUZZ=ON -DCONTACTROM_BUILD_TESTS=OFF.
# Crash reproducers are written to BUILD_DIR/fuzz-findings/<target>/; the exit
# code is the number of targets that found a crash, timeout or leak in
# contactrom's code (findings inside libhdf5 are counted and reported apart).
set -u
seconds=${1:-60}
build=${2:-build-fuzz}
root=$(cd "$(dirname "$0")/.." && pwd)
if [ ! -f "$build/CMakeCache.txt" ]; then
  # -O1, as fuzzing builds usually are: it compiles faster than -O3 and keeps the
  # sanitizers' reports readable.
  CC=${CC:-clang} CXX=${CXX:-clang++} cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=None \
    -DCMAKE_CXX_FLAGS=-O1 -DCMAKE_C_FLAGS=-O1 -DCONTACTROM_FUZZ=ON -DCONTACTROM_BUILD_TESTS=OFF >/dev/null || exit 100
fi
targets="fuzz_csv fuzz_database fuzz_msh"
[ -f "$root/fom/problem_file.hpp" ] && targets="$targets fuzz_problem_file"
[ -f "$root/rom/reduced_model_file.hpp" ] && targets="$targets fuzz_reduced_model"
[ $# -gt 2 ] && { shift 2; targets="$*"; }
cmake --build "$build" --target $targets >/dev/null || exit 100
failures=0
export LSAN_OPTIONS="suppressions=$root/fuzz/lsan.supp:print_suppressions=0"

# Where a finding happened: the first stack frame that is neither a sanitizer
# interceptor, libFuzzer nor the C library. "libhdf5" when it lies in libhdf5,
# "contactrom" otherwise, "not reproduced" when a replay gives no report.
triage() {
  report=$(timeout 300 "$1" "$2" -timeout=30 -rss_limit_mb=4096 2>&1)
  frames=$(printf '%s\n' "$report" | grep -E '^ +#[0-9]+ ')
  [ -z "$frames" ] && { echo "not reproduced"; return; }
  first=$(printf '%s\n' "$frames" | grep -vE 'libstdc\+\+| in (__interceptor_|__asan|__sanitizer|__ubsan|__lsan|malloc|calloc|realloc|free|memcpy|memmove|memset|strlen|operator new|operator delete|fuzzer::)|libc\.so|sysdeps/|libFuzzer|StaticAlarmHandler' | head -1)
  case "$first" in *libhdf5*) echo libhdf5 ;; *libgmsh* | *libOCC* | *libTK*) echo libgmsh ;; *) echo contactrom ;; esac
}

for target in $targets; do
  name=${target#fuzz_}
  work="$build/fuzz-work/$name"
  findings="$build/fuzz-findings/$name"
  mkdir -p "$work" "$findings"
  rm -f "$findings"/*  # this run's findings only
  cp "$root/fuzz/corpus/$name"/* "$work"/ 2>/dev/null
  log="$build/fuzz-findings/$name.log"
  # The HDF5 readers run in fork mode and go on after a finding: libhdf5 1.10
  # itself crashes, hangs or runs out of memory on some corrupted files
  # (fuzz/README.md); each finding is then replayed and attributed below.
  mode=""
  case "$target" in fuzz_database | fuzz_reduced_model | fuzz_msh) mode="-fork=1 -ignore_crashes=1 -ignore_ooms=1 -ignore_timeouts=1" ;; esac
  # -timeout: a single input running longer than 30 s is reported as a hang.
  # shellcheck disable=SC2086
  "$build/fuzz/$target" "$work" $mode -max_total_time="$seconds" -timeout=30 -rss_limit_mb=4096 \
    -artifact_prefix="$findings/" -print_final_stats=1 >"$log" 2>&1
  rc=$?
  runs=$(grep -o 'stat::number_of_executed_units: *[0-9]*' "$log" | grep -o '[0-9]*$' | tail -1)
  [ -z "$runs" ] && runs=$(grep -oE '^#[0-9]+' "$log" | tail -1 | tr -d '#')
  ours=0 theirs=0 lost=0
  for artifact in "$findings"/crash-* "$findings"/leak-* "$findings"/oom-* "$findings"/timeout-* "$findings"/slow-unit-*; do
    [ -f "$artifact" ] || continue
    case $(triage "$build/fuzz/$target" "$artifact") in
      libhdf5 | libgmsh) theirs=$((theirs + 1)) ;;
      contactrom) ours=$((ours + 1)); echo "  $artifact: in contactrom's code" ;;
      *) lost=$((lost + 1)) ;;
    esac
  done
  summary="$target: ${runs:-?} runs in ${seconds} s; findings in contactrom: $ours, inside libhdf5/libgmsh: $theirs, not reproduced: $lost"
  # In fork mode libFuzzer goes on after a finding: the attribution decides.
  passed=$([ -n "$mode" ] && echo $((ours == 0)) || echo $((rc == 0)))
  if [ "$passed" = 1 ]; then
    echo "$summary"
  else
    failures=$((failures + 1))
    echo "$summary; FAILED (exit $rc); see $log and $findings/"
  fi
done
exit $failures
