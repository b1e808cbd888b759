#!/usr/bin/env bash
# Builds the browser viewer (viewer/dist, served by `clayform view` and `clayform snapshot`) when it
# is missing or older than its sources: `npm ci` (only when the lock file changed) then
# `npm run build`. Installs Debian's nodejs and npm when `node` is missing (Debian 12's Node 18 is
# enough: the viewer is built with Vite 6).
#   scripts/viewer.sh                 build if stale
#   scripts/viewer.sh test [--run D]  build if stale, then the end-to-end test in headless Chromium
#                                     (installs Debian's chromium when /usr/bin/chromium is missing);
#                                     --run D tests against a run folder (clayform run ... --out D)
#   scripts/viewer.sh lint [--fixture FILE]
#                                     ESLint on the page and its tests (viewer/eslint.config.js); with
#                                     --fixture, on FILE as if it were a page source instead
#   scripts/viewer.sh studio-test --clayform PATH [--part NAME] [--report FILE] [--shots DIR]
#                                     build if stale, then Clayform Studio's end-to-end test against
#                                     that clayform (e2e/studio.test.mjs: every part, or one of
#                                     drawing, model, regular, corners, constraints: e2e/studio_NAME.mjs)
set -euo pipefail
ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
VIEWER=$ROOT/viewer

apt_install() {
  local sudo=""
  if [[ $(id -u) -ne 0 ]]; then sudo="sudo"; fi
  echo "==> installing Debian packages: $*"
  $sudo apt-get update
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y "$@"
}

if ! command -v node >/dev/null 2>&1 || ! command -v npm >/dev/null 2>&1; then
  apt_install nodejs npm
fi

cd "$VIEWER"
if [[ ! -f node_modules/.package-lock.json || package-lock.json -nt node_modules/.package-lock.json ]]; then
  echo "==> viewer: npm ci"
  npm ci --no-audit --no-fund
fi
stale=0
if [[ ! -f dist/index.html ]]; then
  stale=1
elif [[ -n $(find index.html studio.html vite.config.js package.json package-lock.json src -newer dist/index.html -print -quit) ]]; then
  stale=1
fi
if ((stale)); then
  echo "==> viewer: npm run build"
  npm run build
else
  echo "==> viewer: dist is up to date"
fi

if [[ "${1:-}" == "lint" ]]; then
  if [[ "${2:-}" == "--fixture" ]]; then
    fixture=${3:?--fixture needs a file}
    [[ $fixture == /* ]] || fixture=$OLDPWD/$fixture  # relative to where the script was called
    echo "==> viewer: ESLint on $fixture as a page source"
    exec npx --no-install eslint --stdin --stdin-filename src/lint-fixture.js <"$fixture"
  fi
  echo "==> viewer: ESLint"
  exec npx --no-install eslint .
fi

if [[ "${1:-}" == "test" || "${1:-}" == "studio-test" ]]; then
  what=$1
  shift
  if [[ ! -x ${CHROMIUM:-/usr/bin/chromium} ]]; then apt_install chromium; fi
  if [[ $what == test ]]; then
    echo "==> viewer: end-to-end test"
    node e2e/viewer.test.mjs "$@"
  else
    echo "==> studio: end-to-end test"
    node e2e/studio.test.mjs "$@"
  fi
fi
