#!/usr/bin/env bash
# What carve, holdout and benchmark produce, reduced to digests and figures that a change which
# should not alter behaviour (a refactoring) must leave the same: SHA-256 of every PLY, of the
# textured mesh (OBJ, GLB, texture), and every
# figure of the JSON reports except timings, memory, paths and the build's identity.
#
# Usage: scripts/output_digests.sh OUT_DIR [RAYCARVE]  > digests.txt
#   Runs on one thread (byte-for-byte outputs), on the demo scene (generated) and the three
#   Middlebury sets' given models (from ${RAYCARVE_DATA_DIR:-../shared/data}; skipped when absent).
#   Compare two builds with: diff before.txt after.txt   (no output: the same).
set -euo pipefail
out=${1:?usage: output_digests.sh OUT_DIR [RAYCARVE]}
raycarve=${2:-build/plugin/raycarve}
data=${RAYCARVE_DATA_DIR:-$(dirname "$0")/../../shared/data}
mkdir -p "$out"
quiet() { "$@" > "$out/last.log" 2>&1 || { cat "$out/last.log" >&2; return 1; }; }

# Every JSON figure but the ones that change from run to run, one "path = value" a line.
figures() {
  python3 - "$1" <<'EOF'
import json, re, sys
skip = re.compile(r"seconds|time|memory|_mib|bytes|commit|command_line|version|path|runs|"
                  r"threads|thread_work|core_|summary|carve$")
def walk(prefix, value):
    if isinstance(value, dict):
        for key, item in value.items():
            if not skip.search(key):
                walk(prefix + "." + key, item)
    elif isinstance(value, list):
        for i, item in enumerate(value):
            walk("%s[%d]" % (prefix, i), item)
    else:
        print("%s = %s" % (prefix, json.dumps(value)))
walk(sys.argv[1].split("/")[-1], json.load(open(sys.argv[1])))
EOF
}
digest() { for f in "$@"; do echo "$(basename "$(dirname "$f")")/$(basename "$f") $(sha256sum < "$f" | cut -c1-16)"; done; }

quiet "$raycarve" synth --output_path "$out/demo" --camera_model OPENCV --views 8 --width 640 --height 480
quiet "$raycarve" carve --workspace_path "$out/demo" --output_path "$out/demo_carve" --num_threads 1
echo "== demo: carve at the defaults, one thread"
digest "$out"/demo_carve/{cloud,mesh}.ply "$out"/demo_carve/mesh{.obj,.glb,_texture.png}
figures "$out/demo_carve/report.json"
quiet "$raycarve" holdout --workspace_path "$out/demo" --output_path "$out/demo_carve" --num_threads 1
echo "== demo: holdout at the defaults, one thread"
digest "$out/demo_carve/holdout/mesh.ply"
figures "$out/demo_carve/holdout/holdout.json"
quiet "$raycarve" benchmark --workspace_path "$out/demo" --output_path "$out/demo_carve" --resolution 64
echo "== demo: benchmark at 64 voxels"
digest "$out"/demo_carve/benchmark/cloud_*.ply
figures "$out/demo_carve/benchmark/benchmark.json"

for set in templeSparseRing dinoSparseRing dinoRing; do
  if [ ! -d "$data/middlebury/$set" ]; then
    echo "== $set: skipped ($data/middlebury/$set not found)"
    continue
  fi
  quiet "$raycarve" carve --input_path "$data/middlebury/$set/colmap/given" \
    --image_path "$data/middlebury/$set" --output_path "$out/$set" --num_threads 1
  echo "== $set (given model): carve at the defaults, one thread"
  digest "$out/$set"/{cloud,mesh}.ply "$out/$set"/mesh{.obj,.glb,_texture.png}
  figures "$out/$set/report.json"
done
if [ -d "$data/middlebury/templeSparseRing" ]; then
  quiet "$raycarve" holdout --input_path "$data/middlebury/templeSparseRing/colmap/given" \
    --image_path "$data/middlebury/templeSparseRing" --output_path "$out/templeSparseRing" --num_threads 1
  echo "== templeSparseRing (given model): holdout at the defaults, one thread"
  digest "$out/templeSparseRing/holdout/mesh.ply"
  figures "$out/templeSparseRing/holdout/holdout.json"
fi
