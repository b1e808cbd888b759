#!/usr/bin/env bash
# Builds Clayform and runs its tests in three timed parts, then prints a summary:
#   release   build/ (Release, warnings as errors) and the whole ctest suite: what users get.
#   sanitize  build-sanitize/ (Clang, Debug at -O2: assertions and the tests' floating-point traps
#             on; AddressSanitizer + UndefinedBehaviorSanitizer, every finding fatal) and the
#             whole ctest suite again, examples included.
#   fuzz      the libFuzzer targets of tests/fuzz (built in build-sanitize/), each for
#             CLAY_FUZZ_SECONDS (default 60) from its committed seed corpus, both at once.
# Installs missing Debian packages first (as root, or through sudo). Extra arguments go to both
# ctest runs (e.g. -R exchange). CLAY_TEST_PARTS chooses parts, comma-separated (default
# release,sanitize,fuzz):  CLAY_TEST_PARTS=release scripts/test.sh -R exchange
# CLAYFORM_BUILD_DIR and CLAYFORM_SANITIZE_BUILD_DIR move the two build trees. Every chosen part
# runs even when an earlier one fails; the exit status is 1 when any failed.
source "$(dirname "${BASH_SOURCE[0]}")/common.sh"

CLAY_SANITIZE_BUILD=${CLAYFORM_SANITIZE_BUILD_DIR:-$CLAY_ROOT/build-sanitize}
FUZZ_SECONDS=${CLAY_FUZZ_SECONDS:-60}
FUZZ_TARGETS=(recipe stack studio)  # tests/fuzz/<name>_fuzz.cpp, seeds in tests/fuzz/corpus/<name>/

IFS=', ' read -ra parts <<<"${CLAY_TEST_PARTS:-release,sanitize,fuzz}"
for p in "${parts[@]}"; do
  case "$p" in
    release | sanitize | fuzz) ;;
    *) echo "scripts/test.sh: unknown part '$p' in CLAY_TEST_PARTS (the parts: release, sanitize, fuzz)" >&2; exit 2 ;;
  esac
done
[[ "$FUZZ_SECONDS" =~ ^[1-9][0-9]*$ ]] || { echo "scripts/test.sh: CLAY_FUZZ_SECONDS must be a whole number of seconds" >&2; exit 2; }

clay_ensure_packages

# How the sanitized programs report. ASan: leaks too (LeakSanitizer), static initialization order;
# UBSan: a stack trace with the finding. Both symbolize with LLVM's symbolizer (package llvm-14).
clay_sanitizer_env() {
  local symbolizer=/usr/bin/llvm-symbolizer-14
  local common="symbolize=1"
  [[ -x "$symbolizer" ]] && common+=":external_symbolizer_path=$symbolizer"
  export ASAN_OPTIONS="$common:detect_leaks=1:check_initialization_order=1:strict_init_order=1:allocator_may_return_null=1"
  export UBSAN_OPTIONS="$common:print_stacktrace=1:halt_on_error=1"
  export LSAN_OPTIONS="suppressions=$CLAY_ROOT/scripts/lsan.supp:print_suppressions=0"
}

# Configures build-sanitize/ the first time and builds what is stale (or the targets given).
clay_sanitize_build() {
  if [[ ! -f "$CLAY_SANITIZE_BUILD/CMakeCache.txt" ]]; then
    echo "==> configuring $CLAY_SANITIZE_BUILD"
    # -O2: Eigen's expression templates must be inlined (so must UBSan leave Eigen's headers
    # alone: cmake/sanitizer-ignorelist.txt); line tables are all a sanitizer report needs (full
    # -g makes objects bigger, links slower). No benchmarks: nothing runs them here.
    cmake -S "$CLAY_ROOT" -B "$CLAY_SANITIZE_BUILD" -G Ninja -DCMAKE_BUILD_TYPE=Debug \
      -DCMAKE_CXX_COMPILER=clang++-14 -DCMAKE_CXX_FLAGS_DEBUG="-O2 -gline-tables-only" \
      -DCLAYFORM_SANITIZE=address,undefined -DCLAYFORM_BUILD_FUZZ=ON -DCLAYFORM_BUILD_BENCH=OFF \
      -DCLAYFORM_WERROR=ON
  fi
  echo "==> building $CLAY_SANITIZE_BUILD (only what is stale)"
  cmake --build "$CLAY_SANITIZE_BUILD" --parallel "$(clay_jobs)" "$@"
}

part_release() {
  clay_build
  echo "==> running the test suite (Release)"
  cd "$CLAY_BUILD"
  ctest --output-on-failure --parallel "$(clay_jobs)" --timeout 900 "$@"
}

part_sanitize() {
  clay_sanitize_build
  clay_sanitizer_env
  echo "==> running the test suite (Debug, AddressSanitizer + UndefinedBehaviorSanitizer, FP traps)"
  cd "$CLAY_SANITIZE_BUILD"
  ctest --output-on-failure --parallel "$(clay_jobs)" --timeout 1800 "$@"
}

part_fuzz() {
  local t targets=()
  for t in "${FUZZ_TARGETS[@]}"; do targets+=("fuzz_$t"); done
  clay_sanitize_build --target "${targets[@]}"
  clay_sanitizer_env
  # Each target writes what it finds into build-sanitize/fuzz/<name>/corpus (kept between runs,
  # so a developer's next run goes on from there; the committed seeds are only read) and a
  # crashing input into build-sanitize/fuzz/<name>/artifacts/. One worker per target, all at once.
  local pids=() rc=0 i dir
  for t in "${FUZZ_TARGETS[@]}"; do
    dir=$CLAY_SANITIZE_BUILD/fuzz/$t
    mkdir -p "$dir/corpus" "$dir/artifacts"
    echo "==> fuzzing $t for ${FUZZ_SECONDS} s (log: $dir/fuzz.log)"
    "$CLAY_SANITIZE_BUILD/tests/fuzz/fuzz_$t" -max_total_time="$FUZZ_SECONDS" -timeout=30 -print_final_stats=1 \
      -artifact_prefix="$dir/artifacts/" "$dir/corpus" "$CLAY_ROOT/tests/fuzz/corpus/$t" >"$dir/fuzz.log" 2>&1 &
    pids+=($!)
  done
  for i in "${!FUZZ_TARGETS[@]}"; do
    t=${FUZZ_TARGETS[$i]}
    dir=$CLAY_SANITIZE_BUILD/fuzz/$t
    if wait "${pids[$i]}"; then
      echo "==> fuzz_$t: no finding; $(grep -m1 '^stat::number_of_executed_units' "$dir/fuzz.log" | awk '{print $2}') inputs run," \
        "$(grep -m1 '^stat::average_exec_per_sec' "$dir/fuzz.log" | awk '{print $2}')/s"
    else
      rc=1
      echo "==> fuzz_$t FOUND A CRASH (input in $dir/artifacts/; reproduce: $CLAY_SANITIZE_BUILD/tests/fuzz/fuzz_$t FILE)"
      tail -n 60 "$dir/fuzz.log"
    fi
  done
  return "$rc"
}

declare -A took=() result=()
start_all=$SECONDS
for p in "${parts[@]}"; do
  echo
  echo "======== part: $p ========"
  start=$SECONDS
  set +e
  (
    set -e
    "part_$p" "$@"
  )
  rc=$?
  set -e
  took[$p]=$((SECONDS - start))
  if ((rc == 0)); then result[$p]=passed; else result[$p]="FAILED ($rc)"; fi
  printf '==> part %s: %s in %dm%02ds\n' "$p" "${result[$p]}" $((took[$p] / 60)) $((took[$p] % 60))
done

echo
echo "======== summary ========"
failed=0
for p in "${parts[@]}"; do
  printf '  %-9s %-11s %3dm%02ds\n' "$p" "${result[$p]}" $((took[$p] / 60)) $((took[$p] % 60))
  [[ "${result[$p]}" == passed ]] || failed=1
done
total=$((SECONDS - start_all))
printf '  %-9s %-11s %3dm%02ds\n' total "" $((total / 60)) $((total % 60))
exit "$failed"
