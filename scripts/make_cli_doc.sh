#!/usr/bin/env bash
# docs/cli.md, every command's options, made from the same definitions as `--help`
# (`raycarve <command> --help_markdown`).
# Usage: scripts/make_cli_doc.sh [RAYCARVE] [OUTPUT]   (defaults: build/plugin/raycarve, docs/cli.md)
#        scripts/make_cli_doc.sh --check RAYCARVE DOC   exit 1, with the difference, when DOC is stale
set -euo pipefail
check=0
if [ "${1:-}" = "--check" ]; then check=1; shift; fi
raycarve=${1:-build/plugin/raycarve}
output=${2:-$(dirname "$0")/../docs/cli.md}
commands="carve holdout benchmark compare sfm calibrate model_info model_converter import_middlebury check_background render synth"
generate() {
  echo "# raycarve command line"
  echo
  echo "Every command's options, by group, as \`raycarve <command> --help all\` prints them. Made by"
  echo "\`scripts/make_cli_doc.sh\` from the options' definitions; a test checks that it is current."
  echo "Options marked * are the ones \`--help\` shows first. Every command also takes"
  echo "\`--project_path FILE.ini\` (COLMAP's option files) and glog's \`--log_to_stderr\`, \`--log_level\`, \`--v\`."
  for command in $commands; do
    echo
    "$raycarve" "$command" --help_markdown
  done
  for step in plan run merge; do
    echo
    "$raycarve" tile "$step" --help_markdown
  done
}
if [ $check -eq 1 ]; then
  if ! diff <(generate) "$output"; then
    echo "$output is stale: run scripts/make_cli_doc.sh (the lines above marked < are what the options say now)"
    exit 1
  fi
  echo "$output is current"
else
  generate > "$output.tmp" && mv "$output.tmp" "$output"
fi
