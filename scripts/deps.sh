#!/usr/bin/env bash
# Installs, from Debian's packages, whatever sfsim needs to build, test and run and is missing.
# Used by `make run`, `make test` and CI alike; does nothing when everything is present.
# `scripts/deps.sh slurm` installs instead the optional group for `make test-slurm`: Slurm's
# controller, node daemon and client commands, and munge (tests/slurm/run.sh).
set -euo pipefail

case "${1:-}" in
"")
  PKGS=(
    build-essential pkg-config clang libclang-rt-14-dev
    libtinygltf-dev nlohmann-json3-dev libstb-dev
    libopenimageio-dev openimageio-tools
    libopenexr-dev libpng-dev libfreetype-dev
    fonts-dejavu-core
    libinih-dev libcjson-dev libcriterion-dev
    libembree-dev gnuplot-nox parallel
    libtinyobjloader-dev libgsl-dev
  )
  ;;
slurm)
  PKGS=(slurmctld slurmd slurm-client munge)
  ;;
*)
  echo "usage: scripts/deps.sh [slurm]" >&2
  exit 2
  ;;
esac

missing=()
for p in "${PKGS[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done
[ ${#missing[@]} -eq 0 ] && exit 0

echo "deps: installing missing Debian packages: ${missing[*]}"
SUDO=""
[ "$(id -u)" -ne 0 ] && SUDO="sudo"
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
echo "deps: done"
