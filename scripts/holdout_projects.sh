# Shared by run_threshold_table.sh and run_thread_table.sh (sourced, not run), with `data` and
# `out` set: json_number FILE KEY reads a number from a report; holdout_projects fills `projects`
# with "SET MODEL FLAGS..." for both COLMAP models of each Middlebury set found under $data and
# the paper's generated scene (made in $out/paper once); write_rows FILE writes `rows` as a JSON
# array.
json_number() { grep -o "\"$2\": [-0-9.e+]*" "$1" | head -1 | sed 's/.*: //'; }

holdout_projects() {
  if [ ! -d "$out/paper/sparse" ]; then
    build/plugin/raycarve synth --output_path "$out/paper" --scene paper --views 14 --width 800 \
      --height 600 > "$out/paper.synth.log" 2>&1
  fi
  projects=()
  local set model
  for set in templeSparseRing dinoSparseRing dinoRing; do
    [ -d "$data/middlebury/$set" ] || { echo "skipping $set: not in $data" >&2; continue; }
    for model in given sfm; do
      projects+=("$set $model --input_path $data/middlebury/$set/colmap/$model --image_path $data/middlebury/$set")
    done
  done
  projects+=("paper generated --workspace_path $out/paper")
}

write_rows() {
  local i
  {
    echo "["
    for i in "${!rows[@]}"; do
      echo "  ${rows[$i]}$([ "$i" -lt $((${#rows[@]} - 1)) ] && echo ,)"
    done
    echo "]"
  } > "$1"
}
