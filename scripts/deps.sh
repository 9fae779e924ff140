#!/usr/bin/env bash
# Installs the Debian 12 packages caracarad needs to build, test and run. Idempotent.
set -euo pipefail
pkgs=(build-essential cmake pkg-config libsystemd-dev libgpiod-dev catch2 libtomlplusplus-dev
      dbus python3 python3-dbus python3-gi systemd debootstrap systemd-container valgrind
      clang libclang-rt-dev)
missing=()
for p in "${pkgs[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]})); then
  sudo=""
  [ "$(id -u)" -eq 0 ] || sudo="sudo"
  echo "deps: installing ${missing[*]}"
  $sudo apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi
