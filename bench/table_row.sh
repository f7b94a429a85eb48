#!/bin/bash
# One row of a results table (bench/dataset_table.sh, bench/dog_table.sh):
# `mimic2d eval` of a checkpoint, its "all" line as a Markdown row. Sourced,
# not run.
#
#   TABLE_BIN=build/mimic2d           # the mimic2d binary (default)
#   TABLE_OBJECTS=1                   # add an EO2D column (the ball's 2D
#                                     # error; default 0: no column)
#   table_header                      # the table's first two lines
#   table_row NAME CLIPS NOISE CHECKPOINT OUT_PREFIX [EVAL FLAGS...]
#
# table_row writes the eval's table to OUT_PREFIX.txt and its JSON to
# OUT_PREFIX.json. A missing checkpoint's row says so and the table goes
# on; a failed eval, or one that printed no "all" line, is an error naming
# OUT_PREFIX.txt (never a row with empty cells).

TABLE_BIN=${TABLE_BIN:-build/mimic2d}
TABLE_OBJECTS=${TABLE_OBJECTS:-0}

table_header() {
  local eo2d="" rule=""
  if [ "$TABLE_OBJECTS" = 1 ]; then eo2d=" EO2D (px) |" rule="---|"; fi
  echo "| method | clips | 2D | Succ % | E2D (px) |$eo2d E3D (mm) | E3D root-rel. (mm) | PA-MPJPE (mm) | Jitter (10^3 m/s^3) |"
  echo "|---|---|---|---|---|$rule---|---|---|---|"
}

table_row() {
  local name=$1 clips=$2 noise=$3 checkpoint=$4 prefix=$5
  shift 5
  if [ ! -f "$checkpoint" ]; then
    local cells="| | | | | |"
    if [ "$TABLE_OBJECTS" = 1 ]; then cells="| | | | | | |"; fi
    echo "| $name | $clips | $noise | (no checkpoint $checkpoint) $cells"
    return 0
  fi
  if ! "$TABLE_BIN" eval "$checkpoint" "$@" -o "$prefix.json" \
    > "$prefix.txt" 2>&1; then
    echo "table_row: the eval of $checkpoint failed, see $prefix.txt:" >&2
    tail -n 3 "$prefix.txt" >&2
    return 1
  fi
  # The "all" line: clip view eps frames Succ% E2D EO2D E3D E3Droot E3DPA
  # Jitter. (mawk, Debian's awk, reserves `split`: the clips go in as
  # `clips`.)
  local line
  line=$(awk -v name="$name" -v clips="$clips" -v noise="$noise" \
    -v objects="$TABLE_OBJECTS" '
    $1 == "all" && NF == 11 {
      eo2d = objects == 1 ? " " $7 " |" : ""
      printf "| %s | %s | %s | %s | %s |%s %s | %s | %s | %s |\n",
             name, clips, noise, $5, $6, eo2d, $8, $9, $10, $11 }' "$prefix.txt")
  if [ -z "$line" ]; then
    echo "table_row: no \"all\" line of 11 columns in $prefix.txt" >&2
    return 1
  fi
  echo "$line"
}
