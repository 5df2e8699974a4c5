#!/usr/bin/env bash
# Replaces a generated project's sparse points (exact samples of the truth, seen by every photo
# that sees them) with what COLMAP finds in its photos: SIFT features, matched exhaustively and
# triangulated at the project's true poses (colmap point_triangulator). The points then carry
# COLMAP's density, tracks, noise and wrong matches, as a user's model does, while the cameras
# stay exact, so every measure against the truth still applies.
# Usage: scripts/triangulate_sift_points.sh PROJECT   (PROJECT/images, PROJECT/sparse/0; one camera)
set -euo pipefail
project=$1
[ -d "$project/images" ] && [ -d "$project/sparse/0" ] || { echo "$project: needs images/ and sparse/0/" >&2; exit 1; }
command -v colmap > /dev/null || { echo "triangulate_sift_points.sh needs colmap" >&2; exit 1; }
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
mkdir -p "$work/true" "$work/known" "$work/triangulated"
colmap model_converter --input_path "$project/sparse/0" --output_path "$work/true" --output_type TXT > "$work/log" 2>&1
colmap feature_extractor --database_path "$work/db.db" --image_path "$project/images" \
  --ImageReader.camera_model PINHOLE --ImageReader.single_camera 1 --SiftExtraction.use_gpu 0 >> "$work/log" 2>&1
colmap exhaustive_matcher --database_path "$work/db.db" --SiftMatching.use_gpu 0 >> "$work/log" 2>&1
# The true cameras and poses under the database's image ids, with no points.
python3 - "$work" <<'PY'
import sqlite3, struct, sys
work = sys.argv[1]
db = sqlite3.connect(work + "/db.db")
ids = {name: image_id for image_id, name in db.execute("select image_id, name from images")}
cameras = [l.split() for l in open(work + "/true/cameras.txt") if l.strip() and not l.startswith("#")]
if len(cameras) != 1 or cameras[0][1] != "PINHOLE":
    sys.exit("triangulate_sift_points.sh: expects one PINHOLE camera")
_, _, width, height, *params = cameras[0]
db.execute("update cameras set model=1, width=?, height=?, params=?, prior_focal_length=1 where camera_id=1",
           (int(width), int(height), struct.pack("4d", *map(float, params))))
db.commit()
open(work + "/known/cameras.txt", "w").write("1 PINHOLE %s %s %s\n" % (width, height, " ".join(params)))
lines = [l for l in open(work + "/true/images.txt") if not l.startswith("#")]
with open(work + "/known/images.txt", "w") as out:
    for k in range(0, len(lines) - 1, 2):
        t = lines[k].split()
        out.write("%d %s 1 %s\n\n" % (ids[t[9]], " ".join(t[1:8]), t[9]))
open(work + "/known/points3D.txt", "w").close()
PY
colmap point_triangulator --database_path "$work/db.db" --image_path "$project/images" \
  --input_path "$work/known" --output_path "$work/triangulated" >> "$work/log" 2>&1
# The new model beside the old, then swapped in: an interrupted run leaves one whole model.
rm -rf "$project/sparse/0.sift"
cp -r "$work/triangulated" "$project/sparse/0.sift"
mv "$project/sparse/0" "$work/exact"
mv "$project/sparse/0.sift" "$project/sparse/0"
colmap model_analyzer --path "$project/sparse/0" 2>&1 | grep -E "Points:|Mean track|reprojection" | sed 's/^.*\] //' | tr '\n' ' '
echo
