#!/usr/bin/env bash
# Evidence for automatic masks on backdrops the shared data does not have (not a test; issue
# "object masks for any backdrop"): the dinoSparseRing photos, their object (the masks a default
# carve makes from the black backdrop, edges blended over 1-2 pixels) put in front of three
# backdrops a photographer might use, then the command's defaults on each, with the masks'
# agreement across photos (--agree_masks 1, the default) and without:
#   two_tone  a pale grey-blue wall over a wooden table (the horizon moves from photo to photo)
#   gradient  a sky-blue to white sweep, vignetted
#   cloth     a mottled green cloth with noise
# The dinosaur is pale plaster: the wall and the sweep's white share its colours. Per backdrop:
# mask IoU against the reference masks (min and mean over the 16 photos), and held-out PSNR / IoU
# (every 4th photo left out, scored against the reference masks with --score_mask_path).
# Prints a Markdown table; writes out/backdrop_composites/table.json.
# Needs Python 3 with OpenCV and NumPy (Debian: apt-get install python3-opencv python3-numpy).
# Usage: scripts/run_backdrop_composites.sh   (data: $RAYCARVE_DATA_DIR or ../shared/data)
set -euo pipefail
cd "$(dirname "$0")/.."
python=/usr/bin/python3
"$python" -c "import cv2, numpy" 2> /dev/null || {
  echo "run_backdrop_composites.sh needs python3-opencv and python3-numpy (apt-get install)" >&2
  exit 1
}
data=${RAYCARVE_DATA_DIR:-../shared/data}
set_dir="$data/middlebury/dinoSparseRing"
[ -d "$set_dir" ] || { echo "no $set_dir" >&2; exit 1; }
scripts/setup.sh raycarve >&2
out=out/backdrop_composites
mkdir -p "$out"
model="$set_dir/colmap/given"
build/plugin/raycarve carve --input_path "$model" --image_path "$set_dir" \
  --output_path "$out/reference" > "$out/reference.log" 2>&1
"$python" - "$set_dir" "$out" <<'PY'
import cv2, glob, os, sys
import numpy as np
src, out = sys.argv[1], sys.argv[2]
rng = np.random.default_rng(7)
def backdrop(kind, h, w, i):
    y = np.linspace(0, 1, h)[:, None, None]
    x = np.linspace(0, 1, w)[None, :, None]
    if kind == 'two_tone':  # BGR
        horizon = int(h * (0.5 + 0.08 * np.sin(i)))
        wall = np.array([215, 205, 200], float) * (0.92 + 0.1 * y)
        table = np.array([100, 140, 175], float) * (0.85 + 0.2 * y)
        img = np.where(np.arange(h)[:, None, None] < horizon, wall, table) * np.ones((1, w, 1))
        streak = cv2.GaussianBlur(rng.normal(0, 10, (h, w)).astype(np.float32), (0, 0),
                                  sigmaX=25, sigmaY=1.5)
        img[horizon:] += streak[horizon:, :, None] * 3
    elif kind == 'gradient':
        top, bottom = np.array([220, 160, 120], float), np.array([235, 235, 235], float)
        img = (top * (1 - y) + bottom * y) * np.ones((1, w, 1))
        img *= 1 - 0.35 * ((x - 0.5) ** 2 + (y - 0.5) ** 2)
    else:
        blot = cv2.GaussianBlur(rng.normal(0, 1, (h, w)).astype(np.float32), (0, 0), 20)
        blot /= np.abs(blot).max()
        img = np.array([70, 120, 60], float) * (1 + 0.25 * blot[:, :, None]) + rng.normal(0, 6, (h, w, 1))
    return np.clip(img, 0, 255)
for kind in ['two_tone', 'gradient', 'cloth']:
    os.makedirs(f'{out}/{kind}/images', exist_ok=True)
    for i, path in enumerate(sorted(glob.glob(src + '/*.png'))):
        name = os.path.basename(path)
        photo = cv2.imread(path).astype(float)
        h, w = photo.shape[:2]
        mask = cv2.imread(f'{out}/reference/masks/{name}.png', cv2.IMREAD_GRAYSCALE).astype(np.float32) / 255
        mask = cv2.GaussianBlur(mask, (3, 3), 0.7)[:, :, None]
        composite = mask * photo + (1 - mask) * backdrop(kind, h, w, i)
        cv2.imwrite(f'{out}/{kind}/images/{name}', np.clip(composite, 0, 255).astype(np.uint8))
PY
json_number() { grep -o "\"$2\": [-0-9.e+]*" "$1" | head -1 | sed 's/.*: //'; }
mask_iou() {  # prints "min mean" of the IoU of $1/*.png.png against the reference masks
  "$python" - "$out/reference/masks" "$1" <<'PY'
import cv2, glob, os, sys
import numpy as np
ious = []
for path in sorted(glob.glob(sys.argv[1] + '/*.png')):
    a = cv2.imread(path, cv2.IMREAD_GRAYSCALE) > 0
    other = os.path.join(sys.argv[2], os.path.basename(path))
    b = cv2.imread(other, cv2.IMREAD_GRAYSCALE) > 0 if os.path.exists(other) else np.zeros_like(a)
    ious.append((a & b).sum() / max(1, (a | b).sum()))
print('%.3f %.3f' % (min(ious), sum(ious) / len(ious)))
PY
}
rows=()
echo "| backdrop | agreement | mask IoU min / mean | held-out PSNR / IoU |"
echo "|---|---|---:|---:|"
for kind in two_tone gradient cloth; do
  for agree in 1 0; do
    dir="$out/${kind}_agree$agree"
    build/plugin/raycarve carve --input_path "$model" --image_path "$out/$kind/images" \
      --output_path "$dir/carve" --agree_masks "$agree" > "$dir.carve.log" 2>&1
    read -r iou_min iou_mean <<< "$(mask_iou "$dir/carve/masks")"
    build/plugin/raycarve holdout --input_path "$model" --image_path "$out/$kind/images" \
      --output_path "$dir/holdout" --every 4 --agree_masks "$agree" \
      --score_mask_path "$out/reference/masks" > "$dir.holdout.log" 2>&1
    report="$dir/holdout/holdout/holdout.json"
    psnr=$(json_number "$report" mean_psnr_db) iou=$(json_number "$report" mean_silhouette_iou)
    printf "| %s | %s | %s / %s | %.2f dB / %.3f |\n" "$kind" "$([ "$agree" = 1 ] && echo on || echo off)" \
      "$iou_min" "$iou_mean" "$psnr" "$iou"
    rows+=("{\"backdrop\": \"$kind\", \"agree_masks\": $agree, \"mask_iou_min\": $iou_min, \"mask_iou_mean\": $iou_mean, \"psnr_db\": $psnr, \"silhouette_iou\": $iou}")
  done
done
{
  echo "["
  for i in "${!rows[@]}"; do echo "  ${rows[$i]}$([ "$i" -lt $((${#rows[@]} - 1)) ] && echo ,)"; done
  echo "]"
} > "$out/table.json"
echo "wrote $out/table.json" >&2
