#!/bin/sh
# Rerun the real engines (LIGGGHTS 3.8 `liggghts`, LAMMPS 29Sep2021 `lmp`) on
# the validation decks in templates/ and store their dumps under
# reference/<engine>/<case>/ (dump.gz, log.gz, version.txt, command.txt,
# deck copy). tolerance.json files are written by hand and kept.
#
# Usage: scripts/reference.sh [case ...]   (default: all cases)
# Cases: headon oblique drop settle.  Env: LIGGGHTS=..., LMP=... binaries.
set -eu

root=$(cd "$(dirname "$0")/.." && pwd)
liggghts=${LIGGGHTS:-liggghts}
lmp=${LMP:-lmp}

deck_dir() {
    case "$1" in
        headon|oblique) echo "$root/templates/two_sphere" ;;
        drop) echo "$root/templates/drop" ;;
        settle) echo "$root/templates/settle" ;;
        *) echo "unknown case '$1'" >&2; exit 2 ;;
    esac
}

run_one() { # engine case
    engine=$1
    case_=$2
    dir=$(deck_dir "$case_")
    case "$engine" in
        liggghts) deck="$dir/in.$case_.liggghts"; bin=$liggghts ;;
        lammps) deck="$dir/in.$case_.lammps"; bin=$lmp ;;
    esac
    out="$root/reference/$engine/$case_"
    mkdir -p "$out"
    tmp=$(mktemp -d)
    cp "$deck" "$tmp/in.deck"
    (cd "$tmp" && "$bin" -in in.deck -log log.txt -echo none -screen none) || {
        echo "$engine failed on $case_ (see $tmp)" >&2
        exit 1
    }
    if [ "$engine" = liggghts ]; then
        "$bin" -h 2>/dev/null | grep -m1 'LIGGGHTS (Version' > "$out/version.txt" || true
    else
        "$bin" -h 2>/dev/null | grep -m1 'Large-scale' | sed 's/^ *//' > "$out/version.txt" || true
    fi
    echo "cd <tmpdir> && $bin -in in.deck -log log.txt -echo none -screen none   # in.deck = ${deck#$root/}" > "$out/command.txt"
    cp "$deck" "$out/$(basename "$deck")"
    # drop wall-clock lines so reruns only differ where physics differs
    grep -v -e '^Loop time' -e 'finish time' -e 'Setting up run at' -e '^Memory usage' -e 'Total wall time' \
        -e 'CPU' -e '|' -e 'time (%)' -e '^Performance' -e '^Nlocal' -e '^Nghost' -e '^Neighs' -e '^Histogram' "$tmp/log.txt" \
        | gzip -n -9 > "$out/log.gz"
    gzip -n -9 -c "$tmp/dump.$case_" > "$out/dump.gz"
    rm -rf "$tmp"
    echo "stored reference/$engine/$case_"
}

cases=${*:-headon oblique drop settle}
for c in $cases; do
    run_one liggghts "$c"
    run_one lammps "$c"
done
