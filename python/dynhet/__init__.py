"""dynhet's Python side: reading runs and studies, running studies, the
cross-run analysis and its figures. The C++ engine and nodes write run.h5;
everything above a single run lives here (launch_scripts/ holds the thin
commands users type)."""
