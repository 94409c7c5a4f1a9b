"""The paper's results from a study's runs, by section of the paper
(overlap, transport, clusters, chi4_s4, cutoff, restitution, appendix,
size, driving), over points and fits (points, quantities, verdicts) and
written out by output; cli is analyse_study.sh's command line."""
