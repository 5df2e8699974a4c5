#!/usr/bin/env bash
# Checks the dependency direction of ../shared/STYLE.md on the source tree given as $1:
# calib <- carve <- export <- pipeline <- plugin; carve does no file I/O and uses no PCL; PCL only
# in export/*.cc; Ceres only in .cc files; carve's internal headers (the first line says
# "Internal to carve/", "Internal to calib/") are included only inside their folder and its tests. Prints every violation and exits 1 if there is any.
set -u
root=${1:-.}
cd "$root" || exit 2
status=0
report() { echo "dependency violation: $1"; echo "$2" | sed 's/^/    /'; status=1; }

hits=$(grep -rnE '#include *"(carve|export|pipeline|plugin|samples)/' calib 2>/dev/null)
[ -n "$hits" ] && report "calib/ may use nothing of ours" "$hits"
hits=$(grep -rnE '#include *"(export|pipeline|plugin|samples)/' carve 2>/dev/null)
[ -n "$hits" ] && report "carve/ may use only calib/" "$hits"
hits=$(grep -rnE '#include *"(pipeline|plugin|samples)/' export 2>/dev/null)
[ -n "$hits" ] && report "export/ may use only carve/ and calib/" "$hits"
hits=$(grep -rnE '#include *"(plugin|samples)/' pipeline 2>/dev/null)
[ -n "$hits" ] && report "pipeline/ may use only export/, carve/ and calib/" "$hits"
hits=$(grep -rnE '#include *"(pipeline|plugin)/' samples 2>/dev/null)
[ -n "$hits" ] && report "samples/ may not use pipeline/ or plugin/" "$hits"
for folder in calib carve samples; do
  internal=$(grep -lE "^// Internal to $folder/" $folder/*.h 2>/dev/null | sed 's|^|#include "|; s|$|"|')
  [ -z "$internal" ] && continue
  others=$(ls -d calib carve export pipeline plugin samples benchmarks tests/* 2>/dev/null | grep -vE "^($folder|tests/$folder)$")
  hits=$(grep -rnF "$internal" $others 2>/dev/null)
  [ -n "$hits" ] && report "$folder's internal headers are included only in $folder/ (and its tests)" "$hits"
done
hits=$(grep -rnE 'imread|imwrite|std::ifstream|std::ofstream|std::filesystem|fopen\(|#include *<(fstream|filesystem)>|#include *<pcl/|std::cout|printf\(' carve 2>/dev/null)
[ -n "$hits" ] && report "carve/ does no file I/O, no printing and no PCL" "$hits"
hits=$(grep -rnE '#include *<pcl/' --include='*.h' . 2>/dev/null; grep -rlE '#include *<pcl/' --include='*.cc' calib carve pipeline plugin samples 2>/dev/null)
[ -n "$hits" ] && report "PCL appears only in export/*.cc" "$hits"
hits=$(grep -rnE '#include *<ceres/' --include='*.h' calib carve export pipeline plugin samples 2>/dev/null)
[ -n "$hits" ] && report "Ceres headers only inside .cc files" "$hits"
hits=$(grep -rnE 'std::cout|std::cerr|printf\(' calib carve export pipeline 2>/dev/null | grep -v snprintf)
[ -n "$hits" ] && report "no printing in library code (use glog)" "$hits"
[ $status -eq 0 ] && echo "dependency direction holds"
exit $status
