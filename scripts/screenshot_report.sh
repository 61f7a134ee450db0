#!/usr/bin/env bash
# Screenshot a grasp-sim report.html with headless Chromium (Debian's `chromium` package:
# apt-get install -y chromium), to look at what a person sees.
#
#   grasp-sim scenarios/cup.toml --report out/
#   scripts/screenshot_report.sh out/cup/report.html out/cup/report.png
set -euo pipefail
html=$(realpath "$1")
png=${2:-${html%.html}.png}
profile=$(mktemp -d)
trap 'rm -rf "$profile"' EXIT
chromium --headless --no-sandbox --disable-gpu --disable-quic --no-first-run \
  --disable-background-networking --disable-component-update --disable-sync \
  --user-data-dir="$profile" --hide-scrollbars --window-size=${WINDOW:-1400,2600} \
  --screenshot="$png" "file://$html" >/dev/null 2>&1
echo "$png"
