#!/usr/bin/env bash
# Builds and runs the benchmarks; JSON results go to build/bench/results.json (evaluation),
# build/bench/constraints.json (constraint solve + diagnosis) and build/bench/deform.json (FFD
# lattices). Extra arguments go to all three.
source "$(dirname "${BASH_SOURCE[0]}")/../scripts/common.sh"
clay_ensure_packages
clay_build --target bench_evaluate bench_constraints bench_deform
"$CLAY_BUILD/bench/bench_evaluate" --benchmark_out="$CLAY_BUILD/bench/results.json" \
  --benchmark_out_format=json "$@"
"$CLAY_BUILD/bench/bench_constraints" --benchmark_out="$CLAY_BUILD/bench/constraints.json" \
  --benchmark_out_format=json "$@"
"$CLAY_BUILD/bench/bench_deform" --benchmark_out="$CLAY_BUILD/bench/deform.json" \
  --benchmark_out_format=json "$@"
echo "results: $CLAY_BUILD/bench/results.json $CLAY_BUILD/bench/constraints.json $CLAY_BUILD/bench/deform.json"
