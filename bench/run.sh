#!/usr/bin/env bash
# Builds and runs the benchmarks; JSON results go to build/bench/results.json (evaluation) and
# build/bench/results_self_intersection.json (find_self_intersection). Arguments go to the first.
source "$(dirname "${BASH_SOURCE[0]}")/../scripts/common.sh"
clay_ensure_packages
clay_build --target bench_evaluate bench_self_intersection
"$CLAY_BUILD/bench/bench_evaluate" --benchmark_out="$CLAY_BUILD/bench/results.json" \
  --benchmark_out_format=json "$@"
"$CLAY_BUILD/bench/bench_self_intersection" \
  --benchmark_out="$CLAY_BUILD/bench/results_self_intersection.json" --benchmark_out_format=json
echo "results: $CLAY_BUILD/bench/results.json, $CLAY_BUILD/bench/results_self_intersection.json"
