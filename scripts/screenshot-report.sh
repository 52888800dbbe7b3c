#!/usr/bin/env bash
# Renders a validation report in a real browser (Debian's chromium, headless) and saves a
# full-page screenshot, to check the page by eye:
#   ./scripts/screenshot-report.sh REPORT_DIR [OUT.png]
# Installs chromium from Debian if it is missing (root or sudo). The page needs no network.
set -euo pipefail
dir=${1:?usage: screenshot-report.sh REPORT_DIR [OUT.png]}
out=${2:-$dir/report.png}
if ! command -v chromium >/dev/null; then
  SUDO=""; [ "$(id -u)" -ne 0 ] && SUDO=sudo
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends chromium
fi
profile=$(mktemp -d)
trap 'rm -rf "$profile"' EXIT
chromium --headless --no-sandbox --disable-gpu --disable-quic --no-first-run --disable-background-networking \
  --disable-component-update --disable-sync --user-data-dir="$profile" --hide-scrollbars \
  --window-size=1280,${HEIGHT:-6000} --screenshot="$out" "file://$(realpath "$dir")/report.html" 2>/dev/null
echo "wrote $out"
