#!/usr/bin/env python3
"""The paper's results from a study's runs: see python/dynhet/analysis/cli.py
(analyse_study.sh STUDY_DIR --help)."""
import os
import sys
import warnings

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "python"))
from dynhet.analysis.cli import main  # noqa: E402

if __name__ == "__main__":
    warnings.simplefilter("ignore", RuntimeWarning)
    sys.exit(main())
