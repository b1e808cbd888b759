#!/usr/bin/env bash
# Runs Clayform's main job on the bundled default example and prints where the outputs are.
# Until the recipe runner lands it builds the sample surfaces of examples/01_export_surfaces.cpp,
# exports them to STEP (AP214), IGES and a glTF preview, reads them back and writes a report.
# Installs missing Debian packages first. Output folder: $1, default ./out/demo.
source "$(dirname "${BASH_SOURCE[0]}")/common.sh"
clay_ensure_packages
clay_build --target clayform example_01_export_surfaces
out=${1:-$CLAY_ROOT/out/demo}
mkdir -p "$out"
"$CLAY_BUILD/examples/example_01_export_surfaces" "$out"
echo
echo "==> what the files hold (clayform info):"
"$CLAY_BUILD/cli/clayform" info "$out/sample.step"
echo
echo "Outputs in $out:"
ls -1 "$out" | sed "s|^|  $out/|"
