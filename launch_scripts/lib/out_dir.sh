# Sourced by the launch scripts that write into a directory (run_scene.sh,
# replay.sh): not a command. A command never writes over results it did not
# write for the same purpose; it names what is there and, with --fresh,
# moves it aside (never deletes it).

# held DIR PATTERN...: the entries of DIR that match the shell patterns, one
# a line (none when DIR does not exist).
held() {
  local dir=$1 p f
  shift
  [[ -d $dir ]] || return 0
  for p in "$@"; do
    for f in "$dir"/$p; do [[ -e $f || -L $f ]] && echo "${f##*/}"; done
  done | sort -u
}

# move_aside DIR NAME...: moves these entries of DIR into a new directory
# DIR/old-<time> (old-<time>-2, ... if it exists) and prints its path.
move_aside() {
  local dir=$1 to k=1 f
  shift
  to=$dir/old-$(date +%Y%m%d-%H%M%S)
  while [[ -e $to ]]; do k=$((k + 1)); to=$dir/old-$(date +%Y%m%d-%H%M%S)-$k; done
  mkdir -p "$to"
  for f in "$@"; do mv -- "$dir/$f" "$to/"; done
  echo "$to"
}

# complete_run FILE: whether FILE is a run.h5 marked complete.
complete_run() {
  /usr/bin/python3 -c "import h5py, sys; sys.exit(0 if int(h5py.File(sys.argv[1], 'r').attrs.get('complete', 0)) == 1 else 1)" \
    "$1" 2>/dev/null
}
