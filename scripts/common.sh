# Shared by scripts/demo.sh and scripts/test.sh: install what is missing, configure once, build
# what is stale. Source it; do not run it.
set -euo pipefail

CLAY_ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
CLAY_BUILD=${CLAYFORM_BUILD_DIR:-$CLAY_ROOT/build}

clay_jobs() { nproc 2>/dev/null || echo 2; }

# Installs every package of scripts/packages.txt that dpkg does not list as installed.
clay_ensure_packages() {
  local wanted=() missing=() p
  while read -r p _; do
    [[ -z "$p" || "$p" == \#* ]] && continue
    wanted+=("$p")
  done < "$CLAY_ROOT/scripts/packages.txt"
  for p in "${wanted[@]}"; do
    if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
      missing+=("$p")
    fi
  done
  if ((${#missing[@]} > 0)); then
    echo "==> installing missing Debian packages: ${missing[*]}"
    local sudo=""
    if [[ $(id -u) -ne 0 ]]; then
      command -v sudo >/dev/null || {
        echo "Missing Debian packages: ${missing[*]}. Install them as root (apt-get install ...), or install sudo, then run this again." >&2
        exit 1
      }
      sudo="sudo"
    fi
    $sudo apt-get update
    DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y "${missing[@]}"
  fi
}

# Configures the build tree the first time and rebuilds only what is stale.
clay_build() {
  if [[ ! -f "$CLAY_BUILD/CMakeCache.txt" ]]; then
    echo "==> configuring $CLAY_BUILD"
    cmake -S "$CLAY_ROOT" -B "$CLAY_BUILD" -G Ninja -DCMAKE_BUILD_TYPE=Release -DCLAYFORM_WERROR=ON
  fi
  echo "==> building (only what is stale)"
  cmake --build "$CLAY_BUILD" --parallel "$(clay_jobs)" "$@"
}
