#!/usr/bin/env bash
# The uncertainty band of docs/node.md: the demo bag (make_example_bag, as tools/demo.sh makes
# it) through process_bag with config/demo.yaml plus the uncertainty of
# config/demo_uncertainty.yaml, then one joint's effort with +-2 sigma plotted into
# docs/studies/uncertainty_band.png (bench/plot_uncertainty.py). Needs the package built
# (tools/build.sh process_bag make_example_bag). tools/uncertainty.sh runs it for
# docs/studies/uncertainty.md. JLE_BAND_PARAMETERS=0 leaves the inertial-parameter terms
# out (mass, centre of mass, inertia: 0); JLE_BAND_PNG another output image.
set -euo pipefail
repo=$(cd "$(dirname "$0")/.." && pwd)
ws=${JLE_WS:-${XDG_CACHE_HOME:-$HOME/.cache}/joint_load_estimator/ws}
bin=$ws/devel/lib/joint_load_estimator
demo=$ws/demo
mkdir -p "$demo"
bag=$demo/panda_example.bag
[ -s "$bag" ] || "$bin/make_example_bag" --urdf "$repo/test/data/urdf/panda_demo.urdf" --output "$bag" --effort
config=$demo/demo_uncertainty.yaml
# The wrist sensor's noise goes into its wrench entry (0.5 N, 0.02 N m per component).
sed 's/^    stale_policy: hold$/&\n    force_noise: 0.5\n    moment_noise: 0.02/' "$repo/config/demo.yaml" |
  cat - "$repo/config/demo_uncertainty.yaml" >"$config"
if [ "${JLE_BAND_PARAMETERS:-1}" = 0 ]; then
  sed -i -e 's/^  mass_fraction: .*/  mass_fraction: 0/' -e 's/^  com_offset: .*/  com_offset: 0/' \
    -e 's/^  inertia_fraction: .*/  inertia_fraction: 0/' "$config"
fi
grep -q force_noise "$config" || { echo "uncertainty_band: no wrench entry in config/demo.yaml" >&2; exit 1; }
"$bin/process_bag" --bag "$bag" --urdf "$repo/test/data/urdf/panda_demo.urdf" --config "$config" \
  --csv "$demo/uncertainty.csv"
/usr/bin/python3 "$repo/bench/plot_uncertainty.py" "$demo/uncertainty.csv" "${1:-panda_joint2}" \
  "${JLE_BAND_PNG:-$repo/docs/studies/uncertainty_band.png}"
