#!/usr/bin/env bash
# Runs Clayform's main job on the bundled default example and prints where the outputs are:
# the sail recipe (examples/recipes/sail.json) — a sail filled from three curves, styled by a bound
# and a target curve, given a billow by a Bézier lattice composed exactly — replayed by
# `clayform run` into STEP (AP214), IGES, a glTF preview and report.json, then `clayform info`
# on the STEP file, and a picture of it through the browser viewer (clayform snapshot). Installs
# missing Debian packages first. Output folder: $1, default ./out/demo.
source "$(dirname "${BASH_SOURCE[0]}")/common.sh"
clay_ensure_packages
clay_build --target clayform
out=${1:-$CLAY_ROOT/out/demo}
"$CLAY_BUILD/cli/clayform" run "$CLAY_ROOT/examples/recipes/sail.json" --out "$out" --progress
echo
echo "==> what the files hold (clayform info):"
"$CLAY_BUILD/cli/clayform" info "$out/sail.step"
echo
echo "==> a picture through the browser viewer (clayform snapshot, headless Chromium):"
"$CLAY_ROOT/scripts/viewer.sh"
"$CLAY_BUILD/cli/clayform" snapshot "$out" --png "$out/sail.png" --width 1280 --height 800
echo "Look at it interactively: $CLAY_BUILD/cli/clayform view $out  (then open the address it prints, with its ?token=)"
echo
echo "Outputs in $out:"
ls -1 "$out" | sed "s|^|  $out/|"
