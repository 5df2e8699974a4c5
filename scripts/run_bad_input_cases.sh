#!/usr/bin/env bash
# Issue 43's cases, as a careless or unlucky user meets them, run against one raycarve binary:
# each builds its situation in a fresh folder, runs the command, and is classed
#   clear  exit 1 with a message naming the path or option (or, for valid input, exit 0 with a
#          model), every input byte-identical
#   unclear exit 1 but the message does not say what it names, or exit 2 ("unexpected error")
#   wrong  exit 0 on nonsense, or a hang (killed after 60 s)
#   LOST   an input file changed
# Usage: scripts/run_bad_input_cases.sh [RAYCARVE] > table.md   (needs cjpeg: libjpeg-turbo-progs;
# the permission cases run as nobody through setpriv when run as root)
set -uo pipefail
raycarve=$(realpath "${1:-build/plugin/raycarve}")
command -v cjpeg > /dev/null || { echo "needs cjpeg: apt-get install libjpeg-turbo-progs" >&2; exit 1; }
work=$(mktemp -d /tmp/raycarve_cases_XXXXXX)
chmod 755 "$work"
trap 'chmod -R u+rwX "$work"; rm -rf "$work"' EXIT
cp "$raycarve" "$work/raycarve" && chmod 755 "$work/raycarve"
rc="$work/raycarve"
as_nobody=""
[ "$(id -u)" -eq 0 ] && as_nobody="setpriv --reuid=65534 --regid=65534 --clear-groups"
"$rc" synth --output_path "$work/base" --views 4 --width 96 --height 72 --points 300 \
  --backdrop uniform > /dev/null 2>&1 || { echo "synth failed" >&2; exit 1; }
declare -A count
echo "| case | exit | class | message |"
echo "|---|---:|---|---|"

# fresh NAME: a copy of the generated project at $work/NAME; sums of every file under it
fresh() { rm -rf "${work:?}/$1"; cp -r "$work/base" "$work/$1"; chmod -R a+rX "$work/$1"; }
sums() { find "$@" -type f -exec sha256sum {} + 2>/dev/null | sort; }

# case NAME EXPECT WATCH -- COMMAND...: EXPECT is "error" (exit 1 with WANT in the message) or
# "ok"; WATCH the folder whose files must not change; WANT in $want.
run_case() {
  local name=$1 expect=$2 watch=$3
  shift 4
  local before after out status class
  before=$(sums "$watch")
  out=$(timeout 60 "$@" 2>&1 < /dev/null)
  status=$?
  after=$(sums "$watch")
  local line
  line=$(echo "$out" | grep -E "error|warning|kept nothing" | grep -v "^I20" | tail -1 | cut -c1-150)
  if [ "$before" != "$after" ]; then
    class=LOST
  elif [ $status -eq 124 ] || [ $status -eq 137 ]; then
    class=wrong; line="(killed after 60 s)"
  elif [ "$expect" = ok ]; then
    if [ $status -eq 0 ] && ! echo "$out" | grep -q "kept nothing"; then class=clear; else class=wrong; fi
  elif [ $status -eq 1 ] && echo "$out" | grep -qF -- "$want"; then
    class=clear
  elif [ $status -eq 0 ]; then
    class=wrong
  else
    class=unclear
  fi
  count[$class]=$(( ${count[$class]:-0} + 1 ))
  echo "| $name | $status | $class | ${line//|/\\|} |"
}

# Links inside the output folder and outputs into inputs.
fresh l1; "$rc" carve --workspace_path "$work/l1" --output_path "$work/l1/out" --resolution 16 > /dev/null 2>&1
cp -r "$work/l1/masks" "$work/l1_masks"; rm -rf "$work/l1/out/masks"; ln -s "$work/l1_masks" "$work/l1/out/masks"
want="symbolic link"; run_case "carve: out/masks a link to the user's masks" error "$work/l1_masks" -- \
  "$rc" carve --workspace_path "$work/l1" --output_path "$work/l1/out" --resolution 16
want="mask"; run_case "carve --mask_path M: out/masks a link to M" error "$work/l1_masks" -- \
  "$rc" carve --workspace_path "$work/l1" --output_path "$work/l1/out" --resolution 16 --mask_path "$work/l1_masks"
rm "$work/l1/out/masks"; echo "user's file" > "$work/l1_file"; rm -f "$work/l1/out/mesh.ply"; ln -s "$work/l1_file" "$work/l1/out/mesh.ply"
want="symbolic link"; run_case "carve: out/mesh.ply a link to a user's file" error "$work/l1_file" -- \
  "$rc" carve --workspace_path "$work/l1" --output_path "$work/l1/out" --resolution 16
fresh l2; mkdir -p "$work/l2/out"; ln -s "$work/l2/images" "$work/l2/out/undistorted"
want="undistorted"; run_case "calibrate: out/undistorted a link to the photos" error "$work/l2/images" -- \
  "$rc" calibrate --workspace_path "$work/l2" --output_path "$work/l2/out"
fresh l3; mkdir -p "$work/l3/out"; ln -s "$work/l3/images" "$work/l3/out/holdout"
want="holdout"; run_case "holdout: out/holdout a link to the photos" error "$work/l3/images" -- \
  "$rc" holdout --workspace_path "$work/l3" --output_path "$work/l3/out" --resolution 16 --every 2
fresh l4; "$rc" carve --workspace_path "$work/l4" --output_path "$work/l4/out" --resolution 16 > /dev/null 2>&1
want="photo folder"; run_case "render into the photo folder" error "$work/l4/images" -- \
  "$rc" render --cloud_path "$work/l4/out/cloud.ply" --input_path "$work/l4/sparse/0" \
  --image_path "$work/l4/images" --output_path "$work/l4/images"

# Two carves into one folder at once: the first must finish whole.
fresh t1
( "$rc" carve --workspace_path "$work/t1" --output_path "$work/t1/out" --resolution 128 --min_voxel_pixels 0 > "$work/t1_first.log" 2>&1; echo $? > "$work/t1_first.status" ) &
sleep 0.3
want="another raycarve run"; run_case "a second carve into a folder in use" error "$work/t1/images" -- \
  "$rc" carve --workspace_path "$work/t1" --output_path "$work/t1/out" --resolution 128 --min_voxel_pixels 0
wait
first=$(cat "$work/t1_first.status")
echo "| (the first carve of the two) | $first | $([ "$first" = 0 ] && echo clear || echo wrong) | $(grep error "$work/t1_first.log" | tail -1 | cut -c1-120) |"
if [ "$first" = 0 ]; then count[clear]=$(( ${count[clear]:-0} + 1 )); else count[wrong]=$(( ${count[wrong]:-0} + 1 )); fi

# Filesystem failures (outputs in a folder nobody may write).
mkdir -p "$work/w"; chmod 777 "$work/w"
fresh f1; chmod 000 "$work/f1/images"
want="images"; run_case "photo folder without read permission (as nobody)" error "$work/base" -- \
  $as_nobody "$rc" carve --workspace_path "$work/f1" --output_path "$work/w/f1_out" --resolution 16
chmod 755 "$work/f1/images"; chmod 000 "$work/f1/images/view001.png"
want="view001.png"; run_case "a photo without read permission (as nobody)" error "$work/base" -- \
  $as_nobody "$rc" carve --workspace_path "$work/f1" --output_path "$work/w/f1_out" --resolution 16
chmod 644 "$work/f1/images/view001.png"; mkdir -p "$work/ro"; chmod 555 "$work/ro"
want="$work/ro"; run_case "output folder in a read-only folder (as nobody)" error "$work/base" -- \
  $as_nobody "$rc" carve --workspace_path "$work/f1" --output_path "$work/ro/out" --resolution 16
ln -s "$work/loop_b" "$work/loop_a"; ln -s "$work/loop_a" "$work/loop_b"
want="loop_a"; run_case "a symbolic-link loop as the workspace" error "$work/base" -- \
  "$rc" carve --workspace_path "$work/loop_a"
want="File name too long"; run_case "an output name of 300 bytes" error "$work/base" -- \
  "$rc" carve --workspace_path "$work/f1" --output_path "$work/$(printf 'x%.0s' $(seq 300))" --resolution 16
want="--mesh_samples"; run_case "compare --mesh_samples 2000000000" error "$work/base" -- \
  "$rc" compare --reference_path "$work/base/truth.ply" --input_path "$work/base/truth.ply" --mesh_samples 2000000000

# Damaged photos and odd paths.
fresh p1; djpeg -h > /dev/null 2>&1
"$rc" render --help > /dev/null 2>&1
for view in view001; do
  # A PNG is re-encoded as JPEG through PPM (cjpeg reads PPM): the photo's own pixels.
  python3 - "$work/p1/images/$view.png" "$work/p1/$view.ppm" <<'EOF'
import struct, sys, zlib
data = open(sys.argv[1], 'rb').read()
pos, chunks = 8, {}
idat = b''
while pos < len(data):
    length, kind = struct.unpack('>I4s', data[pos:pos + 8])
    body = data[pos + 8:pos + 8 + length]
    if kind == b'IHDR': width, height, depth, colour = struct.unpack('>IIBB', body[:10])
    if kind == b'IDAT': idat += body
    pos += 12 + length
raw = zlib.decompress(idat)
channels = {2: 3, 6: 4, 0: 1}[colour]
stride = width * channels
rows, previous = [], bytearray(stride)
for y in range(height):
    f = raw[y * (stride + 1)]
    line = bytearray(raw[y * (stride + 1) + 1:(y + 1) * (stride + 1)])
    for x in range(stride):
        a = line[x - channels] if x >= channels else 0
        b = previous[x]
        c = previous[x - channels] if x >= channels else 0
        if f == 1: line[x] = (line[x] + a) & 255
        elif f == 2: line[x] = (line[x] + b) & 255
        elif f == 3: line[x] = (line[x] + (a + b) // 2) & 255
        elif f == 4:
            p = a + b - c; pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
            line[x] = (line[x] + (a if pa <= pb and pa <= pc else b if pb <= pc else c)) & 255
    rows.append(bytes(line)); previous = line
pixels = b''.join(bytes(r[i:i + 3]) for r in rows for i in range(0, stride, channels))
open(sys.argv[2], 'wb').write(b'P6 %d %d 255\n' % (width, height) + pixels)
EOF
  cjpeg -quality 95 "$work/p1/$view.ppm" > "$work/p1/$view.jpg"
done
size=$(stat -c %s "$work/p1/view001.jpg")
head -c $(( size / 2 )) "$work/p1/view001.jpg" > "$work/p1/images/view001.png"
want="view001.png"; run_case "a JPEG photo cut in half" error "$work/base" -- \
  "$rc" carve --workspace_path "$work/p1" --output_path "$work/p1_out" --resolution 16
cp "$work/p1/view001.jpg" "$work/p1/images/view001.png"
printf '\xff\xd0\xff\xd1\xff\xd2\xff\xd3' | dd of="$work/p1/images/view001.png" bs=1 seek=$(( size / 2 )) conv=notrunc 2> /dev/null
want="view001.png"; run_case "a JPEG photo with corrupt data" error "$work/base" -- \
  "$rc" carve --workspace_path "$work/p1" --output_path "$work/p1_out" --resolution 16
cp "$work/p1/view001.jpg" "$work/p1/images/view001.png"
want="unused"; run_case "a whole JPEG photo (valid)" ok "$work/base" -- \
  "$rc" carve --workspace_path "$work/p1" --output_path "$work/p1_out" --resolution 16
fresh p2; rm "$work/p2/images/view002.png"; mkdir "$work/p2/images/view002.png"
want="is a folder"; run_case "a folder where a photo is expected" error "$work/base" -- \
  "$rc" carve --workspace_path "$work/p2" --output_path "$work/p2_out" --resolution 16
rmdir "$work/p2/images/view002.png"; mkfifo "$work/p2/images/view002.png"
want="FIFO"; run_case "a FIFO where a photo is expected" error "$work/base" -- \
  "$rc" carve --workspace_path "$work/p2" --output_path "$work/p2_out" --resolution 16
fresh p3; rm "$work/p3/sparse/0/cameras.bin"; mkdir "$work/p3/sparse/0/cameras.bin"
want="cameras.bin"; run_case "cameras.bin is a folder" error "$work/base" -- \
  "$rc" model_info --input_path "$work/p3/sparse/0"

# Nonsense values.
fresh n1
want="margin"; run_case "--margin 1e308" error "$work/base" -- \
  "$rc" carve --workspace_path "$work/n1" --margin 1e308
want="--max_image_size"; run_case "--max_image_size 1" error "$work/base" -- \
  "$rc" carve --workspace_path "$work/n1" --max_image_size 1
"$rc" model_converter --input_path "$work/n1/sparse/0" --output_path "$work/n1_txt" --output_type TXT > /dev/null 2>&1
sed -i -E 's/^([0-9]+ [A-Z_]+ [0-9]+ [0-9]+) [^ ]+/\1 1e-300/' "$work/n1_txt/cameras.txt"
want="focal length"; run_case "a focal length of 1e-300" error "$work/base" -- \
  "$rc" carve --input_path "$work/n1_txt" --image_path "$work/n1/images" --output_path "$work/n1_out"
"$rc" synth --output_path "$work/fish" --views 4 --width 96 --height 72 --points 300 \
  --camera_model OPENCV_FISHEYE > /dev/null 2>&1
"$rc" model_converter --input_path "$work/fish/sparse/0" --output_path "$work/fish_txt" --output_type TXT > /dev/null 2>&1
sed -i -E 's/^([0-9]+ OPENCV_FISHEYE( [^ ]+){6}) [^ ]+/\1 -1e12/' "$work/fish_txt/cameras.txt"
want="folds the image"; run_case "calibrate: a fisheye k1 of -1e12" error "$work/fish" -- \
  "$rc" calibrate --input_path "$work/fish_txt" --image_path "$work/fish/images" --output_path "$work/fish_out"

# Project files and models.
printf '\xef\xbb\xbfresolution=16\r\n' > "$work/bom.ini"
want="unused"; run_case "an INI file with a byte-order mark and CRLF" ok "$work/base" -- \
  "$rc" carve --workspace_path "$work/n1" --output_path "$work/ini_out" --project_path "$work/bom.ini"
want="--project_path"; run_case "--project_path last without a value" error "$work/base" -- \
  "$rc" carve --workspace_path "$work/n1" --output_path "$work/ini_out" --resolution 16 --project_path
mkdir -p "$work/one"; echo "1 PINHOLE 640 480 500 500 320 240" > "$work/one/cameras.txt"
printf '1 1 0 0 0 0 0 5 1 view001.png\n\n' > "$work/one/images.txt"; : > "$work/one/points3D.txt"
want="unused"; run_case "model_info of a one-image model" ok "$work/one" -- "$rc" model_info --input_path "$work/one"

# A carve in tiles.
want="lies in the input"; run_case "tile plan into the photo folder" error "$work/base" -- \
  "$rc" tile plan --workspace_path "$work/base" --resolution 128 --min_voxel_pixels 0 --tile_path "$work/base/images/tiles"
echo '[1, 2' > "$work/not_a_plan.json"
want="not_a_plan.json"; run_case "tile run of a plan that is not JSON" error "$work/base" -- \
  "$rc" tile run --plan "$work/not_a_plan.json" --index 0
fresh tp
"$rc" tile plan --workspace_path "$work/tp" --resolution 128 --min_voxel_pixels 0 --tile_path "$work/tp_tiles" > /dev/null 2>&1
want="tile_0.bin"; run_case "tile merge before any tile ran" error "$work/tp" -- \
  "$rc" tile merge --plan "$work/tp_tiles/plan.json"

echo
echo "clear ${count[clear]:-0}, unclear ${count[unclear]:-0}, wrong ${count[wrong]:-0}, lost ${count[LOST]:-0}"
