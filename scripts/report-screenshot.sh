#!/usr/bin/env bash
# A screenshot of a map run's whole report.html, as headless Chromium draws it (software WebGL for
# the 3-D view), e.g. docs/images/report.png:
#   bash scripts/report-screenshot.sh OUT/map/report.html docs/images/report.png [SCALE]
# SCALE (default 0.6) shrinks the 1280-pixel-wide page; the picture is as tall as the page.
set -euo pipefail
report=$(realpath "$1")
png=$(realpath -m "$2")
scale=${3:-0.6}
command -v chromium > /dev/null || { echo "report-screenshot: chromium is not installed (scripts/install-deps.sh)" >&2; exit 1; }
work=$(mktemp -d)
measure="$(dirname "$report")/.report-screenshot-$$.html"
trap 'rm -rf "$work" "$measure"' EXIT

chromium_run() {
  timeout 120 chromium --headless=new --no-sandbox --disable-gpu --disable-dev-shm-usage --use-angle=swiftshader \
    --enable-unsafe-swiftshader --user-data-dir="$work/profile" --hide-scrollbars \
    --virtual-time-budget=10000 "$@" 2> "$work/chromium.log"
}

# The page's height: a copy beside the report (its pictures load) notes it on <html>.
sed 's|</body></html>|<script>addEventListener("load", function () { document.documentElement.setAttribute("data-height", document.documentElement.scrollHeight); });</script></body></html>|' \
  "$report" > "$measure"
height=$(chromium_run --window-size=1280,1000 --dump-dom "file://$measure" |
         grep -o 'data-height="[0-9]*"' | head -1 | grep -o '[0-9]*') ||
  { cat "$work/chromium.log" >&2; echo "report-screenshot: could not measure $report" >&2; exit 1; }
chromium_run --window-size="1280,$height" --force-device-scale-factor="$scale" \
  --screenshot="$png" "file://$report" > /dev/null ||
  { cat "$work/chromium.log" >&2; exit 1; }
echo "report-screenshot: $png ($height CSS pixels tall, scale $scale)"
