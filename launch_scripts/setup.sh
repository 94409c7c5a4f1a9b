#!/usr/bin/env bash
# Installs what dynhet needs from Debian packages (only what is missing) and
# builds it with CMake in Release mode. Idempotent; quiet unless something
# fails. Usage: launch_scripts/setup.sh [--force]   (env BUILD_DIR, default ./build)
#
# A build whose id would change (another commit, other uncommitted changes)
# is refused (exit 2) while a process runs a program of that build
# directory: a run's checkpoints carry its build's id, and a resume refuses
# another's, so the running sims could no longer resume from what they
# write. The refusal names them. Build into another BUILD_DIR, or let them
# finish; --force builds anyway (they resume then only with a build of
# their own commit, which gives the same id again). Runs interrupted
# earlier, or queued on Slurm, are not seen here: they too resume only with
# their own build.
set -euo pipefail
force=0
case ${1:-} in
  -h | --help) awk 'NR > 1 && !/^#/ { exit } NR > 1 { sub(/^# ?/, ""); print }' "$0"; exit 0 ;;
  --force) force=1 ;;
  "") ;;
  *) echo "setup: unknown argument '$1' (setup.sh [--force]; see --help)" >&2; exit 2 ;;
esac
root=$(cd "$(dirname "$0")/.." && pwd)
build=${BUILD_DIR:-$root/build}

# The processes running a program of build directory $1, a line each (pid and command).
running_from() {
  local dir exe pid
  dir=$(realpath -m "$1")
  for exe in /proc/[0-9]*/exe; do
    pid=${exe#/proc/}; pid=${pid%/exe}
    [[ $(readlink "$exe" 2>/dev/null) == "$dir"/* ]] || continue
    echo "  pid $pid: $({ tr '\0' ' ' <"/proc/$pid/cmdline"; } 2>/dev/null | cut -c1-160)"
  done
}

# Refuses (exit 2) a build that would change the id of a build directory
# whose programs are running.
guard_running_build() {
  local old new_file new procs version
  [[ -f $build/common/build_id.cpp ]] || return 0
  procs=$(running_from "$build")
  [[ -n $procs ]] || return 0
  version=$(sed -n 's/^project(dynhet VERSION \([0-9.]*\).*/\1/p' "$root/CMakeLists.txt")
  new_file=$(mktemp)
  cmake -DSRC="$root" -DOUT="$new_file" -DVERSION="$version" -P "$root/common/build_id.cmake"
  old=$(sed -n 's/.*kBuildId = "\(.*\)";/\1/p' "$build/common/build_id.cpp")
  new=$(sed -n 's/.*kBuildId = "\(.*\)";/\1/p' "$new_file")
  rm -f "$new_file"
  [[ $old != "$new" ]] || return 0
  if ((force)); then
    echo "setup: --force: building $new over $old while its programs run" >&2
    return 0
  fi
  cat >&2 <<MSG
setup: refused: $build is build $old, and these processes run its programs:
$procs
Building there now would make it build $new. Their checkpoints carry the
old id, and a resume refuses another build's, so they could not resume from
what they write. Build into another directory (BUILD_DIR=<dir> $0),
or let them finish (or stop them and resume them first); \`$0 --force\`
builds anyway (then run_scene.sh, run_study.sh or reproduce.sh with --no-build).
MSG
  exit 2
}

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

guard_running_build
if [[ ! -f "$build/CMakeCache.txt" ]]; then
  cmake -S "$root" -B "$build" -DCMAKE_BUILD_TYPE=Release >"$build.configure.log" 2>&1 ||
    { cat "$build.configure.log" >&2; exit 1; }
fi
cmake --build "$build" -j"$(nproc)" >"$build.build.log" 2>&1 || { tail -50 "$build.build.log" >&2; exit 1; }
