#!/usr/bin/env bash
# A real-size project (not a test): 100 photos of 4000x3000 (12 megapixels), made by enlarging a
# generated scene's 800x600 renders five times (the camera model scaled with them, so the
# geometry is exact; the photos are as blurred as such an enlargement makes them). Carved at the
# defaults (--max_image_size 2400) at 128 and 256 voxels: wall time and the process's peak
# resident memory (/usr/bin/time), and the stage times from report.json. Prints a Markdown table.
# Needs about 3 GB of disk under out/large_project/.
# Usage: scripts/run_large_project.sh
set -euo pipefail
cd "$(dirname "$0")/.."
command -v convert > /dev/null || { echo "run_large_project.sh needs convert (apt-get install imagemagick)" >&2; exit 1; }
command -v python3 > /dev/null || { echo "run_large_project.sh needs python3 (apt-get install python3)" >&2; exit 1; }
scripts/setup.sh raycarve >&2
rc=build/plugin/raycarve
out=out/large_project
mkdir -p "$out"
if [ ! -f "$out/project/sparse/0/cameras.txt" ]; then
  rm -rf "$out/small" "$out/project"
  $rc synth --output_path "$out/small" --views 100 --width 800 --height 600 --backdrop uniform \
    --texture detailed > "$out/synth.log" 2>&1
  mkdir -p "$out/project/images" "$out/project/sparse/0"
  $rc model_converter --input_path "$out/small/sparse/0" --output_path "$out/project/sparse/0" \
    --output_type TXT > /dev/null
  # Five times the pixels along each side: cameras (size, focal lengths, principal point) and
  # every 2D observation scale by 5 (COLMAP's pixel convention has its corner at 0).
  python3 - "$out/project/sparse/0" <<'PY'
import sys
d = sys.argv[1]
lines = open(d + "/cameras.txt").read().splitlines()
out = []
for line in lines:
    if line.startswith("#") or not line.strip():
        out.append(line); continue
    f = line.split()
    cid, model, w, h, params = f[0], f[1], int(f[2]), int(f[3]), [float(x) for x in f[4:]]
    n = 3 if model in ("SIMPLE_PINHOLE", "SIMPLE_RADIAL", "RADIAL", "SIMPLE_RADIAL_FISHEYE", "RADIAL_FISHEYE") else 4
    params = [p * 5 if i < n else p for i, p in enumerate(params)]
    out.append(" ".join([cid, model, str(w * 5), str(h * 5)] + ["%.17g" % p for p in params]))
open(d + "/cameras.txt", "w").write("\n".join(out) + "\n")
lines = open(d + "/images.txt").read().splitlines()
out, header, odd = [], True, False
for line in lines:
    if line.startswith("#"):
        out.append(line); continue
    if not odd:
        out.append(line)
    else:
        f = line.split()
        scaled = []
        for i in range(0, len(f), 3):
            scaled += ["%.17g" % (float(f[i]) * 5), "%.17g" % (float(f[i + 1]) * 5), f[i + 2]]
        out.append(" ".join(scaled))
    odd = not odd
open(d + "/images.txt", "w").write("\n".join(out) + "\n")
PY
  for photo in "$out/small/images/"*.png; do
    convert "$photo" -filter Triangle -resize 4000x3000! -quality 10 \
      "$out/project/images/$(basename "$photo")"
  done
fi
echo "| voxels | wall s | peak resident MiB | photos and masks s | carve s | mesh s |"
echo "|---:|---:|---:|---:|---:|---:|"
for resolution in 128 256; do
  dir="$out/carve_$resolution"
  /usr/bin/time -f "%e %M" -o "$dir.time" $rc carve --workspace_path "$out/project" \
    --output_path "$dir" --resolution "$resolution" > "$dir.log" 2>&1
  read -r wall rss < "$dir.time"
  stages=$(python3 -c 'import json,sys; s=json.load(open(sys.argv[1]))["stage_seconds"]; print("%.1f | %.1f | %.1f" % (s["load_project"], s["carve_setup"] + s["carve"], s["mesh"]))' "$dir/report.json")
  echo "| $resolution | $wall | $((rss / 1024)) | $stages |"
done
