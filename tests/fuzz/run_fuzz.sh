#!/usr/bin/env bash
# Runs a libFuzzer target for SECONDS from a scratch copy of its corpus (the committed corpus is
# never written); a crash leaves its input in the scratch folder and fails.
# Usage: run_fuzz.sh TARGET CORPUS SECONDS
set -euo pipefail
target=$1 corpus=$2 seconds=$3
scratch=$(mktemp -d)
trap 'rm -rf "$scratch"' EXIT
cp -r "$corpus"/. "$scratch"/
mkdir -p "$scratch/artifacts"
set +e
"$target" -max_total_time="$seconds" -rss_limit_mb=2048 -malloc_limit_mb=1024 -timeout=20 \
  -artifact_prefix="$scratch/artifacts/" "$scratch" > "$scratch/log" 2>&1
status=$?
set -e
{ grep -aE "^#[0-9]+[[:space:]]+(DONE|INITED)|ERROR|SUMMARY|Done [0-9]+ runs" "$scratch/log" || true; } | tail -5
[ "$status" -ne 0 ] && tail -40 "$scratch/log"
if [ "$status" -ne 0 ]; then
  echo "fuzz target failed (exit $status); inputs:" && ls -la "$scratch/artifacts"
  for f in "$scratch"/artifacts/*; do [ -f "$f" ] && cp "$f" "/tmp/$(basename "$f")" && echo "kept /tmp/$(basename "$f")"; done
fi
exit "$status"
