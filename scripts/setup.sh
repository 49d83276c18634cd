#!/usr/bin/env bash
# Installs what demx's tests and comparisons need on a fresh Debian machine:
# the real engines (LIGGGHTS 3.8 and LAMMPS with the GRANULAR package) and their
# example decks, and the font of `--plot` charts (fonts-dejavu-core). Safe to
# rerun; does nothing when everything is present.
set -euo pipefail
need=()
command -v liggghts >/dev/null 2>&1 || need+=(liggghts)
command -v lmp >/dev/null 2>&1 || need+=(lammps)
[ -d /usr/share/doc/liggghts/examples ] || need+=(liggghts-doc)
[ -d /usr/share/lammps/examples ] || need+=(lammps-examples)
[ -f /usr/share/fonts/truetype/dejavu/DejaVuSans.ttf ] || need+=(fonts-dejavu-core)
if [ ${#need[@]} -gt 0 ]; then
  SUDO=""
  [ "$(id -u)" -eq 0 ] || SUDO="sudo"
  echo "setup: installing ${need[*]}" >&2
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq "${need[@]}" >/dev/null
fi
(cd "${TMPDIR:-/tmp}" && liggghts -h 2>/dev/null | head -1 >&2) || true  # -h writes log.liggghts in the working directory
lmp -h 2>/dev/null | sed -n 2p >&2 || true
