#!/usr/bin/env bash
# report.html in a real browser: carves a generated scene at the defaults, then opens the page
# from disk in headless Chromium (tests/pipeline/report_page_check.mjs): no console errors, the 3D
# view ready, the model on its canvas. Usage: report_page_test.sh <raycarve> <source dir>
# Exits 77 (CTest: skipped) where Chromium, Node.js or the viewer's npm packages are missing;
# scripts/setup.sh installs all three.
set -euo pipefail
raycarve=$1
source_dir=$2
viewer="$source_dir/pipeline/viewer"
chromium=${RAYCARVE_CHROMIUM:-/usr/bin/chromium}
for need in "$chromium" "$(command -v node || echo node)" "$viewer/node_modules/playwright-core"; do
  if [ ! -e "$need" ]; then
    echo "SKIPPED: $need is missing (scripts/setup.sh installs chromium, nodejs and the viewer's npm packages)"
    exit 77
  fi
done
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
"$raycarve" synth --output_path "$work/scene" > "$work/synth.log" 2>&1
"$raycarve" carve --workspace_path "$work/scene" > "$work/carve.log" 2>&1 ||
  { tail -20 "$work/carve.log"; exit 1; }
page="$work/scene/raycarve/report.html"
if ! grep -q 'id="view-status"' "$page"; then
  echo "FAILED: $page has no 3D view (raycarve was built without the viewer's scripts: run scripts/setup.sh)"
  exit 1
fi
for part in '<h2>Summary</h2>' 'src="preview.png"' '<h2>Convergence</h2>'; do
  grep -q "$part" "$page" || { echo "FAILED: $page lacks $part"; exit 1; }
done
RAYCARVE_VIEWER_DIR="$viewer" RAYCARVE_CHROMIUM="$chromium" \
  node "$source_dir/tests/pipeline/report_page_check.mjs" "$page" "$work/view.png"
