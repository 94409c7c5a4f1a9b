"""dynhet's Python side: reading runs and studies, running studies, the
cross-run analysis and its figures. The C++ engine and nodes write run.h5;
everything above a single run lives here (launch_scripts/ holds the thin
commands users type).

    import dynhet
    run = dynhet.open_run("runs/default/run.h5")     # run.Run
    study = dynhet.open_study("runs/study-quick")     # analysis.study.Analysis
    phi, tau, err, seeds = study.against_phi("tau_alpha")

Modules: run (one run.h5), fits (cross-run fits), study/ (study files,
run lengths, executors), analysis/ (the paper's results by section).
"""
from .run import Observable, Run, open_run  # noqa: F401


def open_study(directory, also=()):
    """A study directory's complete runs as points (analysis.study.Analysis):
    .points, .series(pairs, eps), .against_phi(quantity), ..."""
    from .analysis.study import Analysis
    return Analysis(directory, also)
