#!/bin/sh
# Runs a program under the fixed policy at several frame rates and checks that every row whose simulated time two
# runs share holds the same bytes in the first COLUMNS columns (time and the followed quantities; the count columns
# after them say what each frame did, which differs by frame rate). Frames that take no step repeat a time within one
# run: they must repeat its values too.
# Usage: same_at_every_rate.sh PROGRAM COLUMNS OUT_PREFIX [PROGRAM FLAGS...]
set -eu
program=$1 columns=$2 out=$3
shift 3
files=""
for run in fixed:144:1 fixed:60:1 fixed:30:1 uniform:15:45:1 uniform:15:45:2 uniform:15:45:3 jitter:60:2:1; do
  profile=${run%:*} seed=${run##*:}
  file="$out.$(echo "$profile" | tr : _).$seed.csv"
  "$program" --policy fixed --profile "$profile" --seed "$seed" "$@" > "$file"
  files="$files $file"
done
# shellcheck disable=SC2086
awk -F, -v columns="$columns" '
  FNR == 1 { next }
  {
    row = $1
    for (i = 2; i <= columns; ++i) row = row "," $i
    if (!($1 in first)) { first[$1] = row; file[$1] = FILENAME; next }
    if (first[$1] != row) { printf "differs at t = %s s:\n  %s: %s\n  %s: %s\n", $1, file[$1], first[$1], FILENAME, row; bad = 1 }
    else if (file[$1] != FILENAME) shared += 1
  }
  END {
    if (bad) exit 1
    if (shared < 500) { print "only " shared " rows shared between runs"; exit 1 }
    print shared " rows at shared times, byte-identical across 7 runs"
  }' $files
