#!/usr/bin/env bash
# Installs the Debian packages hardbody needs (idempotent; root or sudo).
set -euo pipefail
pkgs=(build-essential cmake pkg-config
      libeigen3-dev libtomlplusplus-dev libcli11-dev libfmt-dev nlohmann-json3-dev libpcg-cpp-dev
      libgtest-dev libgmock-dev libbenchmark-dev pybind11-dev python3-dev
      python3-numpy python3-gsd python3-matplotlib python3-pytest
      snakemake)   # hardbody campaign: the local executor (Slurm itself: scripts/slurm-local.sh)
missing=()
for p in "${pkgs[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then exit 0; fi
echo "installing: ${missing[*]}" >&2
SUDO=""; [ "$(id -u)" -eq 0 ] || SUDO=sudo
$SUDO apt-get update -qq
DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
