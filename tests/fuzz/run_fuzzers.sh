#!/usr/bin/env bash
# Builds the fuzz harnesses for libFuzzer with AddressSanitizer and UBSan (clang 16, in
# the instrumented tree of tests/configure_sanitized.sh) and runs each one for a bounded
# time over its checked-in corpus (tests/fuzz/corpus/<name>/). Fails when any harness
# finds a crash, a leak, a sanitizer report, a broken invariant, a timeout or an
# out-of-memory input.
#
#   tests/fuzz/run_fuzzers.sh [--seconds N] [--build DIR] [--jobs J] [--no-build] [NAME...]
#
# --seconds N   time per harness (default 20); --jobs J harnesses at once (default: cores)
# --build DIR   the instrumented tree (default build-sanitize); --no-build: use it as it is
# NAME...       only these harnesses (xpressnet, fastrak, ...; default: all)
#
# New inputs that reach new code go to DIR/fuzz/corpus/<name>/ (kept between runs, so
# longer runs build on earlier ones; the checked-in seeds are read, never written). An
# input that fails is written to DIR/fuzz/artifacts/<name>-crash-<sha1> (or -leak-,
# -timeout-, -oom-), its log to DIR/fuzz/logs/<name>.log. Reproduce one with
#   DIR/tests/fuzz/fuzz_<name> DIR/fuzz/artifacts/<name>-crash-<sha1>
# docs/design.md ("Fuzzing and sanitizers") says how to keep it as a regression input.
set -euo pipefail
cd "$(dirname "$0")/../.."
seconds=20 build=build-sanitize jobs=$(nproc) do_build=1 names=()
while (($#)); do
  case $1 in
    --seconds) seconds=$2; shift 2 ;;
    --build) build=$2; shift 2 ;;
    --jobs) jobs=$2; shift 2 ;;
    --no-build) do_build=0; shift ;;
    -h|--help) sed -n '2,/^set -e/p' "$0" | sed '$d; s/^# \{0,1\}//'; exit 0 ;;
    -*) echo "run_fuzzers: unknown option $1" >&2; exit 2 ;;
    *) names+=("$1"); shift ;;
  esac
done
((${#names[@]})) || names=($(ls tests/fuzz/corpus))

if ((do_build)); then
  tests/configure_sanitized.sh "$build"
  cmake --build "$build" -j"$(nproc)" --target $(printf 'fuzz_%s ' "${names[@]}")
fi

work=$(cd "$build" && pwd)/fuzz
mkdir -p "$work/logs" "$work/artifacts"
export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1:abort_on_error=1:symbolize=1}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}

# run_one NAME: one harness for $seconds; its verdict and figures on one line.
run_one() {
  local name=$1 log="$work/logs/$1.log"
  mkdir -p "$work/corpus/$name"
  local rc=0
  "$build/tests/fuzz/fuzz_$name" -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 \
    -malloc_limit_mb=1024 -max_len=65536 -print_final_stats=1 \
    -artifact_prefix="$work/artifacts/$name-" "$work/corpus/$name" "tests/fuzz/corpus/$name" >"$log" 2>&1 || rc=$?
  local runs rate cov
  runs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log")
  rate=$(sed -n 's/^stat::average_exec_per_sec: *//p' "$log")
  cov=$(grep -o 'cov: [0-9]*' "$log" | tail -1)
  if ((rc == 0)); then
    printf '%-14s ok      %9s runs %7s exec/s  %s\n' "$name" "${runs:-?}" "${rate:-?}" "$cov"
  else
    printf '%-14s FAILED  (exit %d) %s\n' "$name" "$rc" "$(grep -m1 -E 'ERROR|runtime error|invariant broken|Test unit written' "$log" || true)"
    grep -E 'Test unit written to' "$log" | sed 's/^/               /' || true
    echo "               log: $log"
    return 1
  fi
}
export -f run_one
export work build seconds

echo "run_fuzzers: ${#names[@]} harnesses, ${seconds} s each, ${jobs} at once"
if printf '%s\n' "${names[@]}" | xargs -P "$jobs" -I{} bash -c 'run_one {}'; then
  echo "run_fuzzers: no failure"
else
  echo "run_fuzzers: FAILED (inputs in $work/artifacts/)" >&2
  exit 1
fi
