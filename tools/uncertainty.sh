#!/usr/bin/env bash
# The uncertainty study in one command: builds test_covariance, test_covariance_pipeline,
# bench_speed_core, process_bag and make_example_bag, runs the covariance checks (their
# Monte Carlo and extrapolation figures), the covariance rows of bench_speed_core (3
# interleaved repetitions of 0.2 s) and the demo's uncertainty band (tools/uncertainty_band.sh,
# with and without the inertial-parameter terms), and rewrites the generated blocks of
# docs/studies/uncertainty.md (tools/uncertainty_page.py) and docs/studies/uncertainty_band.png.
# About 5 min of machine time after the build. JLE_WS as for tools/build.sh; JLE_JOBS build jobs.
set -euo pipefail
repo=$(cd "$(dirname "$0")/.." && pwd)
case "${1:-}" in
  "") ;;
  *) echo "usage: tools/uncertainty.sh" >&2; exit 2 ;;
esac
source "$repo/tools/study_build.sh"
study_build uncertainty -DJLE_UNIT_TESTS=ON test_covariance test_covariance_pipeline \
  bench_speed_core process_bag make_example_bag
bin=$ws/devel/lib/joint_load_estimator
out=$ws/uncertainty_study
mkdir -p "$out"
study=/usr/bin/python3
before=$($study "$repo/tools/study_page.py" load)
start=$(date +%s)
"$bin/test_covariance" >"$out/test_covariance.txt" 2>&1 ||
  { tail -30 "$out/test_covariance.txt"; echo "uncertainty: test_covariance failed" >&2; exit 1; }
"$bin/test_covariance_pipeline" >"$out/test_covariance_pipeline.txt" 2>&1 ||
  { tail -30 "$out/test_covariance_pipeline.txt"; echo "uncertainty: test_covariance_pipeline failed" >&2; exit 1; }
"$bin/bench_speed_core" --benchmark_filter='_cov_' --benchmark_min_time=0.2 \
  --benchmark_repetitions=3 --benchmark_enable_random_interleaving=true \
  --benchmark_out="$out/cov_bench.json" --benchmark_out_format=json >"$out/cov_bench.txt"
bash "$repo/tools/uncertainty_band.sh" >"$out/band.txt"
JLE_BAND_PARAMETERS=0 JLE_BAND_PNG="$out/band_without_parameters.png" \
  bash "$repo/tools/uncertainty_band.sh" >"$out/band_without_parameters.txt"
after=$($study "$repo/tools/study_page.py" load)
$study "$repo/tools/uncertainty_page.py" --dir "$out" --load-before "$before" --load-after "$after" \
  --seconds $(($(date +%s) - start)) --page "$repo/docs/studies/uncertainty.md"
