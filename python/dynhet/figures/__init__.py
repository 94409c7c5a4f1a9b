"""The figures of one run, each read through dynhet.run: overlap, chi4,
msd, displacement, clusters, s4 (main(RUN.h5, OUT.png) each, over common);
launch_scripts/plot_<observable>.py are their commands."""
