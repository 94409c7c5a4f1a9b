#!/usr/bin/env python3
"""The paper's results from a study's runs: see python/dynhet/analysis/cli.py
(analyse_study.sh STUDY_DIR --help)."""
import sys
import warnings

from dynhet.analysis.cli import main

if __name__ == "__main__":
    warnings.simplefilter("ignore", RuntimeWarning)
    sys.exit(main())
