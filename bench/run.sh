#!/usr/bin/env bash
# Builds and runs every benchmark; each writes build/bench/<name>.json (Google Benchmark JSON).
# Extra arguments go to every benchmark (e.g. --benchmark_filter=...).
source "$(dirname "${BASH_SOURCE[0]}")/../scripts/common.sh"
clay_ensure_packages
benches=(evaluate constraints self_intersection deform style compose model studio)
clay_build --target "${benches[@]/#/bench_}"
for name in "${benches[@]}"; do
  "$CLAY_BUILD/bench/bench_$name" --benchmark_out="$CLAY_BUILD/bench/$name.json" \
    --benchmark_out_format=json "$@"
  echo "results: $CLAY_BUILD/bench/$name.json"
done
# The Python binding's figures (FFD of 1 M points against bench_deform in the same run, small
# calls, the GIL, a 64-variant sweep on Dask), when the package was built.
if [ -f "$CLAY_BUILD/python/clayform/__init__.py" ]; then
  PYTHONPATH="$CLAY_BUILD/python" /usr/bin/python3 "$CLAY_ROOT/bench/python_bench.py" \
    --out "$CLAY_BUILD/bench/python.json" --bench-deform "$CLAY_BUILD/bench/bench_deform"
  echo "results: $CLAY_BUILD/bench/python.json"
fi
