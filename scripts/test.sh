#!/usr/bin/env bash
# Builds Clayform and runs the whole test suite through CTest. Installs missing Debian packages
# first (as root, or through sudo). Extra arguments go to ctest (e.g. -R exchange).
source "$(dirname "${BASH_SOURCE[0]}")/common.sh"
clay_ensure_packages
clay_build
echo "==> running the test suite"
cd "$CLAY_BUILD"
ctest --output-on-failure --parallel "$(clay_jobs)" --timeout 900 "$@"
