#!/usr/bin/env bash
# Installs what dynhet needs from Debian packages (only what is missing) and
# builds it with CMake in Release mode. Idempotent; quiet unless something
# fails. Usage: launch_scripts/setup.sh   (env BUILD_DIR, default ./build)
set -euo pipefail
case ${1:-} in -h | --help) awk 'NR > 1 && !/^#/ { exit } NR > 1 { sub(/^# ?/, ""); print }' "$0"; exit 0 ;; esac
root=$(cd "$(dirname "$0")/.." && pwd)
build=${BUILD_DIR:-$root/build}

# Java: the headless JDK builds the types' and the lcm-spy plugins' jars;
# default-jre is the JRE with a GUI that lcm-spy and lcm-logplayer-gui need.
packages=(build-essential cmake pkg-config git
  liblcm-dev liblcm-bin liblcm-java libglib2.0-dev default-jdk-headless default-jre libjchart2d-java
  libeigen3-dev libfftw3-dev libhdf5-dev hdf5-tools libgtest-dev
  libtomlplusplus-dev libcli11-dev zlib1g-dev libcgal-dev libsodium-dev
  python3-matplotlib python3-h5py python3-numpy python3-scipy python3-pytest
  python3-gsd python3-mdanalysis python3-xarray iproute2 util-linux xvfb xauth
  slurmctld slurmd slurm-client munge)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]})); then
  echo "setup: installing ${missing[*]}" >&2
  sudo=""; [[ $EUID -ne 0 ]] && sudo=sudo
  export DEBIAN_FRONTEND=noninteractive
  $sudo apt-get update -qq >/dev/null
  $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi

if [[ ! -f "$build/CMakeCache.txt" ]]; then
  cmake -S "$root" -B "$build" -DCMAKE_BUILD_TYPE=Release >"$build.configure.log" 2>&1 ||
    { cat "$build.configure.log" >&2; exit 1; }
fi
cmake --build "$build" -j"$(nproc)" >"$build.build.log" 2>&1 || { tail -50 "$build.build.log" >&2; exit 1; }
