#!/usr/bin/env bash
# Installs what demx's tests and comparisons need on a fresh Debian machine:
# the real engines (LIGGGHTS 3.8 and LAMMPS with the GRANULAR package) and their
# example decks, the font of `--plot` charts (fonts-dejavu-core), and Slurm
# with munge (slurm-wlm: the one-node cluster of scripts/slurm_local.sh, which
# the Slurm backend's test runs on). Safe to rerun; does nothing when
# everything is present.
set -euo pipefail
need=()
command -v liggghts >/dev/null 2>&1 || need+=(liggghts)
command -v lmp >/dev/null 2>&1 || need+=(lammps)
[ -d /usr/share/doc/liggghts/examples ] || need+=(liggghts-doc)
[ -d /usr/share/lammps/examples ] || need+=(lammps-examples)
[ -f /usr/share/fonts/truetype/dejavu/DejaVuSans.ttf ] || need+=(fonts-dejavu-core)
command -v sbatch >/dev/null 2>&1 || need+=(slurm-wlm)
command -v munged >/dev/null 2>&1 || need+=(munge)
if [ ${#need[@]} -gt 0 ]; then
  SUDO=""
  [ "$(id -u)" -eq 0 ] || SUDO="sudo"
  echo "setup: installing ${need[*]}" >&2
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq "${need[@]}" >/dev/null
fi
(cd "${TMPDIR:-/tmp}" && liggghts -h 2>/dev/null | head -1 >&2) || true  # -h writes log.liggghts in the working directory
lmp -h 2>/dev/null | sed -n 2p >&2 || true
