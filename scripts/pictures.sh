#!/usr/bin/env bash
# Renders the README pictures: runs every example recipe (examples/recipes/*.json) with
# `clayform run` and draws its STEP output with `clayform render` into docs/pictures/NAME.png
# (whole-model recipes: the model as read and each deformed model, docs/pictures/model_*.png),
# then a zebra picture of the sail through the browser viewer (`clayform snapshot --bare`) and the
# studio's walkthrough pictures (viewer/e2e/studio_walkthrough.mjs).
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
  eye=()  # the default view, except where a shape faces elsewhere
  case $name in sail) eye=(--eye 0.35 1 0.25) ;; bottle_model) eye=(--eye -1 -1.2 0.5) ;; esac
  case $name in
    *_model)  # whole models: the model as read, then each deformed model (one picture each)
      source=$(sed -n 's/.*"import": "\.\.\/models\/\([a-z_]*\)\.step".*/\1/p' "$recipe" | head -1)
      "$clayform" render "$CLAY_ROOT/examples/models/$source.step" --png "$pictures/model_$source.png" \
        --width 480 --height 320 "${eye[@]}"
      for step in "$out"/*.step; do
        "$clayform" render "$step" --png "$pictures/model_$(basename "$step" .step).png" \
          --width 480 --height 320 "${eye[@]}"
      done ;;
    *)  # one picture per recipe: its first export (the recipes export one group each)
      steps=("$out"/*.step)
      "$clayform" render "${steps[0]}" --png "$pictures/$name.png" --width 640 --height 420 \
        "${eye[@]}" ;;
  esac
done
"$CLAY_ROOT/scripts/viewer.sh"
"$clayform" snapshot "$CLAY_BUILD/pictures/sail" --png "$pictures/sail_zebra.png" --width 900 --height 560 \
  --mode zebra --bare
# Clayform Studio: the docs' walkthrough (a car hood styled from scratch) played in headless
# Chromium, a picture per step (docs/pictures/studio-*.png).
[[ -x ${CHROMIUM:-/usr/bin/chromium} ]] || {
  echo "scripts/pictures.sh: the studio's pictures need Debian's chromium (apt-get install chromium)" >&2
  exit 1
}
(cd "$CLAY_ROOT/viewer" && node e2e/studio_walkthrough.mjs --clayform "$clayform" --out "$pictures")
ls -la "$pictures"
