# The seed paper's section 4 variants, shared by run_variants.sh and run_variants_photos.sh
# (sourced, not run): json_number FILE KEY reads a number from a report, and run_all_variants
# calls the sourcing script's `run NAME [carve flags...]` once per variant.
json_number() { grep -o "\"$2\": [-0-9.e+]*" "$1" | head -1 | sed 's/.*: //'; }

run_all_variants() {
  # One level unless the variant is about levels (the command line's default is automatic).
  run fifo --lod_levels 1
  run visible_pixels --order visible_pixels --lod_levels 1
  run reprojection --decision reprojection --lod_levels 1
  run incremental_statistics --incremental_statistics 1 --lod_levels 1
  run automatic_levels  # the command line's default: --lod_levels 0 --lod_threshold_scale 1.2
  local levels band
  for levels in 2 3 4; do
    for band in 1 2; do run "lod${levels}_band${band}" --lod_levels "$levels" --lod_band "$band"; done
    # Every level at the final threshold (before --lod_threshold_scale).
    run "lod${levels}_band1_same_threshold" --lod_levels "$levels" --lod_band 1 \
      --lod_threshold_scale 1
    # The full photos at every level (before photos were reduced).
    run "lod${levels}_band1_full_photos" --lod_levels "$levels" --lod_band 1 --lod_reduce_images 0
  done
}
