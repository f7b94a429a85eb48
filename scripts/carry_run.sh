#!/bin/bash
# Carries an unfinished training across machines through git: runs/ is not
# committed, and a long training (the dataset table's, docs/results.md) lasts
# longer than one machine's session.
#
#   scripts/carry_run.sh save NAME     runs/NAME -> assets/runs/NAME (commit it)
#   scripts/carry_run.sh restore NAME  assets/runs/NAME -> runs/NAME, then
#                                      build/mimic2d train CONFIG --resume
#
# Only what --resume needs travels: checkpoint.pt (networks, optimizer,
# normalizer, ASI buffers, counters), train_log.csv and config.yaml. The
# bundles the config names are rebuilt by their own script (deterministic).
# A checkpoint too big to commit goes slim first (`build/mimic2d checkpoint
# slim runs/NAME/checkpoint.pt -o runs/NAME/checkpoint.pt`): without the
# ASI buffers, which the resumed run refills from its bundles.
# restore refuses to replace a run that has trained further.
set -euo pipefail
cd "$(dirname "$0")/.."
usage() { echo "usage: $0 save|restore NAME" >&2; exit 2; }
[ $# -eq 2 ] || usage
action=$1 name=$2
run=runs/$name carried=assets/runs/$name
files=(checkpoint.pt train_log.csv config.yaml)

samples() {  # the last logged sample count of a run folder (0 if none)
  local log=$1/train_log.csv
  [ -f "$log" ] || { echo 0; return; }
  tail -n 1 "$log" | awk -F, '$2 ~ /^[0-9]+$/ {print $2; exit} {print 0}'
}

case $action in
  save) from=$run to=$carried ;;
  restore) from=$carried to=$run ;;
  *) usage ;;
esac
for file in "${files[@]}"; do
  [ -f "$from/$file" ] || { echo "carry_run: $from/$file not found" >&2; exit 1; }
done
if [ "$action" = restore ] && (( $(samples "$to") > $(samples "$from") )); then
  echo "carry_run: $to has trained further ($(samples "$to") samples) than" \
    "$from ($(samples "$from")); not replaced" >&2
  exit 1
fi
# Copy beside, then rename: an interrupted copy never leaves a mixed run.
mkdir -p "$to"
for file in "${files[@]}"; do
  cp "$from/$file" "$to/.$file.tmp"
done
for file in "${files[@]}"; do
  mv "$to/.$file.tmp" "$to/$file"
done
echo "carry_run: $action $name: $(samples "$to") samples in $to"
