#!/usr/bin/env bash
# Renders the README pictures: runs every example recipe (examples/recipes/*.json) with
# `clayform run` and draws its STEP output with `clayform render` into docs/pictures/NAME.png,
# then a zebra picture of the sail through the browser viewer (`clayform snapshot --bare`).
# Installs missing Debian packages and builds first, like the other scripts.
source "$(dirname "${BASH_SOURCE[0]}")/common.sh"
clay_ensure_packages
clay_build --target clayform
clayform="$CLAY_BUILD/cli/clayform"
pictures="$CLAY_ROOT/docs/pictures"
mkdir -p "$pictures"
for recipe in "$CLAY_ROOT"/examples/recipes/*.json; do
  name=$(basename "$recipe" .json)
  out="$CLAY_BUILD/pictures/$name"
  "$clayform" run "$recipe" --out "$out" --quiet > /dev/null
  steps=("$out"/*.step)
  eye=()  # the default view, except where a shape faces elsewhere
  case $name in sail) eye=(--eye 0.35 1 0.25) ;; esac
  # one picture per recipe: its first export (the recipes export one group each)
  "$clayform" render "${steps[0]}" --png "$pictures/$name.png" --width 640 --height 420 "${eye[@]}"
done
"$CLAY_ROOT/scripts/viewer.sh"
"$clayform" snapshot "$CLAY_BUILD/pictures/sail" --png "$pictures/sail_zebra.png" --width 900 --height 560 \
  --mode zebra --bare
ls -la "$pictures"
