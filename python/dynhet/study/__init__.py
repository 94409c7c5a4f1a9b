"""Studies: a sweep of scenes run on this machine or on a Slurm cluster,
resumable. The study file (model), what runs cost (estimates), the study
directory on disk (rundir, index), one run (runner over children and
states), the executors (local, slurm), and study.py's command line (cli)."""
