#!/usr/bin/python3
"""dynhet studies: launch_scripts/run_study.sh is the command, this its
entry point into python/dynhet/study (see dynhet/study/cli.py for usage:
study.py run STUDY.toml ..., study.py task DIR NAME, study.py index DIR)."""
import sys

from dynhet.study.cli import main

if __name__ == "__main__":
    sys.exit(main())
