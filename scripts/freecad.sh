#!/usr/bin/env bash
# Installs the Clayform workbench (freecad/Clayform, docs/freecad.md) into Debian's FreeCAD 0.20
# for the user running it: builds the clayform Python package, copies the workbench into FreeCAD's
# user Mod folder (FreeCAD.getUserAppDataDir()/Mod/Clayform, asked of freecadcmd itself) and
# tells it where the package is (clayform_path.txt). Then start `freecad` and pick the Clayform
# workbench. Installs missing Debian packages first.
#   scripts/freecad.sh            install (build what is stale first)
#   scripts/freecad.sh --start    install, then start FreeCAD
#   scripts/freecad.sh --no-build install what is built (tests: CLAYFORM_PYTHON_DIR names it)
source "$(dirname "${BASH_SOURCE[0]}")/common.sh"
build=1 start=0
for arg in "$@"; do
  case "$arg" in
    --start) start=1 ;;
    --no-build) build=0 ;;
    *) echo "scripts/freecad.sh: unknown argument '$arg' (--start, --no-build)" >&2; exit 2 ;;
  esac
done
if ((build)); then
  clay_ensure_packages
  clay_build --target clayform_python clayform
fi
python_dir=${CLAYFORM_PYTHON_DIR:-$CLAY_BUILD/python}
[[ -f "$python_dir/clayform/__init__.py" ]] || {
  echo "scripts/freecad.sh: no built clayform package in $python_dir; run it without --no-build" >&2
  exit 1
}
command -v freecadcmd >/dev/null || {
  echo "scripts/freecad.sh: freecadcmd not found; install Debian's freecad-python3 (run this script without --no-build, as root or with sudo)" >&2
  exit 1
}
data=$(freecadcmd -c "import FreeCAD; print('USERDATA=' + FreeCAD.getUserAppDataDir())" 2>/dev/null |
  sed -n 's/^USERDATA=//p' | tail -n 1 || true)
[[ -n "$data" ]] || { echo "scripts/freecad.sh: freecadcmd did not say where its user data is" >&2; exit 1; }
mod=${data%/}/Mod/Clayform
rm -rf "$mod"
mkdir -p "$mod"
cp -r "$CLAY_ROOT/freecad/Clayform/." "$mod/"
find "$mod" -name __pycache__ -prune -exec rm -rf {} +
printf '%s\n' "$python_dir" >"$mod/clayform_path.txt"
echo "==> the Clayform workbench is in $mod (the kernel: $python_dir)"
if ((start)); then exec freecad; fi
