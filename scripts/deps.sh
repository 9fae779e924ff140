#!/usr/bin/env bash
# Installs the packages caracarad needs to build, test and run, on Debian 12 or 13 (Raspberry Pi
# OS bookworm or trixie). Idempotent.
set -euo pipefail
# stress-ng: the loaded bench (bench/run.py phase loaded).
# Catch2: "catch2" on Debian 12 (2.13); on Debian 13 "libcatch2-dev" (3.x; "catch2" is only a
# transitional name there). libgpiod-dev is 1.6 on 12 and 2.2 on 13, the build takes either.
# Fast DDS (the ros tests' peer): libfastrtps-dev 2.9 on Debian 12, libfastdds-dev 3.1 on 13.
catch2=libcatch2-dev
fastdds=libfastdds-dev
if [ "$(. /etc/os-release && echo "${VERSION_CODENAME:-}")" = bookworm ]; then
  catch2=catch2
  fastdds=libfastrtps-dev
fi
pkgs=(build-essential cmake pkg-config libsystemd-dev libgpiod-dev "$catch2" libtomlplusplus-dev
      dbus python3 python3-dbus python3-gi python3-yaml systemd debootstrap systemd-container valgrind stress-ng
      clang libclang-rt-dev python3-matplotlib python3-pil ccache libboost-dev nlohmann-json3-dev openssh-client
      udev)
# udev: the kernel test applies the shipped udev rules with systemd-udevd (devices_for_the_daemon_alone).
# caracara-ros (tools/ros): Cyclone DDS and its IDL compiler; its tests' second DDS vendor, Fast DDS
# with fastddsgen (tests/ros), and iproute2 for the private network namespace.
pkgs+=(cyclonedds-dev cyclonedds-tools "$fastdds" fastddsgen iproute2)
# Node.js and npm for the bridge's tests (tests/bridge: the Foxglove and MCAP reference
# implementations): Debian's only when no node with npm is there, since Debian's npm conflicts
# with other nodejs builds (NodeSource's bundles its own npm).
if ! command -v node >/dev/null || ! command -v npm >/dev/null; then
  pkgs+=(nodejs npm)
fi
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
