#!/bin/sh
# Rerun the real engines on the shortened tutorial decks with the settings the
# tests use, and store step/atoms/ke of every thermo line in <deck>.engine.txt.
# Usage: tests/decks/tutorials/engines.sh   (needs liggghts and lmp on PATH)
set -e
here=$(cd "$(dirname "$0")" && pwd)
run() { # dir deck engine vars...
    dir=$1; deck=$2; eng=$3; shift 3
    tmp=$(mktemp -d); cp -r "$here/$dir/." "$tmp/"; mkdir -p "$tmp/post"
    (cd "$tmp" && $eng -in "$deck" -log none "$@" > screen.txt 2>&1)
    { echo "# $eng -in $deck $* (in a copy of tests/decks/tutorials/$dir)"; echo "# step atoms ke"
      awk '/^ *Step/{on=1; next} /^Loop time/{on=0} on && $1 ~ /^[0-9]+$/ {print $1, $2, $3}' "$tmp/screen.txt"; } > "$here/$dir/$deck.engine.txt"
    rm -rf "$tmp"
}
run insert_stream in.insert_stream liggghts -var nrun 3000 -var nthermo 500 -var ndump 1000
run packing in.packing liggghts -var growts_n 400 -var relaxts_n 400 -var nthermo 100
run cohesion in.cohesion liggghts -var nins 3100 -var nend 3200 -var nthermo 500
run cohesion in.noCohesion liggghts -var nins 3100 -var nend 3200 -var nthermo 500
run pour in.pour lmp -var nrun1 4000 -var nrun2 500 -var nthermo 500
run pour in.pour.2d lmp -var nrun1 4000 -var nthermo 500
